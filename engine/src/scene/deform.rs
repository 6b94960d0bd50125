//! Skins and morph targets: glTF 2.0 §3.7.3 ("Skins") and §3.7.2.2 ("Morph Targets"),
//! evaluated on the CPU at a scene time into the posed mesh that the GPU scene flattens
//! (`PreparedScene::expose` re-flattens a deforming object whenever the time changes, unless
//! the real-time frame poses it on the GPU: `gpu/posing.rs` and shaders/accel/pose.wgsl follow
//! the same order and fallbacks).
//!
//! Order, as the specification gives it: morph targets first, in the mesh's own space
//! (p + sum of weight_k x delta_k), then skinning, sum over the vertex's influences of
//! weight_i x (joint_i's world transform x its inverse bind matrix) applied to that point. The
//! skinned mesh node's own transform is ignored (§3.7.3.3), so a skinned object's vertices come
//! out in world space and its transform is the identity.

use super::{Animation, Mesh, Track};
use glam::{DMat4, Mat3, Mat4, Vec3, Vec4};

/// Influences a vertex can have: JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1.
pub const MAX_INFLUENCES: usize = 8;

/// One morph target of a mesh: per-vertex displacements, each list empty or one per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MorphTarget {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Tangent xyz displacements (the handedness does not morph).
    pub tangents: Vec<Vec3>,
}

/// A joint of a skin: the node that places it (its rest world transform and, when it or an
/// ancestor is animated, its animation) and its inverse bind matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub rest: DMat4,
    pub animation: Option<Animation>,
    pub inverse_bind: DMat4,
}

impl Joint {
    /// World transform x inverse bind matrix at `time` (None: the rest pose), in the f32 the
    /// vertices are skinned in. One that is not finite there falls back to the rest pose's, then
    /// to the identity: NaN and Inf never reach a vertex.
    pub fn matrix(&self, time: Option<f64>) -> Mat4 {
        let world = match (&self.animation, time) {
            (Some(a), Some(t)) => a.world_at(t),
            _ => self.rest,
        };
        [world * self.inverse_bind, self.rest * self.inverse_bind]
            .into_iter()
            .map(|m| m.as_mat4())
            .find(|m| m.is_finite())
            .unwrap_or(Mat4::IDENTITY)
    }
}

/// glTF morph weights of a node: the rest weights (the node's, else the mesh's) and a channel
/// per target where an animation drives them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Morph {
    pub weights: Vec<f32>,
    /// One per target, or empty when no animation drives the weights.
    pub tracks: Vec<Track<f64>>,
    /// The driving animation's length in seconds (the weights loop over it).
    pub period: f64,
}

impl Morph {
    pub fn weights_at(&self, time: Option<f64>) -> Vec<f32> {
        match time {
            Some(t) if !self.tracks.is_empty() => self
                .tracks
                .iter()
                .zip(&self.weights)
                .map(|(k, &w)| k.weight_at(t, self.period).map_or(w, |v| v as f32))
                .map(|w| if w.is_finite() { w } else { 0.0 })
                .collect(),
            _ => self.weights.clone(),
        }
    }
}

/// How an object's mesh deforms.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Deform {
    /// The joints its JOINTS_n index.
    pub skin: Vec<Joint>,
    pub morph: Option<Morph>,
}

impl Deform {
    /// Whether the deformation changes with time (an animated joint or driven weights).
    pub fn moves(&self) -> bool {
        self.skin.iter().any(|j| j.animation.is_some())
            || self.morph.as_ref().is_some_and(|m| !m.tracks.is_empty())
    }

    /// `mesh` posed at `time` (None: the rest pose): morphed, then skinned into world space.
    pub fn pose(&self, mesh: &Mesh, time: Option<f64>) -> Mesh {
        let p = self.pose_vertices(mesh, time);
        Mesh { positions: p.positions, normals: p.normals, tangents: p.tangents, ..mesh.clone() }
    }

    /// What posing changes of `mesh` at `time`: its positions, normals and tangents (the rest
    /// is the mesh's own; [`Deform::pose`] for the whole mesh).
    pub fn pose_vertices(&self, mesh: &Mesh, time: Option<f64>) -> Posed {
        let mut m = Posed {
            positions: mesh.positions.clone(),
            normals: mesh.normals.clone(),
            tangents: mesh.tangents.clone(),
        };
        if let Some(morph) = &self.morph {
            let w = morph.weights_at(time);
            for (target, &w) in mesh.targets.iter().zip(&w) {
                if w == 0.0 {
                    continue;
                }
                add(&mut m.positions, &target.positions, w);
                add(&mut m.normals, &target.normals, w);
                for (t, d) in m.tangents.iter_mut().zip(&target.tangents) {
                    *t += (*d * w).extend(0.0);
                }
            }
        }
        if !self.skin.is_empty() && mesh.joints.len() == mesh.positions.len() {
            let joints: Vec<Mat4> = self.skin.iter().map(|j| j.matrix(time)).collect();
            skin(&mut m, mesh, &joints);
        }
        m.normals.iter_mut().for_each(|n| *n = n.normalize_or(Vec3::Z));
        m
    }
}

