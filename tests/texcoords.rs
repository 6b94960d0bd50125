//! Where a material reads its textures and colours: `KHR_texture_transform`, a texture read at
//! TEXCOORD_1 (by `texCoord` or by the transform's override) and COLOR_0, loaded from glTF files
//! and rendered in both modes. A transformed texture must show what the same texture shows at
//! coordinates transformed on the CPU by the extension's formula, and a vertex colour must
//! multiply the base colour as the interpolated attribute says.

use base64::Engine;
use glam::Vec3;
use hush_engine::quality::{Image, srgb_to_linear};
use hush_engine::scene::{Environment, Scene, load_gltf};
use hush_tests::gltf_writer::{GltfWriter, Prim};
use serde_json::{Value, json};

const W: u32 = 32;
const H: u32 = 32;

/// The quad's corners (x, y at z = 0) and their TEXCOORD_0.
const CORNERS: [[f32; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
const UVS: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];

/// The transform under test: offset, rotation (radians), scale.
const OFFSET: [f32; 2] = [0.3, -0.2];
const ROTATION: f32 = 0.7;
const SCALE: [f32; 2] = [1.5, 0.8];

/// KHR_texture_transform as its specification writes it: uv' = T R S uv with
/// R = [cos sin; -sin cos] (rows).
fn transformed(uv: [f32; 2]) -> [f32; 2] {
    let (s, c) = ROTATION.sin_cos();
    let (x, y) = (uv[0] * SCALE[0], uv[1] * SCALE[1]);
    [c * x + s * y + OFFSET[0], -s * x + c * y + OFFSET[1]]
}

/// A 4 x 2 texture, every texel a different colour, as a PNG data URI.
fn texture_uri() -> String {
    let rgba: Vec<u8> =
        hush_tests::TILE_COLOURS.iter().flat_map(|c| [c[0], c[1], c[2], 255]).collect();
    let img = image::RgbaImage::from_raw(4, 2, rgba).unwrap();
    let mut png = vec![];
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png))
}

/// A quad filling the view of a camera on +Z, with `attributes` (name -> accessor) beside its
/// POSITION and NORMAL, material `material` (JSON); `max_depth` as the scene's extras say.
fn quad_file(
    name: &str,
    attributes: impl FnOnce(&mut GltfWriter) -> Vec<(&'static str, usize)>,
    material: Value,
    max_depth: i32,
) -> Scene {
    let mut g = GltfWriter::default();
    g.materials.push(material);
    let positions: Vec<[f32; 3]> = CORNERS.iter().map(|c| [c[0], c[1], 0.0]).collect();
    let mesh = g.mesh(Prim {
        positions: &positions,
        normals: Some(&[[0.0, 0.0, 1.0]; 4]),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: 0,
    });
    for (semantic, accessor) in attributes(&mut g) {
        g.meshes[mesh]["primitives"][0]["attributes"][semantic] = json!(accessor);
    }
    g.node(json!({"mesh": mesh}));
    g.camera([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], 2.0 * 0.5f32.atan());
    g.extras = json!({"max_depth": max_depth});
    let mut j = g.to_json();
    j["images"] = json!([{"uri": texture_uri()}]);
    j["textures"] = json!([{"source": 0}]);
    j["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_texture_transform"));
    let scene = load_gltf(&hush_tests::gltf_writer::write_json(name, &j)).unwrap();
    assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
    scene
}

fn uvs(f: impl Fn([f32; 2]) -> [f32; 2]) -> Vec<f32> {
    UVS.iter().flat_map(|&uv| f(uv)).collect()
}

/// An emitter whose emission is the texture, read as `info` says.
fn emissive(info: Value) -> Value {
    json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
        "emissiveFactor": [1.0, 1.0, 1.0],
        "emissiveTexture": info,
    })
}

fn khr(extra: Value) -> Value {
    let mut t = json!({"offset": OFFSET, "rotation": ROTATION, "scale": SCALE});
    if let Some(o) = extra.as_object() {
        for (k, v) in o {
            t[k] = v.clone();
        }
    }
    json!({"KHR_texture_transform": t})
}

