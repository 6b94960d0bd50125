//! Skins, morph targets and nested animation (glTF 2.0 §3.7.3, §3.7.2.2, §3.11), against an
//! evaluation of the specification written out here: a bar of 9 rings bound to two joints (a
//! root turning about Y, an elbow under it turning about Z), blended over its middle, with one
//! morph target that shears it, both driven by one animation. At t = 1.3 s of its 2 s the
//! loaded scene's posed vertices equal the hand evaluation, and the reference render of the
//! skinned file equals the render of the hand-posed mesh written as a static file: exactly with
//! the same samples, within noise with others. Files that bind vertices to missing joints or carry non-finite bind matrices are
//! refused by name.

use glam::{Mat4, Quat, Vec3};
use hush_engine::quality::relmse;
use hush_engine::scene::{Scene, load_gltf};
use hush_tests::gltf_writer::{GltfWriter, Prim, write_json};
use serde_json::{Value, json};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

const RINGS: usize = 9;
const HALF: f32 = 0.15;
/// The time rendered, as a fraction of the 2 s the keys span.
const T: f64 = 1.3;
const F: f32 = 0.65;

struct Bar {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
    /// Per vertex: (root weight, elbow weight) and the morph target's displacement.
    weights: Vec<[f32; 2]>,
    shear: Vec<[f32; 3]>,
}

fn bar() -> Bar {
    let corners = [(-HALF, -HALF), (HALF, -HALF), (HALF, HALF), (-HALF, HALF)];
    let mut b =
        Bar { positions: vec![], normals: vec![], indices: vec![], weights: vec![], shear: vec![] };
    for j in 0..RINGS {
        let y = j as f32 * 0.25;
        let s = ((y - 0.5) / 1.0).clamp(0.0, 1.0);
        for (x, z) in corners {
            b.positions.push([x, y, z]);
            b.normals.push(Vec3::new(x, 0.0, z).normalize().to_array());
            b.weights.push([1.0 - s, s]);
            b.shear.push([0.4 * y / 2.0, 0.0, 0.0]);
        }
    }
    for j in 0..RINGS as u32 - 1 {
        for k in 0..4u32 {
            let (a, c) = (j * 4 + k, j * 4 + (k + 1) % 4);
            b.indices.extend([a, c, c + 4, a, c + 4, a + 4]);
        }
    }
    // End caps.
    let top = 4 * (RINGS as u32 - 1);
    b.indices.extend([0, 2, 1, 0, 3, 2, top, top + 1, top + 2, top, top + 2, top + 3]);
    b
}

/// The specification's skinning, written out: joint matrices (world x inverse bind) at t, the
/// morph target added first, the weighted sum of the joint matrices applied to the point.
fn posed_by_hand(b: &Bar) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    // Linear keys from the identity: a fraction F of each turn.
    let root = Mat4::from_quat(Quat::from_rotation_y(F * FRAC_PI_4));
    let elbow = root
        * Mat4::from_translation(Vec3::Y)
        * Mat4::from_quat(Quat::from_rotation_z(F * FRAC_PI_2));
    let joints = [root, elbow * Mat4::from_translation(-Vec3::Y)];
    let mut p = vec![];
    let mut n = vec![];
    for i in 0..b.positions.len() {
        let [w0, w1] = b.weights[i];
        let m = joints[0] * w0 + joints[1] * w1;
        let q = Vec3::from(b.positions[i]) + F * Vec3::from(b.shear[i]);
        p.push(m.transform_point3(q).to_array());
        let nm = glam::Mat3::from_mat4(m).inverse().transpose();
        n.push((nm * Vec3::from(b.normals[i])).normalize().to_array());
    }
    (p, n)
}

fn camera_and_light(g: &mut GltfWriter) {
    g.camera([0.4, 1.3, 4.5], [0.2, 1.0, 0.0], 0.75);
    g.extras = json!({"max_depth": 3, "environment": {"radiance": [1.0, 1.0, 1.0]}});
}

