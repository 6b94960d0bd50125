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

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

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
                | "realtime/motion_vertices.wgsl"
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
mod tests;
