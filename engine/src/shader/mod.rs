//! WGSL sources and how programs are put together.
//!
//! A program is a list of modules from `shaders/` concatenated after a generated prelude of
//! feature constants (WGSL declarations may appear in any order, so no include directives are
//! needed). Features a scene does not use select a `*_none.wgsl` module instead, so their
//! bindings and code do not exist in the program at all. Sources are embedded in the binary;
//! every program is validated with naga before it reaches the driver, so errors name the WGSL
//! line rather than a backend's translation of it.
//!
//! Why not WESL or naga_oil: measured on Hush's 17 real-time programs (lavapipe machine), the
//! current WESL releases (0.4.3 to 0.6) need rustc 1.97.1, newer than Hush's 1.95; the last one
//! that builds (0.4.0) parses every program. naga_oil 0.23 composes each of them, at 9-31 ms per
//! program against naga's own 1-6 ms, before the driver's compile (the trace: 296 ms on
//! lavapipe). Both would need every cross-file use named in an import across the 54 files, and
//! naga_oil mangles names, which the Rust/WGSL struct-layout checks below look up. Composition
//! here costs 0.07 ms for the trace, and knows each program's modules exactly, which is all hot
//! reload needs.
//!
//! Every program records the modules it was composed from, which is what hot reload uses to
//! rebuild exactly the pipelines a changed file feeds (`reload.rs`); `library.rs` says where the
//! text comes from (embedded, or a folder on disk that `watch.rs` watches).

pub mod binding;
mod library;
mod pipeline;
mod reflect;
mod reload;
mod watch;

pub use binding::{BindCache, BindKey, Bindings, Resource, set_compute_groups, set_render_groups};
pub use library::{SHADER_DIR_VAR, ShaderLibrary, source_tree_dir};
pub use pipeline::{ShaderHost, compute_pipeline, validated};
pub use reflect::{FixedCompute, ProgramBindings, Slot, reflect};
pub use reload::{Reload, ReloadOutcome, Reloadable};
pub use watch::ShaderWatcher;

use crate::error::ShaderStep;
use anyhow::{Result, anyhow};

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        /// Every WGSL file under `shaders/`, by path relative to that folder.
        pub const SOURCES: &[(&str, &str)] = &[
            $(($path, include_str!(concat!("../../../shaders/", $path)))),*
        ];
    };
}

