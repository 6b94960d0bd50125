//! The still-view mean after TAA (engine/src/passes/converge.rs, shaders/taa/converge*.wgsl):
//! the image shown against a CPU computation of the blend, and the mean's restarts.

use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::Gpu;
use hush_engine::quality::Image;
use hush_engine::settings::{Denoiser, FrameSettings, TaaSettings};

const SIZE: (u32, u32) = (64, 64);

fn cornell() -> (Gpu, Renderer, FrameInput) {
    let dir = hush_tests::oracle("cornell_diffuse");
    let scene = hush_engine::scene::load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    let (gpu, r) = Renderer::headless(scene, BvhKind::DEFAULT, SIZE).unwrap();
    (gpu, r, input)
}

fn settings(bias_sigmas: f32) -> FrameSettings {
    let taa = TaaSettings {
        converge_sigmas: bias_sigmas,
        converge_min_samples: 4.0,
        ..Default::default()
    };
    FrameSettings { denoiser: Denoiser::MARA, taa, ..Default::default() }
}

fn floats(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

/// The mean (rgb, count) and the mean square that the renderer's `frames`-th frame wrote: frame
/// k reads slot k % 2 and writes the other (gpu::PingPong).
fn mean_now(gpu: &Gpu, r: &Renderer, frames: u32) -> (Vec<[f32; 4]>, Vec<f32>) {
    let read = |l: &str| floats(&r.read_texture(gpu, l).unwrap().0);
    let slot = frames % 2;
    let mean = read(&format!("converge/mean {slot}"));
    let m2 = read(&format!("converge/m2 {slot}"));
    (mean.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(), m2)
}

/// Two renderers on the same samples, the stage on in one: TAA's image is the other's (the stage
/// feeds nothing back). The image shown must be TAA's moved towards the mean by
/// w = b^2 / (b^2 + v) over the 3x3 window, as computed here from the read-back mean and mean
/// square; and the stage must move it (a blend that never engages would pass the first check).
#[test]
fn the_image_shown_is_the_minimum_error_blend_of_taa_and_the_mean() {
    let frames = 24;
    let (gpu, mut on, input) = cornell();
    let (gpu_off, mut off, _) = cornell();
    let (s_on, s_off) = (settings(1.0), settings(0.0));
    for _ in 0..frames {
        on.render(&gpu, &input, &s_on, None).unwrap();
        off.render(&gpu_off, &input, &s_off, None).unwrap();
    }
    let shown = on.read_hdr(&gpu).unwrap();
    let taa = off.read_hdr(&gpu_off).unwrap();
    let (mean, m2) = mean_now(&gpu, &on, frames);
    assert!(mean.iter().all(|m| m[3] == frames as f32), "every pixel counts every frame");
    let (w, h) = (SIZE.0 as i32, SIZE.1 as i32);
    let at = |img: &Image, x: i32, y: i32| img.data[(y * w + x) as usize];
    let (mut worst, mut moved, mut heavy) = (0.0f32, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let (mut e2, mut v) = (0.0f32, 0.0f32);
            for (dx, dy) in (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))) {
                let (qx, qy) = (x + dx, y + dy);
                if qx < 0 || qy < 0 || qx >= w || qy >= h {
                    continue;
                }
                let q = (qy * w + qx) as usize;
                let a = glam::Vec3::from_slice(&mean[q][..3]);
                let n = mean[q][3];
                v += (m2[q] - a.dot(a)).max(0.0) * (n / (n - 1.0)) / n;
                let d = at(&taa, qx, qy) - a;
                e2 += d.dot(d);
            }
            let b2 = (e2 - v).max(0.0);
            let wt = if b2 + v > 0.0 { b2 / (b2 + v) } else { 0.0 };
            let p = (y * w + x) as usize;
            let d = at(&taa, x, y);
            let expected = d + (glam::Vec3::from_slice(&mean[p][..3]) - d) * wt;
            let got = at(&shown, x, y);
            let scale = expected.abs().max_element().max(1e-3);
            worst = worst.max((got - expected).abs().max_element() / scale);
            moved +=
                ((got - d).abs().max_element() > 0.01 * d.abs().max_element().max(0.01)) as u32;
            heavy += (wt > 0.5) as u32;
        }
    }
    println!(
        "worst relative difference {worst:.2e}; {moved} pixels moved by over 1%, {heavy} weigh the mean over half"
    );
    // f32 sums in another order, and the shown image's half-float clamp (not reached here).
    assert!(worst < 1e-3, "the image shown differs from the blend by {worst} (relative)");
    assert!(moved > 40, "only {moved} pixels moved: the blend did not engage");
}

