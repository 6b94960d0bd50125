//! glTF import on real scenes and the radiometric conventions of lights.

use glam::{DVec3, Vec3};
use hush_engine::scene::{Light, load_gltf, load_gltf_with};
use hush_tests::gltf_writer::{GltfWriter, Prim};
use hush_tests::{render, shared};
use serde_json::json;

#[test]
#[cfg_attr(
    not(hush_shared_scenes),
    ignore = "needs ../shared/scenes (FlightHelmet, Lantern), absent beside this checkout"
)]
fn scenes_with_missing_textures_warn_and_render() {
    for (path, missing) in [
        ("scenes/FlightHelmet/glTF/FlightHelmet.gltf", "LeatherPartsMat"),
        ("scenes/Lantern/glTF/Lantern.gltf", "Lantern_baseColor"),
    ] {
        let scene = load_gltf_with(&shared().join(path), 64).unwrap();
        assert!(
            scene.warnings.iter().any(|w| w.contains(missing)),
            "{path}: warnings {:?}",
            scene.warnings
        );
        assert!(!scene.textures.is_empty() && scene.triangle_count() > 1000);
        // Normal maps present: every mesh that uses one has tangents (read or generated).
        for o in &scene.objects {
            let m = &scene.meshes[o.mesh];
            if scene.materials[m.material as usize].normal_texture.is_some() {
                assert_eq!(m.tangents.len(), m.positions.len());
            }
        }
        let mut scene = scene;
        scene.add_sun_and_sky_if_unlit();
        let acc = render(&scene, 24, 24, 4, 0).unwrap();
        assert_eq!(acc.nonfinite_samples, 0, "{path}");
        assert!(acc.mean.mean().max_element() > 0.0, "{path}");
    }
}

#[test]
#[cfg_attr(
    not(hush_shared_scenes),
    ignore = "needs ../shared/scenes (living-room, staircase), absent beside this checkout"
)]
fn bitterli_scenes_load_with_their_extras() {
    let lr = load_gltf_with(&shared().join("scenes/living-room/living-room.gltf"), 16).unwrap();
    assert_eq!(lr.resolution, Some((1280, 720)));
    assert_eq!(lr.max_depth, 65);
    assert!(
        matches!(lr.environment, hush_engine::scene::Environment::Map(ref m) if m.rotation_y_degrees == 90.0 && m.width > 0)
    );
    // Its windows are Mitsuba's dielectric: glass, read without a warning.
    let glass = lr.materials.iter().find(|m| m.name == "Glass").expect("the Glass material");
    assert_eq!((glass.transmission, glass.ior, glass.thickness), (1.0, 1.5, 0.01));
    assert!(!lr.warnings.iter().any(|w| w.contains("KHR_materials")), "{:?}", lr.warnings);
    assert!(lr.camera.is_some());
    let st = load_gltf_with(&shared().join("scenes/staircase/staircase.gltf"), 16).unwrap();
    assert_eq!(st.resolution, Some((720, 1280)));
    assert!(st.materials.iter().any(|m| m.is_emissive()));
}

