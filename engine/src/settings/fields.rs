//! One description of every tunable in [`FrameSettings`]: the pass it belongs to, its unit, its
//! range and a line of help. The viewer draws its settings panels from this table and the
//! settings' serde form (no widget is written per field), presets are checked against it, and a
//! test keeps it and the structs in step.

use super::FrameSettings;
use super::View;
use super::field::f;
pub use super::field::{Field, Kind};
use anyhow::{Result, anyhow};
use serde_json::Value;

fn views() -> Vec<String> {
    std::iter::once(View::FINAL.name().to_string())
        .chain(super::all_views().into_iter().map(|v| v.name.to_string()))
        .collect()
}
fn fractions() -> Vec<String> {
    super::SampleFraction::all().map(|f| f.to_string()).collect()
}
fn denoisers() -> Vec<String> {
    super::denoiser_names().into_iter().map(str::to_string).collect()
}

use Kind::{Bool, Choice, Float, Int};

/// The frame's own fields (display, trace), in panel order.
const FRAME_FIELDS: &[Field] = &[
    f(
        "view",
        "display",
        "",
        Choice(views),
        "What the display shows: the image or one buffer of the frame.",
    ),
    f(
        "exposure_ev",
        "display",
        "EV",
        Float(-30.0, 30.0, 0.05),
        "The image is multiplied by 2^EV before tone mapping.",
    ),
    f(
        "accumulate",
        "frame",
        "",
        Bool,
        "Sum frames while nothing changes and show their mean (the converged image).",
    ),
    f("seed", "frame", "", Int(0, u32::MAX as i64), "Seed of every random sequence."),
    f(
        "denoiser",
        "frame",
        "",
        Choice(denoisers),
        "Which denoiser filters the frame: none (the raw 1-sample frame), a built-in one or one the application registered; each says what it is in its summary.",
    ),
    f(
        "max_depth",
        "trace",
        "bounces",
        Int(-1, 64),
        "Path length as Mitsuba counts it (2 = direct light only, -1 = unbounded).",
    ),
    f(
        "paths_per_pixel",
        "trace",
        "paths",
        Int(1, super::MAX_PATHS_PER_PIXEL as i64),
        "Indirect paths per pixel per frame (1 is the paper's real-time setting).",
    ),
    f(
        "uncovered_paths",
        "trace",
        "paths",
        Int(0, super::MAX_PATHS_PER_PIXEL as i64),
        "Paths per pixel where a move uncovered the surface (a denoiser's history restarts there and counts them as that many frames); 0: off.",
    ),
    f(
        "light_candidates",
        "trace",
        "candidates",
        Int(1, super::MAX_LIGHT_CANDIDATES as i64),
        "Light candidates resampled for each matte light sample (RIS, ReSTIR DI's first step); 1: one sample, MIS-weighted as the reference tracer.",
    ),
    f(
        "light_reuse",
        "trace",
        "",
        Bool,
        "With more than one light candidate: merge the reservoir the last frame kept at the surface point (ReSTIR DI's temporal reuse).",
    ),
    f(
        "samples_per_pixel",
        "trace",
        "samples",
        Int(1, super::MAX_SAMPLES_PER_PIXEL as i64),
        "Samples per pixel: the raster's guide and k - 1 traced, mixed into their most similar guides (Voorhuis §5).",
    ),
    f(
        "primary_samples",
        "gbuffer/primaries",
        "samples",
        Int(1, super::MAX_PRIMARY_SAMPLES as i64),
        "With a thin lens: primary rays traced per pixel, whose mean features are the G-buffer (Moon et al. 2017 §4.2). More: cleaner features, k rays each.",
    ),
    f(
        "prefilter",
        "prefilter",
        "",
        Bool,
        "With a thin lens: Moon et al. 2017's pre-filter of the traced G-buffer (world-position weights, bandwidth by SURE).",
    ),
    f(
        "texture_lod",
        "trace",
        "texture mips",
        Bool,
        "Ray cones choose each texture's mip level after the primary hit: an indirect ray reads the mean of its footprint, not one texel (less noise, same converged image).",
    ),
    f(
        "screen_strata",
        "trace",
        "",
        Bool,
        "Each 16x16 tile's pixels share a stratified set of light samples and first matte directions: the same noise per pixel, less left after the denoisers' windows.",
    ),
    f(
        "resample_history_frames",
        "frame/rescale",
        "frames",
        Float(0.0, 1024.0, 1.0),
        "A change of size (resolution scale, window) resamples the histories to the new size, each then counting as at most this many frames; 0 restarts them.",
    ),
    f(
        "sample_fraction",
        "trace",
        "",
        Choice(fractions),
        "Fraction of the pixels traced per frame (Dundr §5): 1/N traces one pixel of every N-pixel tile, each pixel once in N frames.",
    ),
];

