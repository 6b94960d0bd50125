//! Skins, morph targets and nested animation (glTF 2.0 §3.7.3, §3.7.2.2, §3.11), against an
//! evaluation of the specification written out here: a bar of 9 rings bound to two joints (a
//! root turning about Y, an elbow under it turning about Z), blended over its middle, with one
//! morph target that shears it, both driven by one animation. At t = 1.3 s of its 2 s the
//! loaded scene's posed vertices equal the hand evaluation, and the reference render of the
//! skinned file equals the render of the hand-posed mesh written as a static file: exactly with
//! the same samples, within noise with others. Files that bind vertices to missing joints or carry non-finite bind matrices are
//! refused by name.

use glam::{Mat4, Quat, Vec2, Vec3};
use hush_engine::quality::relmse;
use hush_engine::scene::{LoadOptions, Scene, load_gltf, load_gltf_opts};
use hush_tests::gltf_writer::{GltfWriter, Prim, write_json};
use hush_tests::reproject::{pixel_centre_hit, project};
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
    posed_by_hand_at(b, F)
}

/// At the fraction `f` of the keys' 2 s.
fn posed_by_hand_at(b: &Bar, f: f32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    // Linear keys from the identity: a fraction f of each turn.
    let root = Mat4::from_quat(Quat::from_rotation_y(f * FRAC_PI_4));
    let elbow = root
        * Mat4::from_translation(Vec3::Y)
        * Mat4::from_quat(Quat::from_rotation_z(f * FRAC_PI_2));
    let joints = [root, elbow * Mat4::from_translation(-Vec3::Y)];
    let mut p = vec![];
    let mut n = vec![];
    for i in 0..b.positions.len() {
        let [w0, w1] = b.weights[i];
        let m = joints[0] * w0 + joints[1] * w1;
        let q = Vec3::from(b.positions[i]) + f * Vec3::from(b.shear[i]);
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
    skinned_file_opts(name, damage, &LoadOptions::default(), edit)
}

fn skinned_file_opts(
    name: &str,
    damage: Damage,
    opts: &LoadOptions,
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
        "name": "bend",
        "samplers": [sampler(root_keys), sampler(elbow_keys), sampler(weight_keys)],
        "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 2, "path": "rotation"}},
            {"sampler": 2, "target": {"node": 0, "path": "weights"}},
        ],
    }]);
    edit(&mut j);
    load_gltf_opts(&write_json(name, &j), opts).map_err(|e| format!("{e:#}"))
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