embed!(
    "common/math.wgsl",
    "common/rng.wgsl",
    "common/geometry.wgsl",
    "common/motion_none.wgsl",
    "common/motion_blur.wgsl",
    "common/bvh2.wgsl",
    "common/cwbvh.wgsl",
    "common/alpha_none.wgsl",
    "common/alpha_mask.wgsl",
    "common/scene.wgsl",
    "common/textures.wgsl",
    "common/textures_none.wgsl",
    "common/tangents.wgsl",
    "common/tangents_none.wgsl",
    "common/bsdf.wgsl",
    "common/lights.wgsl",
    "common/lights_none.wgsl",
    "common/emitters.wgsl",
    "common/emitters_none.wgsl",
    "common/env_none.wgsl",
    "common/env_constant.wgsl",
    "common/env_map.wgsl",
    "common/params.wgsl",
    "common/camera.wgsl",
    "common/path.wgsl",
    "reference/trace.wgsl",
    "realtime/frame.wgsl",
    "realtime/motion_static.wgsl",
    "realtime/motion_objects.wgsl",
    "realtime/gbuffer.wgsl",
    "realtime/trace.wgsl",
    "realtime/trace_glossy.wgsl",
    "realtime/trace_glossy_none.wgsl",
    "realtime/gbuffer_in.wgsl",
    "realtime/glossy_in.wgsl",
    "realtime/glossy_in_none.wgsl",
    "realtime/composite.wgsl",
    "realtime/display.wgsl",
    "realtime/lens.wgsl",
    "realtime/primaries.wgsl",
    "realtime/primaries_resolve.wgsl",
    "prefilter/common.wgsl",
    "prefilter/covariance.wgsl",
    "prefilter/stats.wgsl",
    "prefilter/sure.wgsl",
    "prefilter/features.wgsl",
    "matte/common.wgsl",
    "matte/sparse_bilateral.wgsl",
    "matte/temporal.wgsl",
    "matte/history_bilateral.wgsl",
    "matte/disocclusion.wgsl",
    "matte/firefly.wgsl",
    "matte/bilateral.wgsl",
    "taa/taa.wgsl",
    "taa/matte.wgsl",
    "taa/matte_none.wgsl",
    "taa/glossy.wgsl",
    "taa/glossy_none.wgsl",
    "glossy/common.wgsl",
    "glossy/diamond.wgsl",
    "glossy/motion.wgsl",
    "glossy/prefilter.wgsl",
    "glossy/temporal.wgsl",
    "glossy/bilateral.wgsl",
    "svgf/common.wgsl",
    "svgf/features_matte.wgsl",
    "progressive/common.wgsl",
    "progressive/signal_matte.wgsl",
    "progressive/signal_glossy.wgsl",
    "progressive/signal_direct.wgsl",
    "progressive/features.wgsl",
    "progressive/temporal.wgsl",
    "progressive/variance.wgsl",
    "progressive/atrous.wgsl",
    "svgf/features_glossy.wgsl",
    "svgf/temporal.wgsl",
    "svgf/temporal_glossy.wgsl",
    "svgf/variance.wgsl",
    "svgf/atrous.wgsl",
    "svgf/final.wgsl",
    "supersample/common.wgsl",
    "supersample/samples.wgsl",
    "supersample/assign.wgsl",
    "supersample/mix.wgsl",
    "supersample/mix_glossy.wgsl",
    "supersample/mix_glossy_none.wgsl",
    "supersample/resolve.wgsl",
    "accel/raycast.wgsl",
);

pub fn source(path: &str) -> Result<&'static str> {
    SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .ok_or_else(|| anyhow!("no shader module {path:?}"))
}

/// A composed program: its label, the modules it is made of and the full text.
pub struct Program {
    pub label: String,
    pub modules: Vec<&'static str>,
    pub text: String,
}

