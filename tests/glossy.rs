//! The glossy chain (Mara et al. 2017 §3.4 stages 8-10, Voorhuis §4): the diamond search on a
//! synthetic motion, the virtual-position reprojection of a plane mirror against geometry, the
//! surface reprojection's normal test, the reflected-hit test of glossy lobes, the bilateral's
//! sigma, and the motion stage made again when its program's constants change.

use glam::{DVec3, Vec2, Vec4};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, GpuRequirements};
use hush_engine::scene::Camera;
use hush_engine::settings::{Denoiser, FrameSettings, GlossySettings, ReflectionMv};
use hush_tests::reproject::{DepthFrame, Surface, neighbours_3x3};
use hush_tests::{half, oct_normal};

/// The search of shaders/glossy/diamond.wgsl over a synthetic previous frame whose world
/// position is (pixel centre, 0): the pixel p of this frame shows the point at p + motion.
const DIAMOND_TEST: &str = r#"
struct Probe {
    h: vec3f,
}

struct TestParams {
    motion: vec2f,
    size: vec2u,
    initial_step: u32,
    max_steps: u32,
    _pad: vec2u,
}

@group(0) @binding(0) var<uniform> u: TestParams;
@group(0) @binding(1) var<storage, read_write> result: array<vec4f>;

fn search_distance(q: vec2i, probe: Probe) -> f32 {
    if any(q < vec2i(0)) || q.x >= i32(u.size.x) || q.y >= i32(u.size.y) {
        return INF;
    }
    return length(vec3f(vec2f(q) + 0.5, 0.0) - probe.h);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if gid.x >= u.size.x || gid.y >= u.size.y {
        return;
    }
    let p = vec2i(gid.xy);
    let centre = vec2f(p) + 0.5;
    let r = diamond_search(p, p, u.initial_step, u.max_steps, Probe(vec3f(centre + u.motion, 0.0)));
    result[gid.y * u.size.x + gid.x] = vec4f(r.coord - centre, f32(r.steps), r.dist);
}
"#;

/// (motion found, iterations, distance) per pixel.
fn run_diamond(gpu: &Gpu, size: (u32, u32), motion: Vec2, initial_step: u32) -> Vec<Vec4> {
    use hush_tests::compute::{Input, run_compute};
    let params: [u32; 8] =
        [motion.x.to_bits(), motion.y.to_bits(), size.0, size.1, initial_step, 64, 0, 0];
    let bytes = run_compute(
        gpu,
        DIAMOND_TEST,
        &["common/math.wgsl", "glossy/diamond.wgsl"],
        &[Input::Uniform(bytemuck::cast_slice(&params))],
        (size.0 * size.1) as u64 * 16,
        (size.0.div_ceil(8), size.1.div_ceil(8)),
    );
    bytemuck::cast_slice::<u8, [f32; 4]>(&bytes).iter().map(|v| Vec4::from_array(*v)).collect()
}

/// Integer motions, small and larger than the first step, are found exactly (distance 0 takes
/// all of eq. (2)'s weight) wherever the moved pixel is on screen; a sub-pixel motion lands
/// within half a pixel (eq. (3) interpolates between the best 2x2 block's centres).
#[test]
fn diamond_search_finds_a_known_motion() {
    let gpu = Gpu::headless(&GpuRequirements::default()).unwrap();
    let size = (64u32, 48u32);
    for (motion, exact) in [
        (Vec2::ZERO, true),
        (Vec2::new(3.0, -2.0), true),
        (Vec2::new(13.0, 7.0), true),
        (Vec2::new(-21.0, 5.0), true),
        (Vec2::new(2.25, -1.5), false),
    ] {
        for initial_step in [4, 1] {
            let out = run_diamond(&gpu, size, motion, initial_step);
            let mut worst = 0.0f32;
            let mut checked = 0;
            for y in 0..size.1 {
                for x in 0..size.0 {
                    let target = Vec2::new(x as f32, y as f32) + 0.5 + motion;
                    // Pixels whose answer lies on screen with a margin for the 2x2 refinement.
                    if target.x < 1.0
                        || target.y < 1.0
                        || target.x > size.0 as f32 - 1.0
                        || target.y > size.1 as f32 - 1.0
                    {
                        continue;
                    }
                    let v = out[(y * size.0 + x) as usize];
                    worst = worst.max((v.truncate().truncate() - motion).length());
                    checked += 1;
                }
            }
            assert!(checked > 500, "{checked}");
            let bound = if exact { 1e-4 } else { 0.5 };
            assert!(
                worst <= bound,
                "motion {motion}, first step {initial_step}: worst error {worst} px (bound {bound})"
            );
        }
    }
}

