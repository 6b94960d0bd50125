//! Hush: a real-time path-tracing renderer. This crate holds everything that renders; windows and
//! UI live in the `hush` viewer, command-line tools in `hush-cli`.
//!
//! Data flows one way: file -> [`scene`] (CPU) -> GPU scene ([`accel`], [`passes`]) -> image
//! ([`quality`] for metrics and files).

// No panic on the frame path or on user input: an error the caller can show instead. An
// `expect` that stays says in its message, or a comment beside it, why it cannot fire.
#![warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

pub mod accel;
pub mod denoise;
pub mod error;
pub mod frame;
pub mod fuzz;
pub mod governor;
pub mod gpu;
pub mod image_io;
pub mod limits;
pub mod passes;
pub mod profile;
pub mod quality;
pub mod scene;
pub mod settings;
pub mod shader;
pub(crate) mod sync;

pub use error::Error;
