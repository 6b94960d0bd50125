//! glTF's alpha modes in both modes, as the Khronos AlphaBlendModeTest lays them out: three
//! emitters in front of a fourth, with base colour alpha 0.3, as OPAQUE (alpha ignored), MASK
//! (cutoff 0.5: cut out) and BLEND (stochastic transparency: 0.3 of the front over 0.7 of the
//! back). The reference tracer and the real-time frames must both converge to those three
//! values, the blend to glTF's "over" operator.

use glam::Vec3;
use hush_engine::scene::load_gltf;
use hush_tests::gltf_writer::{GltfWriter, Prim};
use serde_json::json;

const W: u32 = 48;
const H: u32 = 16;
const ALPHA: f32 = 0.3;
const FRONT: Vec3 = Vec3::new(1.0, 0.25, 0.1);
const BACK: Vec3 = Vec3::new(0.1, 0.4, 1.0);

fn emitter(c: Vec3, alpha: f32, mode: &str) -> serde_json::Value {
    let mut m = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, alpha], "metallicFactor": 0.0},
        "emissiveFactor": c.to_array(),
        "alphaMode": mode,
    });
    if mode == "MASK" {
        m["alphaCutoff"] = json!(0.5);
    }
    m
}

fn quad(g: &mut GltfWriter, x0: f32, x1: f32, z: f32, material: usize) -> usize {
    let (y0, y1) = (-1.0, 1.0);
    g.mesh(Prim {
        positions: &[[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]],
        normals: Some(&[[0.0, 0.0, 1.0]; 4]),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material,
    })
}

#[test]
fn opaque_mask_and_blend_render_alike_in_both_modes() {
    let mut g = GltfWriter::default();
    g.materials.push(emitter(BACK, 1.0, "OPAQUE"));
    for mode in ["OPAQUE", "MASK", "BLEND"] {
        g.materials.push(emitter(FRONT, ALPHA, mode));
    }
    // The back wall spans the view; the three front quads a third of it each, in front.
    let back = quad(&mut g, -3.5, 3.5, -0.5, 0);
    g.node(json!({"mesh": back}));
    for k in 0..3 {
        let x0 = -3.0 + 2.0 * k as f32;
        let m = quad(&mut g, x0, x0 + 2.0, 0.0, k + 1);
        g.node(json!({"mesh": m}));
    }
    // Looking down -Z from z = 3: the view is 2 high at z = 0 and 6 wide (3:1).
    g.camera([0.0, 0.0, 3.0], [0.0, 0.0, 0.0], 2.0 * (1.0f32 / 3.0).atan());
    g.extras = json!({"max_depth": 1, "resolution": [W, H]});
    let scene = load_gltf(&g.write("alpha-modes")).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);

    let expected = [FRONT, BACK, ALPHA * FRONT + (1.0 - ALPHA) * BACK];
    let reference = hush_tests::render(&scene, W, H, 256, 5).unwrap();
    let realtime = hush_tests::realtime_accumulate(&scene, W, H, 128, 5).unwrap();
    // Columns well inside each third (the quads' edges are a pixel's mix).
    for (k, want) in expected.iter().enumerate() {
        let cols = (k as u32 * W / 3 + 2)..((k as u32 + 1) * W / 3 - 2);
        let (mut sum_ref, mut sum_rt, mut worst_z, mut n) = (Vec3::ZERO, Vec3::ZERO, 0f32, 0.0);
        for y in 2..H - 2 {
            for x in cols.clone() {
                let m = reference.mean.at(x, y);
                let sd = reference.variance_of_mean.at(x, y).map(|v| v.max(0.0).sqrt());
                worst_z = worst_z.max(((m - *want).abs() / (sd + 1e-4)).max_element());
                sum_ref += m;
                sum_rt += realtime.at(x, y);
                n += 1.0;
            }
        }
        let (mean_ref, mean_rt) = (sum_ref / n, sum_rt / n);
        println!(
            "third {k}: expected {want}, reference {mean_ref} (worst pixel {worst_z:.1} sigma), real-time {mean_rt}"
        );
        // Opaque and mask pixels see one surface: no noise, the value itself. A blended pixel's
        // 256 draws have a standard error of |FRONT - BACK| sqrt(0.21 / 256) = 0.027; the test
        // allows 5 of them.
        assert!(worst_z < 5.0, "third {k}: a reference pixel {worst_z} standard errors off");
        // The mean over 224 blended pixels of 128 frames each: a standard error of 0.0022 per
        // channel if the draws were independent; 0.01 allows for the raster's draws being
        // correlated along the jitter sequence.
        assert!((mean_rt - *want).abs().max_element() < 0.01, "third {k}: real time {mean_rt}");
        assert!((mean_ref - *want).abs().max_element() < 0.01, "third {k}: reference {mean_ref}");
    }
}
