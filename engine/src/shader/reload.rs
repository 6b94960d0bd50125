//! Pipelines that can be rebuilt from their shader text while Hush runs. A pipeline keeps the
//! program it came from (label, prelude, modules) and how to build it from a shader module; a
//! reload composes the text again, validates it with naga, then creates the module and the
//! pipeline inside a wgpu validation error scope, and swaps only when all of that succeeded.
//! On failure the last good pipeline keeps rendering and the error (file and line) is kept
//! until a later reload of the same pipeline succeeds.

use super::ProgramBindings;
use super::{Bindings, ShaderHost};
use anyhow::{Context, Result};
use std::time::Instant;

type Build<P> =
    Box<dyn Fn(&wgpu::Device, &wgpu::ShaderModule, &wgpu::PipelineLayout) -> P + Send + Sync>;

/// A pipeline with the resources its program declares and the bind group layouts made from them.
struct Built<P> {
    pipeline: P,
    bindings: ProgramBindings,
    layouts: Vec<wgpu::BindGroupLayout>,
}

/// A pipeline whose layout follows its program: each build reflects the program's resources
/// (a reload may use any resource the stage offers, in any order), and bind groups are made
/// from the current build's layouts ([`Reloadable::bind_groups`]).
pub struct Reloadable<P> {
    label: String,
    prelude: String,
    modules: Vec<&'static str>,
    visibility: wgpu::ShaderStages,
    /// The names the stage offers: a program that binds another fails to build.
    offered: Vec<String>,
    build: Build<P>,
    current: Built<P>,
    builds: u32,
    error: Option<String>,
}

/// What one pipeline's reload did.
#[derive(Clone, Debug)]
pub struct ReloadOutcome {
    pub label: String,
    /// Compose, validate, create module and pipeline, in milliseconds.
    pub ms: f64,
    pub error: Option<String>,
}

/// A pipeline the renderer can rebuild when one of its modules changes.
pub trait Reload {
    fn label(&self) -> &str;
    fn modules(&self) -> &[&'static str];
    /// How many times a pipeline was built (1 after creation; +1 per successful reload).
    fn builds(&self) -> u32;
    /// The error of the last failed reload, cleared by a successful one.
    fn error(&self) -> Option<&str>;
    fn reload(&mut self, gpu: &dyn ShaderHost) -> ReloadOutcome;
    /// The program as it would be built now (the text the driver gets).
    fn program(&self, gpu: &dyn ShaderHost) -> Result<super::Program>;
}

impl<P> Reloadable<P> {
    /// Compose and build the pipeline; `build` makes it from a shader module and the layout
    /// reflected from it (and is kept to make it again). `offered`: what the stage can bind
    /// (only the names count here), seen by `visibility`.
    pub fn new(
        gpu: &dyn ShaderHost,
        label: &str,
        prelude: &str,
        modules: &[&'static str],
        visibility: wgpu::ShaderStages,
        offered: &Bindings,
        build: impl Fn(&wgpu::Device, &wgpu::ShaderModule, &wgpu::PipelineLayout) -> P
        + Send
        + Sync
        + 'static,
    ) -> Result<Reloadable<P>> {
        let build: Build<P> = Box::new(build);
        let offered: Vec<String> = offered.names().map(str::to_string).collect();
        let current = make(gpu, label, prelude, modules, visibility, &offered, &build)?;
        Ok(Reloadable {
            label: label.to_string(),
            prelude: prelude.to_string(),
            modules: modules.to_vec(),
            visibility,
            offered,
            build,
            current,
            builds: 1,
            error: None,
        })
    }

    pub fn get(&self) -> &P {
        &self.current.pipeline
    }

    /// The resources the current build's program declares.
    pub fn program_bindings(&self) -> &ProgramBindings {
        &self.current.bindings
    }

    /// The current build's bind groups, each resource found in `resources` by name.
    pub fn bind_groups(
        &self,
        device: &wgpu::Device,
        resources: &Bindings,
    ) -> Result<Vec<wgpu::BindGroup>> {
        resources.create_groups(device, &self.label, &self.current.bindings, &self.current.layouts)
    }
}

fn make<P>(
    gpu: &dyn ShaderHost,
    label: &str,
    prelude: &str,
    modules: &[&'static str],
    visibility: wgpu::ShaderStages,
    offered: &[String],
    build: &Build<P>,
) -> Result<Built<P>> {
    let program = gpu.shaders().compose(label, prelude, modules)?;
    let (module, info) = program.validate_with_info()?;
    let bindings = super::reflect(label, &module, &info)?;
    bindings.check_offered(label, &offered.iter().map(String::as_str).collect::<Vec<_>>())?;
    // naga accepts some programs the pipeline still rejects (an entry point that is gone); the
    // error scope turns those into errors too.
    super::validated(gpu, &format!("creating pipeline {label}"), || {
        let layouts = bindings.layouts(gpu.device(), label, visibility);
        let refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
        let pl = gpu.device().create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &refs,
            immediate_size: 0,
        });
        let module = super::create_module(gpu.device(), label, &program.text);
        let pipeline = build(gpu.device(), &module, &pl);
        Ok(Built { pipeline, bindings, layouts })
    })
    .with_context(|| format!("pipeline {label} ({})", modules.join(", ")))
}

impl<P> Reload for Reloadable<P> {
    fn label(&self) -> &str {
        &self.label
    }

    fn modules(&self) -> &[&'static str] {
        &self.modules
    }

    fn builds(&self) -> u32 {
        self.builds
    }

    fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn program(&self, gpu: &dyn ShaderHost) -> Result<super::Program> {
        gpu.shaders().compose(&self.label, &self.prelude, &self.modules)
    }

    fn reload(&mut self, gpu: &dyn ShaderHost) -> ReloadOutcome {
        let start = Instant::now();
        let result = make(
            gpu,
            &self.label,
            &self.prelude,
            &self.modules,
            self.visibility,
            &self.offered,
            &self.build,
        );
        let ms = start.elapsed().as_secs_f64() * 1e3;
        self.error = match result {
            Ok(p) => {
                self.current = p;
                self.builds += 1;
                None
            }
            Err(e) => {
                let e = format!("{e:#}");
                log::error!("shader reload failed, keeping the last good pipeline: {e}");
                Some(e)
            }
        };
        ReloadOutcome { label: self.label.clone(), ms, error: self.error.clone() }
    }
}
