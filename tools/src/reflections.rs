//! `hush-cli reflections`: how well a denoiser (`--denoiser mara`: the glossy chain; `svgf`: its
//! glossy signal) reprojects reflections, measured as Voorhuis §7.3-7.4 does.
//! 1. Temporal error (Schied et al.: mean |luminance change| between consecutive frames, still
//!    camera and scene) on surfaces with a specular lobe, of the glossy chain's output (TAA and
//!    its jitter off) and of the final image (TAA on), for each reflection motion vector
//!    (diamond, virtual, primary) and with no glossy reprojection at all.
//! 2. A camera strafe (with the scene's animation running): FLIP of the final image against a
//!    per-frame accumulated reference on reflective pixels (roughness under the threshold), and
//!    on the ghost region: reflective pixels whose reference changed since the previous frame
//!    (where a reflected object was and no longer is, or arrived), where a ghost trail shows.
//! 3. Motion vector accuracy on `--mv-scene` (default `spheres`: a mirror and a glossy sphere,
//!    no other specular surface): the diamond search against a brute-force search of a
//!    (2R + 1)^2 window, with and without LDSP scaling, and with the sampled depth of eq. (4)-(5)
//!    instead of the traced representative ray: mean error and share within one pixel.

use crate::cli::{bvh_kind, image_size, load_scene};
use crate::reference::new_renderer;
use anyhow::{Context, Result};
use clap::Args;
use glam::{DMat4, DVec3, Vec3};
use hush_engine::denoise::svgf;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::quality::{Image, flip_map, luminance};
use hush_engine::scene::Camera;
use hush_engine::settings::{Denoiser, FrameSettings, ReflectionMv};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args)]
pub struct ReflectionsArgs {
    /// Scene of parts 1 and 2 (default: the mirror floor and glossy sphere of `reflections`).
    #[arg(default_value = "reflections")]
    pub scene: String,
    #[arg(long, default_value = "spheres")]
    pub mv_scene: String,
    #[arg(long, default_value_t = 160)]
    pub width: u32,
    #[arg(long)]
    pub height: Option<u32>,
    /// Frames of the still-camera run (temporal error over its second half).
    #[arg(long, default_value_t = 40)]
    pub frames: u32,
    /// Frames of the camera strafe.
    #[arg(long, default_value_t = 24)]
    pub path_frames: u32,
    /// Frames accumulated for each strafe frame's reference.
    #[arg(long, default_value_t = 64)]
    pub reference_frames: u32,
    /// Strafe speed along the camera's right axis, scene units per frame.
    #[arg(long, default_value_t = 0.04)]
    pub step: f64,
    /// Brute-force search radius in pixels.
    #[arg(long, default_value_t = 32)]
    pub search_radius: u32,
    /// The denoiser measured: `mara` (its glossy chain) or `svgf` (its glossy signal).
    #[arg(long, default_value = Denoiser::MARA.name())]
    pub denoiser: String,
    /// Start every configuration from this preset's settings (TOML, as the viewer saves);
    /// `--denoiser` and `--disable` then apply.
    #[arg(long)]
    pub preset: Option<PathBuf>,
    /// Stages to switch off in every configuration (see `render --disable`), for ablations.
    #[arg(long, value_delimiter = ',')]
    pub disable: Vec<String>,
    #[arg(long)]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub load: crate::cli::LoadArgs,
}

/// Per-pixel G-buffer facts the measurements mask with.
struct Mask {
    glossy: Vec<bool>,
    reflective: Vec<bool>,
    roughness: Vec<f32>,
}

fn mask(r: &Renderer, gpu: &Gpu, threshold: f32) -> Result<Mask> {
    let (spec, _) = r.read_texture(gpu, "gbuffer/specular")?;
    let (ids, _) = r.read_texture(gpu, "gbuffer/ids")?;
    let n = ids.len() / 8;
    let mut m =
        Mask { glossy: vec![false; n], reflective: vec![false; n], roughness: vec![1.0; n] };
    for i in 0..n {
        let hit = u32::from_le_bytes(ids[i * 8 + 4..i * 8 + 8].try_into().unwrap()) != u32::MAX;
        let f0 = spec[i * 4..i * 4 + 3].iter().copied().max().unwrap_or(0);
        m.roughness[i] = spec[i * 4 + 3] as f32 / 255.0;
        m.glossy[i] = hit && f0 > 0;
        m.reflective[i] = m.glossy[i] && m.roughness[i] < threshold;
    }
    Ok(m)
}