/// A diffuse floor of albedo rho under a point light of intensity I at height d has radiance
/// rho/pi x I/d² directly below it; under a sun of irradiance E at angle theta, rho/pi x E cos theta.
#[test]
fn punctual_lights_follow_the_radiometric_conventions() {
    let rho = 0.5f32;
    for (name, light, expected) in [
        (
            "point",
            json!({"type": "point", "intensity": 8.0, "color": [1.0, 1.0, 1.0]}),
            rho / std::f32::consts::PI * 8.0 / 4.0,
        ),
        (
            "sun",
            json!({"type": "directional", "intensity": 3.0, "color": [1.0, 1.0, 1.0]}),
            rho / std::f32::consts::PI * 3.0 * 0.5,
        ),
        (
            "spot",
            json!({"type": "spot", "intensity": 8.0, "color": [1.0, 1.0, 1.0], "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}),
            rho / std::f32::consts::PI * 8.0 / 4.0,
        ),
    ] {
        let mut g = GltfWriter::default();
        let m = g.lambert([rho; 3]);
        let s = 50.0;
        let mesh = g.mesh(Prim {
            positions: &[[-s, 0.0, -s], [s, 0.0, -s], [s, 0.0, s], [-s, 0.0, s]],
            normals: Some(&[[0.0, 1.0, 0.0]; 4]),
            indices: Some(&[0, 2, 1, 0, 3, 2]),
            material: m,
        });
        g.node(json!({"mesh": mesh}));
        g.lights.push(light);
        // Point and spot: 2 m above the floor under a parent node (hierarchy composes). The sun
        // travels along its node's -Z, rotated to come down at 60 degrees from the zenith.
        let rot60 = [
            -(0.5f32 * std::f32::consts::FRAC_PI_3 + 0.5 * std::f32::consts::FRAC_PI_2).sin(),
            0.0,
            0.0,
            (0.5f32 * std::f32::consts::FRAC_PI_3 + 0.5 * std::f32::consts::FRAC_PI_2).cos(),
        ];
        let down = [
            -(0.5f32 * std::f32::consts::FRAC_PI_2).sin(),
            0.0,
            0.0,
            (0.5f32 * std::f32::consts::FRAC_PI_2).cos(),
        ];
        let child = if name == "sun" {
            g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": rot60}))
        } else {
            g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0.0, 1.5, 0.0], "rotation": down}))
        };
        g.node(json!({"children": [child], "translation": [0.0, 0.5, 0.0]}));
        g.camera([0.0, 1.0, 0.0], [0.0, 0.0, -0.0001], 0.05);
        g.extras = json!({"max_depth": 2});
        let scene = load_gltf(&g.write(name)).unwrap();
        match scene.lights[0] {
            Light::Point { position, .. } | Light::Spot { position, .. } => {
                assert!((position - DVec3::new(0.0, 2.0, 0.0)).length() < 1e-6, "{position}")
            }
            Light::Directional { direction, .. } => {
                assert!((direction.y + 0.5).abs() < 1e-3, "{direction}")
            }
        }
        let acc = render(&scene, 4, 4, 16, 0).unwrap();
        let got = acc.mean.mean();
        println!("{name}: floor radiance {got} (expected {expected})");
        // Direct light only and a narrow view straight down: every sample sees the same value,
        // up to the light's 1/d² variation across the 0.05 rad view (< 0.1%).
        assert!(
            (got - Vec3::splat(expected)).abs().max_element() < 2e-3 * expected,
            "{name}: {got} vs {expected}"
        );
    }
}

#[test]
fn mirrored_transforms_keep_front_faces_counter_clockwise() {
    let mut g = GltfWriter::default();
    let m = g.emitter(1.0);
    let mesh = g.mesh(Prim {
        positions: &[[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]],
        normals: Some(&[[0.0, 1.0, 0.0]; 4]),
        indices: Some(&[0, 2, 1, 0, 3, 2]),
        material: m,
    });
    g.node(json!({"mesh": mesh, "scale": [-1.0, 1.0, 1.0]}));
    g.camera([0.0, 2.0, 0.0], [0.0, 0.0, -0.0001], 0.5);
    let scene = load_gltf(&g.write("mirrored")).unwrap();
    // Seen from above, the (mirrored) emitter's front face is still the lit one.
    let acc = render(&scene, 4, 4, 4, 0).unwrap();
    assert!((acc.mean.mean() - Vec3::ONE).abs().max_element() < 1e-4, "{}", acc.mean.mean());
}