/// Concatenate `prelude` and the embedded `modules`, each preceded by a marker naming the file.
pub fn compose(label: &str, prelude: &str, modules: &[&'static str]) -> Result<Program> {
    compose_with(label, prelude, modules, |m| source(m).map(std::sync::Arc::from))
}

/// `compose` with the text of each module given by `source`.
///
/// Resources are declared without attributes (`var<uniform> frame: Frame;`, `var history:
/// texture_2d<f32>;`, at the start of a line); composing numbers them, in the order they appear,
/// in group [`SHARED_GROUP`] when their module is one of [`shared_module`]'s and in
/// [`STAGE_GROUP`] otherwise. Rust binds them by name ([`reflect`]), so no number is kept by
/// hand, and the attributes go on the declaration's own line, so that errors keep their lines.
pub fn compose_with(
    label: &str,
    prelude: &str,
    modules: &[&'static str],
    source: impl Fn(&str) -> Result<std::sync::Arc<str>>,
) -> Result<Program> {
    let mut text = String::from(prelude);
    let mut next = [0u32; 2];
    for m in modules {
        text.push_str(&format!("\n// ---- {m}\n"));
        let group = if shared_module(m) { SHARED_GROUP } else { STAGE_GROUP };
        for line in source(m)?.split_inclusive('\n') {
            if is_resource_declaration(line) {
                text.push_str(&format!("@group({group}) @binding({}) ", next[group as usize]));
                next[group as usize] += 1;
            }
            text.push_str(line);
        }
    }
    Ok(Program { label: label.to_string(), modules: modules.to_vec(), text })
}

/// The bind group of the scene's buffers and the frame's shared inputs (its uniform, the
/// G-buffer, the trace's glossy outputs, object motion): the same resources in every stage.
pub const SHARED_GROUP: u32 = 0;
/// The bind group of what one stage owns: its parameters, histories and outputs.
pub const STAGE_GROUP: u32 = 1;

/// Modules whose resources are the scene's or the frame's, shared by every stage.
pub fn shared_module(path: &str) -> bool {
    path.starts_with("common/")
        || matches!(
            path,
            "realtime/frame.wgsl"
                | "realtime/gbuffer_in.wgsl"
                | "realtime/glossy_in.wgsl"
                | "realtime/motion_objects.wgsl"
        )
}

/// A module-scope `var` in the uniform, storage or handle address space (the only ones a
/// binding can name): `var<private>` and `var<workgroup>` are not resources.
fn is_resource_declaration(line: &str) -> bool {
    let Some(rest) = line.strip_prefix("var") else { return false };
    match rest.strip_prefix('<') {
        Some(space) => !(space.starts_with("private") || space.starts_with("workgroup")),
        None => rest.starts_with(' '),
    }
}

impl Program {
    /// Map a line of the composed text back to (file, line).
    pub fn locate(&self, line: usize) -> (String, usize) {
        let mut file = "<prelude>".to_string();
        let mut start = 0;
        for (i, l) in self.text.lines().enumerate() {
            if i + 1 > line {
                break;
            }
            if let Some(f) = l.strip_prefix("// ---- ") {
                file = f.to_string();
                start = i + 1;
            }
        }
        (file, line.saturating_sub(start))
    }

    /// The error for `message` at a line of the composed text, located in its source file
    /// ("file:line", as editors and terminals link it; line 0 where naga gave no line).
    fn error(&self, step: ShaderStep, line: Option<usize>, message: String) -> anyhow::Error {
        let (file, line) = line.map_or(("<unknown>".to_string(), 0), |l| self.locate(l));
        crate::Error::Shader { program: self.label.clone(), step, file, line, message }.into()
    }

    /// Parse and validate with naga; errors name the source file and line.
    pub fn validate(&self) -> Result<naga::Module> {
        Ok(self.validate_with_info()?.0)
    }

    /// Validate; also naga's analysis of the module (what each entry point uses).
    pub fn validate_with_info(&self) -> Result<(naga::Module, naga::valid::ModuleInfo)> {
        let module = naga::front::wgsl::parse_str(&self.text).map_err(|e| {
            let line =
                e.location(&self.text).filter(|l| l.length > 0).map(|l| l.line_number as usize);
            self.error(ShaderStep::Parse, line, e.message().to_string())
        })?;
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .map_err(|e| {
            let line = e.spans().next().map(|(s, _)| s.location(&self.text).line_number as usize);
            // naga nests the cause (an entry point is invalid because a function is, because
            // one expression is): name every level.
            let mut why = e.as_inner().to_string();
            let mut source = std::error::Error::source(e.as_inner());
            while let Some(s) = source {
                why += &format!(": {s}");
                source = s.source();
            }
            self.error(ShaderStep::Validation, line, why)
        })?;
        Ok((module, info))
    }

    /// Validate, then create the wgpu module.
    pub fn create(&self, device: &wgpu::Device) -> Result<wgpu::ShaderModule> {
        self.validate()?;
        Ok(create_module(device, &self.label, &self.text))
    }
}

/// The wgpu module of composed program text (every pipeline's module is made here).
pub fn create_module(device: &wgpu::Device, label: &str, text: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(text.into()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const FEATURE_SETS: &[[&str; 6]] = &[
        [
            "common/alpha_none.wgsl",
            "common/textures_none.wgsl",
            "common/tangents_none.wgsl",
            "common/lights_none.wgsl",
            "common/emitters_none.wgsl",
            "common/env_none.wgsl",
        ],
        [
            "common/alpha_mask.wgsl",
            "common/textures.wgsl",
            "common/tangents.wgsl",
            "common/lights.wgsl",
            "common/emitters.wgsl",
            "common/env_map.wgsl",
        ],
        [
            "common/alpha_none.wgsl",
            "common/textures.wgsl",
            "common/tangents_none.wgsl",
            "common/lights.wgsl",
            "common/emitters_none.wgsl",
            "common/env_constant.wgsl",
        ],
        [
            "common/alpha_mask.wgsl",
            "common/textures.wgsl",
            "common/tangents.wgsl",
            "common/lights_none.wgsl",
            "common/emitters.wgsl",
            "common/env_none.wgsl",
        ],
    ];

    /// Every program Hush can compose, over both BVH layouts and the feature alternatives.
    fn all_programs() -> Vec<Program> {
        let mut v = vec![];
        for set in FEATURE_SETS {
            for motion in ["realtime/motion_static.wgsl", "realtime/motion_objects.wgsl"] {
                let m = [
                    "common/math.wgsl",
                    "common/geometry.wgsl",
                    "common/motion_none.wgsl",
                    "common/scene.wgsl",
                    "common/bsdf.wgsl",
                    set[1],
                    set[2],
                    set[0],
                    "realtime/frame.wgsl",
                    motion,
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
        for motion in ["realtime/motion_static.wgsl", "realtime/motion_objects.wgsl"] {
            for stage in [
                &["matte/temporal.wgsl"][..],
                &["matte/sparse_bilateral.wgsl", "matte/history_bilateral.wgsl"],
                &["matte/disocclusion.wgsl"],
                &["matte/firefly.wgsl"],
                &["matte/sparse_bilateral.wgsl", "matte/bilateral.wgsl"],
                &[
                    "realtime/glossy_in.wgsl",
                    "glossy/common.wgsl",
                    "taa/glossy.wgsl",
                    "taa/matte.wgsl",
                    "taa/taa.wgsl",
                ],
                &["taa/glossy_none.wgsl", "taa/matte_none.wgsl", "taa/taa.wgsl"],
            ] {
                let mut m = vec![
                    "common/math.wgsl",
                    "realtime/frame.wgsl",
                    "realtime/gbuffer_in.wgsl",
                    "matte/common.wgsl",
                    motion,
                ];
                m.extend_from_slice(stage);
                v.push(compose(stage[stage.len() - 1], "", &m).unwrap());
            }
        }
        for animated in [false, true] {
            for stage in [
                "glossy/motion.wgsl",
                "glossy/prefilter.wgsl",
                "glossy/temporal.wgsl",
                "glossy/bilateral.wgsl",
            ] {
                v.push(
                    compose(stage, "", &crate::passes::glossy::modules(stage, animated)).unwrap(),
                );
            }
        }
        for animated in [false, true] {
            for glossy in [false, true] {
                let temporal =
                    if glossy { "svgf/temporal_glossy.wgsl" } else { "svgf/temporal.wgsl" };
                for stage in [temporal, "svgf/variance.wgsl", "svgf/atrous.wgsl", "svgf/final.wgsl"]
                {
                    v.push(
                        compose(stage, "", &crate::denoise::svgf::modules(stage, glossy, animated))
                            .unwrap(),
                    );
                }
            }
        }
        for animated in [false, true] {
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
                        v.push(
                            compose(stage, "", &modules(stage, signal, glossy, animated)).unwrap(),
                        );
                    }
                }
            }
        }
        for glossy in [false, true] {
            for stage in
                ["supersample/assign.wgsl", "supersample/mix.wgsl", "supersample/resolve.wgsl"]
            {
                v.push(
                    compose(stage, "", &crate::passes::supersample::modules(stage, glossy))
                        .unwrap(),
                );
            }
        }
        v.push(
            compose(
                "gbuffer/resolve",
                "",
                &["common/math.wgsl", "realtime/frame.wgsl", "realtime/primaries_resolve.wgsl"],
            )
            .unwrap(),
        );
        for stage in ["prefilter/covariance.wgsl", "prefilter/sure.wgsl", "prefilter/features.wgsl"]
        {
            v.push(compose(stage, "", &crate::passes::prefilter::modules(stage)).unwrap());
        }
        for bvh in ["common/bvh2.wgsl", "common/cwbvh.wgsl"] {
            // A scene sets the traversal's stack length (accel::traversal_stack).
            let stack = "const TRAVERSAL_STACK: u32 = 16u;\n";
            v.push(
                compose(
                    "raycast",
                    stack,
                    &[
                        "common/math.wgsl",
                        "common/geometry.wgsl",
                        "common/motion_none.wgsl",
                        bvh,
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
                    bvh,
                    "common/scene.wgsl",
                    "common/bsdf.wgsl",
                    "common/params.wgsl",
                    "common/camera.wgsl",
                    "common/path.wgsl",
                ];
                m.extend(set.iter());
                let prelude = format!(
                    "const HAS_EMITTERS: bool = {};\nconst HAS_ENV: bool = {};\n{stack}",
                    i % 2 == 1,
                    i != 0
                );
                let mut reference = m.clone();
                reference.push("reference/trace.wgsl");
                v.push(compose(&format!("trace {bvh} {i}"), &prelude, &reference).unwrap());
                let glossy = if i % 2 == 0 {
                    "realtime/trace_glossy.wgsl"
                } else {
                    "realtime/trace_glossy_none.wgsl"
                };
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
                m.extend([
                    "realtime/frame.wgsl",
                    "realtime/lens.wgsl",
                    glossy,
                    "realtime/trace.wgsl",
                ]);
                v.push(compose(&format!("realtime trace {bvh} {i}"), &prelude, &m).unwrap());
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
        let (size, offs) = wgsl_layout(p, "Params");
        assert_eq!(size as usize, size_of::<TraceParams>());
        assert_eq!(offs[8] as usize, offset_of!(TraceParams, cam_pos));
        assert_eq!(offs[15] as usize, offset_of!(TraceParams, emit));
        let composite = programs.iter().find(|p| p.label == "realtime/composite.wgsl").unwrap();
        let (size, offs) = wgsl_layout(composite, "Frame");
        use crate::frame::FrameParams;
        assert_eq!(size as usize, size_of::<FrameParams>());
        assert_eq!(offs[7] as usize, offset_of!(FrameParams, jitter));
        assert_eq!(offs[11] as usize, offset_of!(FrameParams, accumulated));
        assert_eq!(offs[12] as usize, offset_of!(FrameParams, paths));
        let taa = programs.iter().find(|p| p.label == "taa/taa.wgsl").unwrap();
        let (size, offs) = wgsl_layout(taa, "DenoiseParams");
        use crate::passes::matte::DenoiseParams;
        assert_eq!(size as usize, size_of::<DenoiseParams>());
        assert_eq!(offs[2] as usize, offset_of!(DenoiseParams, stages));
        assert_eq!(offs[17] as usize, offset_of!(DenoiseParams, history_valid));
        let temporal = programs.iter().find(|p| p.label == "glossy/temporal.wgsl").unwrap();
        let (size, offs) = wgsl_layout(temporal, "GlossyParams");
        use crate::passes::glossy::GlossyParams;
        assert_eq!(size as usize, size_of::<GlossyParams>());
        assert_eq!(offs[5] as usize, offset_of!(GlossyParams, roughness_threshold));
        assert_eq!(offs[17] as usize, offset_of!(GlossyParams, max_sigma_px));
        let atrous = programs.iter().find(|p| p.label == "svgf/atrous.wgsl").unwrap();
        use crate::denoise::svgf::SvgfParams;
        let (size, offs) = wgsl_layout(atrous, "SvgfParams");
        assert_eq!(size as usize, size_of::<SvgfParams>());
        assert_eq!(offs[8] as usize, offset_of!(SvgfParams, settled_levels));
        assert_eq!(wgsl_layout(atrous, "Level").0, 16);
        // obvhs's CWBVH node is read as five vec4u.
        assert_eq!(size_of::<obvhs::cwbvh::node::CwBvhNode>(), 80);
    }
}