/// The scenes: (name, scene). The first has the transformed coordinates baked into TEXCOORD_0;
/// the others must match it; the last (untransformed) must not.
fn variants() -> Vec<(&'static str, Scene)> {
    let baked = quad_file(
        "texcoords-baked",
        |g| vec![("TEXCOORD_0", g.floats(&uvs(transformed), "VEC2"))],
        emissive(json!({"index": 0})),
        1,
    );
    let transform = quad_file(
        "texcoords-transform",
        |g| vec![("TEXCOORD_0", g.floats(&uvs(|uv| uv), "VEC2"))],
        emissive(json!({"index": 0, "extensions": khr(json!({}))})),
        1,
    );
    // TEXCOORD_0 is a constant: a texture read there shows one colour.
    let set1 = quad_file(
        "texcoords-set1",
        |g| {
            vec![
                ("TEXCOORD_0", g.floats(&uvs(|_| [0.6, 0.3]), "VEC2")),
                ("TEXCOORD_1", g.floats(&uvs(|uv| uv), "VEC2")),
            ]
        },
        emissive(json!({"index": 0, "texCoord": 1, "extensions": khr(json!({}))})),
        1,
    );
    let overridden = quad_file(
        "texcoords-override",
        |g| {
            vec![
                ("TEXCOORD_0", g.floats(&uvs(|_| [0.6, 0.3]), "VEC2")),
                ("TEXCOORD_1", g.floats(&uvs(|uv| uv), "VEC2")),
            ]
        },
        emissive(json!({"index": 0, "texCoord": 0, "extensions": khr(json!({"texCoord": 1}))})),
        1,
    );
    let plain = quad_file(
        "texcoords-plain",
        |g| vec![("TEXCOORD_0", g.floats(&uvs(|uv| uv), "VEC2"))],
        emissive(json!({"index": 0})),
        1,
    );
    vec![
        ("baked", baked),
        ("transform", transform),
        ("TEXCOORD_1", set1),
        ("transform's texCoord", overridden),
        ("untransformed", plain),
    ]
}

/// Pixels of `a` and `b` that differ by more than `tol(i)`.
fn differing(a: &Image, b: &Image, tol: impl Fn(usize) -> f32) -> usize {
    (0..a.data.len()).filter(|&i| (a.data[i] - b.data[i]).abs().max_element() > tol(i)).count()
}

#[test]
fn transformed_textures_read_where_the_extension_says_in_both_modes() {
    let scenes = variants();
    // Reference mode: the same seed samples the same positions in every variant, so the
    // images differ only by float rounding of the coordinates (and by the texture where a
    // variant reads the wrong coordinates). 5 standard errors of the mean bound the rest.
    let refs: Vec<_> =
        scenes.iter().map(|(_, s)| hush_tests::render(s, W, H, 64, 3).unwrap()).collect();
    // Real-time frames with the same seed and jitter: likewise.
    let rt: Vec<Image> = scenes
        .iter()
        .map(|(_, s)| hush_tests::realtime_accumulate(s, W, H, 8, 3).unwrap())
        .collect();
    let base = &refs[0];
    let sigma = |i: usize| 5.0 * base.variance_of_mean.data[i].max_element().max(0.0).sqrt();
    for (k, (name, _)) in scenes.iter().enumerate().skip(1) {
        let bad_ref = differing(&refs[k].mean, &base.mean, |i| sigma(i) + 2e-3);
        let bad_rt = differing(&rt[k], &rt[0], |_| 2e-3);
        println!("{name}: {bad_ref} reference and {bad_rt} real-time pixels differ from baked");
        if *name == "untransformed" {
            // The check compares something: without the transform most pixels differ.
            assert!(bad_ref > (W * H / 2) as usize, "{name}: only {bad_ref} pixels differ");
            assert!(bad_rt > (W * H / 2) as usize, "{name}: only {bad_rt} pixels differ");
        } else {
            assert_eq!(bad_ref, 0, "{name}: reference mode");
            assert_eq!(bad_rt, 0, "{name}: real-time mode");
        }
    }
}

