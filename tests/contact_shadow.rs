//! The final bilateral's luminance edge-stop (Mara et al. 2017 §3.4 stage 7, with the guide of
//! shaders/matte/firefly.wgsl) on a contact shadow: a shelf on a wall under an area light casts
//! a shadow a few pixels tall onto the wall beneath it. Shadow and wall are one plane with one
//! normal, so the plane and normal weights pass every tap across the shadow's edge; only the
//! luminance edge-stop keeps the bilateral from blurring the shadow into the lit wall.

use glam::Vec3;
use hush_engine::quality::{Image, luminance};
use hush_engine::scene::{Scene, cuboid, load_gltf, quad};
use hush_engine::settings::{Denoiser, FrameSettings, MatteSettings, TaaSettings};
use hush_tests::gltf_writer::GltfWriter;
use hush_tests::{realtime_accumulate, realtime_frames};
use serde_json::json;

const SIZE: (u32, u32) = (96, 54);

/// A white wall (z = 0) and floor, a shelf 4 cm deep along the wall at 0.8 m, lit from 45 degrees
/// above: the shelf's shadow on the wall is about 4 cm tall, 2 to 3 pixels of a 96x54 view 1.5 m
/// away.
fn shelf_scene() -> Scene {
    let mut g = GltfWriter::default();
    let white = g.lambert([0.7; 3]);
    // An area light above and in front of the shelf, facing the wall at 45 degrees: the wall's
    // light, its shadow included, is all in the matte path (punctual lights go to the undenoised
    // direct term).
    let lamp = g.emitter(20.0);
    let down_the_wall = Vec3::new(0.0, -1.0, 1.0).normalize() * 0.15;
    // The engine's meshes carry a material index of their own; the file's is given beside each.
    let parts = [
        (quad(Vec3::new(0.0, 1.25, 0.0), Vec3::X * 3.0, Vec3::Y * 1.25, 0), white),
        (quad(Vec3::new(0.0, 0.0, 2.0), Vec3::Z * 2.0, Vec3::X * 3.0, 0), white),
        (cuboid(Vec3::new(0.0, 0.81, 0.02), Vec3::new(0.7, 0.01, 0.02), 0), white),
        (quad(Vec3::new(0.0, 1.85, 1.05), Vec3::X * 0.5, down_the_wall, 0), lamp),
    ];
    for (mesh, material) in parts {
        let m = g.engine_mesh(&mesh, material);
        g.node(json!({"mesh": m}));
    }
    g.camera([0.0, 0.81, 1.5], [0.0, 0.81, 0.0], 0.5);
    load_gltf(&g.write("shelf")).unwrap()
}

/// Mean luminance of each row over the middle half of the columns (the shelf spans them all).
fn row_means(img: &Image) -> Vec<f32> {
    let (w, h) = (img.width as usize, img.height as usize);
    (0..h)
        .map(|y| {
            (w / 4..3 * w / 4).map(|x| luminance(img.data[y * w + x])).sum::<f32>() / (w / 2) as f32
        })
        .collect()
}

/// How much of the shadow's depth below the lit wall a denoised image keeps, against 256
/// accumulated frames: the shadow's rows are those under the shelf that the reference shows
/// darker than 60% of the lit wall below them (2 rows at 96x54), the lit rows are the 3 after
/// the next. Measured after 30 frames, seeds 0 to 3: the guided edge-stop keeps 0.826 to 0.845
/// of the depth, no edge-stop 0.485 to 0.500, and the stop of 1250d93, which compared single
/// taps' luminance against the input's spread, 0.677 to 0.689. The bound, 0.76, lies between
/// the last two: it fails for a stop that lets tap noise or the shadow's own contrast widen
/// it, and leaves a different driver's rounding 8% of the depth.
#[test]
fn final_bilateral_keeps_a_contact_shadow() {
    let scene = shelf_scene();
    let reference = row_means(&realtime_accumulate(&scene, SIZE.0, SIZE.1, 256, 1).unwrap());
    let h = reference.len();
    // The lit wall: the median row of the lower third of the view, well under the shadow.
    let mut lower: Vec<f32> = reference[2 * h / 3..].to_vec();
    lower.sort_by(f32::total_cmp);
    let lit = lower[lower.len() / 2];
    // The shelf's front face sits at the view's centre row; the shadow starts under it.
    let shadow: Vec<usize> = (h / 2..2 * h / 3)
        .skip_while(|&y| reference[y] < 0.6 * lit)
        .skip_while(|&y| reference[y] >= 0.6 * lit)
        .take_while(|&y| reference[y] < 0.6 * lit)
        .collect();
    println!(
        "reference rows {:?}, lit wall {lit:.4}, shadow rows {shadow:?}",
        &reference[h / 2 - 2..2 * h / 3]
    );
    assert!((2..=5).contains(&shadow.len()), "the shadow covers rows {shadow:?}");
    let below: Vec<usize> = (shadow[shadow.len() - 1] + 2..shadow[shadow.len() - 1] + 5).collect();
    let depth = |rows: &[f32]| {
        let mean = |ys: &[usize]| ys.iter().map(|&y| rows[y]).sum::<f32>() / ys.len() as f32;
        mean(&below) - mean(&shadow)
    };
    // The bilateral alone: past 16 frames the still-view mean after TAA (passes/converge.rs)
    // gives the shadow back whatever the stop does (0.92 of its depth with no stop).
    let mara = |k: f32| FrameSettings {
        denoiser: Denoiser::MARA,
        matte: MatteSettings { edge_stop_sigmas: k, ..Default::default() },
        taa: TaaSettings { converge_sigmas: 0.0, ..Default::default() },
        ..Default::default()
    };
    let kept = |k: f32| {
        depth(&row_means(&realtime_frames(&scene, SIZE, &mara(k), 30).unwrap())) / depth(&reference)
    };
    let (with_stop, without) = (kept(MatteSettings::default().edge_stop_sigmas), kept(0.0));
    println!("shadow depth kept: with the edge-stop {with_stop:.3}, without {without:.3}");
    assert!(with_stop > 0.76, "the edge-stop keeps {with_stop} of the shadow (no stop: {without})");
    // What the bound stands on: without the stop the bilateral blurs half the shadow away.
    assert!(
        without < 0.6,
        "with no edge-stop the bilateral keeps {without} of the shadow: the scene no longer tests the stop"
    );
}
