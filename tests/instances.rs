//! Meshes stored once for the objects that draw them (engine/src/gpu/prepare/instances.rs): the
//! two levels find the hits one flattened level finds, on random rays, still and moving; the
//! instanced scene renders as its flattened copy in both modes; a mesh drawn a thousand times
//! costs little more GPU memory than drawn once.

use glam::{DMat4, DQuat, DVec3, Vec3};
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, Instancing, PreparedScene};
use hush_engine::passes::Raycaster;
use hush_engine::quality::relmse;
use hush_engine::scene::{
    Animation, Camera, Deform, Environment, Material, Morph, MorphTarget, Object, Scene, Track,
    quad, uv_sphere,
};
use hush_tests::Xorshift;

/// A floor, a ceiling light and `n` copies of an off-centre sphere on a grid, each turned,
/// scaled (one in three non-uniformly) and one in four mirrored. `shared`: one mesh for all
/// of them, else a copy each (which instancing leaves flattened). `moving`: every other copy
/// spins about its vertical over 2 s.
fn field(n: usize, shared: bool, moving: bool) -> Scene {
    let materials = vec![
        Material { base_color: glam::Vec4::new(0.7, 0.7, 0.7, 1.0), ..Default::default() },
        Material { emission: Vec3::splat(6.0), ..Default::default() },
        Material {
            base_color: glam::Vec4::new(0.8, 0.3, 0.2, 1.0),
            roughness: 0.3,
            ..Default::default()
        },
    ];
    let mut meshes = vec![
        quad(Vec3::ZERO, Vec3::new(6.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -6.0), 0),
        quad(Vec3::new(0.0, 4.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0), 1),
    ];
    let sphere = uv_sphere(Vec3::new(0.15, 0.0, 0.05), 0.3, 2, 16, 8);
    let mut objects =
        vec![Object::new("floor", 0, DMat4::IDENTITY), Object::new("light", 1, DMat4::IDENTITY)];
    let side = (n as f64).sqrt().ceil() as usize;
    for i in 0..n {
        let mesh = if shared && i > 0 {
            meshes.len() - 1
        } else {
            meshes.push(sphere.clone());
            meshes.len() - 1
        };
        let (x, z) = ((i % side) as f64, (i / side) as f64);
        let at = DVec3::new((x - side as f64 / 2.0) * 0.9, 0.4, (z - side as f64 / 2.0) * 0.9);
        let turn = DQuat::from_rotation_y(i as f64 * 0.7) * DQuat::from_rotation_x(i as f64 * 0.3);
        let mut scale = DVec3::splat(0.8 + 0.1 * (i % 3) as f64);
        if i % 3 == 1 {
            scale.y *= 1.6;
        }
        if i % 4 == 3 {
            scale.x = -scale.x;
        }
        let mut o = Object::new(
            format!("copy{i}"),
            mesh,
            DMat4::from_scale_rotation_translation(scale, turn, at),
        );
        if moving && i % 2 == 0 {
            let mut a = Animation::rigid(DMat4::IDENTITY, at, turn, scale);
            a.rotation_track = Some(Track {
                times: vec![0.0, 1.0, 2.0],
                values: (0..3).map(|k| DQuat::from_rotation_y(k as f64 * 2.0) * turn).collect(),
                step: false,
                tangents: vec![],
            });
            o.animation = Some(a);
        }
        objects.push(o);
    }
    Scene {
        name: "instance field".into(),
        meshes,
        objects,
        materials,
        camera: Some(Camera::look_at(DVec3::new(0.0, 2.2, 3.5), DVec3::new(0.0, 0.3, 0.0), 60.0)),
        environment: Environment::Constant(Vec3::splat(0.2)),
        max_depth: 4,
        ..Default::default()
    }
}

/// Rays from above the field at random points of it and random directions.
fn rays(seed: u32, origin: DVec3) -> Vec<(Vec3, Vec3, f32)> {
    let mut rng = Xorshift(seed);
    let rebase = |p: DVec3| (p - origin).as_vec3();
    (0..8192)
        .map(|i| {
            let o = rebase(DVec3::new(0.0, 2.5, 1.0));
            let target = rebase(DVec3::new(
                rng.uniform() as f64 * 5.0 - 2.5,
                0.4,
                rng.uniform() as f64 * 5.0 - 2.5,
            ));
            let d = if i % 4 == 3 {
                Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.9, rng.uniform() - 0.5).normalize()
            } else {
                (target - o).normalize()
            };
            (o, d, f32::MAX)
        })
        .collect()
}

