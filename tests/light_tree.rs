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
/// middle, their luminance over two decades, and a few two-sided panels that face every way.
fn hall(rng: &mut Xorshift) -> Vec<Emitter> {
    let mut out = vec![];
    for i in 0..240u32 {
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
            Input::Storage(bytemuck::cast_slice(nodes)),
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
/// choices are counted, and must stay under 0.5% (measured: 0 of the 3854 lit points; the other
/// 242 lie outside the walls, behind every lamp). Where both choose the same leaf the
/// probabilities must agree to 1e-4 relative (measured: exactly equal); a mistake in either
/// side's importance moves them by far more. The walk up must
/// give back the walk down's probability, which is what MIS with BSDF sampling relies on
/// (measured: within 3.3e-7, the products taken in the other order).
#[test]
fn the_gpu_walk_chooses_as_the_cpu_walk() {
    let mut rng = Xorshift(0x1234_5679);
    let tree = LightTree::build(&hall(&mut rng));
    assert!(tree.depth() >= 6, "a tree worth walking: depth {}", tree.depth());
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

/// The matte light sample resampled from 8 candidates (`FrameSettings::light_candidates`,
/// realtime/area_light.wgsl) estimates the same light as one MIS-weighted sample: a still view
/// of the many-lamp hall accumulated over 256 frames at 80x45 has the same mean with both.
/// Measured: the two means differ by 0.11-0.23% per channel, and both lie +0.4-0.8% above
/// Mitsuba's (the real-time frame's bias on this scene at one sample as at eight). A resampling weight off by its 1 / M, or the matte path's first segment still adding
/// the light the resampled sample carries (direct light counted twice), moves the mean by far
/// more than the 1% allowed.
#[test]
fn the_resampled_light_sample_keeps_the_mean() {
    use hush_engine::quality::{Image, compare};
    use hush_engine::settings::FrameSettings;
    let dir = hush_tests::oracle("many_lights");
    let scene = hush_engine::scene::load_gltf(&dir.join("many_lights.gltf")).unwrap();
    let reference = Image::load(&dir.join("reference.exr")).unwrap().box_downsample(4).unwrap();
    let size = (reference.width, reference.height);
    let settings = |light_candidates| FrameSettings {
        max_depth: scene.max_depth,
        seed: 3,
        accumulate: true,
        light_candidates,
        ..Default::default()
    };
    let mean = |img: &Image| {
        let mut m = [0.0f64; 3];
        for p in &img.data {
            (0..3).for_each(|k| m[k] += p[k] as f64);
        }
        m
    };
    let one = hush_tests::realtime_frames(&scene, size, &settings(1), 256).unwrap();
    let eight = hush_tests::realtime_frames(&scene, size, &settings(8), 256).unwrap();
    let (m1, m8) = (mean(&one), mean(&eight));
    let to_ref = |img: &Image| compare(img, &reference).unwrap();
    let (c1, c8) = (to_ref(&one), to_ref(&eight));
    println!(
        "256 frames: 1 candidate relMSE {:.5} bias {:?}; 8 candidates relMSE {:.5} bias {:?}",
        c1.relmse, c1.mean_rel_bias, c8.relmse, c8.mean_rel_bias
    );
    for k in 0..3 {
        let d = m8[k] / m1[k] - 1.0;
        assert!(d.abs() < 0.01, "channel {k}: 8 candidates' mean is {:+.4} off one sample's", d);
        assert!(
            c8.mean_rel_bias[k].abs() < 0.015,
            "channel {k}: {:+.4} off Mitsuba",
            c8.mean_rel_bias[k]
        );
    }
    // The setting took effect: the two runs' samples differ.
    assert!(c1.relmse != c8.relmse, "8 candidates rendered what one did");
}
