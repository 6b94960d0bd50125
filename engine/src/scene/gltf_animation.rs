//! glTF animations (glTF 2.0 §3.11): every channel (translation, rotation, scale and morph
//! target weights) with LINEAR, STEP and CUBICSPLINE samplers, read through the checked
//! accessors of `accessor`. Each channel loops over the length of the animation it belongs to
//! (its longest sampler input), so that the nodes of one rig stay together.

use super::accessor::{self, Data};
use super::gltf_importer::Importer;
use super::{Animation, Morph, Track};
use anyhow::Result;
use glam::{DMat4, DQuat, DVec3};
use std::collections::HashMap;

/// What the file's animations drive: node index -> its own motion (no parent set yet), and
/// node index -> the morph weights it animates (rest weights not set yet).
#[derive(Default)]
pub(super) struct Animated {
    pub nodes: HashMap<usize, Animation>,
    pub weights: HashMap<usize, Morph>,
}

/// Which of the file's animations play: `only` picks one (by index), None plays them all (a
/// node driven by several takes the last one's channel for each property, and loops over the
/// longest of them).
/// A channel that cannot be used (unsorted or non-finite keys, a value count that does not match
/// the keys, weights for a node without morph targets) is a warning and is ignored; a malformed
/// accessor is an error.
pub(super) fn animations(
    imp: &mut Importer,
    doc: &gltf::Document,
    data: &Data,
    only: Option<usize>,
) -> Result<Animated> {
    use gltf::animation::{Interpolation, Property};
    let mut out = Animated::default();
    if let Some(k) = only
        && k >= doc.animations().len()
    {
        anyhow::bail!("animation {k} was asked for; the file has {}", doc.animations().len());
    }
    for anim in doc.animations().filter(|a| only.is_none_or(|k| a.index() == k)) {
        let mut period = 0.0f64;
        let mut touched = vec![];
        for ch in anim.channels() {
            let here = format!("animations[{}].channels[{}]", anim.index(), ch.index());
            let node = ch.target().node();
            let sampler = ch.sampler();
            let interp = sampler.interpolation();
            let property = ch.target().property();
            // Morph weights: one scalar per target and key.
            let targets = node
                .mesh()
                .and_then(|m| m.primitives().next())
                .map_or(0, |p| p.morph_targets().len());
            let (expect, k) = match property {
                Property::Translation => (accessor::TRANSLATION, 3),
                Property::Rotation => (accessor::ROTATION, 4),
                Property::Scale => (accessor::SCALE, 3),
                Property::MorphTargetWeights if targets == 0 => {
                    imp.warn(format!(
                        "{here}: weights of node {} whose mesh has no morph targets; ignored",
                        node.index()
                    ));
                    continue;
                }
                Property::MorphTargetWeights => (accessor::WEIGHTS_KEYS, targets),
            };
            let times: Vec<f64> = accessor::read_f32(
                data,
                sampler.input().index(),
                accessor::KEY_TIMES,
                &mut imp.budget,
                &format!("{here} input"),
            )?
            .into_iter()
            .map(|t| t as f64)
            .collect();
            let values = accessor::read_f32(
                data,
                sampler.output().index(),
                expect,
                &mut imp.budget,
                &format!("{here} output"),
            )?;
            // CUBICSPLINE stores (in-tangent, value, out-tangent) per key.
            let per_key = if interp == Interpolation::CubicSpline { 3 } else { 1 };
            let keys: Vec<&[f32]> =
                values.chunks_exact(k).skip(per_key / 2).step_by(per_key).collect();
            let tangents: Vec<[&[f32]; 2]> = if per_key == 3 {
                values.chunks_exact(3 * k).map(|c| [&c[..k], &c[2 * k..]]).collect()
            } else {
                vec![]
            };
            if keys.len() != times.len() || values.len() != times.len() * k * per_key {
                imp.warn(format!(
                    "{here}: {} keys but {} values; ignored",
                    times.len(),
                    values.len() / k
                ));
                continue;
            }
            let sorted =
                times.windows(2).all(|w| w[0] <= w[1]) && times.iter().all(|t| t.is_finite());
            if !sorted || !values.iter().all(|x| x.is_finite()) {
                imp.warn(format!("{here} has unsorted or non-finite keys; ignored"));
                continue;
            }
            period = period.max(times.last().copied().unwrap_or(0.0));
            let step = interp == Interpolation::Step;
            if property == Property::MorphTargetWeights {
                let tracks = (0..k)
                    .map(|j| Track {
                        times: times.clone(),
                        values: keys.iter().map(|v| v[j] as f64).collect(),
                        step,
                        tangents: tangents
                            .iter()
                            .map(|[a, b]| [a[j] as f64, b[j] as f64])
                            .collect(),
                    })
                    .collect();
                out.weights.insert(node.index(), Morph { weights: vec![], tracks, period: 0.0 });
                touched.push((node.index(), true));
                continue;
            }
            let (t, r, s) = node.transform().decomposed();
            let a = out.nodes.entry(node.index()).or_insert_with(|| {
                Animation::rigid(
                    DMat4::IDENTITY,
                    DVec3::from_array(t.map(|x| x as f64)),
                    DQuat::from_array(r.map(|x| x as f64)),
                    DVec3::from_array(s.map(|x| x as f64)),
                )
            });
            touched.push((node.index(), false));
            let d3 = |v: &[f32]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            let dq =
                |v: &[f32]| DQuat::from_xyzw(v[0] as f64, v[1] as f64, v[2] as f64, v[3] as f64);
            let v3 = || keys.iter().map(|v| d3(v)).collect::<Vec<_>>();
            let t3 = || tangents.iter().map(|[a, b]| [d3(a), d3(b)]).collect::<Vec<_>>();
            match property {
                Property::Translation => {
                    a.translation_track = Some(Track { times, values: v3(), step, tangents: t3() })
                }
                Property::Scale => {
                    a.scale_track = Some(Track { times, values: v3(), step, tangents: t3() })
                }
                _ => {
                    let values = keys
                        .iter()
                        .map(|v| dq(v).normalize())
                        .map(|q| if q.is_finite() { q } else { DQuat::IDENTITY })
                        .collect();
                    // Tangents are not unit quaternions: kept as they are.
                    let tangents = tangents.iter().map(|[a, b]| [dq(a), dq(b)]).collect();
                    a.rotation_track = Some(Track { times, values, step, tangents });
                }
            }
        }
        // Every channel of this animation loops over its whole length.
        for (node, weights) in touched {
            if weights {
                if let Some(m) = out.weights.get_mut(&node) {
                    m.period = m.period.max(period);
                }
            } else if let Some(a) = out.nodes.get_mut(&node) {
                a.period = a.period.max(period);
            }
        }
    }
    out.nodes.retain(|_, a| a.duration() > 0.0 || a.has_tracks());
    Ok(out)
}