/// The colour the quad's COLOR_0 gives its point (x, y): (u, v, 0.5) with u, v from 0 to 1
/// across it, affine, so that both triangles interpolate the same field.
fn colour_at(x: f32, y: f32) -> Vec3 {
    Vec3::new((x + 1.0) * 0.5, (y + 1.0) * 0.5, 0.5)
}

#[test]
fn vertex_colours_multiply_the_base_colour_in_both_modes() {
    let base = Vec3::new(0.8, 0.6, 0.4);
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [base.x, base.y, base.z, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
    });
    let float: Vec<f32> =
        CORNERS.iter().flat_map(|c| colour_at(c[0], c[1]).extend(1.0).to_array()).collect();
    let bytes: Vec<u8> = CORNERS
        .iter()
        .flat_map(|c| colour_at(c[0], c[1]).to_array().map(|x| (x * 255.0).round() as u8))
        .collect();
    for (name, scene) in [
        (
            "float RGBA",
            quad_file(
                "colour-float",
                |g| vec![("COLOR_0", g.floats(&float, "VEC4"))],
                material.clone(),
                2,
            ),
        ),
        (
            "unorm8 RGB",
            quad_file(
                "colour-unorm8",
                |g| vec![("COLOR_0", g.unorm8(&bytes, "VEC3"))],
                material.clone(),
                2,
            ),
        ),
    ] {
        // Under a uniform sky of radiance 1 a Lambertian surface reflects its albedo.
        let scene = Scene { environment: Environment::Constant(Vec3::ONE), ..scene };
        let acc = hush_tests::render(&scene, W, H, 64, 1).unwrap();
        let (mut worst_ref, mut worst_gb) = (0f32, 0f32);
        let (gpu, r) =
            hush_tests::realtime_renderer(&scene, (W, H), &Default::default(), 1).unwrap();
        let (albedo, format) = r.read_texture(&gpu, "gbuffer/base_color").unwrap();
        assert_eq!(format, wgpu::TextureFormat::Rgba8UnormSrgb);
        let srgb = |b: u8| srgb_to_linear(b as f32 / 255.0);
        for y in 0..H {
            for x in 0..W {
                let want = base
                    * colour_at(
                        (x as f32 + 0.5) / W as f32 * 2.0 - 1.0,
                        1.0 - (y as f32 + 0.5) / H as f32 * 2.0,
                    );
                // Reference: the pixel's mean over its footprint is the field at its centre.
                let got = acc.mean.at(x, y);
                let sd = acc.variance_of_mean.at(x, y).max_element().max(0.0).sqrt();
                worst_ref = worst_ref.max((got - want).abs().max_element() - 5.0 * sd);
                // G-buffer: one jittered sample (half a pixel: 0.5 / 32 of the field's range)
                // in 8-bit sRGB.
                let o = ((y * W + x) * 4) as usize;
                let g = Vec3::new(srgb(albedo[o]), srgb(albedo[o + 1]), srgb(albedo[o + 2]));
                worst_gb = worst_gb.max((g - want).abs().max_element());
            }
        }
        println!("{name}: worst reference error beyond 5 sigma {worst_ref}, G-buffer {worst_gb}");
        // The 8-bit file's colours are off by up to 1/510.
        assert!(worst_ref < 4e-3, "{name}: reference {worst_ref}");
        assert!(worst_gb < 0.5 / W as f32 + 8e-3, "{name}: G-buffer {worst_gb}");
    }
}

