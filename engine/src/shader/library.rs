//! Where shader text comes from: the copies embedded in the binary, or a folder on disk that can
//! change while Hush runs (hot reload). Programs name their modules by path relative to
//! `shaders/`, so the set of modules is fixed by the code; a folder must hold every one of them.

use super::{Program, SOURCES, compose_with};
use anyhow::{Context, Result, anyhow};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};

/// Environment variable that points any build (release included) at a shader folder.
pub const SHADER_DIR_VAR: &str = "HUSH_SHADERS";

/// The source tree's shader folder, known at build time (used by debug builds of the viewer).
pub fn source_tree_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

pub struct ShaderLibrary {
    dir: Option<PathBuf>,
    /// Text read from `dir`, by module path; empty when the embedded copies are used.
    texts: RwLock<HashMap<&'static str, Arc<str>>>,
}

impl Default for ShaderLibrary {
    fn default() -> Self {
        ShaderLibrary::embedded()
    }
}

impl ShaderLibrary {
    /// The shaders compiled into the binary.
    pub fn embedded() -> ShaderLibrary {
        ShaderLibrary { dir: None, texts: RwLock::new(HashMap::new()) }
    }

    /// Every module read from `dir` (a copy of `shaders/`).
    pub fn from_dir(dir: &Path) -> Result<ShaderLibrary> {
        let dir = dir.canonicalize().with_context(|| format!("shader folder {}", dir.display()))?;
        let mut texts = HashMap::new();
        for (name, _) in SOURCES {
            let path = dir.join(name);
            let text = std::fs::read_to_string(&path).with_context(|| {
                format!(
                    "reading shader {} (the folder must hold every module of shaders/)",
                    path.display()
                )
            })?;
            texts.insert(*name, Arc::from(text));
        }
        Ok(ShaderLibrary { dir: Some(dir), texts: RwLock::new(texts) })
    }

    /// `$HUSH_SHADERS` when set, else `fallback` when given, else the embedded shaders.
    pub fn from_env_or(fallback: Option<&Path>) -> Result<ShaderLibrary> {
        match std::env::var_os(SHADER_DIR_VAR) {
            Some(d) => {
                ShaderLibrary::from_dir(Path::new(&d)).with_context(|| format!("${SHADER_DIR_VAR}"))
            }
            None => fallback.map_or(Ok(ShaderLibrary::embedded()), ShaderLibrary::from_dir),
        }
    }

    /// The folder shaders are read from; None for the embedded copies.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    /// A module that is not one of `shaders/` (a denoiser an application or a test brings),
    /// composed into programs by its path like any other; an error if the path is taken by
    /// `shaders/` or by another text.
    pub fn add(&self, module: &'static str, text: &str) -> Result<()> {
        let mut texts = crate::sync::write(&self.texts);
        if SOURCES.iter().any(|(n, _)| *n == module)
            || texts.get(module).is_some_and(|t| **t != *text)
        {
            return Err(anyhow!("shader module {module:?} already exists"));
        }
        texts.insert(module, Arc::from(text));
        Ok(())
    }

    pub fn source(&self, module: &str) -> Result<Arc<str>> {
        if let Some(t) = crate::sync::read(&self.texts).get(module) {
            return Ok(t.clone());
        }
        super::source(module).map(Arc::from)
    }

    pub fn compose(&self, label: &str, prelude: &str, modules: &[&'static str]) -> Result<Program> {
        compose_with(label, prelude, modules, |m| self.source(m))
    }

    /// The module a file under the folder is, if it is one.
    pub fn module_of(&self, file: &Path) -> Option<&'static str> {
        let dir = self.dir.as_ref()?;
        let file = file.canonicalize().unwrap_or_else(|_| file.to_path_buf());
        let rel = file.strip_prefix(dir).ok()?.to_string_lossy().replace('\\', "/");
        SOURCES.iter().map(|(n, _)| *n).find(|n| *n == rel)
    }

    /// Read `modules` again from the folder; returns those whose text changed. A file that
    /// cannot be read keeps its last text and is reported.
    pub fn refresh(&self, modules: &[&'static str]) -> (Vec<&'static str>, Vec<String>) {
        let Some(dir) = &self.dir else { return (vec![], vec![]) };
        let (mut changed, mut errors) = (vec![], vec![]);
        for m in modules {
            match std::fs::read_to_string(dir.join(m)) {
                Ok(text) => {
                    let mut texts = crate::sync::write(&self.texts);
                    if texts.get(m).is_none_or(|t| **t != *text) {
                        texts.insert(m, Arc::from(text));
                        changed.push(*m);
                    }
                }
                Err(e) => errors
                    .push(format!("{m}: {}", anyhow!(e).context("reading the changed shader"))),
            }
        }
        (changed, errors)
    }
}