/// A camera above the `reflections` scene's mirror floor, looking at its back wall (z = -8).
fn camera(x: f64) -> Camera {
    Camera::look_at(DVec3::new(x, 1.2, 3.0), DVec3::new(x, 0.2, -4.0), 50.0)
}

/// Mara's virtual position for a plane mirror: the wall seen in the floor lies, unfolded, on
/// the camera ray where it meets the plane z = -8, so its motion vector is that point projected
/// by the previous camera, minus the pixel. Checked on every floor pixel that reflects the wall;
/// the diamond search must agree with it there.
#[test]
fn virtual_position_of_a_plane_mirror_is_analytic() {
    let size = (96u32, 54u32);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::reflection_scene(true), BvhKind::DEFAULT, size)
            .unwrap();
    let mut s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    s.taa.enabled = false; // samples at pixel centres
    s.glossy.reflection_mv = ReflectionMv::Diamond;
    let (before, now) = (camera(-0.15), camera(0.15));
    r.render(&gpu, &FrameInput { camera: before, time: 0.0, shutter: None }, &s, None).unwrap();
    r.render(&gpu, &FrameInput { camera: now, time: 0.0, shutter: None }, &s, None).unwrap();
    let (motion, _) = r.read_texture(&gpu, "glossy/motion").unwrap();
    let motion: &[[f32; 4]] = bytemuck::cast_slice(&motion);
    let (glossy, _) = r.read_texture(&gpu, "trace/glossy").unwrap();
    let origin = r.prepared.origin.as_vec3();
    let cur = r.camera_setup(&now);
    let prev = r.camera_setup(&before);
    let (mut n, mut worst, mut diamond_err, mut within) = (0, 0.0f32, 0.0f32, 0);
    for y in 0..size.1 {
        for x in 0..size.0 {
            let ndc = Vec2::new(
                (x as f32 + 0.5) / size.0 as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / size.1 as f32 * 2.0,
            );
            let d = (cur.fwd + ndc.x * cur.right + ndc.y * cur.up).normalize();
            let c = cur.pos + origin;
            if d.y >= 0.0 {
                continue;
            }
            let s_floor = -c.y / d.y;
            let s_wall = (-8.0 - c.z) / d.z;
            let wall_y = -(c.y + d.y * s_wall);
            let i = (y * size.0 + x) as usize;
            let t = half(&glossy[i * 8 + 6..i * 8 + 8]);
            // Floor pixels whose mirror ray reaches the wall unobstructed (its secondary distance,
            // stored as a half float, is the analytic one), away from the wall's top edge.
            if s_wall <= s_floor
                || !(0.1..3.8).contains(&wall_y)
                || ((s_wall - s_floor) - t).abs() > 4e-3
            {
                continue;
            }
            let v = c + d * s_wall - origin;
            let clip = prev.view_proj * v.extend(1.0);
            let ndc_prev = clip.truncate().truncate() / clip.w;
            let expected = Vec2::new(
                (ndc_prev.x * 0.5 + 0.5) * size.0 as f32,
                (0.5 - ndc_prev.y * 0.5) * size.1 as f32,
            ) - Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let m = motion[i];
            if std::env::var("HUSH_TEST_VERBOSE").is_ok()
                && (Vec2::new(m[2], m[3]) - expected).length() > 0.05
            {
                println!(
                    "({x},{y}) expected {expected} virtual {:?} diamond {:?} t {t} s_floor {s_floor} s_wall {s_wall}",
                    (m[2], m[3]),
                    (m[0], m[1])
                );
            }
            worst = worst.max((Vec2::new(m[2], m[3]) - expected).length());
            let e = (Vec2::new(m[0], m[1]) - expected).length();
            diamond_err += e;
            within += (e <= 1.0) as u32;
            n += 1;
        }
    }
    assert!(n > 200, "only {n} floor pixels reflect the wall");
    // The secondary distance is a half float (steps of 2-4 mm at 3-8 m): hundredths of a pixel.
    assert!(worst < 0.05, "virtual position off by up to {worst} px over {n} pixels");
    // The search is exact to the pixel; eq. (3)'s sub-pixel step weighs the best 2x2 block by
    // distance products, which is not linear interpolation (measured: 0.53 px mean here).
    let mean = diamond_err / n as f32;
    let share = within as f32 / n as f32;
    println!(
        "diamond vs analytic: mean {mean:.3} px, {:.1}% within 1 px, {n} pixels",
        share * 100.0
    );
    assert!(
        mean < 0.75 && share > 0.9,
        "diamond search {mean} px from the analytic motion on average, {share} within 1 px ({n} pixels)"
    );
}