/// The mean continues only while the camera and the settings stand: a moved camera, a changed
/// setting of the samples and another denoiser each restart it at one sample; the display's
/// exposure does not.
#[test]
fn the_still_view_mean_restarts_when_the_view_or_the_settings_change() {
    let (gpu, mut r, input) = cornell();
    let s = settings(1.0);
    let mut rendered = 0;
    let mut run = |r: &mut Renderer, input: &FrameInput, s: &FrameSettings, n: u32| {
        for _ in 0..n {
            r.render(&gpu, input, s, None).unwrap();
        }
        rendered += n;
        let c: Vec<f32> = mean_now(&gpu, r, rendered).0.iter().map(|m| m[3]).collect();
        let (lo, hi) = c.iter().fold((f32::MAX, f32::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        assert_eq!(lo, hi, "every pixel has the same count");
        lo
    };
    assert_eq!(run(&mut r, &input, &s, 6), 6.0);
    let mut moved = input;
    moved.camera.world.w_axis.x += 0.01;
    assert_eq!(run(&mut r, &moved, &s, 1), 1.0, "the camera moved");
    assert_eq!(run(&mut r, &moved, &s, 4), 5.0, "it stands again");
    let brighter = FrameSettings { exposure_ev: 1.0, ..s.clone() };
    assert_eq!(run(&mut r, &moved, &brighter, 1), 6.0, "the exposure is the display's");
    let deeper = FrameSettings { max_depth: s.max_depth + 1, ..s.clone() };
    assert_eq!(run(&mut r, &moved, &deeper, 2), 2.0, "a setting changed");
    let other = FrameSettings { denoiser: Denoiser::SVGF, ..deeper.clone() };
    assert_eq!(run(&mut r, &moved, &other, 3), 3.0, "another denoiser");
}

/// `--disable converge` (`render`, `reflections`) turns the stage off and leaves TAA on.
#[test]
fn the_still_view_mean_is_a_stage_disable_switches_off() {
    use hush_engine::settings::{CONVERGE_STAGE, disable_stage, stage_names};
    assert!(stage_names().contains(&CONVERGE_STAGE));
    let mut s = settings(2.0);
    assert!(disable_stage(&mut s, CONVERGE_STAGE));
    assert_eq!(s.taa.converge_sigmas, 0.0);
    assert!(s.taa.enabled);
    assert_eq!(s.taa.converge_min_samples, 4.0);
}

/// The image shown goes into the composite's buffer, which TAA has read by then and nothing
/// reads after it: 16 bytes a pixel less than a buffer of the stage's own, and the same image
/// bit for bit. Where the frame keeps `composite/hdr` (a readback of the composite's image) the
/// stage writes `converge/shown` instead, and the composite's image stays as the composite
/// wrote it.
#[test]
fn the_image_shown_takes_the_composites_buffer_unless_the_frame_keeps_it() {
    let frames = 8;
    let (gpu, mut shared, input) = cornell();
    let (gpu_k, mut kept, _) = cornell();
    kept.keep(&["composite/hdr"]);
    let s = settings(1.0);
    for _ in 0..frames {
        shared.render(&gpu, &input, &s, None).unwrap();
        kept.render(&gpu_k, &input, &s, None).unwrap();
    }
    let bits = |img: &Image| -> Vec<u32> {
        img.data.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect()
    };
    let shown = shared.read_hdr(&gpu).unwrap();
    assert_eq!(bits(&shown), bits(&kept.read_hdr(&gpu_k).unwrap()), "the images differ");
    assert_eq!(kept.bytes_per_pixel() - shared.bytes_per_pixel(), 16.0);
    let own = |r: &Renderer| r.allocations().iter().any(|(l, _)| l == "converge/shown");
    assert!(!own(&shared) && own(&kept));
    let rgb = |b: Vec<u8>| -> Vec<u32> {
        floats(&b).chunks_exact(4).flat_map(|p| p[..3].to_vec()).map(f32::to_bits).collect()
    };
    let hdr = |r: &Renderer, g: &Gpu| rgb(r.read_buffer(g, "composite/hdr").unwrap());
    assert_eq!(hdr(&shared, &gpu), bits(&shown), "the shared buffer holds the image shown");
    let composite = hdr(&kept, &gpu_k);
    let differ = composite.iter().zip(bits(&shown)).filter(|(a, b)| **a != *b).count();
    assert!(differ * 2 > composite.len(), "the kept composite's image is TAA's: {differ} differ");
}
