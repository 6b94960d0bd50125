//! The radiance cache (hush_engine::passes::cache, shaders/cache/*.wgsl): a cell holds the
//! running mean of the matte samples that fell in it, as a CPU computation from the same samples
//! gives it; a pixel reads its cell's mean from before its own sample; the matte temporal starts a
//! restarted history from it; light does not leak through a thin wall into a dark room; and matte
//! paths that end in the cache keep the light of paths that go on, with less noise, and never
//! end in a cell they reached over a segment shorter than its diagonal.

use glam::{DVec3, Vec3};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::Gpu;
use hush_engine::passes::cache::NO_CELL;
use hush_engine::scene::{Camera, Scene, cuboid, load_gltf, quad};
use hush_engine::settings::{CacheSettings, Denoiser, FrameSettings, TaaSettings, View};
use hush_tests::gltf_writer::GltfWriter;
use hush_tests::halves;
use serde_json::json;
use std::collections::HashMap;

/// Mara with the cache on, primary samples only (`update_tile` 0) unless said otherwise, and no
/// TAA: every frame then traces the same primary rays (pixel centres), so a pixel keeps its cell.
fn settings(update_tile: u32) -> FrameSettings {
    FrameSettings {
        denoiser: Denoiser::MARA,
        taa: TaaSettings { enabled: false, ..Default::default() },
        cache: CacheSettings { enabled: true, update_tile, ..Default::default() },
        ..Default::default()
    }
}

fn u32s(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|b| u32::from_le_bytes(b.try_into().unwrap())).collect()
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect()
}

/// Per cell slot: the sum of the samples (each clamped as the cache clamps them: 64 at exposure
/// 1) that fell in it and how many.
fn cpu_cells(cells: &[u32], matte: &[[f32; 4]]) -> HashMap<u32, ([f64; 3], u32)> {
    let mut sums: HashMap<u32, ([f64; 3], u32)> = HashMap::new();
    for (slot, m) in cells.iter().zip(matte) {
        if *slot == NO_CELL {
            continue;
        }
        let e = sums.entry(*slot).or_default();
        for (sum, v) in e.0.iter_mut().zip(m) {
            *sum += v.clamp(0.0, 64.0) as f64;
        }
        e.1 += 1;
    }
    sums
}

struct Frame {
    matte: Vec<[f32; 4]>,
    cell: Vec<u32>,
    prior: Vec<[f32; 4]>,
    /// The table's cells after the frame: mean rgb, samples.
    cells: Vec<[f32; 4]>,
}

fn frame(gpu: &Gpu, r: &mut Renderer, input: &FrameInput, s: &FrameSettings) -> Frame {
    r.render(gpu, input, s, None).unwrap();
    let cells = f32s(&r.read_buffer(gpu, "cache/cells").unwrap());
    Frame {
        matte: halves(&r.read_texture(gpu, "trace/matte").unwrap().0),
        cell: u32s(&r.read_texture(gpu, "cache/cell").unwrap().0),
        prior: halves(&r.read_texture(gpu, "cache/prior").unwrap().0),
        cells: cells.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
    }
}

/// One fixed-point unit of the cache's sums at exposure 1 (1 / 4096): stochastic rounding moves
/// a mean by less than one.
const UNIT: f64 = 1.0 / 4096.0;