/// Hits of the two levels against one level's: the same misses, the same distances (the
/// instance's ray is carried into its mesh's space, which rounds differently: 1e-4 relative
/// is about 40 f32 ulps), and the same triangle's vertices. Returns the hits.
fn compare(
    kind: BvhKind,
    step: usize,
    two: &PreparedScene,
    one: &PreparedScene,
    gpu: &Gpu,
) -> usize {
    let (g2, g1) = (two.upload(gpu), one.upload(gpu));
    let rays = rays(99 + step as u32, one.origin);
    let (a, _) = Raycaster::new(gpu, &g2).unwrap().cast(gpu, &g2, &rays, false).unwrap();
    let (b, _) = Raycaster::new(gpu, &g1).unwrap().cast(gpu, &g1, &rays, false).unwrap();
    let (mut hits, mut mismatched) = (0, 0);
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        match (x, y) {
            (Some(x), Some(y)) => {
                hits += 1;
                let rel = (x.t - y.t).abs() / y.t.max(1.0);
                assert!(rel < 1e-4, "{kind:?} step {step} ray {i}: t {} against {}", x.t, y.t);
            }
            (None, None) => {}
            // A ray through an edge between two triangles may slip past both in one space
            // and not the other.
            _ => mismatched += 1,
        }
    }
    assert!(mismatched * 1000 <= rays.len(), "{kind:?} step {step}: {mismatched} rays disagree");
    println!("{kind:?} step {step}: {hits} hits, {mismatched} disagree");
    hits
}

#[test]
fn two_levels_find_what_one_level_finds() {
    let moving = field(40, true, true);
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let mut two = PreparedScene::with_instancing(&moving, kind, Instancing::Always).unwrap();
        let mut one = PreparedScene::with_instancing(&moving, kind, Instancing::Never).unwrap();
        assert!(two.features.instances && !one.features.instances);
        // The sphere is stored once: the floor, the light and one sphere.
        let sphere = moving.meshes[2].indices.len() / 3;
        assert_eq!(two.triangle_count(), 4 + sphere);
        assert_eq!(one.triangle_count(), 4 + 40 * sphere);
        let gpu = Gpu::headless(&one.requirements(0, 0)).unwrap();
        for (step, time) in [0.0, 0.6, 1.3].into_iter().enumerate() {
            if step > 0 {
                assert!(two.animate(&moving, time) && !two.geometry_moved);
                assert!(one.animate(&moving, time));
            }
            assert!(compare(kind, step, &two, &one, &gpu) > 4000);
        }
    }
}

#[test]
fn auto_instances_only_where_sharing_pays() {
    let shared = field(12, true, false);
    let copies = field(12, false, false);
    let two = PreparedScene::new(&shared, BvhKind::DEFAULT).unwrap();
    let one = PreparedScene::new(&copies, BvhKind::DEFAULT).unwrap();
    assert!(two.features.instances);
    assert!(!one.features.instances);
    // Two objects of a mesh in a scene of many others do not pay.
    let mut level = hush_engine::scene::default_level();
    let first = level.objects[0].clone();
    level.objects.push(first);
    assert!(!PreparedScene::new(&level, BvhKind::DEFAULT).unwrap().features.instances);
}

#[test]
fn instanced_field_renders_as_its_flattened_copy() {
    let shared = field(12, true, false);
    let copies = field(12, false, false);
    let (w, h) = (64, 48);
    let bias = |a: &hush_engine::quality::Image, b: &hush_engine::quality::Image| {
        (a.mean() / b.mean() - Vec3::ONE).abs().max_element()
    };
    // Reference mode. With the same samples the paths differ only where a hit's rounding in the
    // mesh's space moves a later bounce, so the two differ by less than half of what another
    // seed gives the flattened field, and their means agree.
    let a = hush_tests::render(&shared, w, h, 32, 5).unwrap().mean;
    let b = hush_tests::render(&copies, w, h, 32, 5).unwrap().mean;
    let c = hush_tests::render(&copies, w, h, 32, 6).unwrap().mean;
    let (e, noise) = (relmse(&a, &b), relmse(&c, &b));
    println!("reference: relMSE {e:.2e} (another seed {noise:.2e}), bias {:.4}", bias(&a, &b));
    assert!(e < 0.5 * noise, "reference: relMSE {e} against another seed's {noise}");
    assert!(bias(&a, &b) < 0.005, "reference: bias {}", bias(&a, &b));
    // Real time: the G-buffer's instanced draws and the light traced from them.
    let a = hush_tests::realtime_accumulate(&shared, w, h, 16, 5).unwrap();
    let b = hush_tests::realtime_accumulate(&copies, w, h, 16, 5).unwrap();
    let c = hush_tests::realtime_accumulate(&copies, w, h, 16, 6).unwrap();
    let (e, noise) = (relmse(&a, &b), relmse(&c, &b));
    println!("real time: relMSE {e:.2e} (another seed {noise:.2e}), bias {:.4}", bias(&a, &b));
    assert!(e < 0.5 * noise, "real time: relMSE {e} against another seed's {noise}");
    assert!(bias(&a, &b) < 0.005, "real time: bias {}", bias(&a, &b));
}

