//! One description of every tunable in [`FrameSettings`]: the pass it belongs to, its unit, its
//! range and a line of help. The viewer draws its settings panels from this table and the
//! settings' serde form (no widget is written per field), presets are checked against it, and a
//! test keeps it and the structs in step.

use super::{FrameSettings, ReflectionMv};
use super::View;
use anyhow::{Result, anyhow};
use serde_json::Value;

/// What kind of value a field holds, with its range.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Bool,
    /// Integer in [min, max].
    Int(i64, i64),
    /// Real in [min, max], dragged by `speed` per pixel.
    Float(f64, f64, f64),
    /// One of the names `choices()` lists (the serde names of an enum).
    Choice(fn() -> Vec<String>),
}

#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// Dotted path in the serde form, e.g. `matte.hysteresis`.
    pub path: &'static str,
    /// The pass (or part of the frame) it tunes, as the passes are named in timings.
    pub group: &'static str,
    pub unit: &'static str,
    pub kind: Kind,
    pub help: &'static str,
}

fn names<T: serde::Serialize>(all: &[T]) -> Vec<String> {
    all.iter().map(|v| serde_json::to_value(v).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default()).collect()
}

fn views() -> Vec<String> {
    std::iter::once(View::FINAL.name().to_string()).chain(super::all_views().into_iter().map(|v| v.name.to_string())).collect()
}
fn denoisers() -> Vec<String> {
    super::denoiser_names().into_iter().map(str::to_string).collect()
}
fn reflection_mvs() -> Vec<String> {
    names(&ReflectionMv::ALL)
}

const fn f(path: &'static str, group: &'static str, unit: &'static str, kind: Kind, help: &'static str) -> Field {
    Field { path, group, unit, kind, help }
}

use Kind::{Bool, Choice, Float, Int};

