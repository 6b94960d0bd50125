//! Every uniform the frame uploads against its WGSL mirror, member by member: names, offsets
//! and the struct's size (naga's layout of the composed program), and every switch word's bits
//! against the WGSL constants that test them.

use super::{Program, all_programs};
use std::mem::{offset_of, size_of};

/// A Rust struct's size and its fields' (name, offset), from the field list given.
macro_rules! layout {
    ($t:ty { $($f:ident),* $(,)? }) => {
        (size_of::<$t>(), vec![$((stringify!($f), offset_of!($t, $f))),*])
    };
}

/// The WGSL struct `name` in `p`: its size and its members' (name, offset).
fn wgsl(p: &Program, name: &str) -> (usize, Vec<(String, usize)>) {
    let m = p.validate().unwrap();
    let found = m.types.iter().find_map(|(_, t)| match &t.inner {
        naga::TypeInner::Struct { members, span } if t.name.as_deref() == Some(name) => Some((
            *span as usize,
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
                .collect(),
        )),
        _ => None,
    });
    found.unwrap_or_else(|| panic!("{}: no struct {name}", p.label))
}

/// Padding is `_pad` in Rust (unused fields start with `_`), `pad` or `pad0` in WGSL: all are
/// `pad`.
fn member(name: &str) -> &str {
    let n = name.trim_start_matches('_');
    if n.starts_with("pad") && n[3..].chars().all(|c| c.is_ascii_digit()) { "pad" } else { n }
}

fn same(programs: &[Program], label: &str, name: &str, (size, rust): (usize, Vec<(&str, usize)>)) {
    let p = programs.iter().find(|p| p.label == label).unwrap_or_else(|| panic!("no {label}"));
    let (wgsl_size, members) = wgsl(p, name);
    // Padding may sit on one side only (the sizes below agree all the same).
    fn named(v: &[(impl AsRef<str>, usize)]) -> Vec<(String, usize)> {
        let v = v.iter().map(|(n, o)| (member(n.as_ref()).to_string(), *o));
        v.filter(|(n, _)| n != "pad").collect()
    }
    let (rust, members) = (named(&rust), named(&members));
    assert_eq!(rust, members, "{name}: Rust's fields and offsets against {label}'s");
    assert_eq!(size, wgsl_size, "{name}: Rust's size against {label}'s");
}

