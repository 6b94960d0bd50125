//! The GPU BVH (both layouts) against obvhs's CPU traversal on a real scene.

use glam::{DVec3, Vec3, Vec3A};
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::Raycaster;
use hush_tests::{Xorshift, shared};
use obvhs::{
    BvhBuildParams,
    ray::{Ray, RayHit},
    triangle::Triangle,
};

/// Barycentrics (b1, b2) of p in triangle t, in f64.
fn barycentrics(t: &Triangle, p: DVec3) -> (f64, f64) {
    let v0 = Vec3::from(t.v0).as_dvec3();
    let e1 = Vec3::from(t.v1).as_dvec3() - v0;
    let e2 = Vec3::from(t.v2).as_dvec3() - v0;
    let d = p - v0;
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (dp1, dp2) = (d.dot(e1), d.dot(e2));
    let den = d11 * d22 - d12 * d12;
    ((d22 * dp1 - d12 * dp2) / den, (d11 * dp2 - d12 * dp1) / den)
}

#[test]
#[cfg_attr(
    not(hush_shared_scenes),
    ignore = "needs ../shared/scenes/living-room, absent beside this checkout"
)]
fn gpu_traversal_matches_obvhs_cpu_traversal_on_the_living_room() {
    let path = shared().join("scenes/living-room/living-room.gltf");
    let scene = hush_engine::scene::load_gltf_with(&path, 16).expect("living room loads");
    assert!(scene.triangle_count() > 100_000);
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let prepared = PreparedScene::new(&scene, kind).unwrap();
        let n = prepared.triangle_count();
        // The triangles in input order, as the GPU holds them (scene-relative coordinates).
        let mut tris = vec![Triangle::default(); n];
        for slot in 0..n {
            let orig = prepared.tris[slot * 3 + 1].w.to_bits() as usize;
            let v = |k: usize| Vec3A::from(prepared.tris[slot * 3 + k].truncate());
            tris[orig] = Triangle { v0: v(0), v1: v(1), v2: v(2) };
        }
        // An independent CPU BVH over the same triangles.
        let mut t = std::time::Duration::ZERO;
        let cpu = obvhs::bvh2::builder::build_bvh2_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut t,
        );

        let gpu = Gpu::headless(&prepared.requirements(0, 0)).unwrap();
        let gscene = prepared.upload(&gpu);
        let caster = Raycaster::new(&gpu, &gscene).unwrap();
        let (lo, hi) = scene.bounds().unwrap();
        let (lo, hi) = ((lo - prepared.origin).as_vec3(), (hi - prepared.origin).as_vec3());
        let cam = (scene.camera_or_default().eye() - prepared.origin).as_vec3();
        let mut rng = Xorshift(12345);
        // Half incoherent rays from random points in the bounds, half from the camera.
        let rays: Vec<(Vec3, Vec3, f32)> = (0..8192)
            .map(|i| {
                let o = if i % 2 == 0 {
                    lo + (hi - lo) * Vec3::new(rng.uniform(), rng.uniform(), rng.uniform())
                } else {
                    cam
                };
                (o, rng.dir(), f32::MAX)
            })
            .collect();
        let (gpu_hits, _) = caster.cast(&gpu, &gscene, &rays, false).unwrap();
        let (any_hits, _) = caster.cast(&gpu, &gscene, &rays, true).unwrap();

        let (mut hit_miss_disagree, mut other_triangle, mut hits) = (0, 0, 0);
        let (mut worst_t, mut worst_b) = (0f64, 0f64);
        for (i, (o, d, _)) in rays.iter().enumerate() {
            let ray = Ray::new_inf((*o).into(), (*d).into());
            let mut h = RayHit::none();
            let cpu_hit = cpu.ray_traverse(ray, &mut h, |r, id| {
                tris[cpu.primitive_indices[id] as usize].intersect(r)
            });
            let cpu_tri = cpu_hit.then(|| cpu.primitive_indices[h.primitive_id as usize]);
            assert_eq!(
                any_hits[i].is_some(),
                gpu_hits[i].is_some(),
                "{kind:?}: any-hit and closest-hit disagree on ray {i}"
            );
            match (gpu_hits[i], cpu_tri) {
                (Some(g), Some(ct)) => {
                    hits += 1;
                    let rel = (g.t as f64 - h.t as f64).abs() / (h.t as f64).max(1.0);
                    worst_t = worst_t.max(rel);
                    if g.triangle != ct {
                        other_triangle += 1;
                        continue;
                    }
                    let p = o.as_dvec3() + d.as_dvec3() * h.t as f64;
                    let (b1, b2) = barycentrics(&tris[ct as usize], p);
                    worst_b = worst_b.max((b1 - g.b1 as f64).abs()).max((b2 - g.b2 as f64).abs());
                }
                (None, None) => {}
                (g, c) => {
                    hit_miss_disagree += 1;
                    eprintln!("ray {i}: gpu {g:?} cpu {c:?} t {} o {o} d {d}", h.t);
                }
            }
        }
        println!(
            "{kind:?}: {hits} hits of {} rays; hit/miss disagreements {hit_miss_disagree}; other triangle {other_triangle}; \
             worst relative t error {worst_t:.2e}; worst barycentric error {worst_b:.2e}",
            rays.len()
        );
        // The room is closed: nearly every ray hits something.
        assert!(hits > rays.len() * 9 / 10, "{kind:?}: only {hits} hits");
        // Distances agree to f32 precision of the intersection arithmetic (a few ulps of t).
        assert!(worst_t < 1e-4, "{kind:?}: relative t error {worst_t}");
        // Barycentrics from the GPU's Möller-Trumbore vs an f64 projection of the CPU hit point:
        // the hit point itself carries ~1e-6 relative error, which thin triangles magnify.
        assert!(worst_b < 2e-3, "{kind:?}: barycentric error {worst_b}");
        // A ray through a shared edge or vertex may be given to either triangle (same t, checked
        // above); a ray grazing an edge may be a hit on one side and a miss on the other. Both are
        // rare: at most 0.2% of rays.
        assert!(
            other_triangle * 500 <= rays.len(),
            "{kind:?}: {other_triangle} rays hit another triangle"
        );
        assert!(
            hit_miss_disagree * 500 <= rays.len(),
            "{kind:?}: {hit_miss_disagree} hit/miss disagreements"
        );
    }
}

