//! The GPU's walk of the light tree (shaders/common/light_tree.wgsl) against the CPU's
//! (engine/src/accel/light_tree.rs): both choose a leaf by the same importance, so for the same
//! point, normal and number they choose the same leaf with the same probability, and the walk up
//! from a leaf gives the probability the walk down gave.

use glam::Vec3;
use hush_engine::accel::light_tree::{Emitter, LEAF, LightNode, LightTree};
use hush_engine::gpu::{Gpu, GpuRequirements};
use hush_tests::Xorshift;
use hush_tests::compute::{Input, run_compute};

const WALK_TEST: &str = r#"
struct Query {
    p: vec3f,
    u: f32,
    n: vec3f,
    pad: f32,
}

struct Walk {
    node: u32,
    pmf: f32,
    // light_tree_pmf of the chosen node (0 where none was chosen).
    pmf_up: f32,
    pad: f32,
}

@group(0) @binding(1) var<storage, read> queries: array<Query>;
@group(0) @binding(2) var<storage, read_write> result: array<Walk>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x;
    if i >= arrayLength(&queries) {
        return;
    }
    let q = queries[i];
    let c = light_tree_sample(q.p, q.n, q.u);
    var up = 0.0;
    if c.pmf > 0.0 {
        up = light_tree_pmf(c.node, q.p, q.n);
    }
    result[i] = Walk(c.node, c.pmf, up, 0.0);
}
"#;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Query {
    p: [f32; 3],
    u: f32,
    n: [f32; 3],
    pad: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Walk {
    node: u32,
    pmf: f32,
    pmf_up: f32,
    pad: f32,
}

/// Lamps as the many-lamp hall has them: small one-sided triangles on two walls facing the
/// middle, their luminance over two decades. 600 of them: the tree's 1199 nodes fill more than
/// one texel row (1024 nodes), so the walk's texel addressing is tested across rows.
fn hall(rng: &mut Xorshift) -> Vec<Emitter> {
    let mut out = vec![];
    for i in 0..600u32 {
        let side = if i % 2 == 0 { -3.0 } else { 3.0 };
        let c = Vec3::new(side, 0.5 + 2.5 * rng.uniform(), 18.0 * rng.uniform());
        let (a, b) = (Vec3::new(0.0, 0.15, 0.0), Vec3::new(0.0, 0.0, 0.15));
        // Counter-clockwise seen from the middle of the hall: the face that emits looks in.
        let v = if side < 0.0 { [c, c + a, c + b] } else { [c, c + b, c + a] };
        let lum = 10f32.powf(2.0 * rng.uniform());
        out.push(Emitter::triangle(v, None, lum, 3 * i));
    }
    out
}

fn run(gpu: &Gpu, nodes: &[LightNode], queries: &[Query]) -> Vec<Walk> {
    let out = run_compute(
        gpu,
        WALK_TEST,
        &["common/light_tree.wgsl"],
        &[
            Input::Texels(bytemuck::cast_slice(nodes)),
            Input::Storage(bytemuck::cast_slice(queries)),
        ],
        (queries.len() * std::mem::size_of::<Walk>()) as u64,
        ((queries.len() as u32).div_ceil(64), 1),
    );
    bytemuck::cast_slice::<u8, Walk>(&out).to_vec()
}

