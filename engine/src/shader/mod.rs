//! WGSL sources and how programs are put together.
//!
//! A program is a list of modules from `shaders/` concatenated after a generated prelude of
//! feature constants (WGSL declarations may appear in any order, so no include directives are
//! needed). Features a scene does not use select a `*_none.wgsl` module instead, so their
//! bindings and code do not exist in the program at all. Sources are embedded in the binary;
//! every program is validated with naga before it reaches the driver, so errors name the WGSL
//! line rather than a backend's translation of it.

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
    "reference/params.wgsl",
    "reference/trace.wgsl",
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

/// Concatenate `prelude` and `modules`, each preceded by a marker naming the file.
pub fn compose(label: &str, prelude: &str, modules: &[&'static str]) -> Result<Program> {
    let mut text = String::from(prelude);
    for m in modules {
        text.push_str(&format!("\n// ---- {m}\n"));
        text.push_str(source(m)?);
    }
    Ok(Program { label: label.to_string(), modules: modules.to_vec(), text })
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

    /// Parse and validate with naga; errors name the source file and line.
    pub fn validate(&self) -> Result<naga::Module> {
        let module = naga::front::wgsl::parse_str(&self.text).map_err(|e| {
            let at = e.location(&self.text).map(|l| self.locate(l.line_number as usize));
            anyhow!("{}: WGSL parse error at {:?}: {}", self.label, at, e.message())
        })?;
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .map_err(|e| {
                let at = e.spans().next().map(|(s, _)| self.locate(s.location(&self.text).line_number as usize));
                anyhow!("{}: WGSL validation error at {:?}: {}", self.label, at, e.as_inner())
            })?;
        Ok(module)
    }

    /// Validate, then create the wgpu module.
    pub fn create(&self, device: &wgpu::Device) -> Result<wgpu::ShaderModule> {
        self.validate()?;
        Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&self.label),
            source: wgpu::ShaderSource::Wgsl(self.text.as_str().into()),
        }))
    }
}
