//! Passes: each owns its pipelines and outputs and records itself.

pub mod raycast;
pub mod reference;

pub use raycast::{RayHit, Raycaster};
pub use reference::{Accumulation, ReferenceTracer, TraceView};

pub mod cache;
pub mod chain;
pub mod composite;
pub mod converge;
pub mod gbuffer;
pub mod io;
pub mod prefilter;
pub mod primaries;
pub mod rescale;
pub mod scene;
pub mod schedule;
pub mod supersample;
pub mod taa;
pub mod trace;
pub mod upscale;
