//! The GPU context (headless or with a surface), tracked buffer allocation, readback, and the
//! scene's GPU form.

mod context;
pub mod graph;
pub mod history;
mod memory;
mod pack;
pub mod posing;
pub mod prepare;
mod record;
pub mod scene;
mod texels;
mod timestamps;

pub use crate::shader::binding::{
    BindCache, BindKey, Bindings, Resource, set_compute_groups, set_render_groups,
};
pub use context::{Gpu, GpuRequirements, NO_ADAPTER_HELP, REALTIME_STORAGE_FORMATS};
pub use graph::{FrameGraph, GraphError, GraphPlan, TransientPool};
pub use history::{Parity, PingPong, Tex};
pub use memory::{GpuMemory, readback_buffer, readback_texture};
pub use pack::TEXTURE_BUDGET_BYTES;
pub use prepare::{EnvKind, Instancing, Motion, PreparedScene, SceneFeatures};
pub use record::Recorder;
pub use scene::{GpuScene, PATH_END_NONE};
pub use timestamps::GpuTimer;