/// Every field of [`FrameSettings`] that is saved in presets, in panel order.
pub const FIELDS: &[Field] = &[
    f("view", "display", "", Choice(views), "What the display shows: the image or one buffer of the frame."),
    f("exposure_ev", "display", "EV", Float(-30.0, 30.0, 0.05), "The image is multiplied by 2^EV before tone mapping."),
    f("accumulate", "frame", "", Bool, "Sum frames while nothing changes and show their mean (the converged image)."),
    f("seed", "frame", "", Int(0, u32::MAX as i64), "Seed of every random sequence."),
    f("denoiser", "frame", "", Choice(denoisers), "none: the raw 1-sample frame. mara: the matte and glossy chains and TAA. Others: denoisers the application registered."),
    f("max_depth", "trace", "bounces", Int(-1, 64), "Path length as Mitsuba counts it (2 = direct light only, -1 = unbounded)."),
    f("paths_per_pixel", "trace", "paths", Int(1, 64), "Indirect paths per pixel per frame (1 is the paper's real-time setting)."),
    f("matte.temporal", "matte/temporal", "", Bool, "Stage 3: reverse reprojection with confidence (Mara eq. 11)."),
    f("matte.hysteresis", "matte/temporal", "", Float(0.0, 1.0, 0.001), "h of eq. 11: the history's weight at full confidence (paper 0.98)."),
    f("matte.d0_px", "matte/temporal", "footprints", Float(0.0, 64.0, 0.05), "Eq. 11's d0: full confidence below this reprojection distance."),
    f("matte.d1_px", "matte/temporal", "footprints", Float(0.0, 64.0, 0.05), "Eq. 11's d1: zero confidence beyond this reprojection distance."),
    f("matte.clamp_sigma", "matte/temporal", "sigma", Float(0.0, 16.0, 0.05), "Clamp history to the neighbourhood's mean +- this many deviations (0: off)."),
    f("matte.reprojection_normal_degrees", "matte/temporal", "degrees", Float(0.0, 180.0, 0.5), "Reprojection rejects a previous texel whose normal differs by more (180: off)."),
    f("matte.history_bilateral", "matte/history_bilateral", "", Bool, "Stage 4: sparse bilateral on what is written back to history."),
    f("matte.taps", "matte/history_bilateral", "taps", Int(1, 256), "Taps of both sparse bilaterals (paper 50)."),
    f("matte.history_diameter_fraction", "matte/history_bilateral", "of width", Float(0.0, 0.2, 0.0005), "Disk diameter of the history bilateral (paper 1%)."),
    f("matte.history_full_frames", "matte/history_bilateral", "frames", Float(0.0, 1024.0, 0.1), "Past this history length the disk shrinks as 1/sqrt(length) (0: fixed)."),
    f("matte.resampled_history_frames", "matte/temporal", "frames", Float(0.0, 1024.0, 1.0), "A bilinearly resampled history counts as at most this many frames (0: no cap)."),
    f("matte.normal_power", "matte/history_bilateral", "exponent", Float(0.0, 512.0, 0.5), "Bilateral normal weight: cos^power (both sparse bilaterals)."),
    f("matte.plane_sigma_px", "matte/history_bilateral", "footprints", Float(0.0, 64.0, 0.05), "Bilateral plane-distance sigma (both sparse bilaterals)."),
    f("matte.disocclusion", "matte/disocclusion", "", Bool, "Stage 5: the disocclusion-driven radius r = (1 - min c) R."),
    f("matte.disocclusion_fraction", "matte/disocclusion", "of width", Float(0.0, 0.5, 0.001), "R as a fraction of the width (paper 1/20)."),
    f("matte.low_confidence_multiplier", "matte/disocclusion", "x", Float(1.0, 32.0, 0.05), "Radius multiplier where c < 1/2 (paper 6)."),
    f("matte.firefly", "matte/firefly", "", Bool, "Stage 6: 3x3 median outside the history loop."),
    f("matte.bilateral", "matte/bilateral", "", Bool, "Stage 7: final sparse bilateral with radius r."),
    f("matte.max_radius_fraction", "matte/bilateral", "of width", Float(0.0, 0.5, 0.001), "Largest final-bilateral radius."),
    f("matte.min_radius_fraction", "matte/bilateral", "of width", Float(0.0, 0.5, 0.001), "Smallest final-bilateral radius (0: the paper's (1 - c) R alone)."),
    f("matte.edge_stop_sigmas", "matte/bilateral", "sigma", Float(0.0, 256.0, 0.5), "Final bilateral's luminance edge-stop, in standard deviations of the history's noise (0: none)."),
    f("matte.taa", "taa", "", Bool, "Temporal anti-aliasing with a jittered raster and YCoCg clamping."),
    f("matte.taa_alpha", "taa", "", Float(0.0, 1.0, 0.005), "Weight of the current frame in TAA's blend."),
    f("matte.taa_display_ratio", "taa", "", Float(0.0, 64.0, 0.5), "TAA: the shown image follows a settled pixel's history with this many times its weight (0: shows it as is)."),
    f("matte.taa_current_light", "taa", "", Float(0.0, 1.0, 0.05), "TAA: share of a settled pixel's matte-light lag taken out (the matte temporal's current output in place of TAA's average)."),
    f("matte.taa_current_glossy", "taa", "", Float(0.0, 1.0, 0.05), "TAA: share of a settled pixel's glossy-light lag taken out (the glossy temporal's current output in place of TAA's average)."),
    f("matte.taa_resampled_frames", "taa", "frames", Float(0.0, 64.0, 1.0), "TAA: history length a pixel restarts at when it stands still after moving (0: carries on)."),
    f("matte.taa_still_frames", "taa", "", Float(0.0, 256.0, 1.0), "TAA in a still view: the current frame's weight falls to 1 / this (0: always taa_alpha)."),
    f("glossy.reflection_mv", "glossy/motion", "", Choice(reflection_mvs), "Reflection motion: surface (primary), virtual position, or diamond search."),
    f("glossy.roughness_threshold", "glossy/motion", "roughness", Float(0.0, 1.0, 0.005), "Reflection motion below this roughness, surface motion above (Voorhuis 0.4)."),
    f("glossy.mirror_roughness", "glossy/motion", "roughness", Float(0.0, 1.0, 0.001), "At or below this roughness a surface is a mirror (exact reflected hits)."),
    f("glossy.initial_step", "glossy/motion", "px", Int(1, 64), "First step of the diamond search's large pattern (Appendix A: 4)."),
    f("glossy.max_search_steps", "glossy/motion", "steps", Int(1, 256), "Most large-pattern iterations per pixel."),
    f("glossy.trace_representative_ray", "glossy/motion", "", Bool, "Trace the mirror ray of glossy surfaces under the threshold."),
    f("glossy.temporal", "glossy/temporal", "", Bool, "Stage 8: reprojection of glossy history (off: NoSpecReproj)."),
    f("glossy.hysteresis", "glossy/temporal", "", Float(0.0, 1.0, 0.001), "h for the glossy history."),
    f("glossy.reprojection_normal_degrees", "glossy/temporal", "degrees", Float(0.0, 180.0, 0.5), "Surface reprojection rejects a previous texel whose normal differs by more (180: off)."),
    f("glossy.d0_px", "glossy/temporal", "footprints", Float(0.0, 64.0, 0.05), "Eq. 11's d0 for mirrors, at the reflected distance."),
    f("glossy.d1_px", "glossy/temporal", "footprints", Float(0.0, 64.0, 0.05), "Eq. 11's d1 for mirrors, at the reflected distance."),
    f("glossy.clipping", "glossy/temporal", "", Bool, "Neighbourhood clipping of the reprojected history (Voorhuis 4.2.3)."),
    f("glossy.clip_roughness", "glossy/temporal", "roughness", Float(0.0, 1.0, 0.005), "Clipping applies below this roughness (0.9)."),
    f("glossy.bilateral", "glossy/bilateral", "", Bool, "Stages 9-10: separable bilateral."),
    f("glossy.sigma_scale", "glossy/bilateral", "px", Float(0.0, 9.0, 0.05), "Sigma = scale x roughness^exponent + epsilon (Mara 7)."),
    f("glossy.sigma_exponent", "glossy/bilateral", "", Float(0.0, 4.0, 0.005), "Roughness exponent of sigma (Mara 0.1)."),
    f("glossy.sigma_epsilon_px", "glossy/bilateral", "px", Float(0.0, 9.0, 0.05), "Sigma at roughness 0."),
    f("glossy.sigma_full_frames", "glossy/bilateral", "frames", Float(0.0, 256.0, 0.1), "Past this history length sigma shrinks as 1/sqrt(length) (0: fixed)."),
    f("glossy.resampled_history_frames", "glossy/temporal", "frames", Float(0.0, 1024.0, 1.0), "A bilinearly resampled history counts as at most this many frames (0: no cap)."),
    f("glossy.ray_differential_omega", "glossy/bilateral", "footprints", Float(0.001, 1024.0, 0.1), "Voorhuis eq. 6's omega: sigma x exp(-ray differential / omega)."),
    f("glossy.roughness_sigma", "glossy/bilateral", "roughness", Float(0.0, 1.0, 0.001), "Bilateral weight on roughness differences."),
];