/// In a static view (no camera or object motion) reflections stand still: every pixel's
/// reflection motion is exactly zero, whatever the diamond search matched between the two
/// jittered frames (here 625 of 5184 pixels had a non-zero answer). Bilinear resampling at
/// those answers blurred the still level's reflections: with this rule and the surface test
/// it lets the glossy temporal use, the level's FLIP (160x90, 60 still frames) went from
/// 0.0652 to 0.0623.
#[test]
fn a_static_view_keeps_its_reflections_still() {
    let size = (96u32, 54u32);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::reflection_scene(true), BvhKind::DEFAULT, size)
            .unwrap();
    let mut s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    s.glossy.reflection_mv = ReflectionMv::Diamond;
    for _ in 0..4 {
        r.render(&gpu, &FrameInput { camera: camera(0.0), time: 0.0, shutter: None }, &s, None)
            .unwrap();
    }
    let (motion, _) = r.read_texture(&gpu, "glossy/motion").unwrap();
    let motion: &[[f32; 4]] = bytemuck::cast_slice(&motion);
    let moving = motion.iter().filter(|m| m[0] != 0.0 || m[1] != 0.0).count();
    assert_eq!(
        moving,
        0,
        "{moving} of {} pixels have reflection motion in a static view",
        motion.len()
    );
}

/// Sigma = 7 r^0.1 + epsilon (Mara §3.4): exact on rough surfaces (no ray-differential term
/// above the roughness threshold); below it reduced by Voorhuis eq. (6): on the plane mirror
/// floor between no reduction and a ray differential of 12 footprints (1 to 9 in this view), on
/// the spheres (which minify what they reflect) anywhere down to 0.
#[test]
fn glossy_bilateral_sigma() {
    let g = GlossySettings::default();
    assert!((g.sigma_px(1.0, 0.0) - 8.0).abs() < 1e-5);
    assert!((g.sigma_px(0.2, 0.0) - (7.0 * 0.2f32.powf(0.1) + 1.0)).abs() < 1e-5);
    assert!(
        (g.sigma_px(0.2, 16.0) - (7.0 * 0.2f32.powf(0.1) + 1.0) * (-1.0f32).exp()).abs() < 1e-5
    );
    assert_eq!(g.sigma_px(0.6, 16.0), g.sigma_px(0.6, 0.0));
    assert!((g.sigma_px(0.0, 0.0) - 1.0).abs() < 1e-6);

    let size = (96u32, 54u32);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::reflection_scene(true), BvhKind::DEFAULT, size)
            .unwrap();
    let s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    r.render(&gpu, &FrameInput { camera: camera(0.0), time: 0.0, shutter: None }, &s, None)
        .unwrap();
    let (scratch, _) = r.read_texture(&gpu, "glossy/scratch").unwrap();
    let (specular, _) = r.read_texture(&gpu, "gbuffer/specular").unwrap();
    let (ids, _) = r.read_texture(&gpu, "gbuffer/ids").unwrap();
    let mut seen = [0; 3];
    for i in 0..(size.0 * size.1) as usize {
        if u32::from_le_bytes(ids[i * 8 + 4..i * 8 + 8].try_into().unwrap()) == u32::MAX {
            continue;
        }
        let roughness = specular[i * 4 + 3] as f32 / 255.0;
        let sigma = half(&scratch[i * 8 + 6..i * 8 + 8]);
        let object = u32::from_le_bytes(ids[i * 8..i * 8 + 4].try_into().unwrap());
        // Object 0 is the floor (scene::reflection_scene).
        let most = if object == 0 || roughness >= g.roughness_threshold { 12.0 } else { 1e4 };
        let (lo, hi) = (g.sigma_px(roughness, most), g.sigma_px(roughness, 0.0));
        if std::env::var("HUSH_TEST_VERBOSE").is_ok()
            && !(sigma >= lo - 0.01 * hi - 1e-3 && sigma <= hi * 1.01 + 1e-3)
        {
            println!(
                "pixel ({}, {}) roughness {roughness} sigma {sigma} [{lo}, {hi}]",
                i % size.0 as usize,
                i / size.0 as usize
            );
            continue;
        }
        let tol = 0.01 * hi + 1e-3; // half-float storage
        assert!(
            sigma >= lo - tol && sigma <= hi + tol,
            "pixel {i}: roughness {roughness}, sigma {sigma} outside [{lo}, {hi}]"
        );
        seen[if roughness >= g.roughness_threshold {
            0
        } else if roughness > g.mirror_roughness {
            1
        } else {
            2
        }] += 1;
    }
    assert!(seen.iter().all(|&k| k > 20), "rough, glossy, mirror pixels: {seen:?}");
}