/// A normal map read through KHR_texture_transform tilts the normal along the transformed
/// coordinates: the G-buffer's normals equal those of the same quad with the transform baked
/// into TEXCOORD_0 (whose tangents the importer derives from the baked coordinates), and differ
/// from the normal map read untransformed. The map is the tiles' texture (every texel a
/// different colour, so a different tilt).
#[test]
fn transformed_normal_maps_turn_their_tangent_frame() {
    let lambert = |info: Value| {
        json!({
            "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "normalTexture": info,
        })
    };
    let baked = quad_file(
        "normals-baked",
        |g| vec![("TEXCOORD_0", g.floats(&uvs(transformed), "VEC2"))],
        lambert(json!({"index": 0})),
        2,
    );
    let transform = quad_file(
        "normals-transform",
        |g| vec![("TEXCOORD_0", g.floats(&uvs(|uv| uv), "VEC2"))],
        lambert(json!({"index": 0, "extensions": khr(json!({}))})),
        2,
    );
    let normals = |scene: &Scene| -> Vec<Vec3> {
        let (gpu, r) =
            hush_tests::realtime_renderer(scene, (W, H), &Default::default(), 1).unwrap();
        let (bytes, _) = r.read_texture(&gpu, "gbuffer/normal").unwrap();
        (0..(W * H) as usize).map(|i| hush_tests::oct_normal(&bytes[i * 4..])).collect()
    };
    let (want, got) = (normals(&baked), normals(&transform));
    // The same texels read without the transform's rotation of the frame.
    let unturned: Vec<Vec3> = {
        let mut s = transform.clone();
        let t = s.materials[0].normal_texture.as_mut().unwrap();
        let uv_only = t.transform;
        t.transform = glam::Affine2::IDENTITY;
        // Keep the coordinates: bake them into the mesh's TEXCOORD_0 instead.
        for uv in &mut s.meshes[0].uvs {
            *uv = uv_only.transform_point2(*uv);
        }
        s.meshes[0].tangents = transform.meshes[0].tangents.clone();
        normals(&s)
    };
    let worst = |a: &[Vec3]| {
        a.iter().zip(&want).map(|(x, y)| x.angle_between(*y).to_degrees()).fold(0f32, f32::max)
    };
    let (turned, plain) = (worst(&got), worst(&unturned));
    let tilt = want.iter().map(|n| n.angle_between(Vec3::Z).to_degrees()).fold(0f32, f32::max);
    println!(
        "normal maps: worst angle to the baked quad's normals {turned:.3} degrees with the frame turned, {plain:.2} without (tilts up to {tilt:.1})"
    );
    // Oct-encoded snorm16 normals: 0.01 degrees; a jittered sample may fall on the
    // neighbouring texel at a texel border in one image and not the other, so compare the
    // bulk: at most 10% of pixels beyond 0.5 degrees.
    let far = |a: &[Vec3]| {
        a.iter().zip(&want).filter(|(x, y)| x.angle_between(**y).to_degrees() > 0.5).count()
    };
    assert!(far(&got) * 10 <= want.len(), "{} of {} pixels turned wrong", far(&got), want.len());
    assert!(far(&unturned) * 2 > want.len(), "the check compares something: {plain}");
}