/// Motion vectors of a deforming surface: between two real-time frames (t = 1.2 s and 1.3 s,
/// still camera) every G-buffer pixel on the bar moves by what the hand-posed vertices say: the
/// exact hit of the pixel's centre ray on its stored triangle, carried by the same barycentrics
/// to that triangle's hand-posed vertices at the earlier time and projected. The bound (0.02 px
/// and 2^-10 of the motion) is the Rg16Float storage precision plus f32 projection rounding,
/// as tests/realtime.rs bounds object motion, and inside the 0.05 px Hush asks of it.
#[test]
fn motion_vectors_of_skinned_vertices_follow_the_pose() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::settings::FrameSettings;
    let scene = skinned_file("skinned-bar-motion", Damage::None, |_| {}).unwrap();
    let b = bar();
    let camera = scene.camera.unwrap();
    let size = (64u32, 64u32);
    let (gpu, mut r) =
        Renderer::headless(scene, hush_engine::accel::BvhKind::DEFAULT, size).unwrap();
    let settings = FrameSettings::default();
    let (t0, t1) = (1.2f64, 1.3f64);
    for t in [t0, t1] {
        r.render(&gpu, &FrameInput { camera, time: t, shutter: None }, &settings, None).unwrap();
    }
    let ids = r.read_texture(&gpu, "gbuffer/ids").unwrap().0;
    let motion = r.read_texture(&gpu, "gbuffer/motion").unwrap().0;
    let setup = r.camera_setup(&camera);
    let origin = r.prepared.origin.as_vec3();
    let (before, _) = posed_by_hand_at(&b, t0 as f32 / 2.0);
    // Posed on the GPU: its triangles, not the CPU's last flattening.
    let tris = &r.read_triangles(&gpu).unwrap();
    let (mut worst, mut checked, mut moving) = (0f32, 0, 0);
    for y in 0..size.1 as usize {
        for x in 0..size.0 as usize {
            let o = (y * size.0 as usize + x) * 8;
            let slot = u32::from_le_bytes(ids[o + 4..o + 8].try_into().unwrap());
            if slot == u32::MAX {
                continue;
            }
            let p = pixel_centre_hit(&setup, size, (x, y), tris, slot);
            let v = |k: usize| tris[slot as usize * 3 + k].truncate();
            // Barycentrics of p, and the mesh triangle the slot holds (its input index).
            let (e1, e2, ep) = (v(1) - v(0), v(2) - v(0), p - v(0));
            let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let den = d11 * d22 - d12 * d12;
            let bu = (d22 * ep.dot(e1) - d12 * ep.dot(e2)) / den;
            let bv = (d11 * ep.dot(e2) - d12 * ep.dot(e1)) / den;
            let tri = tris[slot as usize * 3 + 1].w.to_bits() as usize;
            let corner = |k: usize| Vec3::from(before[b.indices[3 * tri + k] as usize]) - origin;
            let prev = corner(0) + bu * (corner(1) - corner(0)) + bv * (corner(2) - corner(0));
            let expected =
                project(&setup.view_proj, prev, size) - project(&setup.view_proj, p, size);
            let m = (y * size.0 as usize + x) * 4;
            let got = Vec2::new(hush_tests::half(&motion[m..]), hush_tests::half(&motion[m + 2..]));
            let err = (got - expected).length();
            let bound = 0.02 + expected.length() / 1024.0;
            assert!(
                err <= bound,
                "pixel ({x}, {y}): motion {got}, expected {expected} (error {err} > {bound})"
            );
            worst = worst.max(err);
            checked += 1;
            moving += (expected.length() > 0.25) as u32;
        }
    }
    println!(
        "skinned motion vectors: {checked} pixels ({moving} moving over 0.25 px), worst error {worst:.4} px"
    );
    assert!(moving > 50, "only {moving} pixels of the bar move");
}