/// Frame 0 fills the cells from the level's primary samples; each cell's mean and count must be
/// the CPU's over the pixels the GPU put in it, within one fixed-point unit. Frame 1 (the same
/// rays, new paths) must leave each cell the mean of both frames' samples, and give no pixel a
/// prior: the last frame saw them all.
#[test]
fn a_cell_holds_the_mean_of_its_samples() {
    let size = (48, 27);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::default_level(), BvhKind::DEFAULT, size).unwrap();
    let camera = Camera::look_at(DVec3::new(-3.0, 1.7, 4.0), DVec3::new(-2.0, 1.2, -6.0), 60.0);
    let input = FrameInput { camera, time: 0.0, shutter: None };
    let s = settings(0);
    let f0 = frame(&gpu, &mut r, &input, &s);
    let cpu0 = cpu_cells(&f0.cell, &f0.matte);
    let pixels = f0.cell.iter().filter(|c| **c != NO_CELL).count();
    println!("{} cells over {pixels} of {} pixels", cpu0.len(), f0.cell.len());
    assert!(pixels > f0.cell.len() / 2, "{pixels} pixels have a cell");
    // A cell covers a few pixels: 8-pixel cells over a 48x27 view.
    assert!(cpu0.len() > 20 && cpu0.len() < pixels / 2, "{} cells", cpu0.len());
    let centroids = f32s(&r.read_buffer(&gpu, "cache/centroids").unwrap());
    for (slot, (sum, n)) in &cpu0 {
        // The mean squared luminance (in 1/1024 units, each luminance at most 16).
        let l2 = f0
            .cell
            .iter()
            .zip(&f0.matte)
            .filter(|(s, _)| *s == slot)
            .map(|(_, m)| {
                let c = m.map(|v| v.clamp(0.0, 64.0) as f64);
                let l = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).min(16.0);
                l * l
            })
            .sum::<f64>()
            / *n as f64;
        let got = centroids[*slot as usize * 4 + 3] as f64;
        assert!((got - l2).abs() <= 1.01 / 1024.0 + 1e-5 * l2, "cell {slot}: {got} against {l2}");
        let gpu_cell = f0.cells[*slot as usize];
        assert_eq!(gpu_cell[3], *n as f32, "cell {slot}'s samples");
        for k in 0..3 {
            let mean = sum[k] / *n as f64;
            let d = (gpu_cell[k] as f64 - mean).abs();
            assert!(d <= UNIT * 1.01, "cell {slot} channel {k}: {} against {mean}", gpu_cell[k]);
        }
    }
    let f1 = frame(&gpu, &mut r, &input, &s);
    assert_eq!(f1.cell, f0.cell, "the same rays fall in the same cells");
    let with_prior = f1.prior.iter().filter(|p| **p != [0.0; 4]).count();
    assert_eq!(with_prior, 0, "pixels the last frame saw with a prior");
    let cpu1 = cpu_cells(&f1.cell, &f1.matte);
    for (slot, (sum, n)) in &cpu1 {
        let (sum0, n0) = cpu0[slot];
        let c = f1.cells[*slot as usize];
        assert_eq!(c[3], (n + n0) as f32);
        for k in 0..3 {
            let mean = (sum[k] + sum0[k]) / (n + n0) as f64;
            assert!((c[k] as f64 - mean).abs() <= 2.0 * UNIT, "cell {slot}: {c:?}, {mean}");
        }
    }
}

/// After a jump, a pixel the last frame did not see reads its cell's mean as the frames before
/// left it (its own sample not in it), weighted as min(samples, prior_frames); where the matte
/// temporal finds no history, it starts from that prior: mix(prior, sample, k / (k + a)) for a
/// sample of k paths (FrameSettings::uncovered_paths), with a history length of k + a.
#[test]
fn an_uncovered_pixel_starts_from_its_cells_mean() {
    let size = (48, 27);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::default_level(), BvhKind::DEFAULT, size).unwrap();
    let at = |eye: DVec3| FrameInput {
        camera: Camera::look_at(eye, eye + DVec3::new(0.3, -0.3, -3.0), 60.0),
        time: 0.0,
        shutter: None,
    };
    let s = settings(4);
    for _ in 0..6 {
        r.render(&gpu, &at(DVec3::new(-3.0, 1.7, 4.0)), &s, None).unwrap();
    }
    let before = f32s(&r.read_buffer(&gpu, "cache/cells").unwrap());
    let f = frame(&gpu, &mut r, &at(DVec3::new(-4.0, 1.9, 6.0)), &s);
    let reason = u32s(&r.read_texture(&gpu, "matte/reason").unwrap().0);
    let temporal = f32s(&r.read_texture(&gpu, "matte/temporal").unwrap().0);
    let mut checked = 0;
    let flagged = reason.iter().filter(|r| **r & 1 != 0).count();
    let with_prior = f.prior.iter().filter(|p| p[3] > 0.0).count();
    println!("{flagged} disoccluded, {with_prior} with a prior");
    for i in 0..f.cell.len() {
        let p = f.prior[i];
        if p[3] > 0.0 {
            let c = &before[f.cell[i] as usize * 4..][..4];
            assert_eq!(p[3], c[3].min(s.cache.prior_frames), "pixel {i}'s prior weight");
            for k in 0..3 {
                // Rgba16Float: 11 significant bits.
                let d = (p[k] - c[k]).abs();
                assert!(d <= c[k].abs() / 1024.0 + 1e-7, "pixel {i}: {p:?}, {c:?}");
            }
        }
        if reason[i] & 1 == 0 || p[3] <= 0.0 {
            continue;
        }
        checked += 1;
        // The pixel's own sample counts as the paths it averages (the trace's matte alpha: more
        // where the trace found the surface uncovered too, realtime/uncovered.wgsl).
        let paths = f.matte[i][3];
        assert!(paths >= 1.0, "pixel {i}'s paths: {paths}");
        let w = paths / (paths + p[3]);
        for k in 0..3 {
            let want = p[k] + (f.matte[i][k] - p[k]) * w;
            let got = temporal[i * 4 + k];
            assert!(
                (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
                "pixel {i}: {got} against {want}"
            );
        }
        assert_eq!(reason[i] >> 8, (paths + p[3]) as u32, "pixel {i}'s history length");
    }
    println!("{checked} disoccluded pixels with a prior");
    assert!(checked > 50, "{checked} disoccluded pixels with a prior");
    for view in ["cache/prior", "cache/prior frames"] {
        let shown =
            r.display_image(&gpu, &FrameSettings { view: View::named(view), ..s.clone() }).unwrap();
        assert!(shown.pixels().any(|p| p.0[..3] != [0, 0, 0]), "the view {view} is black");
    }
}

