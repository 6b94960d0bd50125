//! Pixels a move uncovered (realtime/uncovered.wgsl, `FrameSettings::uncovered_paths`): the
//! trace shoots more paths where the last frame did not see the surface (every pixel it had off
//! screen, and none that a CPU test of the two depth buffers finds it saw: the level's jump),
//! averages them (two seeds differ less there: cornell_diffuse stepped back), and the
//! matte temporal counts the restarted history as that many frames; a first frame, a still
//! frame and the setting at 0 trace one path everywhere.

use glam::{DMat4, DVec3, Mat4, Vec4};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::Gpu;
use hush_engine::quality::{DepthView, Visibility};
use hush_engine::scene::{Camera, Scene, load_gltf};
use hush_engine::settings::{Denoiser, FrameSettings, TaaSettings};
use hush_tests::half;

const SIZE: (u32, u32) = (128, 72);
const PATHS: u32 = 8;

/// Mara without TAA, so that the raster samples pixel centres (no jitter) and the CPU's test
/// below reads the same depths the trace's does (with TAA's jitter, a grazing floor at this
/// size moves by more than the test's 2% between rows, and a still frame would flag it).
fn settings(uncovered_paths: u32, seed: u32) -> FrameSettings {
    FrameSettings {
        denoiser: Denoiser::MARA,
        taa: TaaSettings { enabled: false, ..Default::default() },
        uncovered_paths,
        seed,
        ..Default::default()
    }
}

/// The level's jump (tools/scripts/jump.json): 1.5 m right and forward, which uncovers the hall
/// behind the box and the pillars' far sides.
fn cameras() -> [FrameInput; 2] {
    let at = |eye: DVec3| FrameInput {
        camera: Camera::look_at(eye, eye + DVec3::new(0.0, -0.0207, -1.0), 60.0),
        time: 0.0,
        shutter: None,
    };
    [at(DVec3::new(0.0, 1.7, 8.5)), at(DVec3::new(1.5, 1.7, 7.0))]
}

struct Frame {
    /// The matte light and, in its alpha, the paths it averages.
    matte: Vec<[f32; 4]>,
    depth: Vec<f32>,
    view_proj: Mat4,
    /// Mara's history length after the temporal stage.
    frames: Vec<u32>,
}

fn frame(gpu: &Gpu, r: &mut Renderer, input: &FrameInput, s: &FrameSettings) -> Frame {
    r.render(gpu, input, s, None).unwrap();
    let matte = r.read_texture(gpu, "trace/matte").unwrap().0;
    let matte = matte
        .chunks_exact(8)
        .map(|t| [half(&t[0..2]), half(&t[2..4]), half(&t[4..6]), half(&t[6..8])])
        .collect();
    let depth = bytemuck::pod_collect_to_vec(&r.read_texture(gpu, "gbuffer/depth").unwrap().0);
    let reason: Vec<u32> =
        bytemuck::pod_collect_to_vec(&r.read_texture(gpu, "matte/reason").unwrap().0);
    Frame {
        matte,
        depth,
        view_proj: r.camera_setup(&input.camera).view_proj,
        frames: reason.iter().map(|r| r >> 8).collect(),
    }
}

/// What `before` knew of each pixel of `now`, by the CPU's depth test
/// (hush_engine::quality::visibility, which `hush-cli quality` scores by).
fn visibility(before: &Frame, now: &Frame) -> Vec<Visibility> {
    let b = DepthView { depth: &before.depth, view_proj: before.view_proj };
    let n = DepthView { depth: &now.depth, view_proj: now.view_proj };
    hush_engine::quality::visibility(&b, &n, SIZE)
}

/// The CPU's twin of realtime/uncovered.wgsl's `seen_on_a_plane`: the previous depth,
/// interpolated bilinearly where the pixel's point projects (TAA off: the last frame sampled
/// pixel centres), within 2% of the point's.
fn seen_on_a_plane(before: &Frame, now: &Frame) -> Vec<bool> {
    let (w, h) = (SIZE.0 as i64, SIZE.1 as i64);
    let inverse = now.view_proj.inverse();
    let at = |x: i64, y: i64| before.depth[(y * w + x) as usize];
    (0..(w * h) as usize)
        .map(|i| {
            let (x, y) = ((i as i64 % w) as f32 + 0.5, (i as i64 / w) as f32 + 0.5);
            let ndc =
                Vec4::new(x / w as f32 * 2.0 - 1.0, 1.0 - y / h as f32 * 2.0, now.depth[i], 1.0);
            let p = inverse * ndc;
            let c = before.view_proj * (p / p.w);
            let u = (
                (c.x / c.w + 1.0) * 0.5 * w as f32 - 0.5,
                (1.0 - c.y / c.w) * 0.5 * h as f32 - 0.5,
            );
            let (tx, ty) = (u.0.floor() as i64, u.1.floor() as i64);
            if c.w <= 0.0 || tx < 0 || ty < 0 || tx + 1 >= w || ty + 1 >= h {
                return false;
            }
            let (fx, fy) = (u.0 - tx as f32, u.1 - ty as f32);
            let d = [at(tx, ty), at(tx + 1, ty), at(tx, ty + 1), at(tx + 1, ty + 1)];
            if d.iter().any(|d| *d <= 0.0) {
                return false;
            }
            let top = d[0] + (d[1] - d[0]) * fx;
            let bottom = d[2] + (d[3] - d[2]) * fx;
            let expected = c.z / c.w;
            (top + (bottom - top) * fy - expected).abs() <= 0.02 * expected
        })
        .collect()
}