/// The reference tracer's mean over a shutter open from 0.6 s to 1.3 s (the spinning copies
/// turn 1.4 rad).
fn blurred(scene: &Scene, seed: u32) -> hush_engine::quality::Image {
    use hush_engine::passes::{ReferenceTracer, TraceView};
    let (w, h) = (64, 48);
    let mut prepared = PreparedScene::new(scene, BvhKind::DEFAULT).unwrap();
    prepared.expose(scene, 1.3, Some(0.6));
    assert!(prepared.shutter_moves());
    let gpu = Gpu::headless(&prepared.requirements((w * h) as u64, 32)).unwrap();
    let gscene = prepared.upload(&gpu);
    let camera = scene.camera_or_default();
    let view = TraceView {
        shutter_camera: Some(camera),
        ..TraceView::new(camera, (w, h), scene.max_depth, seed)
    };
    let mut t = ReferenceTracer::new(&gpu, &prepared, &gscene, &view).unwrap();
    t.dispatch(&gpu, 32);
    t.readback(&gpu).unwrap().mean
}

#[test]
fn instances_blur_as_their_flattened_copies() {
    // Instances move by their transforms blended over the shutter; flattened copies by their
    // vertices blended: the same motion.
    let shared = field(12, true, true);
    let copies = field(12, false, true);
    assert!(PreparedScene::new(&shared, BvhKind::DEFAULT).unwrap().features.instances);
    let (a, b, c) = (blurred(&shared, 5), blurred(&copies, 5), blurred(&copies, 6));
    let (e, noise) = (relmse(&a, &b), relmse(&c, &b));
    let bias = (a.mean() / b.mean() - Vec3::ONE).abs().max_element();
    println!("blurred: relMSE {e:.2e} (another seed {noise:.2e}), bias {bias:.4}");
    assert!(e < 0.5 * noise, "blurred: relMSE {e} against another seed's {noise}");
    assert!(bias < 0.005, "blurred: bias {bias}");
}

#[test]
#[cfg_attr(
    not(hush_shared_scenes),
    ignore = "needs ../shared/scenes (FlightHelmet), absent beside this checkout"
)]
fn a_thousand_flight_helmets_cost_little_more_memory_than_one() {
    let path = hush_tests::shared().join("scenes/FlightHelmet/glTF/FlightHelmet.gltf");
    let one = Scene::load(path.to_str().unwrap()).unwrap();
    // A thousand helmets side by side, 0.6 m apart.
    let mut many = one.clone();
    many.objects = (0..1000)
        .flat_map(|k| {
            let shift = DMat4::from_translation(DVec3::new(
                (k % 40) as f64 * 0.6,
                0.0,
                (k / 40) as f64 * 0.6,
            ));
            one.objects.iter().map(move |o| Object { transform: shift * o.transform, ..o.clone() })
        })
        .collect();
    let (p1, p1000) = (
        PreparedScene::new(&one, BvhKind::DEFAULT).unwrap(),
        PreparedScene::new(&many, BvhKind::DEFAULT).unwrap(),
    );
    assert!(!p1.features.instances && p1000.features.instances);
    let gpu = Gpu::headless(&p1000.requirements(0, 0)).unwrap();
    let (m1, m1000) =
        (p1.upload(&gpu).memory.total_bytes(), p1000.upload(&gpu).memory.total_bytes());
    let ratio = m1000 as f64 / m1 as f64;
    println!("FlightHelmet: one {m1} bytes, a thousand {m1000} bytes ({ratio:.3}x)");
    assert!(ratio <= 1.1, "a thousand helmets take {ratio:.3}x the memory of one");
}

/// `s` with a quad beside the field whose one morph target lifts it 0.5 over 2 s: a scene whose
/// meshes deform, where motion vectors are per vertex (realtime/motion_vertices.wgsl).
fn with_morph(mut s: Scene) -> Scene {
    let mut m =
        quad(Vec3::new(1.8, 0.05, 1.2), Vec3::new(0.8, 0.0, 0.0), Vec3::new(0.0, 0.0, -0.8), 2);
    m.targets = vec![MorphTarget {
        positions: vec![Vec3::new(0.0, 0.5, 0.0); m.positions.len()],
        ..Default::default()
    }];
    s.meshes.push(m);
    let mut o = Object::new("morph", s.meshes.len() - 1, DMat4::IDENTITY);
    o.deform = Some(std::sync::Arc::new(Deform {
        skin: vec![],
        morph: Some(Morph {
            weights: vec![0.0],
            tracks: vec![Track {
                times: vec![0.0, 2.0],
                values: vec![0.0, 1.0],
                step: false,
                tangents: vec![],
            }],
            period: 2.0,
        }),
    }));
    s.objects.push(o);
    s
}

