//! `hush-cli bench SCENE --mode animate`: what a frame of the scene's animation costs before
//! anything is drawn: posing and placing the objects that move, the BVH (re)build, and writing
//! the changed geometry to the GPU (waited for). Measured over `--frames` frames 1/60 s apart,
//! after one warm-up frame; reported as the median and the minimum per part, with the moving
//! objects' tree refit (while it stays within the refit limit) and rebuilt every frame.

use crate::bench::BenchArgs;
use crate::cli::load_scene;
use anyhow::{Context, Result, bail};
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, PreparedScene};
use serde::Serialize;
use std::time::Instant;

#[derive(Serialize)]
struct AnimateRun {
    /// Whether the moving objects' tree was refit (while within the refit limit) or rebuilt.
    refit: bool,
    /// Median and minimum milliseconds: PreparedScene::animate (pose, flatten, BVH, buffers).
    animate_ms: [f64; 2],
    /// Of which the BVH build or refit.
    bvh_ms: [f64; 2],
    /// GpuScene::update_geometry and the wait for the queue.
    upload_ms: [f64; 2],
    total_ms: [f64; 2],
}

#[derive(Serialize)]
struct AnimateReport {
    scene: String,
    bvh: String,
    adapter: String,
    triangles: usize,
    moving_objects: usize,
    frames: u32,
    runs: Vec<AnimateRun>,
}

fn median_min(v: &mut [f64]) -> [f64; 2] {
    v.sort_by(f64::total_cmp);
    [v[v.len() / 2], v[0]]
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let scene = load_scene(&a.scene, &a.load)?;
    if !scene.is_animated() {
        bail!("{}: nothing in the scene moves; --mode animate measures animated scenes", a.scene);
    }
    let kind = match &a.bvh {
        Some(s) => BvhKind::parse(s).with_context(|| format!("--bvh {s:?}"))?,
        None => BvhKind::DEFAULT,
    };
    let mut runs = vec![];
    let (mut adapter, mut triangles) = (String::new(), 0);
    // The same frames with the moving part's tree refit, then rebuilt every frame.
    for refit in [true, false] {
        let mut prepared = PreparedScene::new(&scene, kind)?;
        prepared.refit = refit;
        let gpu = Gpu::headless(&prepared.requirements(a.width as u64 * a.height as u64, 32))?;
        let mut gscene = prepared.upload(&gpu);
        let (mut animate, mut build, mut upload, mut total) = (vec![], vec![], vec![], vec![]);
        for f in 0..=a.frames.max(1) {
            let t = f as f64 / 60.0;
            let start = Instant::now();
            let moved = prepared.animate(&scene, t);
            let posed = start.elapsed();
            gscene.update_geometry(&gpu, &prepared, moved);
            gpu.wait()?;
            let all = start.elapsed();
            if f > 0 {
                animate.push(posed.as_secs_f64() * 1e3);
                build.push(if moved { prepared.accel.build_time.as_secs_f64() * 1e3 } else { 0.0 });
                upload.push((all - posed).as_secs_f64() * 1e3);
                total.push(all.as_secs_f64() * 1e3);
            }
        }
        adapter = gpu.info.name.clone();
        triangles = prepared.triangle_count();
        runs.push(AnimateRun {
            refit,
            animate_ms: median_min(&mut animate),
            bvh_ms: median_min(&mut build),
            upload_ms: median_min(&mut upload),
            total_ms: median_min(&mut total),
        });
    }
    let r = AnimateReport {
        scene: a.scene.clone(),
        bvh: kind.name().into(),
        adapter,
        triangles,
        moving_objects: scene.objects.iter().filter(|o| o.moves()).count(),
        frames: a.frames.max(1),
        runs,
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        println!(
            "{} ({} triangles, {} moving objects, {} BVH) on {}, per frame, median / min ms:",
            r.scene, r.triangles, r.moving_objects, r.bvh, r.adapter
        );
        for run in &r.runs {
            println!(
                "  {}: animate {:.3} / {:.3} (BVH {:.3} / {:.3}), upload {:.3} / {:.3}, total {:.3} / {:.3}",
                if run.refit { "refit" } else { "rebuilt" },
                run.animate_ms[0],
                run.animate_ms[1],
                run.bvh_ms[0],
                run.bvh_ms[1],
                run.upload_ms[0],
                run.upload_ms[1],
                run.total_ms[0],
                run.total_ms[1]
            );
        }
    }
    Ok(())
}
