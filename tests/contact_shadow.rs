//! The final bilateral's luminance edge-stop (Mara et al. 2017 §3.4 stage 7, with the guide of
//! shaders/matte/firefly.wgsl) on a contact shadow: a shelf on a wall under a sun casts a shadow
//! a few pixels tall onto the wall beneath it. Shadow and wall are one plane with one normal, so
//! the plane and normal weights pass every tap across the shadow's edge; only the luminance
//! edge-stop keeps the bilateral from blurring the shadow into the lit wall.

use glam::Vec3;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::quality::{Image, luminance};
use hush_engine::scene::{Scene, load_gltf};
use hush_engine::settings::{Denoiser, FrameSettings, MatteSettings};
use hush_tests::gltf_writer::{GltfWriter, Prim};
use hush_tests::realtime_accumulate;
use serde_json::json;

const SIZE: (u32, u32) = (96, 54);

/// An axis-aligned box from `lo` to `hi`: 6 faces, outward normals, counter-clockwise seen from
/// outside.
fn cuboid(g: &mut GltfWriter, lo: [f32; 3], hi: [f32; 3], material: usize) -> usize {
    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
    let (mut pos, mut nrm, mut idx) = (vec![], vec![], vec![]);
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for axis in 0..3 {
        // (u, v, axis) is right-handed: u x v points along the axis.
        let (u, v) = (axes[(axis + 1) % 3], axes[(axis + 2) % 3]);
        for far in [false, true] {
            let n = if far { axes[axis] } else { -axes[axis] };
            let base = pos.len() as u32;
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let t = u * a + v * b + if far { axes[axis] } else { Vec3::ZERO };
                pos.push((lo + (hi - lo) * t).to_array());
                nrm.push(n.to_array());
            }
            let quad = if far { [0, 1, 2, 0, 2, 3] } else { [0, 2, 1, 0, 3, 2] };
            idx.extend(quad.iter().map(|i| base + i));
        }
    }
    g.mesh(Prim { positions: &pos, normals: Some(&nrm), indices: Some(&idx), material })
}

/// A white wall (z = 0) and floor, a shelf 4 cm deep along the wall at 0.8 m, lit from 45 degrees
/// above: the shelf's shadow on the wall is about 4 cm tall, 2 to 3 pixels of a 96x54 view 1.5 m
/// away.
fn shelf_scene() -> Scene {
    let mut g = GltfWriter::default();
    let white = g.lambert([0.7; 3]);
    let wall = g.mesh(Prim {
        positions: &[[-3.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 2.5, 0.0], [-3.0, 2.5, 0.0]],
        normals: Some(&[[0.0, 0.0, 1.0]; 4]),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: white,
    });
    let floor = g.mesh(Prim {
        positions: &[[-3.0, 0.0, 0.0], [-3.0, 0.0, 4.0], [3.0, 0.0, 4.0], [3.0, 0.0, 0.0]],
        normals: Some(&[[0.0, 1.0, 0.0]; 4]),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: white,
    });
    let shelf = cuboid(&mut g, [-0.7, 0.80, 0.0], [0.7, 0.82, 0.04], white);
    for m in [wall, floor, shelf] {
        g.node(json!({"mesh": m}));
    }
    // An area light above and in front of the shelf, facing the wall at 45 degrees: the wall's
    // light, its shadow included, is all in the matte path (punctual lights go to the undenoised
    // direct term).
    let lamp = g.emitter(20.0);
    let (c, u, v) = (Vec3::new(0.0, 1.85, 1.05), Vec3::X * 0.5, Vec3::new(0.0, 1.0, -1.0).normalize() * 0.15);
    let facing = Vec3::new(0.0, -1.0, -1.0).normalize().to_array();
    let lamp = g.mesh(Prim {
        positions: &[(c - u - v).to_array(), (c + u - v).to_array(), (c + u + v).to_array(), (c - u + v).to_array()],
        normals: Some(&[facing; 4]),
        indices: Some(&[0, 2, 1, 0, 3, 2]),
        material: lamp,
    });
    g.node(json!({"mesh": lamp}));
    g.camera([0.0, 0.81, 1.5], [0.0, 0.81, 0.0], 0.5);
    load_gltf(&g.write("shelf")).unwrap()
}

fn denoised(scene: &Scene, s: &FrameSettings, n: u32) -> Image {
    let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, SIZE).unwrap();
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0 };
    for _ in 0..n {
        r.render(&gpu, &input, s, None).unwrap();
    }
    r.read_hdr(&gpu).unwrap()
}

/// Mean luminance of each row over the middle half of the columns (the shelf spans them all).
fn row_means(img: &Image) -> Vec<f32> {
    let (w, h) = (img.width as usize, img.height as usize);
    (0..h).map(|y| (w / 4..3 * w / 4).map(|x| luminance(img.data[y * w + x])).sum::<f32>() / (w / 2) as f32).collect()
}

/// How much of the shadow's depth below the lit wall a denoised image keeps, against 256
/// accumulated frames: the shadow's rows are those under the shelf that the reference shows
/// darker than 60% of the lit wall below them (2 rows at 96x54), the lit rows are the 3 after
/// the next. Measured after 30 frames, seeds 0 to 3: the guided edge-stop keeps 0.826 to 0.845
/// of the depth, no edge-stop 0.486 to 0.502, and the stop of 1250d93, which compared single
/// taps' luminance against the input's spread, 0.675 to 0.695. The bound, 0.76, lies between
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
    let shadow: Vec<usize> = (h / 2..2 * h / 3).skip_while(|&y| reference[y] < 0.6 * lit).skip_while(|&y| reference[y] >= 0.6 * lit).take_while(|&y| reference[y] < 0.6 * lit).collect();
    println!("reference rows {:?}, lit wall {lit:.4}, shadow rows {shadow:?}", &reference[h / 2 - 2..2 * h / 3]);
    assert!((2..=5).contains(&shadow.len()), "the shadow covers rows {shadow:?}");
    let below: Vec<usize> = (shadow[shadow.len() - 1] + 2..shadow[shadow.len() - 1] + 5).collect();
    let depth = |rows: &[f32]| {
        let mean = |ys: &[usize]| ys.iter().map(|&y| rows[y]).sum::<f32>() / ys.len() as f32;
        mean(&below) - mean(&shadow)
    };
    let mara = |k: f32| FrameSettings { denoiser: Denoiser::Mara, matte: MatteSettings { edge_stop_sigmas: k, ..Default::default() }, ..Default::default() };
    let kept = |k: f32| depth(&row_means(&denoised(&scene, &mara(k), 30))) / depth(&reference);
    let (with_stop, without) = (kept(MatteSettings::default().edge_stop_sigmas), kept(0.0));
    println!("shadow depth kept: with the edge-stop {with_stop:.3}, without {without:.3}");
    assert!(with_stop > 0.76, "the edge-stop keeps {with_stop} of the shadow (no stop: {without})");
    // What the bound stands on: without the stop the bilateral blurs half the shadow away.
    assert!(without < 0.6, "with no edge-stop the bilateral keeps {without} of the shadow: the scene no longer tests the stop");
}