/// 4096 points in and around the hall (a third with no normal, as the real-time frame's
/// candidates on a glossy lobe), against the CPU walk. The two compute the importance in f32
/// with the same operations but WGSL's inverseSqrt and sqrt are not correctly rounded (a few
/// ulps), so a number within that of a split's probability may take the other child: such
/// choices are counted, and must stay under 0.5% (measured: 0 of the 3882 lit points; the other
/// 214 lie outside the walls, behind every lamp). Where both choose the same leaf the
/// probabilities must agree to 1e-4 relative (measured: exactly equal); a mistake in either
/// side's importance moves them by far more. The walk up must
/// give back the walk down's probability, which is what MIS with BSDF sampling relies on
/// (measured: within 4.7e-7, the products taken in the other order).
#[test]
fn the_gpu_walk_chooses_as_the_cpu_walk() {
    let mut rng = Xorshift(0x1234_5679);
    let tree = LightTree::build(&hall(&mut rng));
    assert!(tree.depth() >= 6, "a tree worth walking: depth {}", tree.depth());
    assert!(tree.nodes.len() > 1024, "nodes on two texel rows: {}", tree.nodes.len());
    let queries: Vec<Query> = (0..4096)
        .map(|i| {
            let p =
                Vec3::new(-3.5 + 7.0 * rng.uniform(), 4.0 * rng.uniform(), 19.0 * rng.uniform());
            let n = if i % 3 == 0 { Vec3::ZERO } else { rng.dir() };
            Query { p: p.into(), u: rng.uniform(), n: n.into(), pad: 0.0 }
        })
        .collect();
    let gpu = Gpu::headless(&GpuRequirements::default()).unwrap();
    let got = run(&gpu, &tree.nodes, &queries);
    let (mut other_leaf, mut worst, mut worst_up, mut chosen) = (0, 0.0f32, 0.0f32, 0);
    for (i, (q, g)) in queries.iter().zip(&got).enumerate() {
        let (p, n) = (Vec3::from(q.p), Vec3::from(q.n));
        let want = tree.sample(p, n, q.u);
        let Some((leaf, pmf)) = want else {
            assert_eq!(g.pmf, 0.0, "query {i}: the CPU finds no light, the GPU {g:?}");
            continue;
        };
        assert!(g.pmf > 0.0, "query {i}: the GPU finds no light, the CPU leaf {leaf}");
        assert_ne!(tree.nodes[g.node as usize].child & LEAF, 0, "query {i}: {g:?} is no leaf");
        chosen += 1;
        let rel = |a: f32, b: f32| (a - b).abs() / b.max(1e-30);
        worst_up = worst_up.max(rel(g.pmf_up, g.pmf));
        assert!(rel(g.pmf_up, g.pmf) < 1e-4, "query {i}: walk up {} down {}", g.pmf_up, g.pmf);
        if g.node != leaf {
            other_leaf += 1;
            // The other leaf still has the CPU's probability for it.
            let cpu = tree.pmf(g.node, p, n);
            assert!(rel(g.pmf, cpu) < 1e-4, "query {i}: leaf {} pmf {} CPU {cpu}", g.node, g.pmf);
            continue;
        }
        worst = worst.max(rel(g.pmf, pmf));
        assert!(rel(g.pmf, pmf) < 1e-4, "query {i}: leaf {leaf} GPU pmf {} CPU {pmf}", g.pmf);
    }
    println!(
        "{chosen} of {} queries lit; other leaf {other_leaf}; worst relative pmf error {worst:.2e}, walk up {worst_up:.2e}",
        queries.len()
    );
    assert!(chosen > queries.len() / 2, "most points in the hall see a lamp: {chosen}");
    assert!(other_leaf * 200 < chosen, "{other_leaf} of {chosen} walks chose another leaf");
}

fn hall_scene() -> (hush_engine::scene::Scene, hush_engine::quality::Image) {
    let dir = hush_tests::oracle("many_lights");
    let scene = hush_engine::scene::load_gltf(&dir.join("many_lights.gltf")).unwrap();
    let reference = hush_engine::quality::Image::load(&dir.join("reference.exr")).unwrap();
    (scene, reference.box_downsample(4).unwrap())
}

/// Real-time settings for the hall: `candidates` light candidates, reservoirs reused or not.
fn resampling(
    max_depth: i32,
    accumulate: bool,
    candidates: u32,
    reuse: bool,
) -> hush_engine::settings::FrameSettings {
    hush_engine::settings::FrameSettings {
        max_depth,
        seed: 3,
        accumulate,
        light_candidates: candidates,
        light_reuse: reuse,
        ..Default::default()
    }
}

fn channel_means(img: &hush_engine::quality::Image) -> [f64; 3] {
    let mut m = [0.0f64; 3];
    for p in &img.data {
        (0..3).for_each(|k| m[k] += p[k] as f64);
    }
    m
}