/// The G-buffer's object ids and motion vectors of moving instances equal their flattened
/// copies', in a scene of rigid objects and in one where a mesh also deforms (per-vertex
/// motion, where an instanced mesh's previous vertices are marked (w = 1) so that its points move
/// by their instances' transforms). Measured: 5,064 pixels agree on their object; rigid, 235
/// move, worst difference 0.001 px; with the morphing quad, 812 move, worst 0.0002 px (reading
/// the prototypes' slots as world-space vertices put a still pixel 17 px off).
#[test]
fn moving_instances_have_their_flattened_copies_motion_vectors() {
    for deforming in [false, true] {
        let scene = |shared| {
            let s = field(12, shared, true);
            if deforming { with_morph(s) } else { s }
        };
        let (two, one) = (scene(true), scene(false));
        motion_vectors_agree(two, one, deforming);
    }
}

fn motion_vectors_agree(two: Scene, one: Scene, deforming: bool) {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::settings::FrameSettings;
    let size = (96u32, 72u32);
    // The G-buffer's object ids and motion vectors between 1.2 s and 1.3 s.
    let gbuffer = |scene: Scene| {
        let camera = scene.camera.unwrap();
        let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, size).unwrap();
        for time in [1.2, 1.3] {
            let input = FrameInput { camera, time, shutter: None };
            r.render(&gpu, &input, &FrameSettings::default(), None).unwrap();
        }
        assert_eq!(r.prepared.features.instances, r.prepared.triangle_count() < 1000);
        assert_eq!(r.prepared.features.deforming, deforming);
        let ids = r.read_texture(&gpu, "gbuffer/ids").unwrap().0;
        let motion = r.read_texture(&gpu, "gbuffer/motion").unwrap().0;
        (0..(size.0 * size.1) as usize)
            .map(|i| {
                let object = u32::from_le_bytes(ids[i * 8..i * 8 + 4].try_into().unwrap());
                let m = &motion[i * 4..];
                (object, glam::Vec2::new(hush_tests::half(m), hush_tests::half(&m[2..])))
            })
            .collect::<Vec<_>>()
    };
    let two = gbuffer(two);
    let one = gbuffer(one);
    let (mut same, mut other, mut moving, mut worst) = (0, 0, 0, 0f32);
    for (i, ((a, ma), (b, mb))) in two.iter().zip(&one).enumerate() {
        if a != b {
            // A silhouette pixel may fall on either side in the two rasters.
            other += 1;
            continue;
        }
        if *a == u32::MAX {
            continue;
        }
        same += 1;
        let err = (*ma - *mb).length();
        // Half floats: 11 bits of mantissa.
        let bound = 0.02 + mb.length() / 1024.0;
        assert!(err <= bound, "pixel {i}: motion {ma} against {mb}");
        worst = worst.max(err);
        moving += (mb.length() > 0.25 && *a >= 2) as u32;
    }
    println!(
        "deforming {deforming}: {same} pixels agree on their object ({other} do not), {moving} move; worst {worst:.4} px"
    );
    assert!(other * 100 <= same, "{other} pixels show another object");
    assert!(moving > 100, "only {moving} pixels move");
}

#[test]
fn degenerate_instances_draw_nothing_and_nothing_non_finite() {
    // A copy squashed flat, one scaled by 1e30 and one with a NaN in its transform, among
    // sound ones: all three are left out of the top level (the huge one's determinant
    // overflows f32, as its triangles' areas do where flattening drops them), and no pixel in
    // either mode is NaN or Inf.
    let mut scene = field(12, true, false);
    scene.objects[2].transform = DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0));
    scene.objects[3].transform = DMat4::from_scale(DVec3::splat(1e30));
    scene.objects[4].transform.x_axis.x = f64::NAN;
    let p = PreparedScene::new(&scene, BvhKind::DEFAULT).unwrap();
    assert!(p.features.instances);
    assert!(p.instances.iter().all(|v| v.is_finite()));
    assert_eq!(p.tlas_order.len(), 9, "{:?}", p.tlas_order);
    let a = hush_tests::render(&scene, 32, 24, 4, 1).unwrap();
    assert_eq!(a.nonfinite_samples, 0);
    assert!(a.mean.data.iter().all(|c| c.is_finite()));
    let b = hush_tests::realtime_accumulate(&scene, 32, 24, 2, 1).unwrap();
    assert!(b.data.iter().all(|c| c.is_finite()));
}
