use super::*;

mod layouts;

const FEATURE_SETS: &[[&str; 9]] = &[
    [
        "common/alpha_none.wgsl",
        "common/textures_none.wgsl",
        "common/tangents_none.wgsl",
        "common/lights_none.wgsl",
        "common/emitters_none.wgsl",
        "common/env_none.wgsl",
        "common/texcoords_none.wgsl",
        "common/attributes_none.wgsl",
        "common/transmission.wgsl",
    ],
    [
        "common/alpha_mask.wgsl",
        "common/textures.wgsl",
        "common/tangents.wgsl",
        "common/lights.wgsl",
        "common/emitters.wgsl",
        "common/env_map.wgsl",
        "common/texcoords.wgsl",
        "common/attributes.wgsl",
        "common/transmission_none.wgsl",
    ],
    [
        "common/alpha_none.wgsl",
        "common/textures.wgsl",
        "common/tangents_none.wgsl",
        "common/lights.wgsl",
        "common/emitters_none.wgsl",
        "common/env_constant.wgsl",
        "common/texcoords.wgsl",
        "common/attributes_none.wgsl",
        "common/transmission.wgsl",
    ],
    [
        "common/alpha_mask.wgsl",
        "common/textures.wgsl",
        "common/tangents.wgsl",
        "common/lights_none.wgsl",
        "common/emitters.wgsl",
        "common/env_none.wgsl",
        "common/texcoords_none.wgsl",
        "common/attributes.wgsl",
        "common/transmission_none.wgsl",
    ],
];

const MOTIONS: [crate::gpu::Motion; 3] =
    [crate::gpu::Motion::Static, crate::gpu::Motion::Objects, crate::gpu::Motion::Vertices];