/// NormalTangentMirrorTest's point, on a file of our own: two quads mirror images of each other
/// about x = 0, the right one's TEXCOORD_0 running right to left (a mirrored UV island, which
/// flips its tangents' handedness), both normal-mapped with the tiles' texture. The G-buffer's
/// normals must be mirror images too: n(x) = (-n.x, n.y, n.z) at -x. With the handedness
/// ignored (tangents' w forced to +1) the right half's tilt in y turns the wrong way.
#[test]
fn mirrored_uv_islands_mirror_their_normal_maps() {
    let mut g = GltfWriter::default();
    g.materials.push(json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        "normalTexture": {"index": 0},
    }));
    let mesh = g.mesh(Prim {
        positions: &[
            [-1.0, -1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        normals: Some(&[[0.0, 0.0, 1.0]; 8]),
        indices: Some(&[0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7]),
        material: 0,
    });
    let uv = g.floats(
        &[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0],
        "VEC2",
    );
    g.meshes[mesh]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(uv);
    g.node(json!({"mesh": mesh}));
    g.camera([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], 2.0 * 0.5f32.atan());
    g.extras = json!({"max_depth": 2});
    let mut j = g.to_json();
    j["images"] = json!([{"uri": texture_uri()}]);
    j["textures"] = json!([{"source": 0, "sampler": 0}]);
    j["samplers"] = json!([{"magFilter": 9728}]);
    let scene = load_gltf(&hush_tests::gltf_writer::write_json("mirrored-uvs", &j)).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let tangents = &scene.meshes[0].tangents;
    // glTF's v runs down the image: the plain island is left-handed (w = -1), its mirror not.
    assert!(tangents[..4].iter().all(|t| t.w < 0.0) && tangents[4..].iter().all(|t| t.w > 0.0));
    // Mirror pairs that disagree by more than 2 degrees (a jittered sample near a texel border
    // may read the neighbouring texel on one side only: NEAREST keeps that to the borders).
    let asymmetric = |scene: &Scene| {
        let (gpu, r) =
            hush_tests::realtime_renderer(scene, (W, H), &Default::default(), 1).unwrap();
        let (bytes, _) = r.read_texture(&gpu, "gbuffer/normal").unwrap();
        let n = |x: u32, y: u32| hush_tests::oct_normal(&bytes[((y * W + x) * 4) as usize..]);
        let mut bad = 0;
        for y in 0..H {
            for x in 0..W / 2 {
                let (l, r) = (n(x, y), n(W - 1 - x, y));
                if Vec3::new(-l.x, l.y, l.z).angle_between(r).to_degrees() > 2.0 {
                    bad += 1;
                }
            }
        }
        bad
    };
    let with = asymmetric(&scene);
    let mut unsigned = scene.clone();
    for t in &mut unsigned.meshes[0].tangents {
        t.w = 1.0;
    }
    let without = asymmetric(&unsigned);
    let pairs = (W * H / 2) as usize;
    println!(
        "mirrored UVs: {with} of {pairs} mirror pairs disagree; {without} with the handedness ignored"
    );
    assert!(with * 10 <= pairs, "{with} of {pairs} pairs are not mirror images");
    assert!(without * 2 > pairs, "the check compares something: {without}");
}

/// Hush's export keeps what these files say: each texture's TEXCOORD set and transform (a
/// mirrored one too), TEXCOORD_1 and COLOR_0.
#[test]
fn export_keeps_texture_transforms_sets_and_vertex_colours() {
    let mut scenes: Vec<(&str, Scene)> = variants();
    let colours: Vec<f32> = CORNERS.iter().flat_map(|c| [c[0], c[1], 0.5, 1.0]).collect();
    scenes.push((
        "colours and a mirrored transform",
        quad_file(
            "export-colours",
            |g| {
                vec![
                    ("COLOR_0", g.floats(&colours, "VEC4")),
                    ("TEXCOORD_0", g.floats(&uvs(|uv| uv), "VEC2")),
                ]
            },
            emissive(json!({"index": 0, "extensions": khr(json!({"scale": [-1.5, 0.8]}))})),
            1,
        ),
    ));
    for (name, scene) in scenes {
        let dir = hush_tests::gltf_writer::temp_dir("texcoords-export");
        let path = dir.join("exported.gltf");
        hush_engine::scene::save_gltf(&scene, &path).unwrap();
        let back = load_gltf(&path).unwrap();
        assert!(back.warnings.is_empty(), "{name}: {:?}", back.warnings);
        for (a, b) in scene.materials.iter().zip(&back.materials) {
            for (ta, tb) in a.texture_refs().into_iter().zip(b.texture_refs()) {
                match (ta, tb) {
                    (None, None) => {}
                    (Some(ta), Some(tb)) => {
                        assert_eq!(ta.set, tb.set, "{name}");
                        assert!(
                            ta.transform.abs_diff_eq(tb.transform, 1e-5),
                            "{name}: {:?} against {:?}",
                            ta.transform,
                            tb.transform
                        );
                    }
                    _ => panic!("{name}: a texture lost or gained"),
                }
            }
        }
        let (ma, mb) = (&scene.meshes[0], &back.meshes[0]);
        assert_eq!(ma.uvs1, mb.uvs1, "{name}");
        assert_eq!(ma.colors, mb.colors, "{name}");
        println!("{name}: {} TEXCOORD_1, {} COLOR_0 kept", mb.uvs1.len(), mb.colors.len());
    }
}