/// A file with two animations: all play by default, `LoadOptions::animation` picks one (the
/// other's channels are left out), an index past the file's is refused, and the scene knows
/// their names and its loop length.
#[test]
fn one_of_several_animations_plays_when_asked() {
    // "wave": the root joint slides 1 m along X over 4 s.
    let wave = |j: &mut Value| {
        let times = j["accessors"].as_array().unwrap().len();
        let view = j["bufferViews"].as_array().unwrap().len();
        let data: Vec<u8> = [0.0f32, 4.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
            .iter()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        use base64::Engine;
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&data)
        );
        j["buffers"].as_array_mut().unwrap().push(json!({"byteLength": 32, "uri": uri}));
        let buffer = j["buffers"].as_array().unwrap().len() - 1;
        j["bufferViews"].as_array_mut().unwrap().extend([
            json!({"buffer": buffer, "byteOffset": 0, "byteLength": 8}),
            json!({"buffer": buffer, "byteOffset": 8, "byteLength": 24}),
        ]);
        j["accessors"].as_array_mut().unwrap().extend([
            json!({"bufferView": view, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [4.0]}),
            json!({"bufferView": view + 1, "componentType": 5126, "count": 2, "type": "VEC3"}),
        ]);
        j["animations"].as_array_mut().unwrap().push(json!({"name": "wave",
            "samplers": [{"input": times, "output": times + 1}],
            "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}));
    };
    let opts = |a: Option<usize>| LoadOptions { animation: a, ..LoadOptions::default() };
    let all = skinned_file_opts("two-animations", Damage::None, &opts(None), wave).unwrap();
    let bend = skinned_file_opts("two-animations-0", Damage::None, &opts(Some(0)), wave).unwrap();
    let slide = skinned_file_opts("two-animations-1", Damage::None, &opts(Some(1)), wave).unwrap();
    assert_eq!(all.animations, ["bend", "wave"]);
    assert_eq!(
        (all.animation_length(), bend.animation_length(), slide.animation_length()),
        (4.0, 2.0, 4.0)
    );
    let posed = |s: &Scene, t: f64| {
        s.objects[0].mesh_at(&s.meshes[s.objects[0].mesh], Some(t)).positions[0]
    };
    let rest = Vec3::from(bar().positions[0]);
    // At 2 s: "bend" alone has looped back to its rest; "wave" alone has slid the bar 0.5 m.
    assert!((posed(&bend, 2.0) - rest).length() < 1e-5, "{}", posed(&bend, 2.0));
    assert!(
        (posed(&slide, 2.0) - (rest + 0.5 * Vec3::X)).length() < 1e-5,
        "{}",
        posed(&slide, 2.0)
    );
    // Both at once: the bend and the slide.
    assert!((posed(&all, 1.3) - posed(&slide, 1.3)).length() > 0.01);
    assert!((posed(&all, 1.3) - posed(&bend, 1.3)).length() > 0.01);
    let e = skinned_file_opts("two-animations-5", Damage::None, &opts(Some(5)), wave).unwrap_err();
    assert!(e.contains("animation 5 was asked for; the file has 2"), "{e}");
}

/// Motion blur of a deforming mesh: with the shutter open from 1.2 s to 1.3 s, each triangle's
/// vertices at the open (what the motion-blurred trace interpolates from) are the hand-posed
/// ones at 1.2 s, and at the close those at 1.3 s.
#[test]
fn a_deforming_mesh_blurs_from_its_pose_at_the_shutters_open() {
    let scene = skinned_file("skinned-bar-shutter", Damage::None, |_| {}).unwrap();
    let b = bar();
    let mut p =
        hush_engine::gpu::PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
    assert!(p.expose(&scene, 1.3, Some(1.2)));
    assert!(p.shutter_moves());
    let origin = p.origin.as_vec3();
    let (open, _) = posed_by_hand_at(&b, 0.6);
    let (close, _) = posed_by_hand_at(&b, 0.65);
    let mut worst = 0f32;
    for slot in 0..p.triangle_count() {
        let tri = p.tris[slot * 3 + 1].w.to_bits() as usize;
        for k in 0..3 {
            let v = b.indices[3 * tri + k] as usize;
            let o = p.tris_open[slot * 3 + k].truncate();
            let c = p.tris[slot * 3 + k].truncate();
            worst = worst.max((o - (Vec3::from(open[v]) - origin)).length());
            worst = worst.max((c - (Vec3::from(close[v]) - origin)).length());
        }
    }
    assert!(worst < 1e-5, "vertices {worst} m off");
    // The shutter closed again: no motion left.
    assert!(p.expose(&scene, 1.3, None));
    assert!(!p.shutter_moves());
}

/// History on a deforming surface: SVGF over 5 real-time frames of the bar bending, 0.45 s of
/// animation a frame, seen from close by (still camera). The temporal test moves each pixel's
/// surface point by its triangle's vertices (realtime/motion_vertices.wgsl, previous_surface):
/// at least 90% of the bar's pixels, and of those moving over 10 px a frame, carry every frame
/// of history at the end (measured: 3,077 of 3,347 and 487 of 514). Moved by its object's
/// transform instead (the identity for a skinned mesh), 2,465 and 19 do: the fast part
/// restarts every frame.
#[test]
fn deforming_surfaces_keep_their_history() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::settings::{Denoiser, FrameSettings};
    const FRAMES: u32 = 5;
    // Closer along the same line of sight: the bar fills the frame and its upper half moves
    // more than 10 pixels a frame, past the temporal test's reach of 8.5 footprints.
    let scene = skinned_file("skinned-bar-history", Damage::None, |j| {
        for n in j["nodes"].as_array_mut().unwrap() {
            if n.get("camera").is_some() {
                let m = n["matrix"].as_array_mut().unwrap();
                let (eye, target) = (Vec3::new(0.4, 1.3, 4.5), Vec3::new(0.2, 1.0, 0.0));
                let closer = eye + 0.45 * (target - eye);
                for k in 0..3 {
                    m[12 + k] = json!(closer[k]);
                }
            }
        }
    })
    .unwrap();
    let camera = scene.camera.unwrap();
    let size = (128u32, 128u32);
    let (gpu, mut r) =
        Renderer::headless(scene, hush_engine::accel::BvhKind::DEFAULT, size).unwrap();
    let settings = FrameSettings { denoiser: Denoiser::SVGF, ..FrameSettings::default() };
    for k in 0..FRAMES {
        let input = FrameInput { camera, time: 0.45 * k as f64, shutter: None };
        r.render(&gpu, &input, &settings, None).unwrap();
    }
    let ids = r.read_texture(&gpu, "gbuffer/ids").unwrap().0;
    // The history length (z) of both parities; the latest is the larger.
    let lengths: Vec<Vec<f32>> = (0..2)
        .map(|k| {
            let (b, format) = r.read_texture(&gpu, &format!("svgf/matte moments {k}")).unwrap();
            let texel = format.block_copy_size(None).unwrap() as usize;
            b.chunks_exact(texel)
                .map(|t| match texel {
                    8 => hush_tests::half(&t[4..6]),
                    _ => f32::from_le_bytes(t[8..12].try_into().unwrap()),
                })
                .collect()
        })
        .collect();
    let motion = r.read_texture(&gpu, "gbuffer/motion").unwrap().0;
    let (mut on_bar, mut kept, mut fast, mut fast_kept) = (0, 0, 0, 0);
    for i in 0..(size.0 * size.1) as usize {
        let slot = u32::from_le_bytes(ids[i * 8 + 4..i * 8 + 8].try_into().unwrap());
        if slot == u32::MAX {
            continue;
        }
        on_bar += 1;
        let long = lengths[0][i].max(lengths[1][i]) >= FRAMES as f32 - 1.0;
        kept += long as u32;
        let m =
            Vec2::new(hush_tests::half(&motion[i * 4..]), hush_tests::half(&motion[i * 4 + 2..]));
        if m.length() > 10.0 {
            fast += 1;
            fast_kept += long as u32;
        }
    }
    println!("{fast_kept} of {fast} pixels moving over 10 px a frame kept their history");
    println!("{kept} of {on_bar} bar pixels carry {} frames of history or more", FRAMES - 1);
    assert!(on_bar > 200);
    assert!(kept * 10 >= on_bar * 9, "only {kept} of {on_bar} bar pixels kept their history");
    assert!(fast > 200, "only {fast} pixels move over 10 px a frame");
    assert!(fast_kept * 10 >= fast * 9, "{fast_kept} of {fast} fast pixels kept their history");
}

/// Posing on the GPU (gpu/posing.rs): the bar posed by the real-time frame at each of 12 times
/// over its animation equals the CPU's flattening at that time triangle by triangle (matched by
/// input index; the bound is f32 rounding of a 2 m bar, the CPU skinning in world space and then
/// rebasing, the GPU in rebased space), nothing non-finite reaches the triangles, and every
/// triangle lies inside each box on its path from the moving tree's root as the GPU refit
/// quantized them, before and after a CPU rebuild halfway. The CPU's nodes from the rest pose
/// fail that last test on the bent bar, so the boxes are the GPU's own.
#[test]
fn gpu_posing_matches_the_cpu_and_its_refit_boxes_hold_every_triangle() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::gpu::PreparedScene;
    use hush_engine::settings::FrameSettings;
    let scene = skinned_file("skinned-bar-gpu", Damage::None, |_| {}).unwrap();
    let camera = scene.camera.unwrap();
    let (gpu, mut r) =
        Renderer::headless(scene.clone(), hush_engine::accel::BvhKind::DEFAULT, (16, 16)).unwrap();
    assert!(r.gpu_posing().is_some(), "the bar is posed on the CPU");
    let rest_nodes = r.prepared.accel.nodes.clone();
    let settings = FrameSettings::default();
    let (mut worst, mut rest_misses) = (0f32, 0);
    for k in 0..12 {
        let t = 0.17 * k as f64;
        // Halfway, one CPU flattening and rebuild as a degraded refit asks for: the GPU takes
        // over again from its slots and tree.
        if k == 6 {
            r.prepared.rebuild_posing = true;
        }
        r.render(&gpu, &FrameInput { camera, time: t, shutter: None }, &settings, None).unwrap();
        let got = r.read_triangles(&gpu).unwrap();
        assert!(got.iter().all(|v| v.is_finite()), "t = {t}: a non-finite vertex");
        let mut cpu = PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
        cpu.animate(&scene, t);
        let (g, c) = (
            hush_tests::triangles_by_input(&got, &got),
            hush_tests::triangles_by_input(&cpu.tris, &cpu.tris),
        );
        assert_eq!(g.len(), c.len());
        for ((gi, gv, _), (ci, cv, _)) in g.iter().zip(&c) {
            assert_eq!(gi, ci);
            for (a, b) in gv.iter().zip(cv) {
                worst = worst.max((*a - *b).length());
            }
        }
        let root = r.prepared.dynamic_root().unwrap() as usize;
        let nodes = r.read_bvh_nodes(&gpu).unwrap();
        let misses = boxes_missing_triangles(&nodes, root, &got);
        assert_eq!(misses, 0, "t = {t}: {misses} triangle vertices outside a box on their path");
        rest_misses += boxes_missing_triangles(&rest_nodes, root, &got);
    }
    // The refit's cost, read back a frame or two late: still at one time until it arrives,
    // against the CPU's refit of the same (rest) tree to that pose. Each frame waits for the
    // GPU, so a readback copied in one frame is mapped by the next and taken by the one after;
    // the value has arrived once three frames in a row have read back the same cost (a loaded
    // machine can leave the mapping pending a frame longer without the wait).
    let still = 1.9;
    let mut seen = vec![];
    for _ in 0..24 {
        r.render(&gpu, &FrameInput { camera, time: still, shutter: None }, &settings, None)
            .unwrap();
        gpu.wait().unwrap();
        seen.push(r.gpu_posing().unwrap().last_cost_ratio);
        if seen.len() >= 6 && seen[seen.len() - 3..].windows(2).all(|w| w[0] == w[1]) {
            break;
        }
    }
    let mut cpu = PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
    cpu.animate(&scene, still);
    let (built, refit) = cpu.moving_tree_costs().unwrap();
    let p = r.gpu_posing().unwrap();
    let gpu_ratio = p.last_cost_ratio.unwrap_or(f32::NAN);
    println!(
        "GPU-posed bar within {worst:e} m of the CPU's; {rest_misses} vertices outside the rest pose's boxes; refit cost {gpu_ratio} x its built cost on the GPU, {} on the CPU; {} rebuilds asked",
        refit / built,
        p.rebuilds
    );
    assert!((gpu_ratio / (refit / built) - 1.0).abs() < 1e-3, "GPU refit cost {gpu_ratio}");
    assert!(worst < 2e-6, "GPU pose {worst} m from the CPU's");
    assert!(rest_misses > 100, "the rest pose's boxes hold the posed bar: the check is vacuous");
}

