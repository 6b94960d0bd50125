//! glTF skins and morph targets, read through the checked accessors of `accessor`: a
//! primitive's JOINTS_n/WEIGHTS_n and targets, and a skin's inverse bind matrices. Every index
//! and count is checked here, so that posing (`deform`) never indexes out of range.

use super::accessor::{self, Data, Expect};
use super::gltf_importer::Importer;
use super::{Animation, Deform, Joint, MAX_INFLUENCES, Mesh, Morph, MorphTarget, Scene};
use anyhow::{Result, bail};
use glam::{DMat4, Vec3};
use std::collections::HashMap;
use std::sync::Arc;

/// A primitive's JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1 into `m` (weights normalised, a
/// vertex whose weights sum to zero following its first joint, with one warning), or nothing
/// for a primitive without them. Joint indices are checked against the skin when it is known
/// (`check_joints`).
pub(super) fn read_influences(
    imp: &mut Importer,
    prim: &gltf::Primitive,
    data: &Data,
    here: &str,
    m: &mut Mesh,
) -> Result<()> {
    let n = m.positions.len();
    let mut joints: Vec<[u16; MAX_INFLUENCES]> = vec![];
    let mut weights: Vec<[f32; MAX_INFLUENCES]> = vec![];
    for set in 0..2u32 {
        let (Some(j), Some(w)) =
            (prim.get(&gltf::Semantic::Joints(set)), prim.get(&gltf::Semantic::Weights(set)))
        else {
            continue;
        };
        let read = |imp: &mut Importer, i: usize, e: Expect, name: &str| -> Result<Vec<f32>> {
            let what = format!("{here}.attributes.{name}_{set}");
            let v = accessor::read_f32(data, i, e, &mut imp.budget, &what)?;
            if v.len() != 4 * n {
                bail!(
                    "{what} has {} elements and POSITION {n}; a primitive's attributes have one count",
                    v.len() / 4
                );
            }
            Ok(v)
        };
        let jv = read(imp, j.index(), accessor::JOINTS, "JOINTS")?;
        let wv = read(imp, w.index(), accessor::WEIGHTS, "WEIGHTS")?;
        if joints.is_empty() {
            joints = vec![[0; MAX_INFLUENCES]; n];
            weights = vec![[0.0; MAX_INFLUENCES]; n];
        }
        for i in 0..n {
            for k in 0..4 {
                joints[i][4 * set as usize + k] = jv[4 * i + k] as u16;
                weights[i][4 * set as usize + k] = wv[4 * i + k];
            }
        }
    }
    let unweighted = weights.iter_mut().map(super::deform::normalise).filter(|&f| f).count();
    if unweighted > 0 {
        imp.warn(format!(
            "{here}: {unweighted} vertices have skin weights that sum to zero; each follows its first joint"
        ));
    }
    m.joints = joints;
    m.weights = weights;
    Ok(())
}

/// A primitive's morph targets into `m` (each displacement list one per vertex or empty).
pub(super) fn read_targets(
    imp: &mut Importer,
    prim: &gltf::Primitive,
    data: &Data,
    here: &str,
    quantized: bool,
    m: &mut Mesh,
) -> Result<()> {
    let n = m.positions.len();
    let read = |imp: &mut Importer, a: Option<gltf::Accessor>, e: Expect, what: String| {
        let Some(a) = a else { return Ok(vec![]) };
        let v = accessor::read_f32(data, a.index(), e, &mut imp.budget, &what)?;
        if v.len() != 3 * n {
            bail!("{what} has {} elements and POSITION {n}", v.len() / 3);
        }
        Ok(v.chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .map(|d| if d.is_finite() { d } else { Vec3::ZERO })
            .collect())
    };
    let (pos, dir) = if quantized {
        (accessor::Q_TARGET_POSITION, accessor::Q_TARGET_DIRECTION)
    } else {
        (accessor::TARGET, accessor::TARGET)
    };
    for (t, target) in prim.morph_targets().enumerate() {
        let at = |name: &str| format!("{here}.targets[{t}].{name}");
        m.targets.push(MorphTarget {
            positions: read(imp, target.positions(), pos, at("POSITION"))?,
            normals: read(imp, target.normals(), dir, at("NORMAL"))?,
            tangents: read(imp, target.tangents(), dir, at("TANGENT"))?,
        });
    }
    Ok(())
}