/// What a file breaks: nothing, its second inverse bind matrix (NaN), or the weights of its
/// first ring (all zero).
#[derive(Clone, Copy, PartialEq)]
enum Damage {
    None,
    NanBind,
    ZeroWeights,
}

/// The skinned, morphed and animated file; `edit` changes its JSON before it is written.
fn skinned_file(
    name: &str,
    damage: Damage,
    edit: impl FnOnce(&mut Value),
) -> Result<Scene, String> {
    let mut b = bar();
    if damage == Damage::ZeroWeights {
        b.weights[..4].fill([0.0, 0.0]);
    }
    let mut g = GltfWriter::default();
    let material = g.lambert([0.5, 0.5, 0.5]);
    let mesh = g.mesh(Prim {
        positions: &b.positions,
        normals: Some(&b.normals),
        indices: Some(&b.indices),
        material,
    });
    let joints: Vec<u8> = b.positions.iter().flat_map(|_| [0u8, 1, 0, 0]).collect();
    let joints = g.unorm8(&joints, "VEC4");
    g.accessors[joints]["normalized"] = json!(false);
    let weights: Vec<f32> = b.weights.iter().flat_map(|w| [w[0], w[1], 0.0, 0.0]).collect();
    let weights = g.floats(&weights, "VEC4");
    let shear: Vec<f32> = b.shear.iter().flatten().copied().collect();
    let shear = g.floats(&shear, "VEC3");
    let mut ibm: Vec<f32> = [Mat4::IDENTITY, Mat4::from_translation(-Vec3::Y)]
        .iter()
        .flat_map(|m| m.to_cols_array())
        .collect();
    if damage == Damage::NanBind {
        ibm[16 + 13] = f32::NAN;
    }
    let ibm = g.floats(&ibm, "MAT4");
    let times = g.floats(&[0.0, 2.0], "SCALAR");
    let turn = |q: Quat| [0.0, 0.0, 0.0, 1.0, q.x, q.y, q.z, q.w];
    let root_keys = g.floats(&turn(Quat::from_rotation_y(FRAC_PI_4)), "VEC4");
    let elbow_keys = g.floats(&turn(Quat::from_rotation_z(FRAC_PI_2)), "VEC4");
    let weight_keys = g.floats(&[0.0, 1.0], "SCALAR");
    {
        let p = &mut g.meshes[mesh]["primitives"][0];
        p["attributes"]["JOINTS_0"] = json!(joints);
        p["attributes"]["WEIGHTS_0"] = json!(weights);
        p["targets"] = json!([{"POSITION": shear}]);
        g.meshes[mesh]["weights"] = json!([0.0]);
    }
    // The mesh node's own translation must be ignored: its joints place a skinned mesh.
    g.node(json!({"mesh": mesh, "skin": 0, "translation": [5.0, 0.0, 0.0]}));
    g.node(json!({"name": "root", "children": [2]}));
    g.node(json!({"name": "elbow", "translation": [0.0, 1.0, 0.0]}));
    camera_and_light(&mut g);
    let mut j = g.to_json();
    j["skins"] = json!([{"joints": [1, 2], "inverseBindMatrices": ibm}]);
    let sampler = |o: usize| json!({"input": times, "output": o, "interpolation": "LINEAR"});
    j["animations"] = json!([{
        "samplers": [sampler(root_keys), sampler(elbow_keys), sampler(weight_keys)],
        "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 2, "path": "rotation"}},
            {"sampler": 2, "target": {"node": 0, "path": "weights"}},
        ],
    }]);
    edit(&mut j);
    load_gltf(&write_json(name, &j)).map_err(|e| format!("{e:#}"))
}