/// Two closed rooms side by side, one wall 2 cm thick between them at x = 0.37 .. 0.39 (not on
/// any power-of-two cell boundary), the floor, ceiling and side walls running under, over and
/// past it. Room A (x < 0.37) has an area light under its ceiling; room B has none, so every
/// surface in it is black.
fn two_rooms() -> Scene {
    let mut g = GltfWriter::default();
    let white = g.lambert([0.7; 3]);
    let lamp = g.emitter(20.0);
    let (x0, x1) = (-4.6, 5.0);
    let (cx, hx) = ((x0 + x1) / 2.0, (x1 - x0) / 2.0 + 0.1);
    let parts = [
        // Floor, ceiling, the two side walls and the two end walls, 10 cm slabs.
        (cuboid(Vec3::new(cx, -0.05, 0.0), Vec3::new(hx, 0.05, 2.1), 0), white),
        (cuboid(Vec3::new(cx, 2.55, 0.0), Vec3::new(hx, 0.05, 2.1), 0), white),
        (cuboid(Vec3::new(cx, 1.25, -2.05), Vec3::new(hx, 1.3, 0.05), 0), white),
        (cuboid(Vec3::new(cx, 1.25, 2.05), Vec3::new(hx, 1.3, 0.05), 0), white),
        (cuboid(Vec3::new(x0 - 0.05, 1.25, 0.0), Vec3::new(0.05, 1.3, 2.1), 0), white),
        (cuboid(Vec3::new(x1 + 0.05, 1.25, 0.0), Vec3::new(0.05, 1.3, 2.1), 0), white),
        // The thin wall, from floor to ceiling and side to side.
        (cuboid(Vec3::new(0.38, 1.25, 0.0), Vec3::new(0.01, 1.25, 2.0), 0), white),
        // The light, facing down (X x Z = -Y).
        (quad(Vec3::new(-2.0, 2.45, 0.0), Vec3::X * 0.6, Vec3::Z * 0.6, 0), lamp),
    ];
    for (mesh, material) in parts {
        let m = g.engine_mesh(&mesh, material);
        g.node(json!({"mesh": m}));
    }
    g.camera([-2.62, 1.2, 0.0], [0.38, 0.5, 0.0], 1.0);
    load_gltf(&g.write("two_rooms")).unwrap()
}

/// Where pixel (x, y)'s centre ray from `eye` along `fwd` (up +Y, vertical field `fov` radians)
/// meets room B (x in [0.39, 5], y in [0, 2.5], z in [-2, 2]), and the face's axis (0: x).
fn room_b_hit(eye: Vec3, fwd: Vec3, fov: f32, size: (u32, u32), x: u32, y: u32) -> (Vec3, usize) {
    let right = fwd.cross(Vec3::Y).normalize();
    let up = right.cross(fwd);
    let t = (fov / 2.0).tan();
    let aspect = size.0 as f32 / size.1 as f32;
    let ndc_x = (x as f32 + 0.5) / size.0 as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - (y as f32 + 0.5) / size.1 as f32 * 2.0;
    let d = (fwd + right * (ndc_x * t * aspect) + up * (ndc_y * t)).normalize();
    let (lo, hi) = (Vec3::new(0.39, 0.0, -2.0), Vec3::new(5.0, 2.5, 2.0));
    let mut best = (f32::MAX, 0);
    for k in 0..3 {
        if d[k] != 0.0 {
            let plane = if d[k] > 0.0 { hi[k] } else { lo[k] };
            let s = (plane - eye[k]) / d[k];
            if s > 0.0 && s < best.0 {
                best = (s, k);
            }
        }
    }
    (eye + d * best.0, best.1)
}