/// The light samples resampled from 8 candidates (`FrameSettings::light_candidates`,
/// realtime/area_light.wgsl), and the same with the matte sample merged with the last frame's
/// reservoir (`light_reuse`, realtime/reservoir.wgsl), estimate the light one MIS-weighted sample
/// does: a still view of the many-lamp hall accumulated over 256 frames at 80x45 keeps its mean.
/// Measured against one sample's mean: resampled -0.32% / -0.24% / -0.18% (r, g, b); with the
/// reservoirs -0.17% / -0.17% / -0.14% (at 160x90 and 512 frames the reservoirs moved it -0.16%
/// / -0.18% / -0.16% from resampling alone: the 1 / M merge with visibility reuse, Bitterli et
/// al. §4.3); all lie +0.3-0.8% above Mitsuba's (one sample's real-time bias on this scene is
/// +0.7-0.8% at this size). A resampling weight off by its 1 / M, or a path's first segment still
/// adding the light its vertex's resampled sample carries (direct light counted twice), moves the
/// mean by far more than the 1% allowed.
#[test]
fn the_resampled_light_sample_keeps_the_mean() {
    use hush_engine::quality::compare;
    let (scene, reference) = hall_scene();
    let size = (reference.width, reference.height);
    let d = scene.max_depth;
    let run = |s| hush_tests::realtime_frames(&scene, size, &s, 256).unwrap();
    let one = run(resampling(d, true, 1, false));
    let m1 = channel_means(&one);
    let c1 = compare(&one, &reference).unwrap();
    println!("256 frames, one sample: relMSE {:.5}, bias {:?}", c1.relmse, c1.mean_rel_bias);
    for (name, reuse) in [("8 candidates", false), ("8 candidates and reservoirs", true)] {
        let img = run(resampling(d, true, 8, reuse));
        let m = channel_means(&img);
        let c = compare(&img, &reference).unwrap();
        let off: Vec<f64> = (0..3).map(|k| m[k] / m1[k] - 1.0).collect();
        println!(
            "{name}: relMSE {:.5}, bias {:?}, against one sample {off:+.4?}",
            c.relmse, c.mean_rel_bias
        );
        for (k, (o, b)) in off.iter().zip(c.mean_rel_bias).enumerate() {
            assert!(o.abs() < 0.01, "{name}, channel {k}: {o:+.4} off one sample's mean");
            assert!(b.abs() < 0.015, "{name}, channel {k}: {b:+.4} off Mitsuba");
        }
        // The setting took effect: the runs' samples differ.
        assert!(c.relmse != c1.relmse, "{name} rendered what one sample did");
    }
}

/// What resampling and reuse are for: the direct light alone (max_depth 2) of one raw frame (the
/// 30th, no denoiser) against 256 accumulated frames of one sample. Measured at 80x45: FLIP
/// 0.2576 / 0.2014 / 0.1682, relMSE 1.246 / 0.275 / 0.207 (one sample / 8 candidates / and
/// reservoirs; at 320x180 FLIP 0.217 / 0.161 / 0.122). The relMSE of one frame is its few
/// brightest pixels', so FLIP judges each step: at least 7% lower, and resampling's relMSE at
/// least 20% lower; a merge that never engages, or candidates that are all the first, fail.
#[test]
fn resampling_and_reuse_lower_the_direct_lights_noise() {
    use hush_engine::quality::compare;
    let (scene, reference) = hall_scene();
    let size = (reference.width, reference.height);
    let converged =
        hush_tests::realtime_frames(&scene, size, &resampling(2, true, 1, false), 256).unwrap();
    let frame = |c, r| {
        let img =
            hush_tests::realtime_frames(&scene, size, &resampling(2, false, c, r), 30).unwrap();
        compare(&img, &converged).unwrap()
    };
    let (one, eight, reused) = (frame(1, false), frame(8, false), frame(8, true));
    println!(
        "direct light, frame 30 at {}x{}: relMSE {:.4} / {:.4} / {:.4}, FLIP {:.4} / {:.4} / {:.4} (one sample / 8 candidates / and reservoirs)",
        size.0, size.1, one.relmse, eight.relmse, reused.relmse, one.flip, eight.flip, reused.flip
    );
    let (r1, r8, rr) = (one.relmse, eight.relmse, reused.relmse);
    assert!(r8 < 0.8 * r1, "8 candidates: relMSE {r8} against {r1}");
    assert!(eight.flip < 0.93 * one.flip, "8 candidates: FLIP {} against {}", eight.flip, one.flip);
    assert!(
        reused.flip < 0.93 * eight.flip,
        "reservoirs: FLIP {} against {}",
        reused.flip,
        eight.flip
    );
    assert!(rr < r8, "reservoirs: relMSE {rr} against {r8}");
}