fn baked_file(positions: &[[f32; 3]], normals: &[[f32; 3]]) -> Scene {
    let b = bar();
    let mut g = GltfWriter::default();
    let material = g.lambert([0.5, 0.5, 0.5]);
    let mesh =
        g.mesh(Prim { positions, normals: Some(normals), indices: Some(&b.indices), material });
    g.node(json!({"mesh": mesh}));
    camera_and_light(&mut g);
    load_gltf(&g.write("skin-baked")).unwrap()
}

#[test]
fn skinned_and_morphed_meshes_pose_as_the_specification_says() {
    let scene = skinned_file("skinned-bar", Damage::None, |_| {}).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert!(scene.is_animated());
    let o = &scene.objects[0];
    let posed = o.mesh_at(&scene.meshes[o.mesh], Some(T));
    let (want, want_n) = posed_by_hand(&bar());
    let worst = posed
        .positions
        .iter()
        .zip(&want)
        .map(|(p, w)| (*p - Vec3::from(*w)).length())
        .fold(0.0, f32::max);
    println!("posed vertices within {worst} m of the hand evaluation");
    assert!(worst < 1e-5, "posed vertices {worst} m off");
    // At rest (no time) the bar stands in its bind pose.
    let rest = o.mesh_at(&scene.meshes[o.mesh], None);
    assert!(
        (rest.positions[35] - Vec3::new(-HALF, 2.0, HALF)).length() < 1e-6,
        "{}",
        rest.positions[35]
    );

    const N: u32 = 64;
    let baked = baked_file(&want, &want_n);
    let reference = hush_tests::render(&baked, N, N, 256, 2).unwrap().mean;
    // The same samples (seed) through the skinned file: nothing but the pose can differ, and a
    // pose off by any fraction of a pixel changes some pixel.
    let same = hush_tests::render_at(&scene, (N, N), 256, 2, T).unwrap().mean;
    let identical = relmse(&same, &reference);
    // Other samples: the images differ by their noise alone (mean bias well under 1%).
    let other = hush_tests::render_at(&scene, (N, N), 256, 1, T).unwrap().mean;
    let (err, bias) = (relmse(&other, &reference), other.mean() / reference.mean() - Vec3::ONE);
    println!(
        "skinned against baked: relMSE {identical:e} with the same samples, {err:.5} with others; mean bias {bias}"
    );
    assert!(identical < 1e-9, "same samples, relMSE {identical}");
    assert!(bias.abs().max_element() < 0.01, "bias {bias}");
}

/// Hostile skins: a vertex bound to a joint the skin lacks and a non-finite inverse bind
/// matrix are refused by name; weights that sum to zero are a warning and a documented
/// fallback (the vertex follows its first joint).
#[test]
fn hostile_skins_are_refused_or_fall_back() {
    let e = skinned_file("skin-two-joints-one", Damage::None, |j| {
        j["skins"][0]["joints"] = json!([1]);
    })
    .unwrap_err();
    assert!(e.contains("joint 1 of a skin with 1 joints"), "{e}");
    // A joint node that no scene node leads to.
    let e = skinned_file("skin-orphan-joint", Damage::None, |j| {
        j["nodes"].as_array_mut().unwrap().push(json!({"name": "orphan"}));
        let orphan = j["nodes"].as_array().unwrap().len() - 1;
        j["skins"][0]["joints"] = json!([1, orphan]);
    })
    .unwrap_err();
    assert!(e.contains("joints[1]") && e.contains("does not place"), "{e}");
    let e = skinned_file("skin-nan-bind", Damage::NanBind, |_| {}).unwrap_err();
    assert!(e.contains("inverseBindMatrices[1] is not finite"), "{e}");
    let s = skinned_file("skin-zero-weights", Damage::ZeroWeights, |_| {}).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("4 vertices") && w.contains("first joint")),
        "{:?}",
        s.warnings
    );
    let o = &s.objects[0];
    let posed = o.mesh_at(&s.meshes[o.mesh], Some(T));
    assert!(posed.positions.iter().all(|p| p.is_finite()));
}