#[test]
fn every_uniform_matches_its_wgsl_mirror_member_by_member() {
    use crate::denoise::mara::glossy::GlossyParams;
    use crate::denoise::mara::matte::MatteParams;
    use crate::denoise::progressive::ProgressiveParams;
    use crate::denoise::svgf::SvgfParams;
    use crate::frame::FrameParams;
    use crate::passes::cache::CacheParams;
    use crate::passes::converge::ConvergeParams;
    use crate::passes::taa::TaaParams;
    let v = all_programs();
    same(
        &v,
        "progressive/atrous.wgsl",
        "ProgressiveParams",
        layout!(ProgressiveParams {
            alpha,
            still_samples,
            sigma_n,
            sigma_d,
            sigma_l,
            epsilon_l,
            temporal,
            epsilon_full_samples,
            feedback_samples,
            symmetric_luminance,
            reach_samples,
            variance_cap,
            normal_min_cos,
            _pad,
        }),
    );
    same(
        &v,
        "svgf/atrous.wgsl",
        "SvgfParams",
        layout!(SvgfParams {
            bits,
            alpha,
            alpha_moments,
            sigma_l,
            sigma_n,
            sigma_z,
            still_frames,
            settled_samples,
            settled_levels,
            regression_radius,
            regression_k,
            regression_samples,
            regression_order,
            regression_full_samples,
            spike_ratio,
            normal_min_cos,
        }),
    );
    same(
        &v,
        "matte/temporal.wgsl",
        "MatteParams",
        layout!(MatteParams {
            stages,
            taps,
            max_radius_px,
            hysteresis,
            clamp_sigma,
            history_radius_px,
            disocclusion_radius_px,
            low_confidence_multiplier,
            normal_power,
            plane_sigma_px,
            rotation,
            history_full_frames,
            min_radius_px,
            edge_stop_sigmas,
            reprojection_min_cos,
            resampled_history_frames,
            still_frames,
            edge_stop_full_frames,
            still_normal_min_cos,
            tap_sigma,
        }),
    );
    same(
        &v,
        "taa/taa.wgsl",
        "TaaParams",
        layout!(TaaParams {
            enabled,
            alpha,
            still_frames,
            resampled_frames,
            display_ratio,
            current_light,
            current_glossy,
            moving_glossy,
        }),
    );
    same(
        &v,
        "glossy/temporal.wgsl",
        "GlossyParams",
        layout!(GlossyParams {
            stages,
            mode,
            initial_step,
            max_search_steps,
            roughness_threshold,
            mirror_roughness,
            clip_roughness,
            hysteresis,
            d0_px,
            d1_px,
            sigma_scale,
            sigma_exponent,
            sigma_epsilon_px,
            omega,
            roughness_sigma,
            far,
            max_sigma_px,
            representative_traced,
            sigma_full_frames,
            static_view,
            reprojection_min_cos,
            resampled_history_frames,
            still_frames,
        }),
    );
    same(
        &v,
        "cache/resolve.wgsl",
        "CacheParams",
        layout!(CacheParams {
            capacity,
            cell_pixels,
            max_samples,
            max_age,
            prior_frames,
            update_tile,
            fixed_scale,
            sample_clamp,
            path_end_samples,
            path_end_error,
            pad,
        }),
    );
    use crate::passes::upscale::UpscaleParams;
    for label in ["taa/upscale_samples.wgsl", "taa/upscale.wgsl", "taa/upscale_shown.wgsl"] {
        same(
            &v,
            label,
            "UpscaleParams",
            layout!(UpscaleParams {
                out_size,
                sigma,
                moving_weight,
                fill_weight,
                continues,
                raw_continues,
                bias_sigmas,
                min_samples,
                moving_frames,
                materials,
                _pad,
            }),
        );
    }
    same(
        &v,
        "taa/converge.wgsl",
        "ConvergeParams",
        layout!(ConvergeParams { continues, bias_sigmas, min_samples, _pad }),
    );
    same(
        &v,
        "realtime/composite.wgsl",
        "Frame",
        layout!(FrameParams {
            view_proj,
            unjittered_view_proj,
            prev_view_proj,
            cam_pos,
            cam_right,
            cam_up,
            cam_fwd,
            jitter,
            size,
            index,
            exposure,
            accumulated,
            paths,
            representative_roughness,
            samples,
            period,
            primary_samples,
            rescaled_frames,
            uncovered_paths,
            prev_jitter_x,
            prev_jitter_y,
            inv_view_proj,
            prev_inv_view_proj,
            jitter_shift,
            history_valid,
            static_view,
            d0_px,
            d1_px,
            inject_nonfinite,
            light_candidates,
        }),
    );
}

/// The WGSL constants `prefix*` of module `path`: (name, value).
fn constants(path: &str, prefix: &str) -> Vec<(String, u32)> {
    let text = crate::shader::source(path).unwrap();
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("const ")?.split_once(": u32 = "))
        .filter(|(n, _)| n.starts_with(prefix))
        .map(|(n, v)| {
            (n.to_string(), v.trim_end_matches(';').trim_end_matches('u').parse().unwrap())
        })
        .collect()
}

/// A switch word's bits, as Rust packs them (bit i: the i-th switch), against the WGSL
/// constants named for them: the same names, and each constant 1 << i.
fn same_bits(path: &str, prefix: &str, rust: &[(&str, bool)]) {
    let want: Vec<(String, u32)> =
        rust.iter().enumerate().map(|(i, (n, _))| (n.to_string(), 1u32 << i)).collect();
    assert_eq!(
        constants(path, prefix),
        want,
        "{path}'s {prefix}* constants against Rust's switches"
    );
}

#[test]
fn every_switch_word_matches_its_wgsl_constants() {
    use crate::settings::{GlossySettings, MatteSettings, SvgfSettings};
    let sv = SvgfSettings::default();
    same_bits("svgf/common.wgsl", "SV_", &sv.switches());
    assert_eq!(sv.bits(), crate::settings::switch_bits(&sv.switches()));
    same_bits("matte/common.wgsl", "STAGE_", &MatteSettings::default().switches());
    same_bits("glossy/common.wgsl", "GSTAGE_", &GlossySettings::default().switches());
}
