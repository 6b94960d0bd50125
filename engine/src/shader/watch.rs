//! Watch a shader folder and report which modules changed. Editors save in bursts (write,
//! rename, touch), so events are debounced: one report per file per quiet interval.

use super::ShaderLibrary;
use anyhow::{Context, Result};
use notify_debouncer_mini::notify::{RecommendedWatcher, RecursiveMode};
use notify_debouncer_mini::{DebounceEventResult, Debouncer, new_debouncer};
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

/// Quiet time after the last event on a file before it is reported.
pub const DEBOUNCE: Duration = Duration::from_millis(150);

pub struct ShaderWatcher {
    _debouncer: Debouncer<RecommendedWatcher>,
    events: Receiver<DebounceEventResult>,
}

impl ShaderWatcher {
    /// Watch the library's folder (an error for embedded shaders: there is nothing to watch).
    pub fn new(library: &ShaderLibrary) -> Result<ShaderWatcher> {
        let dir = library.dir().context("the shaders are embedded in the binary; point Hush at a folder (--shaders DIR or $HUSH_SHADERS) to reload them")?;
        let (tx, events) = channel();
        let mut debouncer =
            new_debouncer(DEBOUNCE, tx).context("starting the shader file watcher")?;
        debouncer
            .watcher()
            .watch(dir, RecursiveMode::Recursive)
            .with_context(|| format!("watching {}", dir.display()))?;
        Ok(ShaderWatcher { _debouncer: debouncer, events })
    }

    /// Modules changed since the last call (never blocks); watcher errors are logged.
    pub fn changed(&self, library: &ShaderLibrary) -> Vec<&'static str> {
        let mut out = vec![];
        while let Ok(batch) = self.events.try_recv() {
            match batch {
                Ok(events) => {
                    for e in events {
                        if let Some(m) = library.module_of(&e.path)
                            && !out.contains(&m)
                        {
                            out.push(m);
                        }
                    }
                }
                Err(e) => log::warn!("shader watcher: {e}"),
            }
        }
        out
    }
}
