//! Pixels a move uncovered (realtime/uncovered.wgsl, `FrameSettings::uncovered_paths`): the
//! trace shoots more paths exactly where the last frame did not see the surface, as a CPU test
//! of the two depth buffers decides it (the level's jump), averages them (two seeds differ less
//! there; cornell_diffuse stepped sideways), and the
//! matte temporal counts the restarted history as that many frames; a first frame, a still
//! frame and the setting at 0 trace one path everywhere.

use glam::{DMat4, DVec3, Mat4};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::Gpu;
use hush_engine::quality::DepthView;
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

/// The pixels of `now` whose surface `before` did not see, by the CPU's test
/// (hush_engine::quality::uncovered, which `hush-cli quality` scores).
fn uncovered(before: &Frame, now: &Frame) -> Vec<bool> {
    let b = DepthView { depth: &before.depth, view_proj: before.view_proj };
    let n = DepthView { depth: &now.depth, view_proj: now.view_proj };
    hush_engine::quality::uncovered(&b, &n, SIZE)
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
    let mask = uncovered(&still, &moved);
    let n = mask.iter().filter(|m| **m).count();
    let pixels = mask.len();
    println!("{n} of {pixels} pixels uncovered");
    assert!(n > pixels / 50 && n < pixels / 2, "{n} uncovered pixels");
    let got = paths(&moved);
    // The trace tests the hit point, the CPU the depth at the pixel centre: a pixel on the 2%
    // boundary may fall either way.
    let disagree =
        mask.iter().zip(&got).filter(|(m, p)| **p != if **m { PATHS } else { 1 }).count();
    println!("{disagree} pixels disagree with the CPU's test");
    assert!(disagree <= pixels / 200, "{disagree} pixels disagree");
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

/// Two seeds' matte light at the pixels a turn brings into cornell_diffuse's view
/// differs by sqrt(2) sigma / sqrt(k): with 8 paths the mean squared difference is 1/8 of one
/// path's. The box (one area light, diffuse walls) has no rare bright paths, which on the level
/// (sun and sky through openings) make a mean of a thousand pixels' squares swing by 5x between
/// runs; the bound 0.3 is 2.4x the expected ratio.
#[test]
fn uncovered_paths_are_averaged() {
    let dir = hush_tests::oracle("cornell_diffuse");
    let scene = load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let camera = scene.camera_or_default();
    let mut stepped = camera;
    // Turned 10 degrees: a strip at the side is new.
    stepped.world = camera.world * DMat4::from_rotation_y(10f64.to_radians());
    let input = |camera| FrameInput { camera, time: 0.0, shutter: None };
    let spread = |k: u32| {
        let cams = [input(camera), input(stepped)];
        let [_, still, a] = jump(scene.clone(), cams, &settings(k, 1));
        let [_, _, b] = jump(scene.clone(), cams, &settings(k, 2));
        let mask = uncovered(&still, &a);
        let (sum, n) = (0..mask.len()).filter(|i| mask[*i]).fold((0.0, 0), |(s, n), i| {
            let d: f64 =
                (0..3).map(|c| (a.matte[i][c] - b.matte[i][c]) as f64).map(|d| d * d).sum();
            (s + d, n + 1)
        });
        println!("{k} paths: {n} uncovered pixels");
        sum / n.max(1) as f64
    };
    let (one, many) = (spread(0), spread(PATHS));
    println!("mean squared difference of two seeds: 1 path {one:.5}, {PATHS} paths {many:.5}");
    assert!(one > 0.0 && many < 0.3 * one, "{many} against {one}");
}
