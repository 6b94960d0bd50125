//! `hush-cli bench SCENE --mode animate`: what a frame of the scene's animation costs before
//! anything is drawn: posing and placing the objects that move, the BVH (re)build, and writing
//! the changed geometry to the GPU (waited for). Measured over `--frames` frames 1/60 s apart,
//! after one warm-up frame; reported as the median and the minimum per part, with the moving
//! objects' tree refit (while it stays within the refit limit) and rebuilt every frame. A scene
//! whose shared meshes are stored once (instancing) is measured so, then flattened as without
//! instancing (at most 5 frames: flattening a crowd of 10,000 copies stores 10 M triangles).

use crate::bench::BenchArgs;
use crate::cli::load_scene;
use anyhow::{Context, Result, bail};
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, Instancing, PreparedScene};
use serde::Serialize;
use std::time::Instant;

#[derive(Serialize)]
struct AnimateRun {
    /// `instanced`; `refit` or `rebuilt`: the moving objects' tree refit (while within the refit
    /// limit) or rebuilt, `flattened` where the scene would instance.
    run: String,
    /// Median and minimum milliseconds: PreparedScene::animate (pose, flatten, BVH, buffers).
    animate_ms: [f64; 2],
    /// Of which the BVH build or refit.
    bvh_ms: [f64; 2],
    /// Of which the instances' top-level tree and transforms.
    top_level_ms: [f64; 2],
    /// The scene's GPU memory (bytes) after the last frame.
    gpu_bytes: u64,
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

/// The scene's frames with its deforming meshes posed on the GPU: `animate_ms` the CPU's part
/// (transforms, joint matrices, morph weights), `upload_ms` recording, submitting and waiting
/// for the pose, refit and copies.
fn gpu_posed(
    scene: &hush_engine::scene::Scene,
    kind: BvhKind,
    a: &BenchArgs,
) -> Result<AnimateRun> {
    use hush_engine::gpu::Recorder;
    use hush_engine::gpu::posing::GpuPosing;
    let mut prepared = PreparedScene::new(scene, kind)?;
    let gpu = Gpu::headless(&prepared.requirements(a.width as u64 * a.height as u64, 32))?;
    let mut gs = prepared.upload(&gpu);
    let mut posing = GpuPosing::new(&gpu, &prepared)?.context("posing on the GPU")?;
    prepared.gpu_posing = true;
    let (mut cpu, mut gpu_ms, mut total) = (vec![], vec![], vec![]);
    for f in 0..=a.frames.max(1) {
        let start = Instant::now();
        let moved = prepared.animate(scene, f as f64 / 60.0);
        gs.update_geometry(&gpu, &prepared, moved);
        posing.prepare(&gpu, scene, &mut prepared, &gs)?;
        let posed = start.elapsed();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        posing.record(&mut Recorder::new(&gpu, &mut enc, None), &gs);
        gpu.queue.submit([enc.finish()]);
        posing.submitted();
        gpu.wait()?;
        let all = start.elapsed();
        if f > 0 {
            cpu.push(posed.as_secs_f64() * 1e3);
            gpu_ms.push((all - posed).as_secs_f64() * 1e3);
            total.push(all.as_secs_f64() * 1e3);
        }
    }
    Ok(AnimateRun {
        run: format!("gpu posed ({} CPU rebuilds)", posing.rebuilds),
        animate_ms: median_min(&mut cpu),
        bvh_ms: [0.0; 2],
        top_level_ms: [0.0; 2],
        gpu_bytes: gs.memory.total_bytes() + posing.memory_bytes(),
        upload_ms: median_min(&mut gpu_ms),
        total_ms: median_min(&mut total),
    })
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
    let instanced = PreparedScene::new(&scene, kind)?.features.instances;
    // The same frames with the moving part's tree refit, then rebuilt every frame; instanced
    // first where the scene instances.
    let mut configs = vec![];
    if PreparedScene::new(&scene, kind)?.posing_supported() {
        runs.push(gpu_posed(&scene, kind, a)?);
    }
    if instanced {
        configs.push(("instanced".to_string(), true, Instancing::Auto));
    }
    let (flat, prefix) =
        if instanced { (Instancing::Never, "flattened, ") } else { (Instancing::Auto, "") };
    configs.push((format!("{prefix}refit"), true, flat));
    configs.push((format!("{prefix}rebuilt"), false, flat));
    for (name, refit, instancing) in configs {
        let mut prepared = PreparedScene::with_instancing(&scene, kind, instancing)?;
        prepared.refit = refit;
        let frames =
            if instancing == Instancing::Never { a.frames.clamp(1, 5) } else { a.frames.max(1) };
        // A flattened crowd may not fit the device at all: its frames are then measured on
        // the CPU alone (upload and GPU memory left out).
        let gpu = match Gpu::headless(&prepared.requirements(a.width as u64 * a.height as u64, 32))
        {
            Ok(g) => Some(g),
            Err(e) if instancing == Instancing::Never => {
                eprintln!("{name}: {e:#}; measured on the CPU alone");
                None
            }
            Err(e) => return Err(e),
        };
        let mut gscene = gpu.as_ref().map(|g| prepared.upload(g));
        let (mut animate, mut build, mut top, mut upload, mut total) =
            (vec![], vec![], vec![], vec![], vec![]);
        for f in 0..=frames {
            let t = f as f64 / 60.0;
            let start = Instant::now();
            let moved = prepared.animate(&scene, t);
            let posed = start.elapsed();
            if let (Some(gpu), Some(gs)) = (gpu.as_ref(), gscene.as_mut()) {
                gs.update_geometry(gpu, &prepared, moved);
                gpu.wait()?;
            }
            let all = start.elapsed();
            if f > 0 {
                animate.push(posed.as_secs_f64() * 1e3);
                let rebuilt = moved && prepared.geometry_moved;
                build.push(if rebuilt {
                    prepared.accel.build_time.as_secs_f64() * 1e3
                } else {
                    0.0
                });
                let placed = moved && prepared.features.instances;
                top.push(if placed { prepared.tlas_build_time.as_secs_f64() * 1e3 } else { 0.0 });
                upload.push(if gpu.is_some() {
                    (all - posed).as_secs_f64() * 1e3
                } else {
                    f64::NAN
                });
                total.push(all.as_secs_f64() * 1e3);
            }
        }
        if let Some(g) = &gpu {
            adapter = g.info.name.clone();
        }
        triangles = triangles.max(prepared.triangle_count());
        runs.push(AnimateRun {
            run: name,
            animate_ms: median_min(&mut animate),
            bvh_ms: median_min(&mut build),
            top_level_ms: median_min(&mut top),
            gpu_bytes: gscene.map_or(0, |g| g.memory.total_bytes()),
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
                "  {}: animate {:.3} / {:.3} (BVH {:.3} / {:.3}, top level {:.3} / {:.3}), upload {:.3} / {:.3}, total {:.3} / {:.3}; GPU memory {:.1} MB",
                run.run,
                run.animate_ms[0],
                run.animate_ms[1],
                run.bvh_ms[0],
                run.bvh_ms[1],
                run.top_level_ms[0],
                run.top_level_ms[1],
                run.upload_ms[0],
                run.upload_ms[1],
                run.total_ms[0],
                run.total_ms[1],
                run.gpu_bytes as f64 / 1e6
            );
        }
    }
    Ok(())
}