/// Frames: the first camera (no history), the same again (still), then the second camera.
fn jump(scene: Scene, [a, b]: [FrameInput; 2], s: &FrameSettings) -> [Frame; 3] {
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, SIZE).unwrap();
    [frame(&gpu, &mut r, &a, s), frame(&gpu, &mut r, &a, s), frame(&gpu, &mut r, &b, s)]
}

fn level_jump(s: &FrameSettings) -> [Frame; 3] {
    jump(hush_engine::scene::default_level(), cameras(), s)
}

fn paths(f: &Frame) -> Vec<u32> {
    f.matte.iter().map(|m| m[3] as u32).collect()
}

#[test]
fn uncovered_pixels_trace_more_paths_and_their_histories_count_them() {
    let [first, still, moved] = level_jump(&settings(PATHS, 1));
    assert!(paths(&first).iter().all(|p| *p == 1), "the first frame has no history to restart");
    assert!(paths(&still).iter().all(|p| *p == 1), "a still frame uncovers nothing");
    let vis = visibility(&still, &moved);
    let got = paths(&moved);
    let pixels = got.len();
    let count = |f: &dyn Fn(usize) -> bool| (0..pixels).filter(|i| f(*i)).count();
    let hidden = count(&|i| vis[i] != Visibility::Seen && vis[i] != Visibility::Background);
    let on_plane = seen_on_a_plane(&still, &moved);
    let expected =
        |i: usize| vis[i] != Visibility::Seen && vis[i] != Visibility::Background && !on_plane[i];
    let flagged = count(&|i| got[i] == PATHS);
    println!("{hidden} pixels the 3x3 test does not find, {flagged} took {PATHS} paths");
    assert!(flagged > pixels / 50 && flagged < hidden, "{flagged} of {hidden}");
    // The trace tests the hit point, the CPU the depth at the pixel centre: a pixel on the 2%
    // boundary may fall either way.
    let disagree = count(&|i| (got[i] == PATHS) != expected(i));
    println!("{disagree} pixels disagree with the CPU's tests");
    assert!(disagree <= pixels / 200, "{disagree} pixels disagree");
    assert_eq!(
        count(&|i| got[i] != PATHS && got[i] != 1),
        0,
        "path counts other than 1 and {PATHS}"
    );
    // Where Mara's matte temporal restarts the history (it keeps a neighbour's within its
    // position test at most of these pixels: they continue at 3 frames), it counts the
    // sample as its paths, and the cache's prior on top where it has one; with one path it
    // would count 1 plus the prior.
    let restarted: Vec<u32> = (0..pixels)
        .filter(|i| got[*i] == PATHS && moved.frames[*i] != 3)
        .map(|i| moved.frames[i])
        .collect();
    println!("{} of them restarted", restarted.len());
    assert!(restarted.len() >= 20, "{} restarted histories", restarted.len());
    let short = restarted.iter().filter(|f| **f < PATHS).count();
    assert_eq!(short, 0, "restarted histories counting fewer than {PATHS} frames");
    let off = level_jump(&settings(0, 1));
    assert!(paths(&off[2]).iter().all(|p| *p == 1), "uncovered_paths 0 traces one path");
}

/// Two seeds' matte light at the pixels a step back brings into cornell_diffuse's view (a ring
/// the last frame had off screen) differs by sqrt(2) sigma / sqrt(k): with 8 paths the mean
/// squared difference is 1/8 of one path's. The box (one area light, diffuse walls) has no rare
/// bright paths, which on the level (sun and sky through openings) make a mean of a thousand
/// pixels' squares swing by 5x between runs; the bound 0.3 is 2.4x the expected ratio.
#[test]
fn uncovered_paths_are_averaged() {
    let dir = hush_tests::oracle("cornell_diffuse");
    let scene = load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let camera = scene.camera_or_default();
    let mut closer = camera;
    // From 80 cm further in to the oracle's camera: a ring of walls at the image's edge is new.
    closer.world = camera.world * DMat4::from_translation(DVec3::new(0.0, 0.0, -0.8));
    let input = |camera| FrameInput { camera, time: 0.0, shutter: None };
    let spread = |k: u32| {
        let cams = [input(closer), input(camera)];
        let [_, still, a] = jump(scene.clone(), cams, &settings(k, 1));
        let [_, _, b] = jump(scene.clone(), cams, &settings(k, 2));
        let vis = visibility(&still, &a);
        let ring: Vec<usize> =
            (0..vis.len()).filter(|i| vis[*i] == Visibility::OffScreen).collect();
        let sum: f64 = ring
            .iter()
            .map(|&i| {
                (0..3).map(|c| (a.matte[i][c] - b.matte[i][c]) as f64).map(|d| d * d).sum::<f64>()
            })
            .sum();
        let traced = ring.iter().filter(|&&i| paths(&a)[i] == k.max(1)).count();
        println!(
            "{k} paths: {} pixels off screen last frame, {traced} of them traced {}",
            ring.len(),
            k.max(1)
        );
        assert!(ring.len() > 200 && traced * 100 >= ring.len() * 99, "{traced} of {}", ring.len());
        sum / ring.len() as f64
    };
    let (one, many) = (spread(0), spread(PATHS));
    println!("mean squared difference of two seeds: 1 path {one:.5}, {PATHS} paths {many:.5}");
    assert!(one > 0.0 && many < 0.3 * one, "{many} against {one}");
}