/// Posing on the GPU with the shutter open (motion blur, 1.2 s to 1.3 s, real-time frames):
/// the GPU's vertices at the open and at the close equal the CPU's exposure of the same
/// interval (which `a_deforming_mesh_blurs_from_its_pose_at_the_shutters_open` checks by hand),
/// and the refit boxes hold both ends of every triangle. The boxes of a frame with the shutter
/// closed at 1.3 s miss the open ends, so the check sees the sweep.
#[test]
fn gpu_posing_blurs_from_the_pose_at_the_shutters_open() {
    use hush_engine::frame::{FrameInput, Renderer, ShutterOpen};
    use hush_engine::gpu::PreparedScene;
    use hush_engine::settings::FrameSettings;
    let scene = skinned_file("skinned-bar-gpu-shutter", Damage::None, |_| {}).unwrap();
    let camera = scene.camera.unwrap();
    let (gpu, mut r) =
        Renderer::headless(scene.clone(), hush_engine::accel::BvhKind::DEFAULT, (16, 16)).unwrap();
    assert!(r.gpu_posing().is_some());
    let settings = FrameSettings::default();
    let root = r.prepared.dynamic_root().unwrap() as usize;
    let (open_t, close_t) = (1.2, 1.3);
    r.render(&gpu, &FrameInput { camera, time: close_t, shutter: None }, &settings, None).unwrap();
    let instant_nodes = r.read_bvh_nodes(&gpu).unwrap();
    let shutter = Some(ShutterOpen { camera, time: open_t });
    r.render(&gpu, &FrameInput { camera, time: close_t, shutter }, &settings, None).unwrap();
    let close = r.read_triangles(&gpu).unwrap();
    let open = r.read_triangles_at_open(&gpu).unwrap().unwrap();
    let mut cpu = PreparedScene::new(&scene, hush_engine::accel::BvhKind::DEFAULT).unwrap();
    cpu.expose(&scene, close_t, Some(open_t));
    let (g, c) = (
        hush_tests::triangles_by_input(&close, &open),
        hush_tests::triangles_by_input(&cpu.tris, &cpu.tris_open),
    );
    assert_eq!(g.len(), c.len());
    let (mut worst, mut swept) = (0f32, 0f32);
    for ((gi, gc, go), (ci, cc, co)) in g.iter().zip(&c) {
        assert_eq!(gi, ci);
        for k in 0..3 {
            worst = worst.max((gc[k] - cc[k]).length()).max((go[k] - co[k]).length());
            swept = swept.max((go[k] - gc[k]).length());
        }
    }
    let nodes = r.read_bvh_nodes(&gpu).unwrap();
    let misses = boxes_missing_triangles(&nodes, root, &close)
        + boxes_missing_triangles(&nodes, root, &open);
    let instant_misses = boxes_missing_triangles(&instant_nodes, root, &open);
    println!(
        "GPU-posed shutter ends within {worst:e} m of the CPU's (the bar sweeps up to {swept} m); {misses} vertices outside the swept boxes, {instant_misses} of the open ends outside the instant's"
    );
    assert!(worst < 2e-6, "GPU shutter ends {worst} m from the CPU's");
    assert!(swept > 0.01, "the bar barely moves during the shutter ({swept} m)");
    assert_eq!(misses, 0, "{misses} vertices outside the swept boxes");
    assert!(instant_misses > 10, "the instant's boxes hold the open ends: the check is vacuous");
}