/// Every field of [`FrameSettings`] that is saved in presets, in panel order: the frame's, its
/// reprojection test's, the radiance cache's, each denoiser's as the registry lists them ([`super::registry`]), then
/// TAA's.
pub fn fields() -> impl Iterator<Item = &'static Field> {
    let denoisers = super::registry::denoisers();
    let own: Vec<&'static Field> =
        denoisers.iter().flat_map(|d| d.fields.iter().flat_map(|f| f.iter())).collect();
    FRAME_FIELDS
        .iter()
        .chain(super::reprojection::FIELDS)
        .chain(super::cache::FIELDS)
        .chain(own)
        .chain(super::taa::FIELDS)
}

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
        // serde_json fails only on maps with non-string keys and on failing Serialize impls;
        // the settings are structs of numbers, booleans and strings.
        #[allow(clippy::expect_used)]
        serde_json::to_value(self).expect("settings serialize")
    }

    /// Settings from a JSON value; every field must be one [`fields`] describes, in range. What
    /// `v` leaves out keeps its default.
    pub fn from_value(v: &Value) -> Result<FrameSettings> {
        let moved = moved(v);
        let v = &moved;
        let mut full = FrameSettings::default().to_value();
        let known = leaves(&full);
        for leaf in leaves(v) {
            if !known.contains(&leaf) {
                return Err(anyhow!(
                    "unknown setting {leaf:?} (settings are: {})",
                    known.join(", ")
                ));
            }
        }
        for field in fields() {
            if let Some(x) = get(v, field.path) {
                check(field, x)?;
            }
        }
        merge(&mut full, v);
        serde_json::from_value(full).map_err(|e| anyhow!("bad settings: {e}"))
    }
}

/// Settings that moved to another group (old path, new path): a preset saved before the move
/// loads as it did. Eq. (11)'s distances steer every denoiser's reprojection, so they left
/// Mara's matte group for the frame's own.
const MOVED: &[(&str, &str)] =
    &[("matte.d0_px", "reprojection.d0_px"), ("matte.d1_px", "reprojection.d1_px")];

/// `v` with every [`MOVED`] setting at its new path (a value there already wins).
fn moved(v: &Value) -> Value {
    let mut v = v.clone();
    for (old, new) in MOVED {
        let Some((group, key)) = old.split_once('.') else { continue };
        let Some(x) = v.get_mut(group).and_then(Value::as_object_mut).and_then(|g| g.remove(key))
        else {
            continue;
        };
        let Some((to, to_key)) = new.split_once('.') else { continue };
        if let Some(obj) = v.as_object_mut() {
            let g = obj.entry(to).or_insert_with(|| Value::Object(Default::default()));
            if let Some(g) = g.as_object_mut() {
                g.entry(to_key).or_insert(x);
            }
        }
    }
    v
}

/// `over`'s leaves written into `base`.
fn merge(base: &mut Value, over: &Value) {
    match (base, over) {
        (Value::Object(b), Value::Object(o)) => {
            for (k, v) in o {
                match b.get_mut(k) {
                    Some(slot) => merge(slot, v),
                    None => {
                        b.insert(k.clone(), v.clone());
                    }
                }
            }
        }
        (b, o) => *b = o.clone(),
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
    fn a_preset_from_before_a_setting_moved_loads_it_at_its_new_place() {
        let v = serde_json::json!({"matte": {"d1_px": 12.0, "hysteresis": 0.9}});
        let s = FrameSettings::from_value(&v).unwrap();
        assert_eq!(s.reprojection.d1_px, 12.0);
        assert_eq!(s.matte.hysteresis, 0.9);
        // Out of range at its old place is refused as at its new one.
        let bad = serde_json::json!({"matte": {"d0_px": -1.0}});
        let e = FrameSettings::from_value(&bad).unwrap_err().to_string();
        assert!(e.contains("reprojection.d0_px"), "{e}");
    }

    #[test]
    fn every_setting_is_described_once_and_defaults_are_in_range() {
        let v = FrameSettings::default().to_value();
        let leaves = leaves(&v);
        for leaf in &leaves {
            assert_eq!(
                fields().filter(|f| f.path == leaf).count(),
                1,
                "{leaf} must be described exactly once in fields()"
            );
        }
        for f in fields() {
            let x = get(&v, f.path)
                .unwrap_or_else(|| panic!("{} is described but is not a setting", f.path));
            check(f, x).unwrap();
        }
        assert_eq!(leaves.len(), fields().count());
    }

    #[test]
    fn bad_values_are_clear_errors() {
        let mut v = FrameSettings::default().to_value();
        *get_mut(&mut v, "matte.hysteresis").unwrap() = serde_json::json!(1.5);
        assert!(
            format!("{:#}", FrameSettings::from_value(&v).unwrap_err())
                .contains("matte.hysteresis")
        );
        let mut v = FrameSettings::default().to_value();
        v["matte"]["hysterisis"] = serde_json::json!(0.9);
        assert!(
            format!("{:#}", FrameSettings::from_value(&v).unwrap_err())
                .contains("matte.hysterisis")
        );
        let mut v = FrameSettings::default().to_value();
        v["view"] = serde_json::json!("Nope");
        assert!(FrameSettings::from_value(&v).is_err());
    }
}