/// A cast larger than the device's storage binding (32 bytes a ray) goes in batches: every ray
/// gets its hit, in order.
#[test]
fn casts_larger_than_a_binding_go_in_batches() {
    let scene = hush_engine::scene::load_gltf(
        &hush_tests::oracle("cornell_diffuse").join("cornell_diffuse.gltf"),
    )
    .unwrap();
    let prepared = PreparedScene::new(&scene, BvhKind::Cwbvh).unwrap();
    let gpu = Gpu::headless(&prepared.requirements(0, 0)).unwrap();
    let gscene = prepared.upload(&gpu);
    let caster = Raycaster::new(&gpu, &gscene).unwrap();
    let most = gpu.device.limits().max_storage_buffer_binding_size as usize / 32;
    // From the box's centre: straight up hits the ceiling, the rest alternate down to the floor.
    let centre =
        ((scene.bounds().unwrap().0 + scene.bounds().unwrap().1) * 0.5 - prepared.origin).as_vec3();
    let rays: Vec<(Vec3, Vec3, f32)> = (0..most + 1000)
        .map(|i| (centre, if i % 2 == 0 { Vec3::Y } else { Vec3::NEG_Y }, f32::MAX))
        .collect();
    let (hits, _) = caster.cast(&gpu, &gscene, &rays, false).unwrap();
    assert_eq!(hits.len(), rays.len());
    let (up, down) = (hits[0].unwrap().t, hits[1].unwrap().t);
    for (i, h) in hits.iter().enumerate().skip(most - 2) {
        let t = h.unwrap_or_else(|| panic!("ray {i} missed")).t;
        assert_eq!(t, if i % 2 == 0 { up } else { down }, "ray {i}");
    }
}