/// Joint matrices that overflow on the GPU: a skinned quad whose joint scales towards 1e37
/// (finite in f32) with corners 100 m out, so that posed corners pass f32's range (about
/// 3.4e38). The GPU's pose keeps such a vertex at rest (shaders/accel/pose.wgsl) where the CPU
/// drops its triangle: nothing non-finite reaches the triangles, and the frame stays finite.
/// Without the shader's guard the first frame's triangles hold Inf and the test fails.
#[test]
fn overflowing_joints_never_reach_the_gpu_trace() {
    use glam::{DMat4, DQuat, DVec3, Vec4};
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::scene::{
        Animation, Camera, Deform, Environment, Joint, MAX_INFLUENCES, Material, Object, Track,
        quad,
    };
    use hush_engine::settings::FrameSettings;
    let mut a = Animation::rigid(DMat4::IDENTITY, DVec3::ZERO, DQuat::IDENTITY, DVec3::ONE);
    a.scale_track = Some(Track {
        times: vec![0.0, 1.0],
        values: vec![DVec3::ONE, DVec3::splat(1e37)],
        step: false,
        tangents: vec![],
    });
    let joint = Joint { rest: DMat4::IDENTITY, animation: Some(a), inverse_bind: DMat4::IDENTITY };
    let mut skinned = quad(Vec3::ZERO, Vec3::new(100.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -100.0), 0);
    let mut w = [0.0; MAX_INFLUENCES];
    w[0] = 1.0;
    skinned.joints = vec![[0; MAX_INFLUENCES]; skinned.positions.len()];
    skinned.weights = vec![w; skinned.positions.len()];
    let floor =
        quad(Vec3::new(0.0, -1.0, 0.0), Vec3::new(5.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -5.0), 0);
    let mut o = Object::new("hostile", 1, DMat4::IDENTITY);
    o.deform = Some(std::sync::Arc::new(Deform { skin: vec![joint], morph: None }));
    let scene = Scene {
        name: "overflowing joint".into(),
        meshes: vec![floor, skinned],
        objects: vec![Object::new("floor", 0, DMat4::IDENTITY), o],
        materials: vec![Material { base_color: Vec4::splat(0.7), ..Default::default() }],
        camera: Some(Camera::look_at(DVec3::new(0.0, 3.0, 6.0), DVec3::ZERO, 60.0)),
        environment: Environment::Constant(Vec3::splat(0.5)),
        max_depth: 3,
        ..Default::default()
    };
    let camera = scene.camera.unwrap();
    let times = [0.5, 0.9];
    // The specification's pose leaves f32's range at both times: the guard is what holds.
    let deform = scene.objects[1].deform.clone().unwrap();
    for t in times {
        let posed = deform.pose_vertices(&scene.meshes[1], Some(t));
        let out = posed.positions.iter().filter(|p| !p.is_finite()).count();
        assert!(out > 0, "t = {t}: the pose stays within f32's range");
    }
    let (gpu, mut r) =
        Renderer::headless(scene, hush_engine::accel::BvhKind::DEFAULT, (16, 16)).unwrap();
    assert!(r.gpu_posing().is_some(), "the quad is posed on the CPU");
    let settings = FrameSettings::default();
    for t in times {
        r.render(&gpu, &FrameInput { camera, time: t, shutter: None }, &settings, None).unwrap();
        let tris = r.read_triangles(&gpu).unwrap();
        assert!(tris.iter().all(|v| v.is_finite()), "t = {t}: a non-finite vertex");
        let img = r.read_hdr(&gpu).unwrap();
        assert!(img.data.iter().all(|p| p.is_finite()), "t = {t}: a non-finite pixel");
    }
}