/// Room A's camera looks at the thin wall from 3 m for 8 frames (primary and secondary samples
/// fill its cells); then a camera 3 m from the wall in room B looks back at it, and its first
/// frame's priors come from what room A left. Every surface of room B is black, so a prior above
/// zero is light that leaked. At 64x48 an 8-pixel cell is 1 m wide here, so the floor, ceiling
/// and side walls, which run on under the wall, put room B's pixels within a metre of it in
/// cells that room A lit (540 pixels, measured); the wall's face in B, whose normal differs, in
/// none. The centroid's test must refuse all of them: no pixel of B gets light. Then, over B's
/// next frames, the matte paths of B's pixels end in the cells they reach (unlimited path
/// length), the straddling ones among them, whose centroids B's black samples pull towards B
/// while A's light stays in their means: the centroid weighs samples by their light, so it stays
/// behind the wall and no path brings light (with every sample weighing the same, 533 pixels
/// did).
#[test]
fn no_light_leaks_through_a_thin_wall_into_a_dark_room() {
    let scene = two_rooms();
    let size = (64, 48);
    let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, size).unwrap();
    let fov = 60f32;
    // Unlimited path length, where matte paths may end in the cache.
    let s = FrameSettings { max_depth: -1, ..settings(4) };
    let a = FrameInput {
        camera: Camera::look_at(DVec3::new(-2.62, 1.2, 0.0), DVec3::new(0.38, 0.6, 0.0), fov),
        time: 0.0,
        shutter: None,
    };
    for _ in 0..8 {
        r.render(&gpu, &a, &s, None).unwrap();
    }
    // Room A's cells, as the B camera's first frame finds them.
    let cells_a = f32s(&r.read_buffer(&gpu, "cache/cells").unwrap());
    let lit: Vec<f32> = cells_a.chunks_exact(4).filter(|c| c[3] > 0.0).map(|c| c[0]).collect();
    let mean_a = lit.iter().sum::<f32>() / lit.len().max(1) as f32;
    println!("room A: {} cells, mean red {mean_a:.4}", lit.len());
    assert!(lit.len() > 50 && mean_a > 0.01, "room A's cells: {} lit, mean {mean_a}", lit.len());

    let (eye, target) = (Vec3::new(3.38, 1.2, 0.0), Vec3::new(0.38, 0.6, 0.0));
    let b = FrameInput { camera: Camera::look_at(eye.as_dvec3(), target.as_dvec3(), fov), ..a };
    r.render(&gpu, &b, &s, None).unwrap();
    let prior_b = halves(&r.read_texture(&gpu, "cache/prior").unwrap().0);
    let cell_b = u32s(&r.read_texture(&gpu, "cache/cell").unwrap().0);
    let origin = r.prepared.origin.as_vec3();
    let cell_pixels = s.cache.cell_pixels;
    let spread = 2.0 * (fov.to_radians() / 2.0).tan() / size.1 as f32;
    let (mut wall, mut found_lit, mut leaked) = (0, 0, 0);
    for y in 0..size.1 {
        for x in 0..size.0 {
            let i = (y * size.0 + x) as usize;
            let (p, axis) =
                room_b_hit(eye, (target - eye).normalize(), fov.to_radians(), size, x, y);
            // The cell's edge (shaders/cache/cells.wgsl) and whether it reaches past the wall,
            // in the rebased space the GPU grids.
            let c = 2f32.powf((p.distance(eye) * spread * cell_pixels).log2().ceil());
            let reaches_a = ((p.x - origin.x) / c).floor() * c < 0.37 - origin.x + 1e-3;
            let on_wall = axis == 0 && p.x < 0.4;
            let slot = cell_b[i];
            let lit = slot != NO_CELL && cells_a[slot as usize * 4] > 0.0;
            wall += on_wall as usize;
            found_lit += lit as usize;
            assert!(!(lit && on_wall), "the wall's face in room B shares a lit cell at ({x}, {y})");
            assert!(!lit || reaches_a, "({x}, {y}) is in a lit cell that does not reach room A");
            leaked += (prior_b[i][..3] != [0.0; 3]) as usize;
        }
    }
    println!("room B: {wall} wall pixels, {found_lit} in cells room A lit, {leaked} with light");
    assert!(wall > size.0 as usize * 4, "the view shows the wall ({wall} pixels)");
    assert!(
        found_lit >= 100,
        "{found_lit} pixels of B in cells A lit: the test has no straddling cell"
    );
    assert_eq!(leaked, 0, "pixels of room B with light");
    // Matte paths from room B's surfaces end in the cells they reach (cache/path_end.wgsl),
    // those straddling the wall among them: their light must not come through either.
    for k in 0..4 {
        r.render(&gpu, &b, &s, None).unwrap();
        let matte = halves(&r.read_texture(&gpu, "trace/matte").unwrap().0);
        let lit = matte.iter().filter(|m| m[..3] != [0.0; 3]).count();
        assert_eq!(lit, 0, "frame {k} in room B: pixels whose matte path brought light");
    }
}