/// Every program Hush can compose, over both BVH layouts and the feature alternatives.
pub(super) fn all_programs() -> Vec<Program> {
    let mut v = vec![];
    for set in FEATURE_SETS {
        for motion in [
            "realtime/motion_static.wgsl",
            "realtime/motion_objects.wgsl",
            "realtime/motion_vertices.wgsl",
        ] {
            let m = [
                "common/math.wgsl",
                "common/rng.wgsl",
                "common/geometry.wgsl",
                "common/motion_none.wgsl",
                if motion.contains("objects") {
                    "common/instances.wgsl"
                } else {
                    "common/instances_none.wgsl"
                },
                "common/scene.wgsl",
                "common/bsdf.wgsl",
                set[1],
                set[2],
                set[0],
                set[6],
                set[7],
                set[8],
                "realtime/frame.wgsl",
                motion,
                "realtime/gbuffer_dither.wgsl",
                "realtime/gbuffer.wgsl",
            ];
            v.push(compose("gbuffer", "", &m).unwrap());
        }
    }
    for glossy in ["realtime/glossy_in.wgsl", "realtime/glossy_in_none.wgsl"] {
        let m = [
            "common/math.wgsl",
            "common/rng.wgsl",
            "realtime/frame.wgsl",
            "realtime/gbuffer_in.wgsl",
            glossy,
            "realtime/remodulate.wgsl",
            "realtime/composite.wgsl",
        ];
        v.push(compose("realtime/composite.wgsl", "", &m).unwrap());
        let display = [
            "common/math.wgsl",
            "common/rng.wgsl",
            "realtime/frame.wgsl",
            "realtime/gbuffer_in.wgsl",
            glossy,
            "realtime/display.wgsl",
        ];
        v.push(compose("realtime/display.wgsl", "", &display).unwrap());
    }
    for glossy in [false, true] {
        for mean in [true, false] {
            let m = crate::passes::converge::modules(glossy, mean);
            v.push(compose(m[m.len() - 1], "", &m).unwrap());
        }
    }
    for motion in MOTIONS {
        for glossy in [false, true] {
            for pass in crate::passes::upscale::Pass::ALL {
                let m = crate::passes::upscale::modules(motion, glossy, pass);
                v.push(compose(m[m.len() - 1], "", &m).unwrap());
            }
        }
    }
    for (format, main) in [
        ("rgba32float", "realtime/rescale_float.wgsl"),
        ("r32float", "realtime/rescale_float.wgsl"),
        ("r32uint", "realtime/rescale_uint.wgsl"),
        ("rg32uint", "realtime/rescale_uint.wgsl"),
    ] {
        let prelude = format!("alias Dst = texture_storage_2d<{format}, write>;\n");
        let m =
            ["common/bilinear.wgsl", "realtime/rescale.wgsl", main, "realtime/rescale_main.wgsl"];
        v.push(compose(main, &prelude, &m).unwrap());
    }
    let gbuffer =
        ["common/bilinear.wgsl", "realtime/rescale.wgsl", "realtime/rescale_gbuffer.wgsl"];
    v.push(compose("realtime/rescale_gbuffer.wgsl", "", &gbuffer).unwrap());
    for motion in [
        "realtime/motion_static.wgsl",
        "realtime/motion_objects.wgsl",
        "realtime/motion_vertices.wgsl",
    ] {
        for stage in [
            &["cache/prior_none.wgsl", "matte/temporal.wgsl"][..],
            &["cache/prior.wgsl", "matte/temporal.wgsl"],
            &[
                "realtime/uncertainty_none.wgsl",
                "common/feature_weight.wgsl",
                "matte/sparse_bilateral.wgsl",
                "matte/history_bilateral.wgsl",
            ],
            &["matte/disocclusion.wgsl"],
            &["matte/firefly.wgsl"],
            &[
                "realtime/uncertainty_none.wgsl",
                "common/feature_weight.wgsl",
                "matte/sparse_bilateral.wgsl",
                "matte/bilateral.wgsl",
            ],
            &[
                "realtime/uncertainty.wgsl",
                "common/feature_weight.wgsl",
                "matte/sparse_bilateral.wgsl",
                "matte/bilateral.wgsl",
            ],
            &[
                "realtime/glossy_in.wgsl",
                "glossy/common.wgsl",
                "taa/glossy.wgsl",
                "taa/glossy_term.wgsl",
                "taa/matte.wgsl",
                "taa/history_test.wgsl",
                "taa/taa.wgsl",
            ],
            &[
                "realtime/glossy_in_none.wgsl",
                "taa/glossy_none.wgsl",
                "taa/glossy_term.wgsl",
                "taa/matte_none.wgsl",
                "taa/history_test.wgsl",
                "taa/taa.wgsl",
            ],
            &[
                "realtime/glossy_in.wgsl",
                "taa/glossy_none.wgsl",
                "taa/glossy_term.wgsl",
                "taa/matte_moments.wgsl",
                "taa/history_test.wgsl",
                "taa/taa.wgsl",
            ],
        ] {
            let mut m = vec![
                "common/math.wgsl",
                "realtime/frame.wgsl",
                "realtime/gbuffer_in.wgsl",
                "common/bilinear.wgsl",
                "realtime/reproject.wgsl",
                "matte/common.wgsl",
                motion,
            ];
            m.extend_from_slice(stage);
            v.push(compose(stage[stage.len() - 1], "", &m).unwrap());
        }
    }
    for animated in MOTIONS {
        for stage in [
            "glossy/motion.wgsl",
            "glossy/prefilter.wgsl",
            "glossy/temporal.wgsl",
            "glossy/bilateral.wgsl",
        ] {
            let m = crate::denoise::mara::glossy::modules(stage, animated);
            if stage == "glossy/motion.wgsl" {
                // Each of the search's program variants.
                for traced_hits in [false, true] {
                    for reference_radius in [0, 4] {
                        let p = crate::denoise::mara::glossy::MotionProgram {
                            traced_hits,
                            reference_radius,
                        };
                        v.push(compose(stage, &p.prelude(), &m).unwrap());
                    }
                }
                continue;
            }
            if stage == "glossy/bilateral.wgsl" {
                // With the pre-filter's feature uncertainty, and without.
                for u in ["realtime/uncertainty.wgsl", "realtime/uncertainty_none.wgsl"] {
                    let mut m = m.clone();
                    m.insert(m.len() - 1, u);
                    v.push(compose(stage, "", &m).unwrap());
                }
            } else {
                v.push(compose(stage, "", &m).unwrap());
            }
        }
    }
    for animated in MOTIONS {
        for glossy in [false, true] {
            let temporal =
                if glossy { "svgf/temporal_glossy.wgsl" } else { "svgf/temporal_matte.wgsl" };
            for stage in [
                temporal,
                "svgf/variance.wgsl",
                "svgf/atrous.wgsl",
                "svgf/spread.wgsl",
                "svgf/regression.wgsl",
                "svgf/final.wgsl",
            ] {
                let mut m = crate::denoise::svgf::modules(stage, glossy, animated);
                if stage == "svgf/temporal_matte.wgsl" {
                    // The radiance cache's prior, and none.
                    let mut with_prior = m.clone();
                    with_prior.push("cache/prior.wgsl");
                    v.push(compose(stage, "", &with_prior).unwrap());
                    m.push("cache/prior_none.wgsl");
                }
                if stage == "svgf/atrous.wgsl" {
                    // SVGF's 5x5 kernel; the 3x3 below.
                    let mut with = m.clone();
                    with.insert(with.len() - 1, crate::denoise::svgf::kernel_module(true));
                    if glossy {
                        with.insert(with.len() - 1, "realtime/uncertainty_none.wgsl");
                    }
                    v.push(compose(stage, "", &with).unwrap());
                    m.insert(m.len() - 1, crate::denoise::svgf::kernel_module(false));
                }
                if crate::denoise::svgf::reads_uncertainty(stage, glossy) {
                    // With the pre-filter's feature uncertainty, and without.
                    let mut with = m.clone();
                    with.insert(with.len() - 1, "realtime/uncertainty.wgsl");
                    v.push(compose(stage, "", &with).unwrap());
                    m.insert(m.len() - 1, "realtime/uncertainty_none.wgsl");
                }
                v.push(compose(stage, "", &m).unwrap());
            }
        }
    }
    let resolve = ["common/math.wgsl", "common/rng.wgsl", "cache/cells.wgsl", "cache/resolve.wgsl"];
    v.push(compose("cache/resolve.wgsl", "", &resolve).unwrap());
    for (label, module) in crate::gpu::posing::PROGRAMS {
        v.push(compose(label, "", &[module]).unwrap());
    }
    for animated in MOTIONS {
        for glossy in [false, true] {
            use crate::denoise::progressive::{Signal, modules};
            let signals: &[Signal] = if glossy {
                &[Signal::Matte, Signal::Glossy, Signal::Direct]
            } else {
                &[Signal::Matte, Signal::Direct]
            };
            for &signal in signals {
                for stage in [
                    "progressive/features.wgsl",
                    "progressive/temporal.wgsl",
                    "progressive/variance.wgsl",
                    "progressive/atrous.wgsl",
                ] {
                    v.push(compose(stage, "", &modules(stage, signal, glossy, animated)).unwrap());
                }
            }
        }
    }
    for glossy in [false, true] {
        for stage in ["supersample/assign.wgsl", "supersample/mix.wgsl", "supersample/resolve.wgsl"]
        {
            v.push(
                compose(stage, "", &crate::passes::supersample::modules(stage, glossy)).unwrap(),
            );
        }
    }
    v.push(
        compose(
            "gbuffer/resolve",
            "",
            &[
                "common/math.wgsl",
                "common/rng.wgsl",
                "realtime/frame.wgsl",
                "realtime/gbuffer_dither.wgsl",
                "realtime/primaries_resolve.wgsl",
            ],
        )
        .unwrap(),
    );
    for stage in ["prefilter/covariance.wgsl", "prefilter/sure.wgsl", "prefilter/features.wgsl"] {
        v.push(compose(stage, "", &crate::passes::prefilter::modules(stage)).unwrap());
    }
    for bvh in ["common/bvh2.wgsl", "common/cwbvh.wgsl"] {
        // A scene sets the traversal's stack length (accel::traversal_stack).
        let stack = "const TRAVERSAL_STACK: u32 = 16u;\nconst DYNAMIC_ROOT: u32 = 7u;\nconst TLAS_STACK: u32 = 12u;\n";
        v.push(
            compose(
                "raycast",
                stack,
                &[
                    "common/math.wgsl",
                    "common/geometry.wgsl",
                    "common/motion_none.wgsl",
                    "common/instances.wgsl",
                    bvh,
                    "common/tlas.wgsl",
                    "common/alpha_none.wgsl",
                    "accel/raycast.wgsl",
                ],
            )
            .unwrap(),
        );
        for (i, set) in FEATURE_SETS.iter().enumerate() {
            let mut m = vec![
                "common/math.wgsl",
                "common/rng.wgsl",
                "common/geometry.wgsl",
                if i % 2 == 0 { "common/motion_none.wgsl" } else { "common/motion_blur.wgsl" },
                // Instances with and without motion blur, and neither.
                if i % 3 == 0 { "common/instances_none.wgsl" } else { "common/instances.wgsl" },
                bvh,
                if i % 3 == 0 { "common/tlas_none.wgsl" } else { "common/tlas.wgsl" },
                "common/scene.wgsl",
                "common/bsdf.wgsl",
                "common/params.wgsl",
                "common/camera.wgsl",
                "common/path.wgsl",
                "common/path_end_none.wgsl",
            ];
            m.extend(set.iter());
            if set.contains(&"common/emitters.wgsl") {
                m.push("common/light_tree.wgsl");
            }
            let prelude = format!(
                "const HAS_EMITTERS: bool = {};\nconst HAS_ENV: bool = {};\n{stack}",
                i % 2 == 1,
                i != 0
            );
            let mut reference = m.clone();
            reference.push("reference/trace.wgsl");
            v.push(compose(&format!("trace {bvh} {i}"), &prelude, &reference).unwrap());
            // Every glossy output: all, the light alone (no stage reads the reflection data),
            // none.
            let glossy = [
                "realtime/trace_glossy.wgsl",
                "realtime/trace_glossy_light.wgsl",
                "realtime/trace_glossy_none.wgsl",
            ][i % 3];
            let mut primaries = m.clone();
            primaries.extend([
                "realtime/frame.wgsl",
                if i % 2 == 0 {
                    "realtime/motion_static.wgsl"
                } else {
                    "realtime/motion_objects.wgsl"
                },
                "realtime/lens.wgsl",
                "realtime/primaries.wgsl",
            ]);
            v.push(compose(&format!("primaries {bvh} {i}"), &prelude, &primaries).unwrap());
            // Paths that may end in the radiance cache (passes/cache.rs, with_path_ends).
            let mut cache = crate::passes::cache::with_path_ends(m.clone());
            m.extend([
                "realtime/frame.wgsl",
                "realtime/lens.wgsl",
                "realtime/area_light.wgsl",
                glossy,
            ]);
            // With the cache, the trace of a denoised frame: the previous depth's uncovered test,
            // and the light samples' reservoirs.
            let mut cached_trace = crate::passes::cache::with_path_ends(m.clone());
            cached_trace.extend([
                "realtime/seen.wgsl",
                "realtime/uncovered.wgsl",
                "realtime/reservoir.wgsl",
                "realtime/trace.wgsl",
            ]);
            let name = format!("realtime trace with the cache {bvh} {i}");
            v.push(compose(&name, &prelude, &cached_trace).unwrap());
            m.extend([
                "realtime/uncovered_none.wgsl",
                "realtime/reservoir_none.wgsl",
                "realtime/trace.wgsl",
            ]);
            v.push(compose(&format!("realtime trace {bvh} {i}"), &prelude, &m).unwrap());
            cache.extend([
                "realtime/frame.wgsl",
                "realtime/lens.wgsl",
                "realtime/area_light.wgsl",
                "realtime/seen.wgsl",
                "cache/update.wgsl",
            ]);
            v.push(compose(&format!("cache update {bvh} {i}"), &prelude, &cache).unwrap());
            m.extend(["supersample/common.wgsl", "supersample/samples.wgsl"]);
            v.push(compose(&format!("supersample samples {bvh} {i}"), &prelude, &m).unwrap());
        }
    }
    v
}