/// A skin's inverse bind matrices (the identity for each joint without an accessor), checked
/// finite.
pub(super) fn inverse_binds(
    imp: &mut Importer,
    skin: &gltf::Skin,
    data: &Data,
) -> Result<Vec<DMat4>> {
    let here = format!("skins[{}]", skin.index());
    let joints = skin.joints().len();
    let Some(a) = skin.inverse_bind_matrices() else {
        return Ok(vec![DMat4::IDENTITY; joints]);
    };
    let what = format!("{here}.inverseBindMatrices");
    let v = accessor::read_f32(data, a.index(), accessor::MATRICES, &mut imp.budget, &what)?;
    if v.len() < 16 * joints {
        bail!("{what} holds {} matrices for {joints} joints", v.len() / 16);
    }
    let m: Vec<DMat4> = v
        .chunks_exact(16)
        .take(joints)
        .map(|c| DMat4::from_cols_slice(&c.iter().map(|&x| x as f64).collect::<Vec<_>>()))
        .collect();
    if let Some(bad) = m.iter().position(|m| !m.is_finite()) {
        bail!("{what}[{bad}] is not finite");
    }
    Ok(m)
}

/// Refuse a mesh whose JOINTS name a joint the skin lacks.
pub(super) fn check_joints(m: &Mesh, joints: usize, here: &str) -> Result<()> {
    for (i, (js, ws)) in m.joints.iter().zip(&m.weights).enumerate() {
        for k in 0..MAX_INFLUENCES {
            if ws[k] > 0.0 && js[k] as usize >= joints {
                bail!(
                    "{here}: vertex {i} is bound to joint {} of a skin with {joints} joints",
                    js[k]
                );
            }
        }
    }
    Ok(())
}

impl Importer<'_> {
    /// The morph weights of `node` showing `mesh`: its rest weights (the node's, else the
    /// mesh's, else zeros) and the channel that drives them, or None without morph targets.
    pub(super) fn morph(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        driven: &mut HashMap<usize, Morph>,
    ) -> Option<Morph> {
        let targets = mesh.primitives().map(|p| p.morph_targets().len()).min().unwrap_or(0);
        if targets == 0 {
            return None;
        }
        let mut weights: Vec<f32> =
            node.weights().or(mesh.weights()).map(|w| w.to_vec()).unwrap_or_default();
        if weights.len() != targets {
            if !weights.is_empty() {
                self.warn(format!(
                    "nodes[{}]: {} morph weights for {targets} targets; missing ones are 0",
                    node.index(),
                    weights.len()
                ));
            }
            weights.resize(targets, 0.0);
        }
        weights.iter_mut().for_each(|w| *w = if w.is_finite() { *w } else { 0.0 });
        let (tracks, period) = match driven.remove(&node.index()) {
            Some(m) if m.tracks.len() == targets => (m.tracks, m.period),
            _ => (vec![], 0.0),
        };
        Some(Morph { weights, tracks, period })
    }

    /// Give each skinned object its joints: the placement the walk found for each joint node
    /// and the skin's inverse bind matrices; refuse joints outside the scene or vertices bound
    /// to joints the skin lacks.
    pub(super) fn bind_skins(
        &mut self,
        doc: &gltf::Document,
        data: &Data,
        placed: &HashMap<usize, (DMat4, Option<Animation>)>,
        skinned: &[(usize, usize)],
        scene: &mut Scene,
    ) -> Result<()> {
        let mut skins: HashMap<usize, Vec<Joint>> = HashMap::new();
        for &(object, s) in skinned {
            if let std::collections::hash_map::Entry::Vacant(slot) = skins.entry(s) {
                let Some(skin) = doc.skins().nth(s) else { bail!("skins[{s}] does not exist") };
                let binds = inverse_binds(self, &skin, data)?;
                let mut joints = vec![];
                for (k, (node, inverse_bind)) in skin.joints().zip(binds).enumerate() {
                    let Some((rest, animation)) = placed.get(&node.index()) else {
                        bail!(
                            "skins[{s}].joints[{k}] is nodes[{}], which the scene does not place",
                            node.index()
                        );
                    };
                    joints.push(Joint { rest: *rest, animation: animation.clone(), inverse_bind });
                }
                slot.insert(joints);
            }
            let joints = &skins[&s];
            let o = &mut scene.objects[object];
            check_joints(&scene.meshes[o.mesh], joints.len(), &format!("skins[{s}]"))?;
            let morph = o.deform.as_ref().and_then(|d| d.morph.clone());
            o.deform = Some(Arc::new(Deform { skin: joints.clone(), morph }));
        }
        Ok(())
    }
}
