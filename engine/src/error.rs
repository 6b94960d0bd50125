//! The errors a caller of Hush branches on. Everything else is an [`anyhow::Error`] with
//! context (which file, which mesh, which pass); these sit in its chain, found with
//! [`Error::find`], so a caller can tell a file over a budget from a bug, or a lost device from a
//! bad shader edit, whatever context was added on the way up.

/// A Hush error a caller may act on.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene file needs more of a load budget ([`crate::limits::Limits`]) than it allows:
    /// refused before the work, with the flag that would allow it.
    #[error(
        "{what} needs {need} against the {budget} budget of {limit}; if the file is trusted, \
         raise it with --limit {budget}={need}"
    )]
    OverBudget { budget: &'static str, what: String, need: u64, limit: u64 },
    /// A panic caught at the import boundary: a bug in Hush or a library it uses, which the fuzz
    /// targets and the corpus replay treat as the failure it is.
    #[error(
        "internal error while importing (a bug in Hush or a library it uses; please report it \
         with the file): {0}"
    )]
    ImportPanic(String),
    /// A file requires glTF extensions Hush does not implement.
    #[error(
        "the file requires glTF extensions Hush does not support: {} (supported: {})",
        .unsupported.join(", "),
        .supported.join(", ")
    )]
    UnsupportedExtension { unsupported: Vec<String>, supported: Vec<String> },
    /// WGSL that does not parse or validate, located in its source file (`line` 0: naga gave
    /// no line).
    #[error("{program}: WGSL {step} error at {}: {message}", at(.file, *.line))]
    Shader { program: String, step: ShaderStep, file: String, line: usize, message: String },
    /// The GPU device is gone (driver reset, removed adapter, destroyed): make a new
    /// [`crate::gpu::Gpu`] and renderer.
    #[error("the GPU device was lost ({reason}): {message}")]
    DeviceLost { reason: String, message: String },
}

/// Where WGSL failed: naga's parser or its validator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderStep {
    Parse,
    Validation,
}

impl std::fmt::Display for ShaderStep {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(match self {
            ShaderStep::Parse => "parse",
            ShaderStep::Validation => "validation",
        })
    }
}

/// "file:line", as editors and terminals link it.
fn at(file: &str, line: usize) -> String {
    match line {
        0 => "an unknown line".to_string(),
        l => format!("{file}:{l}"),
    }
}

impl Error {
    /// The Hush error in `e`'s chain, if there is one.
    pub fn find(e: &anyhow::Error) -> Option<&Error> {
        e.chain().find_map(|c| c.downcast_ref::<Error>())
    }
}

/// The message of a caught panic (`std::panic::catch_unwind`'s payload), or "panic" where it
/// carries none.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context;

    #[test]
    fn found_under_context() {
        let e: anyhow::Error = Error::ImportPanic("x".into()).into();
        let e = Err::<(), _>(e).context("loading a.gltf").context("opening").unwrap_err();
        assert!(matches!(Error::find(&e), Some(Error::ImportPanic(m)) if m == "x"));
        assert!(Error::find(&anyhow::anyhow!("plain")).is_none());
    }
}