/// An animated scene's two trees (the static objects' built once, the moving objects' rebuilt
/// at each move, visited after it: engine/src/gpu/prepare/assemble.rs) find what one tree over
/// the same triangles finds: the default level with its cube turning, before and after a move
/// (after which only the moving part is uploaded again), against the level with the cube placed
/// where the animation has it and nothing animated. 8,192 rays, both layouts: the same hit or
/// miss, the same distance within rounding and the same triangle (by its vertices) but for a
/// ray through a shared edge (at most 0.2%, as against obvhs above).
#[test]
fn split_trees_find_what_one_tree_finds() {
    let animated = hush_engine::scene::default_level();
    let cube = animated.objects.iter().position(|o| o.animation.is_some()).unwrap();
    for kind in [BvhKind::Bvh2, BvhKind::Cwbvh] {
        let mut prepared = PreparedScene::new(&animated, kind).unwrap();
        assert!(prepared.dynamic_root().is_some(), "{kind:?}: the level is split");
        let gpu = Gpu::headless(&prepared.requirements(0, 0)).unwrap();
        let mut gscene = prepared.upload(&gpu);
        for (step, time) in [(0, None), (1, Some(1.3)), (2, Some(2.9))] {
            if let Some(t) = time {
                let moved = prepared.animate(&animated, t);
                assert!(moved);
                gscene.update_geometry(&gpu, &prepared, moved);
            }
            // The same scene with nothing animated and the cube where it is now.
            let mut still = animated.clone();
            for o in &mut still.objects {
                o.transform = time.map_or(o.transform, |t| o.transform_at(t));
                o.animation = None;
            }
            let single = PreparedScene::new(&still, kind).unwrap();
            assert!(single.dynamic_root().is_none());
            assert_eq!(single.origin, prepared.origin);
            let sgpu = single.upload(&gpu);
            let caster = Raycaster::new(&gpu, &gscene).unwrap();
            let single_caster = Raycaster::new(&gpu, &sgpu).unwrap();
            let cube_at =
                (still.objects[cube].transform.w_axis.truncate() - prepared.origin).as_vec3();
            let mut rng = Xorshift(777 + step);
            // Half the rays aimed near the cube, half anywhere.
            let rays: Vec<(Vec3, Vec3, f32)> = (0..8192)
                .map(|i| {
                    let o = cube_at + Vec3::new(3.0, 1.0, 2.5);
                    let target =
                        cube_at + (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5);
                    let d = if i % 2 == 0 { (target - o).normalize() } else { rng.dir() };
                    (o, d, f32::MAX)
                })
                .collect();
            let (a, _) = caster.cast(&gpu, &gscene, &rays, false).unwrap();
            let (b, _) = single_caster.cast(&gpu, &sgpu, &rays, false).unwrap();
            let vertices = |p: &PreparedScene, orig: u32| {
                let slot = (0..p.triangle_count())
                    .find(|&s| p.tris[s * 3 + 1].w.to_bits() == orig)
                    .unwrap();
                [0, 1, 2].map(|k| p.tris[slot * 3 + k].truncate())
            };
            let (mut on_cube, mut hits, mut other) = (0, 0, 0);
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                match (x, y) {
                    (Some(x), Some(y)) => {
                        hits += 1;
                        // Two trees may order a ray's tests differently: a ray through a shared
                        // edge may go to either triangle, at the same distance within rounding.
                        let rel = (x.t - y.t).abs() / y.t.max(1.0);
                        assert!(
                            rel < 1e-5,
                            "{kind:?} step {step} ray {i}: t {} against {}",
                            x.t,
                            y.t
                        );
                        other += (vertices(&prepared, x.triangle) != vertices(&single, y.triangle))
                            as u32;
                        on_cube += (x.triangle >= prepared.static_inputs()) as u32;
                    }
                    (None, None) => {}
                    _ => panic!("{kind:?} step {step} ray {i}: {x:?} against {y:?}"),
                }
            }
            assert!(other * 500 <= hits, "{kind:?} step {step}: {other} rays hit another triangle");
            println!(
                "{kind:?} step {step}: {hits} hits, {on_cube} on the moving cube, {other} on another triangle"
            );
            assert!(on_cube > 1000, "{kind:?} step {step}: only {on_cube} rays hit the cube");
        }
    }
}