/// The glossy history of a pixel comes from its own face. In a still view every frame samples
/// another sub-pixel position, so a pixel on a crease or a ledge thinner than a pixel shows one
/// face in one frame and the other face in the next, and eq. (11)'s position test passes
/// both (they are within a footprint of each other). The two faces reflect different things
/// under different Fresnel weights, and the chain filters glossy light divided by F: a history
/// that mixes them came out ten times too bright on the staircase's table edge (row 177 at
/// 160x284: 4.3 against a reference of 0.46). The reprojection's normal test
/// (GlossySettings::reprojection_normal_degrees) rejects such texels. The test recomputes the
/// 3x3 reprojection on the CPU (positions through both frames' jittered cameras, distances in
/// footprints as tests/denoise.rs does) and finds the pixels where a texel passes the position
/// test but none of them is on a face within the angle: their confidence must be 0.
#[test]
fn glossy_history_stays_on_its_face() {
    use hush_engine::frame::halton_jitter;
    use hush_engine::settings::ReprojectionSettings;
    let size = (96u32, 54u32);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::default_level(), BvhKind::DEFAULT, size).unwrap();
    let cam = Camera::look_at(DVec3::new(-3.0, 1.7, 4.0), DVec3::new(-2.0, 1.2, -6.0), 60.0);
    let s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    let warm = 7;
    for _ in 0..warm {
        r.render(&gpu, &FrameInput { camera: cam, time: 0.0, shutter: None }, &s, None).unwrap();
    }
    let read = |r: &Renderer, n: &str| r.read_texture(&gpu, n).unwrap().0;
    let (depth0, normal0) = (read(&r, "gbuffer/depth"), read(&r, "gbuffer/normal"));
    r.render(&gpu, &FrameInput { camera: cam, time: 0.0, shutter: None }, &s, None).unwrap();
    let (depth1, normal1, info) =
        (read(&r, "gbuffer/depth"), read(&r, "gbuffer/normal"), read(&r, "glossy/info"));
    let setup = r.camera_setup(&cam);
    let (inv0, inv1) = (
        setup.jittered(halton_jitter(warm - 1), size).inverse(),
        setup.jittered(halton_jitter(warm), size).inverse(),
    );
    let before = DepthFrame { depth: &depth0, inv_view_proj: inv0, size };
    let now = DepthFrame { depth: &depth1, inv_view_proj: inv1, size };
    let (m, cos_max) = (
        ReprojectionSettings::default(),
        GlossySettings::default().reprojection_normal_degrees.to_radians().cos(),
    );
    let (mut creases, mut kept) = (0, Vec::new());
    for y in 0..size.1 as i64 {
        for x in 0..size.0 as i64 {
            let Some(p) = now.world(x, y) else { continue };
            let i = now.index(x, y).unwrap();
            let surface = Surface::new(p, oct_normal(&normal1[i * 4..]), &setup, size.1);
            // (distance in footprints, cosine to this normal) of each previous texel with a surface.
            let texels: Vec<(f32, f32)> = neighbours_3x3(x, y)
                .filter_map(|(tx, ty)| Some((before.world(tx, ty)?, before.index(tx, ty)?)))
                .map(|(prev, t)| {
                    (surface.distance(prev), surface.n.dot(oct_normal(&normal0[t * 4..])))
                })
                .collect();
            // Margins around d0, d1 and the angle keep float rounding from deciding a pixel.
            let position_only = texels.iter().any(|&(dist, _)| dist < 0.9 * m.d0_px);
            let same_face =
                texels.iter().any(|&(dist, cos)| dist < 1.1 * m.d1_px && cos >= cos_max - 0.02);
            if position_only && !same_face {
                creases += 1;
                let c = half(&info[i * 8..]);
                if c != 0.0 {
                    kept.push((x, y, c));
                }
            }
        }
    }
    println!("{creases} crease pixels, {} kept another face's glossy history", kept.len());
    assert!(creases >= 10, "the view has only {creases} crease pixels");
    assert!(
        kept.is_empty(),
        "crease pixels kept another face's glossy history (x, y, confidence): {:?}",
        &kept[..kept.len().min(20)]
    );
}