#[test]
fn every_program_validates_with_naga() {
    for p in all_programs() {
        if let Err(e) = p.validate() {
            panic!("{e:#}");
        }
    }
}

#[test]
fn every_wgsl_file_is_embedded_and_used() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let mut files = vec![];
    let mut stack = vec![dir.clone()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "wgsl") {
                files.push(p.strip_prefix(&dir).unwrap().to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let programs = all_programs();
    for f in &files {
        assert!(SOURCES.iter().any(|(p, _)| p == f), "{f} is not embedded in shader::SOURCES");
        assert!(
            programs.iter().any(|p| p.modules.contains(&f.as_str())),
            "{f} is in no validated program"
        );
    }
    assert_eq!(files.len(), SOURCES.len(), "SOURCES lists a file that does not exist");
}

#[test]
fn every_storage_texture_format_is_checked_before_the_frame() {
    use wgpu::TextureFormat as F;
    let named = |w: &str| match w {
        "r32float" => Some(F::R32Float),
        "r32uint" => Some(F::R32Uint),
        "rg32float" => Some(F::Rg32Float),
        "rg32uint" => Some(F::Rg32Uint),
        "rgba16float" => Some(F::Rgba16Float),
        "rgba32float" => Some(F::Rgba32Float),
        "rgba32uint" => Some(F::Rgba32Uint),
        _ => None,
    };
    let mut seen = 0;
    for (path, text) in SOURCES {
        for part in text.split("texture_storage_2d<").skip(1) {
            let w = part.split(|c: char| !c.is_ascii_alphanumeric()).next().unwrap();
            let f = named(w).unwrap_or_else(|| panic!("{path}: storage format {w} has no entry"));
            assert!(
                crate::gpu::REALTIME_STORAGE_FORMATS.contains(&f),
                "{path} writes {w}, which gpu::REALTIME_STORAGE_FORMATS does not check"
            );
            seen += 1;
        }
    }
    assert!(seen > 50, "only {seen} storage textures found in shaders/");
}

#[test]
fn errors_name_the_file_and_line() {
    let p = Program {
        label: "t".into(),
        modules: vec![],
        text: "// ---- a.wgsl\nfn f() {}\n// ---- b.wgsl\nfn g() -> u32 {\n  return 1u +;\n}\n"
            .into(),
    };
    let e = format!("{:#}", p.validate().unwrap_err());
    assert!(e.contains("b.wgsl:2"), "{e}");
}

/// Size and member offsets of a WGSL struct as naga lays it out for storage/uniform use.
fn wgsl_layout(p: &Program, name: &str) -> (u32, Vec<u32>) {
    let m = p.validate().unwrap();
    for (_, t) in m.types.iter() {
        if t.name.as_deref() == Some(name)
            && let naga::TypeInner::Struct { members, span } = &t.inner
        {
            return (*span, members.iter().map(|m| m.offset).collect());
        }
    }
    panic!("no struct {name}");
}

#[test]
fn gpu_structs_match_their_wgsl_mirrors() {
    use crate::accel::Bvh2GpuNode;
    use crate::gpu::prepare::{GpuLight, GpuMaterial};
    use crate::passes::reference::TraceParams;
    use std::mem::{offset_of, size_of};
    let programs = all_programs();
    let p = programs.iter().find(|p| p.label == "trace common/bvh2.wgsl 1").unwrap(); // every feature
    assert_eq!(
        wgsl_layout(p, "Material"),
        (
            size_of::<GpuMaterial>() as u32,
            vec![
                offset_of!(GpuMaterial, base_color),
                offset_of!(GpuMaterial, emission),
                offset_of!(GpuMaterial, metallic),
                offset_of!(GpuMaterial, specular_color),
                offset_of!(GpuMaterial, roughness),
                offset_of!(GpuMaterial, specular_factor),
                offset_of!(GpuMaterial, alpha_cutoff),
                offset_of!(GpuMaterial, normal_scale),
                offset_of!(GpuMaterial, flags),
                offset_of!(GpuMaterial, tex)
            ]
            .into_iter()
            .map(|o| o as u32)
            .collect()
        )
    );
    assert_eq!(
        wgsl_layout(p, "Light"),
        (
            size_of::<GpuLight>() as u32,
            vec![
                offset_of!(GpuLight, pos),
                offset_of!(GpuLight, kind),
                offset_of!(GpuLight, dir),
                offset_of!(GpuLight, cos_outer),
                offset_of!(GpuLight, intensity),
                offset_of!(GpuLight, cos_inner)
            ]
            .into_iter()
            .map(|o| o as u32)
            .collect()
        )
    );
    assert_eq!(
        wgsl_layout(p, "Bvh2Node"),
        (
            size_of::<Bvh2GpuNode>() as u32,
            vec![
                offset_of!(Bvh2GpuNode, lmin),
                offset_of!(Bvh2GpuNode, l_index),
                offset_of!(Bvh2GpuNode, lmax),
                offset_of!(Bvh2GpuNode, l_count),
                offset_of!(Bvh2GpuNode, rmin),
                offset_of!(Bvh2GpuNode, r_index),
                offset_of!(Bvh2GpuNode, rmax),
                offset_of!(Bvh2GpuNode, r_count)
            ]
            .into_iter()
            .map(|o| o as u32)
            .collect()
        )
    );
    // The walk reads a node's first three texels into WGSL's `LightNode` word by word, in the
    // order of its members (light_tree.wgsl `light_node`), and a leaf's area from texel 3.
    use crate::accel::light_tree::LightNode;
    assert_eq!(
        wgsl_layout(p, "LightNode"),
        (
            48,
            [
                offset_of!(LightNode, centre),
                offset_of!(LightNode, radius),
                offset_of!(LightNode, axis),
                offset_of!(LightNode, cos_o),
                offset_of!(LightNode, sin_o),
                offset_of!(LightNode, power),
                offset_of!(LightNode, child),
                offset_of!(LightNode, parent),
            ]
            .map(|o| o as u32)
            .to_vec()
        )
    );
    assert_eq!((offset_of!(LightNode, area), size_of::<LightNode>()), (48, 64));
    let (size, offs) = wgsl_layout(p, "Params");
    assert_eq!(size as usize, size_of::<TraceParams>());
    assert_eq!(offs[8] as usize, offset_of!(TraceParams, cam_pos));
    assert_eq!(offs[15] as usize, offset_of!(TraceParams, lens));
    let composite = programs.iter().find(|p| p.label == "realtime/composite.wgsl").unwrap();
    let (size, offs) = wgsl_layout(composite, "Frame");
    use crate::frame::FrameParams;
    assert_eq!(size as usize, size_of::<FrameParams>());
    assert_eq!(offs[7] as usize, offset_of!(FrameParams, jitter));
    assert_eq!(offs[11] as usize, offset_of!(FrameParams, accumulated));
    assert_eq!(offs[12] as usize, offset_of!(FrameParams, paths));
    assert_eq!(offs[18] as usize, offset_of!(FrameParams, uncovered_paths));
    assert_eq!(offs[20] as usize, offset_of!(FrameParams, prev_jitter_y));
    let converge = programs.iter().find(|p| p.label == "taa/converge.wgsl").unwrap();
    let (size, offs) = wgsl_layout(converge, "ConvergeParams");
    use crate::passes::converge::ConvergeParams;
    assert_eq!(size as usize, size_of::<ConvergeParams>());
    assert_eq!(offs[2] as usize, offset_of!(ConvergeParams, min_samples));
    let temporal = programs.iter().find(|p| p.label == "glossy/temporal.wgsl").unwrap();
    let (size, offs) = wgsl_layout(temporal, "GlossyParams");
    use crate::denoise::mara::glossy::GlossyParams;
    assert_eq!(size as usize, size_of::<GlossyParams>());
    assert_eq!(offs[4] as usize, offset_of!(GlossyParams, roughness_threshold));
    assert_eq!(offs[16] as usize, offset_of!(GlossyParams, max_sigma_px));
    let atrous = programs.iter().find(|p| p.label == "svgf/atrous.wgsl").unwrap();
    use crate::denoise::svgf::SvgfParams;
    let (size, offs) = wgsl_layout(atrous, "SvgfParams");
    assert_eq!(size as usize, size_of::<SvgfParams>());
    assert_eq!(offs[8] as usize, offset_of!(SvgfParams, settled_levels));
    assert_eq!(offs[12] as usize, offset_of!(SvgfParams, regression_order));
    assert_eq!(offs[13] as usize, offset_of!(SvgfParams, regression_full_samples));
    assert_eq!(wgsl_layout(atrous, "Level").0, 16);
    let resolve = programs.iter().find(|p| p.label == "cache/resolve.wgsl").unwrap();
    use crate::passes::cache::CacheParams;
    let (size, offs) = wgsl_layout(resolve, "CacheParams");
    assert_eq!(size as usize, size_of::<CacheParams>());
    assert_eq!(offs[5] as usize, offset_of!(CacheParams, update_tile));
    assert_eq!(offs[7] as usize, offset_of!(CacheParams, sample_clamp));
    // obvhs's CWBVH node is read as five vec4u.
    assert_eq!(size_of::<obvhs::cwbvh::node::CwBvhNode>(), 80);
}