/// The cache switched on and off between frames, under Mara and SVGF: their temporal stages are
/// made again for a frame that offers a prior and one that does not, and every image stays
/// finite.
#[test]
fn the_cache_can_be_switched_between_frames() {
    let size = (32, 18);
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::default_level(), BvhKind::DEFAULT, size).unwrap();
    for (k, denoiser) in [Denoiser::MARA, Denoiser::SVGF].into_iter().enumerate() {
        for on in [true, false, true, false] {
            let s = FrameSettings {
                denoiser: denoiser.clone(),
                cache: CacheSettings { enabled: on, ..Default::default() },
                ..Default::default()
            };
            let eye = DVec3::new(-3.0 + k as f64, 1.7, 4.0);
            let camera = Camera::look_at(eye, eye + DVec3::new(0.5, -0.3, -3.0), 60.0);
            r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &s, None).unwrap();
            let img = r.read_hdr(&gpu).unwrap();
            assert!(img.data.iter().all(|v| v.is_finite()), "{denoiser:?}, cache {on}");
        }
    }
}

/// Per pixel, the mean and variance over frames of the trace's matte light's luminance.
fn matte_moments(frames: &[Vec<[f32; 4]>]) -> Vec<(f64, f64)> {
    let n = frames.len() as f64;
    (0..frames[0].len())
        .map(|i| {
            let y: Vec<f64> = frames
                .iter()
                .map(|f| (0.2126 * f[i][0] + 0.7152 * f[i][1] + 0.0722 * f[i][2]) as f64)
                .collect();
            let mean = y.iter().sum::<f64>() / n;
            (mean, y.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0))
        })
        .collect()
}

/// Room A of the two rooms, lit by its ceiling light, white walls: a matte path there bounces
/// many times. With unlimited path length (max_depth -1) and paths ending in the cache
/// (`path_end_samples`), frames 8-31 of a still view must keep the matte light of paths that go
/// on (the mean over the image within 2%) with less noise (the mean of the pixels' variances
/// over frames at most half). Measured: mean 1.1910 against 1.1989 (-0.7%), variance 0.1532
/// against 0.3349 (0.46x: Russian roulette's long paths are what the cells replace; at 64x48 a
/// cell is about a metre wide, and the segments shorter than its diagonal go on). Under a path
/// length limit paths must not end in the cache (its cells carry light from every bounce: +9%
/// here at 6 segments, 1.1221 against 1.0288), so the trace's matte light is then the same with
/// and without it.
#[test]
fn paths_that_end_in_the_cache_keep_the_light_with_less_noise() {
    let scene = two_rooms();
    let size = (64, 48);
    let input = FrameInput {
        camera: Camera::look_at(DVec3::new(-2.62, 1.2, 0.0), DVec3::new(0.38, 0.6, 0.0), 60.0),
        time: 0.0,
        shutter: None,
    };
    let run = |path_end_samples: f32, max_depth: i32| {
        let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, size).unwrap();
        let mut s = settings(4);
        s.cache.path_end_samples = path_end_samples;
        s.max_depth = max_depth;
        let mut frames = vec![];
        for k in 0..32 {
            r.render(&gpu, &input, &s, None).unwrap();
            if k >= 8 {
                frames.push(halves(&r.read_texture(&gpu, "trace/matte").unwrap().0));
            }
        }
        frames
    };
    let summary = |frames: &[Vec<[f32; 4]>]| {
        let m = matte_moments(frames);
        let n = m.len() as f64;
        (m.iter().map(|v| v.0).sum::<f64>() / n, m.iter().map(|v| v.1).sum::<f64>() / n)
    };
    let (mean_on, var_on) = summary(&run(16.0, -1));
    let (mean_off, var_off) = summary(&run(0.0, -1));
    println!(
        "matte light, unlimited length: mean {mean_on:.4} ending in the cache, {mean_off:.4} going on; variance {var_on:.4}, {var_off:.4}"
    );
    assert!((mean_on / mean_off - 1.0).abs() <= 0.02, "mean {mean_on} against {mean_off}");
    assert!(var_on <= 0.5 * var_off, "variance {var_on} against {var_off}");
    assert!(run(16.0, 6) == run(0.0, 6), "paths ended in the cache under a length limit");
}