/// The value at a dotted path of a serde form.
pub fn get<'a>(v: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(v, |v, k| v.get(k))
}

pub fn get_mut<'a>(v: &'a mut Value, path: &str) -> Option<&'a mut Value> {
    path.split('.').try_fold(v, |v, k| v.get_mut(k))
}

/// Dotted paths of every leaf of a serde form.
pub fn leaves(v: &Value) -> Vec<String> {
    fn walk(v: &Value, prefix: &str, out: &mut Vec<String>) {
        match v {
            Value::Object(m) => {
                for (k, v) in m {
                    let p = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                    walk(v, &p, out);
                }
            }
            _ => out.push(prefix.to_string()),
        }
    }
    let mut out = vec![];
    walk(v, "", &mut out);
    out
}

impl FrameSettings {
    /// The settings as a JSON value (the form panels edit and presets store).
    pub fn to_value(&self) -> Value {
        serde_json::to_value(self).expect("settings serialize")
    }

    /// Settings from a JSON value; every field must be one [`FIELDS`] describes, in range.
    pub fn from_value(v: &Value) -> Result<FrameSettings> {
        let known = leaves(&FrameSettings::default().to_value());
        for leaf in leaves(v) {
            if !known.contains(&leaf) {
                return Err(anyhow!("unknown setting {leaf:?} (settings are: {})", known.join(", ")));
            }
        }
        for field in FIELDS {
            if let Some(x) = get(v, field.path) {
                check(field, x)?;
            }
        }
        serde_json::from_value(v.clone()).map_err(|e| anyhow!("bad settings: {e}"))
    }
}

fn check(field: &Field, x: &Value) -> Result<()> {
    let bad = |why: String| Err(anyhow!("setting {}: {why}", field.path));
    match field.kind {
        Bool if !x.is_boolean() => bad(format!("{x} is not true or false")),
        Int(lo, hi) => match x.as_i64() {
            Some(i) if (lo..=hi).contains(&i) => Ok(()),
            _ => bad(format!("{x} is not an integer in {lo}..={hi}")),
        },
        Float(lo, hi, _) => match x.as_f64() {
            Some(f) if f.is_finite() && (lo..=hi).contains(&f) => Ok(()),
            _ => bad(format!("{x} is not a number in {lo}..={hi}")),
        },
        Choice(choices) => {
            let all = choices();
            match x.as_str() {
                Some(s) if all.iter().any(|c| c == s) => Ok(()),
                _ => bad(format!("{x} is not one of {}", all.join(", "))),
            }
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_is_described_once_and_defaults_are_in_range() {
        let v = FrameSettings::default().to_value();
        let leaves = leaves(&v);
        for leaf in &leaves {
            assert_eq!(FIELDS.iter().filter(|f| f.path == leaf).count(), 1, "{leaf} must be described exactly once in FIELDS");
        }
        for f in FIELDS {
            let x = get(&v, f.path).unwrap_or_else(|| panic!("{} is described but is not a setting", f.path));
            check(f, x).unwrap();
        }
        assert_eq!(leaves.len(), FIELDS.len());
    }

    #[test]
    fn bad_values_are_clear_errors() {
        let mut v = FrameSettings::default().to_value();
        *get_mut(&mut v, "matte.hysteresis").unwrap() = serde_json::json!(1.5);
        assert!(format!("{:#}", FrameSettings::from_value(&v).unwrap_err()).contains("matte.hysteresis"));
        let mut v = FrameSettings::default().to_value();
        v["matte"]["hysterisis"] = serde_json::json!(0.9);
        assert!(format!("{:#}", FrameSettings::from_value(&v).unwrap_err()).contains("matte.hysterisis"));
        let mut v = FrameSettings::default().to_value();
        v["view"] = serde_json::json!("Nope");
        assert!(FrameSettings::from_value(&v).is_err());
    }
}