/// `glossy.hit_test`: where the history follows reflection motion, a glossy (not mirror)
/// pixel keeps its history only where its previous pixel reflected the same point. The
/// `reflections` scene, the camera strafing 10 cm a frame and the box sliding, 8 frames, with
/// the test on and off: the glossy pixels whose confidence the test alone lowers must be ones none of
/// whose 3x3 previous glossy pixels reflected a point within this pixel's reflected footprint
/// (the distance to its nearest neighbour's reflected point; the test starts lowering at 2
/// reaches, a reach being at least that footprint), and it must lower some. Measured at
/// 96x54: of 604 glossy pixels it lowers 12, none within a footprint; a reach of 1e-4 lowers
/// 591, 441 of them within a footprint; a test of mirrors alone lowers none.
#[test]
fn glossy_history_follows_its_reflected_point() {
    let size = (96u32, 54u32);
    let run = |hit_test: bool| {
        let (gpu, mut r) =
            Renderer::headless(hush_engine::scene::reflection_scene(true), BvhKind::DEFAULT, size)
                .unwrap();
        let mut s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
        s.glossy.hit_test = hit_test;
        let frames = 8;
        for k in 0..frames {
            let input =
                FrameInput { camera: camera(k as f64 * 0.1), time: k as f64 * 0.1, shutter: None };
            r.render(&gpu, &input, &s, None).unwrap();
        }
        let read = |n: &str| r.read_texture(&gpu, n).unwrap().0;
        // This frame wrote hit `frames % 2`'s partner: the other slot is the previous frame's.
        let hits = [read("glossy/hit 0"), read("glossy/hit 1")];
        let parity = frames % 2;
        let (now, before) = (hits[1 - parity as usize].clone(), hits[parity as usize].clone());
        (read("glossy/info"), read("glossy/motion"), now, before)
    };
    let (info_on, motion, now, before) = run(true);
    let (info_off, motion_off, now_off, _) = run(false);
    // The trace does not depend on the test: both runs saw the same hits and motion.
    assert!(now == now_off && motion == motion_off);
    let texel = |b: &[u8], i: usize| -> Vec4 {
        let f: &[f32] = bytemuck::cast_slice(&b[i * 16..i * 16 + 16]);
        Vec4::new(f[0], f[1], f[2], f[3])
    };
    // Hit class by the w encoding of shaders/glossy/common.wgsl: glossy t + 1 (> 0, < 1e30).
    let glossy = |w: f32| w > 0.0 && w < 1e29;
    let (w, h) = (size.0 as i64, size.1 as i64);
    let (mut rejected, mut stayed) = (0, 0);
    let mut glossy_pixels = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let hit = texel(&now, i);
            if !glossy(hit.w) {
                continue;
            }
            let (c_on, c_off) = (half(&info_on[i * 8..]), half(&info_off[i * 8..]));
            glossy_pixels += 1;
            if !(c_on < c_off) {
                continue;
            }
            rejected += 1;
            let m = texel(&motion, i);
            let q = (x as f32 + 0.5 + m.x, y as f32 + 0.5 + m.y);
            let closest = neighbours_3x3(q.0.floor() as i64, q.1.floor() as i64)
                .filter(|&(tx, ty)| tx >= 0 && ty >= 0 && tx < w && ty < h)
                .map(|(tx, ty)| texel(&before, (ty * w + tx) as usize))
                .filter(|p| glossy(p.w))
                .map(|p| (p.truncate() - hit.truncate()).length())
                .fold(f32::INFINITY, f32::min);
            // This pixel's reflected footprint: how far its nearest neighbour's reflected point lies
            // (another across the edge of a reflected object lies far).
            let spacing: Vec<f32> = [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)]
                .into_iter()
                .filter(|&(nx, ny)| nx >= 0 && ny >= 0 && nx < w && ny < h)
                .map(|(nx, ny)| texel(&now, (ny * w + nx) as usize))
                .filter(|n| glossy(n.w))
                .map(|n| (n.truncate() - hit.truncate()).length())
                .collect();
            let footprint = spacing.iter().copied().fold(f32::INFINITY, f32::min);
            stayed += (closest <= footprint) as u32;
        }
    }
    println!(
        "of {glossy_pixels} glossy pixels the hit test lowered {rejected} pixels' confidence, {stayed} of them within a footprint of a previous reflected point"
    );
    assert!(rejected >= 5, "the hit test lowered only {rejected} glossy pixels' confidence");
    assert_eq!(stayed, 0, "{stayed} pixels lost confidence though their reflected point stayed");
}