/// A closed white box 40 cm wide with a light under its lid, seen from its centre.
fn small_box() -> Scene {
    let mut g = GltfWriter::default();
    let white = g.lambert([0.7; 3]);
    let lamp = g.emitter(20.0);
    let (h, t) = (0.2, 0.05);
    let parts = [
        // Floor, lid and four walls, 10 cm slabs whose inner faces bound the box.
        (cuboid(Vec3::new(0.0, -h - t, 0.0), Vec3::new(h + 2.0 * t, t, h + 2.0 * t), 0), white),
        (cuboid(Vec3::new(0.0, h + t, 0.0), Vec3::new(h + 2.0 * t, t, h + 2.0 * t), 0), white),
        (cuboid(Vec3::new(-h - t, 0.0, 0.0), Vec3::new(t, h, h), 0), white),
        (cuboid(Vec3::new(h + t, 0.0, 0.0), Vec3::new(t, h, h), 0), white),
        (cuboid(Vec3::new(0.0, 0.0, -h - t), Vec3::new(h, h, t), 0), white),
        (cuboid(Vec3::new(0.0, 0.0, h + t), Vec3::new(h, h, t), 0), white),
        // The light, facing down (X x Z = -Y).
        (quad(Vec3::new(0.0, h - 0.01, 0.0), Vec3::X * 0.05, Vec3::Z * 0.05, 0), lamp),
    ];
    for (mesh, material) in parts {
        let m = g.engine_mesh(&mesh, material);
        g.node(json!({"mesh": m}));
    }
    g.camera([0.0, 0.0, 0.0], [1.0, -0.2, 0.3], 1.0);
    load_gltf(&g.write("small_box")).unwrap()
}

/// SHaRC's segment test (cache/path_end.wgsl): a path does not end at a vertex it reached over
/// a segment no longer than the vertex's cell's diagonal, where the cell's mean stands for light
/// that changes within it (a corner, the floor under a step). In a 40 cm box seen at 16x12 with
/// 32-pixel cells every cell is at least 1 m wide (1.73 m across), and no segment in the box is
/// longer than 0.7 m: no path may end, so the trace's matte light is the same as with path ends
/// off, frame by frame. Without the test the cells (which fill within a frame here) ended the
/// paths and the two differed from the first frames on. The two rooms above show that paths do
/// end where their segments are long.
#[test]
fn paths_do_not_end_in_a_cell_they_reached_over_a_short_segment() {
    let scene = small_box();
    let size = (16, 12);
    let input = FrameInput {
        camera: Camera::look_at(DVec3::ZERO, DVec3::new(1.0, -0.2, 0.3), 60.0),
        time: 0.0,
        shutter: None,
    };
    let run = |path_end_samples: f32| {
        let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, size).unwrap();
        let mut s = settings(4);
        s.cache.cell_pixels = 32.0;
        s.cache.path_end_samples = path_end_samples;
        s.max_depth = -1;
        (0..12)
            .map(|_| {
                r.render(&gpu, &input, &s, None).unwrap();
                halves(&r.read_texture(&gpu, "trace/matte").unwrap().0)
            })
            .collect::<Vec<_>>()
    };
    let (on, off) = (run(16.0), run(0.0));
    let lit = off.iter().flatten().filter(|p| p[0] > 0.0).count();
    assert!(lit > off.len() * 100, "{lit} lit matte samples over {} frames", off.len());
    for (k, (a, b)) in on.iter().zip(&off).enumerate() {
        let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
        assert_eq!(differ, 0, "frame {k}: pixels whose matte light differs with path ends on");
    }
}
