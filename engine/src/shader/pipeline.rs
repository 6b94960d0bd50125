//! Pipeline creation: what building a pipeline from composed WGSL needs of the device, and the
//! validation scope every build runs in.

use super::ShaderLibrary;
use anyhow::Result;

/// What building a pipeline needs: a device and the shader text. [`crate::gpu::Gpu`] is one;
/// `shader` asks for this rather than the whole GPU context, so that the GPU context may hold a
/// [`ShaderLibrary`] without the two modules depending on each other.
pub trait ShaderHost {
    fn device(&self) -> &wgpu::Device;
    fn shaders(&self) -> &ShaderLibrary;
    /// An error when the device can no longer run anything ([`crate::Error::DeviceLost`]).
    fn check_lost(&self) -> Result<()>;
}

/// Run `f` inside a validation error scope of `host`'s device: what wgpu would only log becomes
/// an error with `what` as its context.
pub fn validated<T>(host: &dyn ShaderHost, what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    use anyhow::Context;
    host.check_lost().with_context(|| what.to_string())?;
    let scope = host.device().push_error_scope(wgpu::ErrorFilter::Validation);
    let r = f();
    let e = pollster::block_on(scope.pop());
    host.check_lost().with_context(|| what.to_string())?;
    let v = r?;
    match e {
        // The error's sources say which binding, entry point or limit was wrong.
        Some(e) => Err(anyhow::Error::new(e).context(what.to_string())),
        None => Ok(v),
    }
}

/// A compute pipeline with entry point `entry`.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}
