//! Presets: settings saved as TOML files. A preset may hold only some settings (the rest keep
//! their defaults); unknown names and out-of-range values are errors that name the setting.

use super::FrameSettings;
use anyhow::{Context, Result};
use std::path::Path;

impl FrameSettings {
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string_pretty(self).context("writing settings as TOML")
    }

    pub fn from_toml(text: &str) -> Result<FrameSettings> {
        let v: serde_json::Value = toml::from_str(text).context("reading TOML settings")?;
        FrameSettings::from_value(&v)
    }

    pub fn save_preset(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_toml()?)
            .with_context(|| format!("writing preset {}", path.display()))
    }

    /// The path length a preset file names, if it names one: a preset saved without
    /// `max_depth` keeps the scene's instead of the default's.
    pub fn preset_max_depth(path: &Path) -> Result<Option<i32>> {
        let text = crate::limits::read_text_file(path)
            .with_context(|| format!("reading preset {}", path.display()))?;
        let v: toml::Value = toml::from_str(&text)
            .with_context(|| format!("reading TOML settings of preset {}", path.display()))?;
        Ok(v.get("max_depth").and_then(|d| d.as_integer()).map(|d| d as i32))
    }

    pub fn load_preset(path: &Path) -> Result<FrameSettings> {
        let text = crate::limits::read_text_file(path)
            .with_context(|| format!("reading preset {}", path.display()))?;
        FrameSettings::from_toml(&text).with_context(|| format!("preset {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::{Denoiser, ReflectionMv};

    #[test]
    fn settings_round_trip_through_a_preset_file() {
        let mut s = FrameSettings {
            exposure_ev: -1.25,
            max_depth: 4,
            seed: 7,
            denoiser: Denoiser::MARA,
            paths_per_pixel: 2,
            view: crate::settings::View::named("glossy/sigma"),
            ..Default::default()
        };
        s.matte.hysteresis = 0.9;
        s.matte.firefly = false;
        s.matte.taps = 32;
        s.glossy.reflection_mv = ReflectionMv::Virtual;
        s.glossy.sigma_full_frames = 0.0;
        s.glossy.roughness_sigma = 0.123;
        let path = std::env::temp_dir().join(format!("hush-preset-{}.toml", std::process::id()));
        s.save_preset(&path).unwrap();
        let back = FrameSettings::load_preset(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(back, s);
    }

    #[test]
    fn a_partial_preset_keeps_the_other_defaults() {
        let s =
            FrameSettings::from_toml("denoiser = \"mara\"\n[matte]\nfirefly = false\n").unwrap();
        assert_eq!(
            s,
            FrameSettings {
                denoiser: Denoiser::MARA,
                matte: crate::settings::MatteSettings { firefly: false, ..Default::default() },
                ..Default::default()
            }
        );
        let e =
            format!("{:#}", FrameSettings::from_toml("[glossy]\nsigma_scael = 3.0\n").unwrap_err());
        assert!(e.contains("glossy.sigma_scael"), "{e}");
    }

    #[test]
    fn a_preset_names_its_path_length_only_when_it_sets_one() {
        let path =
            std::env::temp_dir().join(format!("hush-preset-depth-{}.toml", std::process::id()));
        std::fs::write(&path, "denoiser = \"mara\"\n").unwrap();
        let without = FrameSettings::preset_max_depth(&path).unwrap();
        std::fs::write(&path, "max_depth = 3\n").unwrap();
        let with = FrameSettings::preset_max_depth(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!((without, with), (None, Some(3)));
    }

    #[test]
    fn the_shipped_presets_load() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../presets");
        let mut n = 0;
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            let s = FrameSettings::load_preset(&p).unwrap_or_else(|e| panic!("{e:#}"));
            assert_ne!(s, FrameSettings::default(), "{} changes nothing", p.display());
            n += 1;
        }
        assert!(n >= 5);
        // Schied et al.'s SVGF is one configuration, in code and in the preset.
        let schied = FrameSettings::load_preset(&dir.join("schied.toml")).unwrap();
        assert_eq!(schied.svgf, crate::settings::SvgfSettings::schied());
        assert_eq!(schied.denoiser, Denoiser::SVGF);
    }
}