/// The point of the Khronos OrientationTest, on a file of Hush's own: six arrows built along +Y,
/// turned by node quaternions, node matrices and nested nodes (mixing both) to point along +X,
/// -X, +Y, -Y, +Z and -Z, each a colour of its own. Where each arrow's middle projects (the
/// camera's pinhole projection of the intended direction, computed here), both modes show that
/// arrow's colour. Swapped quaternion components, a transposed matrix or nested transforms
/// composed in the wrong order move arrows off their spots (the nested -Z arrow lands on +X).
#[test]
fn node_rotations_point_every_arrow_where_it_should() {
    use std::f32::consts::FRAC_1_SQRT_2 as H;
    let colours: [[f32; 3]; 6] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 1.0],
        [1.0, 0.0, 1.0],
    ];
    let directions = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
    let mut g = GltfWriter::default();
    let arrows: Vec<usize> = colours
        .iter()
        .map(|c| {
            g.materials.push(json!({
                "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
                "emissiveFactor": c, "doubleSided": true,
            }));
            let m = g.materials.len() as u32 - 1;
            let b = hush_engine::scene::cuboid(Vec3::new(0.0, 1.5, 0.0), Vec3::new(0.25, 1.0, 0.25), m);
            g.engine_mesh(&b, m as usize)
        })
        .collect();
    // +X: a quaternion, 90 degrees about -Z. -X: a matrix, 90 degrees about +Z (column-major).
    g.node(json!({"mesh": arrows[0], "rotation": [0.0, 0.0, -H, H]}));
    g.node(json!({"mesh": arrows[1], "matrix": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}));
    // +Y: a parent's matrix (90 degrees about +X) undone by its child's quaternion.
    let child = g.node(json!({"mesh": arrows[2], "rotation": [-H, 0.0, 0.0, H]}));
    g.node(
        json!({"children": [child], "matrix": [1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1]}),
    );
    // -Y: half a turn about Z. +Z: a matrix, 90 degrees about +X.
    g.node(json!({"mesh": arrows[3], "rotation": [0.0, 0.0, 1.0, 0.0]}));
    g.node(json!({"mesh": arrows[4], "matrix": [1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1]}));
    // -Z: the child turns +Y to +X, then its parent turns +X to -Z (90 degrees about +Y).
    let child = g.node(json!({"mesh": arrows[5], "rotation": [0.0, 0.0, -H, H]}));
    g.node(json!({"children": [child], "rotation": [0.0, H, 0.0, H]}));
    let (eye, target, yfov) = (Vec3::new(7.0, 5.5, 9.0), Vec3::new(0.0, 0.3, 0.0), 0.6f32);
    g.camera(eye.to_array(), target.to_array(), yfov);
    g.extras = json!({"max_depth": 1});
    let scene = load_gltf(&g.write("orientation")).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);

    const N: u32 = 64;
    // The pinhole projection of the camera written above (square image).
    let z = (eye - target).normalize();
    let x = Vec3::Y.cross(z).normalize();
    let y = z.cross(x);
    let pixel = |p: Vec3| {
        let d = p - eye;
        let s = (yfov / 2.0).tan() * -d.dot(z);
        let (u, v) = (d.dot(x) / s, d.dot(y) / s);
        (((u + 1.0) / 2.0 * N as f32) as u32, ((1.0 - v) / 2.0 * N as f32) as u32)
    };
    let reference = render(&scene, N, N, 16, 3).unwrap().mean;
    let realtime = hush_tests::realtime_accumulate(&scene, N, N, 8, 3).unwrap();
    for (mode, img) in [("reference", &reference), ("real time", &realtime)] {
        for (k, d) in directions.iter().enumerate() {
            let (px, py) = pixel(1.5 * *d);
            let seen = img.at(px, py);
            // The nearest of the six colours and black: an arrow 3.5 pixels wide leaves its
            // middle pixel that arrow's colour, within the few pixels' jitter at its edges.
            let nearest = colours
                .iter()
                .chain(std::iter::once(&[0.0; 3]))
                .map(|c| (Vec3::from(*c) - seen).length())
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            println!("{mode}: arrow {d} at ({px}, {py}) shows {seen}");
            assert!(
                nearest.0 == k && nearest.1 < 0.35,
                "{mode}: the pixel where the {d} arrow should be shows {seen}"
            );
        }
    }
}

/// A thin-lens camera survives Hush's own glTF export.
#[test]
fn a_thin_lens_round_trips_through_export() {
    let scene =
        hush_engine::scene::load_gltf(&hush_tests::oracle("cornell_dof").join("cornell_dof.gltf"))
            .unwrap();
    let path = hush_tests::gltf_writer::temp_dir("lens_export").join("dof.gltf");
    hush_engine::scene::save_gltf(&scene, &path).unwrap();
    let back = hush_engine::scene::load_gltf(&path).unwrap();
    let lens = |s: &hush_engine::scene::Scene| s.camera.as_ref().and_then(|c| c.lens);
    assert!(lens(&scene).is_some());
    assert_eq!(lens(&back), lens(&scene));
}

