//! Mara's and SVGF's filters keep the mean of the light they filter: on a plane lit evenly and
//! on a plane lit from one side (a gradient of 13:1 across the image, curved as a small area
//! light's falloff is), the denoised image's mean over each band across the gradient is the
//! converged image's. A filter whose weights lean one way along a gradient (a luminance
//! edge-stop that prefers the darker side, a regression whose window is cut at the image's
//! border, a blur that does not shrink as the history converges) moves light from one band to
//! another, a bias no number of frames removes. The progressive filter's weight reads the light
//! as it is shown, so a dim floor shown brighter keeps its gradient.

use glam::Vec3;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::quality::{Image, luminance};
use hush_engine::scene::Scene;
use hush_engine::settings::{Denoiser, FrameSettings, TaaSettings};
use hush_tests::gltf_writer::floor_under_light;

const SIZE: u32 = 64;
const BANDS: usize = 8;

/// Lit evenly: a 20 m emitter 1 m above a floor seen over about half a metre.
fn even() -> Scene {
    floor_under_light("bias_even", (Vec3::new(0.0, 1.0, 0.0), 10.0, 1.0), [0.0, 0.5, 0.0])
}

/// Lit from one side: a 40 cm emitter 60 cm up and 1.5 m off, well outside the view, its light
/// falling off to about 1/13 across the 1.3 m the camera sees (tests/area_light.rs checks this
/// light against a quadrature of the emitter).
fn from_one_side() -> Scene {
    // Written and loaded once: both tests use it, and two threads writing the same file raced.
    static SCENE: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    SCENE
        .get_or_init(|| {
            floor_under_light("bias_side", (Vec3::new(-1.5, 0.6, 0.0), 0.2, 10.0), [0.0, 1.2, 0.0])
        })
        .clone()
}

/// The mean luminance of each of BANDS vertical bands (across x, the gradient's direction).
fn bands(img: &Image) -> [f64; BANDS] {
    let mut sum = [0f64; BANDS];
    let w = img.width as usize;
    for (i, v) in img.data.iter().enumerate() {
        sum[(i % w) * BANDS / w] += luminance(*v) as f64;
    }
    let per_band = (img.data.len() / BANDS) as f64;
    sum.map(|s| s / per_band)
}

fn render(scene: &Scene, s: &FrameSettings, frames: u32) -> Image {
    let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, (SIZE, SIZE)).unwrap();
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    for _ in 0..frames {
        r.render(&gpu, &input, s, None).unwrap();
    }
    r.read_hdr(&gpu).unwrap()
}

/// The band means of 1024 accumulated frames of the floor lit from one side: both tests score
/// against it, and the first to ask renders it once for both (about 15 s on lavapipe).
fn from_one_side_reference() -> [f64; BANDS] {
    static REFERENCE: std::sync::OnceLock<[f64; BANDS]> = std::sync::OnceLock::new();
    *REFERENCE.get_or_init(|| {
        let accumulate = FrameSettings { accumulate: true, ..Default::default() };
        bands(&render(&from_one_side(), &accumulate, 1024))
    })
}

/// The denoiser's own image: TAA and the still-view mean after it off (the mean would replace a
/// biased pixel by the plain mean of its samples, hiding the filter's bias).
fn denoised(denoiser: Denoiser) -> FrameSettings {
    FrameSettings {
        denoiser,
        taa: TaaSettings { enabled: false, converge_sigmas: 0.0, ..Default::default() },
        ..Default::default()
    }
}

/// Mara's and SVGF's own images after 128 still frames against 1024 accumulated ones, band by
/// band. The floor's light is all direct (the floor sees nothing but the emitter), so a band's
/// mean over 512 pixels is known to about 0.2% after 128 frames (the plain accumulation of 128
/// frames departs from the 1024 by at most 0.18% in either scene); 1% is a bias. Measured, the
/// largest departure in any band: evenly lit, Mara 0.20%, SVGF 0.22%; lit from one side, Mara
/// 0.48%, SVGF 0.70% (both in the band at the image's edge nearest the light, where the filters
/// reach inwards only, over a falling light); SVGF without its luminance edge-stop (sigma_l 64)
/// and regression, 2.3%. The progressive filter is not held to it: its luminance weight's
/// epsilon is an amount of displayed light, as Dundr's (0.05, here 0.025 after 128 samples),
/// and this floor's light is 0.006 to 0.075 at the default exposure, so it blurs across the
/// gradient: 38% too bright in the darkest band (8% shown at +3.5 EV); what it shows, after TAA
/// and the still-view mean, departs by 0.97% (docs/decisions.md).
#[test]
fn mara_and_svgf_keep_the_mean_of_an_even_light_and_of_a_gradient() {
    for (name, scene) in [("even", even()), ("from one side", from_one_side())] {
        let accumulate = FrameSettings { accumulate: true, ..Default::default() };
        let reference = match name {
            "even" => bands(&render(&scene, &accumulate, 1024)),
            _ => from_one_side_reference(),
        };
        let plain = bands(&render(&scene, &accumulate, 128));
        let worst = |b: &[f64; BANDS]| {
            b.iter().zip(&reference).map(|(x, r)| (x / r - 1.0).abs()).fold(0.0, f64::max)
        };
        println!(
            "{name}: band means {reference:.4?}; 128 accumulated frames depart {:.4}",
            worst(&plain)
        );
        assert!(worst(&plain) < 0.004, "{name}: the accumulation's noise {}", worst(&plain));
        for d in [Denoiser::MARA, Denoiser::SVGF] {
            let b = bands(&render(&scene, &denoised(d.clone()), 128));
            println!("  {}: {b:.4?}, largest departure {:.4}", d.name(), worst(&b));
            assert!(
                worst(&b) < 0.01,
                "{name}, {}: band means {b:?} against {reference:?}",
                d.name()
            );
        }
    }
}

/// The progressive filter's luminance weight reads displayed light: the floor lit from one side,
/// shown at +3.5 EV (its brightest band at 0.85 on screen), keeps each band within 15% after 128
/// still frames (TAA and the still-view mean off). Measured: 8.4% in the darkest band, the
/// others within 2%; with epsilon in the light's own units, as at 0 EV, 38.4%.
#[test]
fn the_progressive_filter_weighs_light_as_it_is_shown() {
    let scene = from_one_side();
    let reference = from_one_side_reference();
    let shown_brighter = FrameSettings { exposure_ev: 3.5, ..denoised(Denoiser::PROGRESSIVE) };
    let b = bands(&render(&scene, &shown_brighter, 128));
    let worst = b.iter().zip(&reference).map(|(x, r)| (x / r - 1.0).abs()).fold(0.0, f64::max);
    println!(
        "progressive at +3.5 EV: {b:.4?} against {reference:.4?}, largest departure {worst:.4}"
    );
    assert!(worst < 0.15, "band means {b:?} against {reference:?}");
}