/// A mesh's posed vertices ([`Deform::pose_vertices`]).
pub struct Posed {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub tangents: Vec<Vec4>,
}

fn add(v: &mut [Vec3], d: &[Vec3], w: f32) {
    for (p, d) in v.iter_mut().zip(d) {
        *p += *d * w;
    }
}

/// Linear blend skinning of `m`'s vertices by `joints` (joint matrices); the influences were
/// checked at load (indices in range, weights normalised). In f32, as the GPU would: each
/// vertex's positions by the weighted sum of its joints' matrices, its normal by the weighted
/// sum of their inverse transposes (exact for a vertex on one joint, the usual approximation
/// between joints), its tangent by their linear parts.
fn skin(m: &mut Posed, mesh: &Mesh, mats: &[Mat4]) {
    let normal_mats: Vec<Mat3> = mats
        .iter()
        .map(|j| {
            let n = Mat3::from_mat4(*j).inverse().transpose();
            if n.is_finite() { n } else { Mat3::IDENTITY }
        })
        .collect();
    for i in 0..m.positions.len() {
        let (js, ws) = (&mesh.joints[i], &mesh.weights[i]);
        let (mut blended, mut normal) = (Mat4::ZERO, Mat3::ZERO);
        for k in 0..MAX_INFLUENCES {
            if ws[k] > 0.0 {
                blended += mats[js[k] as usize] * ws[k];
                normal += normal_mats[js[k] as usize] * ws[k];
            }
        }
        let p = blended.transform_point3(m.positions[i]);
        m.positions[i] = if p.is_finite() { p } else { Vec3::NAN };
        if let Some(nrm) = m.normals.get_mut(i) {
            let v = normal * *nrm;
            *nrm = if v.is_finite() { v } else { *nrm };
        }
        if let Some(t) = m.tangents.get_mut(i) {
            let v = blended.transform_vector3(t.truncate()).normalize_or_zero();
            *t = if v.is_finite() && v != Vec3::ZERO { v.extend(t.w) } else { *t };
        }
    }
}

/// Normalise one vertex's weights (glTF: they sum to 1); a vertex whose weights sum to zero or
/// are not finite follows its first joint alone. Returns whether it needed that fallback.
pub fn normalise(w: &mut [f32; MAX_INFLUENCES]) -> bool {
    w.iter_mut().for_each(|x| *x = if x.is_finite() { x.max(0.0) } else { 0.0 });
    let sum: f32 = w.iter().sum();
    if sum > 0.0 && sum.is_finite() {
        w.iter_mut().for_each(|x| *x /= sum);
        false
    } else {
        *w = [0.0; MAX_INFLUENCES];
        w[0] = 1.0;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Animation;
    use glam::{DQuat, DVec3, Vec2};

    /// A joint whose animation overflows f32 (a scale key of 1e300) poses its vertices at its
    /// rest pose instead of at infinity or NaN: nothing non-finite reaches the flattened
    /// triangles.
    #[test]
    fn non_finite_joint_matrices_fall_back_to_the_rest_pose() {
        let mut a = Animation::rigid(DMat4::IDENTITY, DVec3::X, DQuat::IDENTITY, DVec3::ONE);
        a.scale_track = Some(Track {
            times: vec![0.0, 1.0],
            values: vec![DVec3::ONE, DVec3::splat(1e300)],
            step: false,
            tangents: vec![],
        });
        let joint = Joint {
            rest: DMat4::from_translation(DVec3::X),
            animation: Some(a),
            inverse_bind: DMat4::from_translation(DVec3::NEG_X),
        };
        assert!(joint.matrix(Some(0.5)).is_finite());
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            uvs: vec![Vec2::ZERO; 3],
            indices: vec![0, 1, 2],
            joints: vec![[0; MAX_INFLUENCES]; 3],
            weights: vec![
                {
                    let mut w = [0.0; MAX_INFLUENCES];
                    w[0] = 1.0;
                    w
                };
                3
            ],
            ..Default::default()
        };
        let d = Deform { skin: vec![joint], morph: None };
        for t in [0.0, 0.5, 0.999, 1.0, f64::NAN] {
            let p = d.pose_vertices(&mesh, Some(t));
            assert!(
                p.positions.iter().chain(&p.normals).all(|v| v.is_finite()),
                "t = {t}: {:?}",
                p.positions
            );
        }
        // Near the overflowing key the scale leaves f32: the rest pose (world x inverse bind =
        // identity) holds.
        let p = d.pose_vertices(&mesh, Some(0.999));
        assert_eq!(p.positions, mesh.positions);
    }
}