/// KHR_materials_ior sets a dielectric's normal-incidence reflectance to ((ior - 1) / (ior + 1))²:
/// a black, polished quad seen head-on under a uniform sky of radiance 1 reflects exactly that
/// (Schlick's F at cos 0.9997 differs from F0 by under 1e-12), in the reference tracer and in the
/// G-buffer's F0.
#[test]
fn index_of_refraction_sets_the_reflectance() {
    for (ior, json_ior) in [(1.5f32, None), (2.0, Some(2.0)), (1.2, Some(1.2))] {
        let mut g = GltfWriter::default();
        let mut material = json!({
            "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.0},
        });
        if let Some(i) = json_ior {
            material["extensions"] = json!({"KHR_materials_ior": {"ior": i}});
        }
        g.materials.push(material);
        let mesh = g.mesh(Prim {
            positions: &[[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]],
            normals: Some(&[[0.0, 0.0, 1.0]; 4]),
            indices: Some(&[0, 1, 2, 0, 2, 3]),
            material: 0,
        });
        g.node(json!({"mesh": mesh}));
        g.camera([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], 0.05);
        g.extras = json!({"max_depth": 2, "environment": {"radiance": [1.0, 1.0, 1.0]}});
        let scene = load_gltf(&g.write(&format!("ior-{ior}"))).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
        let got = render(&scene, 4, 4, 4, 0).unwrap().mean.mean();
        println!("ior {ior}: reflected {got}, F0 {f0}");
        assert!((got - Vec3::splat(f0)).abs().max_element() < 1e-4, "ior {ior}: {got} vs {f0}");
        let (gpu, r) =
            hush_tests::realtime_renderer(&scene, (4, 4), &Default::default(), 1).unwrap();
        let (spec, _) = r.read_texture(&gpu, "gbuffer/specular").unwrap();
        let g_f0 = spec[0] as f32 / 255.0;
        assert!((g_f0 - f0).abs() <= 1.0 / 255.0, "ior {ior}: G-buffer F0 {g_f0} vs {f0}");
    }
}

/// A CUBICSPLINE translation channel moves its node along glTF 2.0 Appendix C's Hermite
/// spline (not linearly between the keys), without a warning; Hush's export writes it back as
/// CUBICSPLINE and the re-import moves the same way.
#[test]
fn cubic_spline_channels_follow_their_tangents_and_round_trip() {
    let mut g = GltfWriter::default();
    let m = g.lambert([0.5, 0.5, 0.5]);
    let mesh = g.mesh(Prim {
        positions: &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        normals: None,
        indices: None,
        material: m,
    });
    let node = g.node(json!({"mesh": mesh}));
    g.camera([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 0.8);
    let times = g.floats(&[0.0, 2.0], "SCALAR");
    // Key 0: in (9, 9, 9), value (0, 0, 0), out (1, 0, 0); key 1: in (0, 3, 0), value (2, 0, 0),
    // out (9, 9, 9).
    let out = g.floats(
        &[9.0, 9.0, 9.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 3.0, 0.0, 2.0, 0.0, 0.0, 9.0, 9.0, 9.0],
        "VEC3",
    );
    let mut j = g.to_json();
    j["accessors"][times]["min"] = json!([0.0]);
    j["accessors"][times]["max"] = json!([2.0]);
    j["animations"] = json!([{
        "samplers": [{"input": times, "output": out, "interpolation": "CUBICSPLINE"}],
        "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]
    }]);
    let want = |t: f64| {
        let (s, dt) = (t / 2.0, 2.0);
        let (p0, b0, p1, a1) = (
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
        );
        p0 * (2.0 * s * s * s - 3.0 * s * s + 1.0)
            + b0 * dt * (s * s * s - 2.0 * s * s + s)
            + p1 * (-2.0 * s * s * s + 3.0 * s * s)
            + a1 * dt * (s * s * s - s * s)
    };
    let scene = load_gltf(&hush_tests::gltf_writer::write_json("cubic-spline", &j)).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let dir = hush_tests::gltf_writer::temp_dir("cubic-spline-export");
    hush_engine::scene::save_gltf(&scene, &dir.join("exported.gltf")).unwrap();
    let back = load_gltf(&dir.join("exported.gltf")).unwrap();
    for s in [&scene, &back] {
        let o = s.objects.iter().find(|o| o.animation.is_some()).expect("an animated object");
        for t in [0.25, 1.0, 1.5] {
            let p = o.transform_at(t).transform_point3(DVec3::ZERO);
            assert!((p - want(t)).length() < 1e-5, "t = {t}: {p} against {}", want(t));
        }
    }
    // At t = 1 the spline stands at (1.25, -0.75, 0): the linear path would be at (1, 0, 0).
    assert!((want(1.0) - DVec3::new(1.25, -0.75, 0.0)).length() < 1e-12);
}