/// A lamp that moved is shaded where it is now: a reservoir names its light's triangle and the
/// point's barycentrics, not a position, so the frame after a jump draws no light from where the
/// lamp was. The sliding box of `reflection_scene` made a lamp (the sun and sky taken out), 24
/// frames at its first place with reservoirs reused, then one frame after it jumped 1.2 m (it is
/// 0.8 m wide): over the pixels its first place lit at least twice as brightly as its second
/// (64 accumulated frames of each), that frame's mean against the second place's accumulation.
/// Measured over 732 pixels: the first place lit them 39.4x as brightly; the frame after the
/// jump 1.028x the second place's light with reservoirs, 1.111x without (one frame's noise). A
/// ghost of the old place would bring up to 39x; 1.25 is allowed.
#[test]
fn a_moved_lamps_reservoirs_light_where_it_is_now() {
    use glam::DVec3;
    use hush_engine::accel::BvhKind;
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::quality::luminance;
    use hush_engine::scene::{Camera, Environment};
    let mut scene = hush_engine::scene::reflection_scene(false);
    scene.lights.clear();
    scene.environment = Environment::None;
    let mut lamp = scene.materials[0].clone();
    lamp.emission = glam::Vec3::splat(8.0);
    scene.materials.push(lamp);
    let bx = scene.objects.iter().find(|o| o.name == "sliding box").expect("the sliding box").mesh;
    scene.meshes[bx].material = scene.materials.len() as u32 - 1;
    let camera = Camera::look_at(DVec3::new(-0.9, 3.0, -0.8), DVec3::new(-0.9, 0.0, -3.2), 60.0);
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (96, 64)).unwrap();
    let at = |time| FrameInput { camera, time, shutter: None };
    let accumulate = |r: &mut Renderer, time| {
        let s = resampling(2, true, 1, false);
        for _ in 0..64 {
            r.render(&gpu, &at(time), &s, None).unwrap();
        }
        r.read_hdr(&gpu).unwrap()
    };
    let before = accumulate(&mut r, 0.0);
    let after = accumulate(&mut r, 0.8);
    let lum = |p: &glam::Vec3| luminance(*p) as f64;
    let region: Vec<usize> = (0..after.data.len())
        .filter(|&i| lum(&before.data[i]) > 2.0 * lum(&after.data[i]) + 1e-3)
        .collect();
    assert!(region.len() > 200, "only {} pixels lit mostly by the first place", region.len());
    let mean = |img: &hush_engine::quality::Image| {
        region.iter().map(|&i| lum(&img.data[i])).sum::<f64>() / region.len() as f64
    };
    let mut jumped = |reuse| {
        let s = resampling(2, false, 8, reuse);
        for _ in 0..24 {
            r.render(&gpu, &at(0.0), &s, None).unwrap();
        }
        r.render(&gpu, &at(0.8), &s, None).unwrap();
        mean(&r.read_hdr(&gpu).unwrap()) / mean(&after)
    };
    let (reused, fresh) = (jumped(true), jumped(false));
    println!(
        "{} pixels: first place {:.3}x the second's light; the frame after the jump {reused:.3}x with reservoirs, {fresh:.3}x without",
        region.len(),
        mean(&before) / mean(&after)
    );
    assert!(reused < 1.25, "the old place still lights its pixels: {reused:.3}x");
}