/// Triangle vertices (of `tris`, three vec4 a slot) outside a box on their path from the CWBVH
/// node `root`: each child box dequantized as the traversal reads it (p + q x 2^e).
fn boxes_missing_triangles(nodes: &[u8], root: usize, tris: &[glam::Vec4]) -> usize {
    let node = |i: usize| &nodes[i * 80..i * 80 + 80];
    let word = |n: &[u8], w: usize| u32::from_le_bytes(n[w * 4..w * 4 + 4].try_into().unwrap());
    let mut misses = 0;
    let mut stack = vec![(root, vec![])];
    while let Some((i, path)) = stack.pop() {
        let n = node(i);
        let p = Vec3::new(
            f32::from_bits(word(n, 0)),
            f32::from_bits(word(n, 1)),
            f32::from_bits(word(n, 2)),
        );
        let e = Vec3::new(
            f32::from_bits((n[12] as u32) << 23),
            f32::from_bits((n[13] as u32) << 23),
            f32::from_bits((n[14] as u32) << 23),
        );
        let imask = n[15];
        let (child_base, prim_base) = (word(n, 4), word(n, 5));
        for c in 0..8 {
            let meta = n[24 + c];
            if meta == 0 {
                continue;
            }
            let q = |at: usize| n[at + c] as f32;
            let lo = p + Vec3::new(q(32), q(48), q(64)) * e;
            let hi = p + Vec3::new(q(40), q(56), q(72)) * e;
            let mut path = path.clone();
            path.push((lo, hi));
            if imask & (1 << c) == 0 {
                let first = prim_base + (meta & 31) as u32;
                for s in first..first + (meta & 0xe0).count_ones() {
                    for k in 0..3 {
                        let v = tris[s as usize * 3 + k].truncate();
                        let slack = 1e-6 * (1.0 + v.abs().max_element());
                        misses += path.iter().any(|(lo, hi)| {
                            v.cmplt(*lo - slack).any() || v.cmpgt(*hi + slack).any()
                        }) as usize;
                    }
                }
            } else {
                let slot = (meta & 31) as u32 - 24;
                let rel = (imask as u32 & !(u32::MAX << slot)).count_ones();
                stack.push(((child_base + rel) as usize, path));
            }
        }
    }
    misses
}