/// The reflection motion's program has the brute-force search compiled in only while
/// `glossy.reference_search_radius` asks for it (denoise/mara/glossy.rs: MotionProgram), so a change of
/// the setting between frames must make the stage again, in Mara's glossy chain and in SVGF's
/// glossy signal alike. The search view's fourth channel is the brute-force search's best
/// distance: zero everywhere without it, and set on reflective pixels with it. With the stage
/// kept, the frame after the switch would still show no brute-force distances.
#[test]
fn the_reference_search_comes_and_goes_with_its_setting() {
    let size = (96u32, 54u32);
    for (denoiser, search) in
        [(Denoiser::MARA, "glossy/search"), (Denoiser::SVGF, "svgf/glossy search")]
    {
        let (gpu, mut r) =
            Renderer::headless(hush_engine::scene::reflection_scene(true), BvhKind::DEFAULT, size)
                .unwrap();
        // SVGF's search view is read after the frame.
        r.keep(&[search]);
        let name = format!("{denoiser:?}");
        let mut s = FrameSettings { denoiser, ..Default::default() };
        s.glossy.reflection_mv = ReflectionMv::Diamond;
        // The camera strafes, so that every frame after the first searches.
        let mut measured = vec![];
        for (i, radius) in [0u32, 0, 4, 4, 0].into_iter().enumerate() {
            s.glossy.reference_search_radius = radius;
            let input = FrameInput { camera: camera(0.05 * i as f64), time: 0.0, shutter: None };
            r.render(&gpu, &input, &s, None).unwrap();
            let (texels, _) = r.read_texture(&gpu, search).unwrap();
            let with_distance = texels.chunks_exact(8).filter(|t| half(&t[6..8]) != 0.0).count();
            measured.push(with_distance);
        }
        println!("{name}: pixels with a brute-force distance, frame by frame: {measured:?}");
        assert_eq!(measured[1], 0, "{name}: a brute-force distance with the search off");
        assert!(
            measured[2] > 200 && measured[3] > 200,
            "{name}: the brute-force search did not start with its setting: {measured:?}"
        );
        assert_eq!(measured[4], 0, "{name}: the brute-force search outlived its setting");
    }
}
