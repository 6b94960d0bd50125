//! The GPU context (headless or with a surface), tracked buffer allocation, readback, and the
//! scene's GPU form.

mod context;
mod memory;
pub mod prepare;
pub mod scene;

pub use context::{Gpu, GpuRequirements, NO_ADAPTER_HELP};
pub use memory::{GpuMemory, readback_buffer};
pub use prepare::{EnvKind, PreparedScene, SceneFeatures};
pub use scene::GpuScene;