/// An Rgba16Float or Rgba32Float texture as vec4s.
fn read_vec4(r: &Renderer, gpu: &Gpu, name: &str) -> Result<Vec<[f32; 4]>> {
    let (bytes, format) = r.read_texture(gpu, name)?;
    Ok(match format {
        wgpu::TextureFormat::Rgba32Float => bytemuck::cast_slice::<u8, [f32; 4]>(&bytes).to_vec(),
        _ => bytes
            .chunks_exact(8)
            .map(|c| {
                std::array::from_fn(|k| half::f16::from_le_bytes([c[2 * k], c[2 * k + 1]]).to_f32())
            })
            .collect(),
    })
}

fn masked_mean(values: impl Iterator<Item = f64>, mask: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for (v, m) in values.zip(mask) {
        if *m {
            s += v;
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { s / n as f64 }
}

/// The ways of reprojecting reflections that are compared: Mara's chain with each reflection
/// motion vector and with none, or SVGF with and without Voorhuis's reflection reprojection and
/// with no glossy accumulation ("NoSpecReproj").
fn configs(base: &FrameSettings) -> Vec<(&'static str, FrameSettings)> {
    let mut v = vec![];
    if base.denoiser == Denoiser::SVGF {
        v.push(("diamond", base.clone()));
        let mut primary = base.clone();
        primary.svgf.reflection_reprojection = false;
        v.push(("primary", primary));
        let mut off = base.clone();
        off.svgf.glossy_temporal = false;
        v.push(("no reprojection", off));
        return v;
    }
    for mv in [ReflectionMv::Diamond, ReflectionMv::Virtual, ReflectionMv::Primary] {
        let mut s = base.clone();
        s.glossy.reflection_mv = mv;
        v.push((mv.name(), s));
    }
    let mut off = base.clone();
    off.glossy.temporal = false;
    v.push(("no reprojection", off));
    v
}

/// The scene's camera moved along its right axis by `offset`.
fn strafed(c: Camera, offset: f64) -> Camera {
    let right = c.world.transform_vector3(DVec3::X).normalize();
    Camera { world: DMat4::from_translation(right * offset) * c.world, ..c }
}

pub fn run(a: ReflectionsArgs) -> Result<()> {
    crate::cli::check_output_dir(&a.out_dir, "--out-dir")?;
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("creating {}", a.out_dir.display()))?;
    let scene = load_scene(&a.scene, &a.load)?;
    let size = image_size(&scene, Some(a.width), a.height);
    let prepared = PreparedScene::new(&scene, bvh_kind(&None)?)?;
    let gpu = Gpu::headless(&prepared.realtime_requirements(size))?;
    let base =
        crate::cli::preset_settings(a.preset.as_deref(), Some(&a.denoiser), &a.disable, None)?;
    let svgf = base.denoiser == Denoiser::SVGF;
    if !svgf && base.denoiser != Denoiser::MARA {
        let (m, s) = (Denoiser::MARA.name(), Denoiser::SVGF.name());
        anyhow::bail!("--denoiser {}: reflections measures {m} or {s}", a.denoiser);
    }
    let threshold =
        if svgf { base.svgf.roughness_threshold } else { base.glossy.roughness_threshold };
    // What the glossy denoiser writes for the composite.
    let glossy_output = if svgf { svgf::GLOSSY_OUTPUT } else { "glossy/denoised" };
    let camera = scene.camera_or_default();
    let mut csv = std::fs::File::create(a.out_dir.join("reflections.csv"))?;
    writeln!(csv, "part,config,metric,value")?;
    println!("{} at {}x{} on {}", a.scene, size.0, size.1, gpu.info.name);

    // 1. Temporal error, still camera and scene: the chain's output on a still raster (TAA off:
    // its sub-pixel jitter changes what every pixel samples, and that aliasing is TAA's to
    // remove), and the final image with TAA on glossy pixels.
    println!(
        "  still camera, {} frames: temporal error (mean |dY| on glossy pixels, second half)",
        a.frames
    );
    println!("    {:16} {:>14} {:>14} {:>14}", "", "chain output", "final image", "raw glossy");
    let mut still = vec![];
    for (name, s) in configs(&base) {
        let mut row = vec![];
        for taa in [false, true] {
            let mut s = s.clone();
            s.taa.enabled = taa;
            let mut r = new_renderer(&gpu, &scene, size)?;
            let mut prev: Option<(Vec<f32>, Vec<f32>)> = None;
            let (mut chain_err, mut raw_err) = (vec![], vec![]);
            for _ in 0..a.frames {
                r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &s, None)?;
                let m = mask(&r, &gpu, threshold)?;
                let y: Vec<f32> = if taa {
                    r.read_hdr(&gpu)?.data.iter().map(|v| luminance(*v)).collect()
                } else {
                    read_vec4(&r, &gpu, glossy_output)?
                        .iter()
                        .map(|v| luminance(Vec3::new(v[0], v[1], v[2])))
                        .collect()
                };
                let raw: Vec<f32> = read_vec4(&r, &gpu, "trace/glossy")?
                    .iter()
                    .map(|v| luminance(Vec3::new(v[0], v[1], v[2])))
                    .collect();
                if let Some((p, pr)) = &prev {
                    chain_err.push(masked_mean(
                        y.iter().zip(p).map(|(a, b)| (a - b).abs() as f64),
                        &m.glossy,
                    ));
                    raw_err.push(masked_mean(
                        raw.iter().zip(pr).map(|(a, b)| (a - b).abs() as f64),
                        &m.glossy,
                    ));
                }
                prev = Some((y, raw));
            }
            row.push(crate::quality::Scores::settled(&chain_err));
            if taa {
                row.push(crate::quality::Scores::settled(&raw_err));
            }
        }
        println!("    {name:16} {:14.5} {:14.5} {:14.5}", row[0], row[1], row[2]);
        writeln!(csv, "still,{name},temporal_error_chain_output,{:.6}", row[0])?;
        writeln!(csv, "still,{name},temporal_error_final_image,{:.6}", row[1])?;
        still.push((name, row[0], row[1]));
    }
    if let Some(off) = still.iter().find(|s| s.0 == "no reprojection").cloned() {
        for (name, chain, fin) in &still {
            if *name != "no reprojection" {
                println!(
                    "    no reprojection / {name}: {:.2}x (chain output), {:.2}x (final image)",
                    off.1 / chain.max(1e-12),
                    off.2 / fin.max(1e-12)
                );
            }
        }
    }

    // 2. Camera strafe: references, then each configuration.
    let inputs: Vec<FrameInput> = (0..a.path_frames)
        .map(|k| FrameInput {
            camera: strafed(camera, (k as f64 - a.path_frames as f64 / 2.0) * a.step),
            time: k as f64 / 30.0,
            shutter: None,
        })
        .collect();
    let mut refr = new_renderer(&gpu, &scene, size)?;
    let acc = FrameSettings { accumulate: true, seed: 7919, ..Default::default() };
    let mut references: Vec<Image> = vec![];
    for input in &inputs {
        for _ in 0..a.reference_frames {
            refr.render(&gpu, input, &acc, None)?;
        }
        references.push(refr.read_hdr(&gpu)?);
    }
    drop(refr);
    println!(
        "  camera strafe, {} frames ({} reference frames each): FLIP of reflective pixels, and of the ghost region",
        a.path_frames, a.reference_frames
    );
    let mut flips = std::fs::File::create(a.out_dir.join("strafe.csv"))?;
    writeln!(flips, "frame,config,flip_reflective,flip_ghost_region")?;
    for (name, s) in configs(&base) {
        let mut r = new_renderer(&gpu, &scene, size)?;
        let (mut fr, mut fg) = (vec![], vec![]);
        for (k, input) in inputs.iter().enumerate() {
            r.render(&gpu, input, &s, None)?;
            let img = r.read_hdr(&gpu)?;
            let m = mask(&r, &gpu, threshold)?;
            let f = flip_map(&img, &references[k]);
            let refl = masked_mean(f.iter().map(|v| *v as f64), &m.reflective);
            // The ghost region: reflective pixels whose reference luminance changed by over 20%.
            let ghost: Vec<bool> = if k == 0 {
                vec![false; f.len()]
            } else {
                references[k]
                    .data
                    .iter()
                    .zip(&references[k - 1].data)
                    .zip(&m.reflective)
                    .map(|((c, p), r)| {
                        *r && ((luminance(*c) - luminance(*p)).abs()
                            > 0.2 * luminance(*c).max(luminance(*p)).max(0.02))
                    })
                    .collect()
            };
            let g = masked_mean(f.iter().map(|v| *v as f64), &ghost);
            writeln!(flips, "{k},{name},{refl:.5},{g:.5}")?;
            // The first quarter fills the history; score the rest.
            if k >= inputs.len() / 4 {
                fr.push(refl);
                fg.push(g);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        println!(
            "    {name:16} reflective FLIP {:.4}   ghost-region FLIP {:.4}",
            mean(&fr),
            mean(&fg)
        );
        writeln!(csv, "strafe,{name},flip_reflective,{:.5}", mean(&fr))?;
        writeln!(csv, "strafe,{name},flip_ghost_region,{:.5}", mean(&fg))?;
    }

    // 3. Motion vector accuracy against a brute-force search.
    let mv_scene = load_scene(&a.mv_scene, &a.load)?;
    let mv_camera = mv_scene.camera_or_default();
    println!(
        "  motion vectors on {} against a brute-force search of {}x{} pixels (strafe {} per frame)",
        a.mv_scene,
        2 * a.search_radius + 1,
        2 * a.search_radius + 1,
        a.step * 3.0
    );
    for (initial_step, traced) in [(4u32, true), (1, true), (4, false)] {
        let mut s = base.clone();
        s.glossy.initial_step = initial_step;
        s.glossy.trace_representative_ray = traced;
        s.glossy.reference_search_radius = a.search_radius;
        let mut r = new_renderer(&gpu, &mv_scene, size)?;
        // The search's textures are read after each frame.
        r.keep(&[svgf::GLOSSY_PREFIX]);
        // (sum of errors, within one pixel, count) for mirror and glossy pixels.
        let mut stats = [(0.0f64, 0usize, 0usize); 2];
        for k in 0..a.path_frames {
            let input = FrameInput {
                camera: strafed(mv_camera, (k as f64 - a.path_frames as f64 / 2.0) * a.step * 3.0),
                time: 0.0,
                shutter: None,
            };
            r.render(&gpu, &input, &s, None)?;
            if k == 0 {
                continue;
            }
            let m = mask(&r, &gpu, threshold)?;
            // SVGF runs the glossy chain's search on textures of its own.
            let prefix = if svgf { svgf::GLOSSY_PREFIX } else { "glossy/" };
            let motion = read_vec4(&r, &gpu, &format!("{prefix}motion"))?;
            let search = read_vec4(&r, &gpu, &format!("{prefix}search"))?;
            for i in 0..motion.len() {
                // Reflective pixels where the brute force found a match (finite distance).
                if !m.reflective[i] || !search[i][3].is_finite() || search[i][3] > 6.0e4 {
                    continue;
                }
                let e = ((motion[i][0] - motion[i][2]).powi(2)
                    + (motion[i][1] - motion[i][3]).powi(2))
                .sqrt() as f64;
                let c = &mut stats[(m.roughness[i] > 0.01) as usize];
                c.0 += e;
                c.1 += (e <= 1.0) as usize;
                c.2 += 1;
            }
        }
        let scaling = match (initial_step > 1, traced) {
            (true, true) => "with LDSP scaling",
            (false, true) => "without LDSP scaling",
            _ => "sampled depth, eq. 5",
        };
        for (kind, (sum, within, n)) in ["mirror sphere", "glossy sphere"].iter().zip(stats) {
            let mean = sum / n.max(1) as f64;
            let share = within as f64 / n.max(1) as f64 * 100.0;
            println!(
                "    {kind:14} {scaling:22} mean error {mean:.3} px, {share:.1}% within 1 px ({n} vectors)"
            );
            writeln!(csv, "motion,{kind} {scaling},mean_error_px,{mean:.4}")?;
            writeln!(csv, "motion,{kind} {scaling},within_1px_percent,{share:.2}")?;
        }
    }
    println!("  wrote {}", a.out_dir.join("reflections.csv").display());
    Ok(())
}
