//! Node animation: glTF's translation / rotation / scale channels, sampled in f64 and looped over
//! their animation's length, through every animated ancestor of the node. Skins and morph
//! targets, which deform a mesh rather than move it, are `deform`'s.

use glam::{DMat4, DQuat, DVec3};
use std::sync::Arc;

/// One keyframed property. `step` is glTF's STEP interpolation; with `tangents` (an in- and an
/// out-tangent per key) CUBICSPLINE, the cubic Hermite spline of glTF 2.0 Appendix C (for
/// rotations on the quaternion's components, then normalised); otherwise LINEAR (slerp for
/// rotations).
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    pub times: Vec<f64>,
    pub values: Vec<T>,
    pub step: bool,
    /// CUBICSPLINE: (in-tangent, out-tangent) of each key; empty for STEP and LINEAR.
    pub tangents: Vec<[T; 2]>,
}

/// A node's animated local transform and what places it: the static transform from its nearest
/// animated ancestor's frame (the world, without one) to its parent's frame, and that ancestor's
/// own animation.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub parent: DMat4,
    /// The nearest animated ancestor's animation; `parent` is then relative to it.
    pub parent_motion: Option<Arc<Animation>>,
    /// Seconds in which the channels loop: the length of the glTF animation they belong to,
    /// so that every node of a rig loops together. 0: the last key of these channels.
    pub period: f64,
    /// The node's rest transform, used for channels it does not animate.
    pub translation: DVec3,
    pub rotation: DQuat,
    pub scale: DVec3,
    pub translation_track: Option<Track<DVec3>>,
    pub rotation_track: Option<Track<DQuat>>,
    pub scale_track: Option<Track<DVec3>>,
}

pub trait Lerp: Copy {
    fn lerp_to(self, other: Self, t: f64) -> Self;
    /// a p0 + b m0 + c p1 + d m1 (a cubic Hermite spline's basis weights).
    fn hermite(p0: Self, m0: Self, p1: Self, m1: Self, w: [f64; 4]) -> Self;
}

impl Lerp for DVec3 {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        self.lerp(other, t)
    }
    fn hermite(p0: Self, m0: Self, p1: Self, m1: Self, w: [f64; 4]) -> Self {
        p0 * w[0] + m0 * w[1] + p1 * w[2] + m1 * w[3]
    }
}

impl Lerp for f64 {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        self + (other - self) * t
    }
    fn hermite(p0: Self, m0: Self, p1: Self, m1: Self, w: [f64; 4]) -> Self {
        p0 * w[0] + m0 * w[1] + p1 * w[2] + m1 * w[3]
    }
}

impl Lerp for DQuat {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        self.slerp(other, t).normalize()
    }
    fn hermite(p0: Self, m0: Self, p1: Self, m1: Self, w: [f64; 4]) -> Self {
        let v = |q: DQuat| glam::DVec4::from_array(q.to_array());
        let q = v(p0) * w[0] + v(m0) * w[1] + v(p1) * w[2] + v(m1) * w[3];
        let q = DQuat::from_vec4(q).normalize();
        if q.is_finite() { q } else { p0 }
    }
}

impl<T: Lerp> Track<T> {
    fn sample(&self, t: f64) -> Option<T> {
        let n = self.times.len().min(self.values.len());
        if n == 0 {
            return None;
        }
        // Keys are sorted on import; partition_point finds the first key after t.
        let k = self.times[..n].partition_point(|&x| x <= t);
        if k == 0 {
            return Some(self.values[0]);
        }
        if k >= n {
            return Some(self.values[n - 1]);
        }
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        if self.step || t1 <= t0 {
            return Some(self.values[k - 1]);
        }
        let s = (t - t0) / (t1 - t0);
        if self.tangents.len() >= n {
            // glTF 2.0 Appendix C: tangents scaled by the interval, the out-tangent of key k - 1
            // and the in-tangent of key k.
            let (s2, s3, dt) = (s * s, s * s * s, t1 - t0);
            let w = [
                2.0 * s3 - 3.0 * s2 + 1.0,
                (s3 - 2.0 * s2 + s) * dt,
                -2.0 * s3 + 3.0 * s2,
                (s3 - s2) * dt,
            ];
            let (m0, m1) = (self.tangents[k - 1][1], self.tangents[k][0]);
            return Some(T::hermite(self.values[k - 1], m0, self.values[k], m1, w));
        }
        Some(self.values[k - 1].lerp_to(self.values[k], s))
    }

    fn end(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }
}

impl Animation {
    /// A node moved by its own channels alone, under the static world transform `parent`.
    pub fn rigid(parent: DMat4, translation: DVec3, rotation: DQuat, scale: DVec3) -> Animation {
        Animation {
            parent,
            parent_motion: None,
            period: 0.0,
            translation,
            rotation,
            scale,
            translation_track: None,
            rotation_track: None,
            scale_track: None,
        }
    }

    /// A node without channels of its own that moves with `ancestor`, `local` below it.
    pub fn carried(ancestor: Animation, local: DMat4) -> Animation {
        Animation {
            parent_motion: Some(Arc::new(ancestor)),
            ..Animation::rigid(local, DVec3::ZERO, DQuat::IDENTITY, DVec3::ONE)
        }
    }

    /// Whether this node has channels of its own (not only an animated ancestor).
    pub fn has_tracks(&self) -> bool {
        self.translation_track.is_some()
            || self.rotation_track.is_some()
            || self.scale_track.is_some()
    }

    /// Length of this node's own loop in seconds: its animation's, or the last key of its
    /// channels.
    fn own_period(&self) -> f64 {
        let a = self.translation_track.as_ref().map_or(0.0, |t| t.end());
        let b = self.rotation_track.as_ref().map_or(0.0, |t| t.end());
        let c = self.scale_track.as_ref().map_or(0.0, |t| t.end());
        self.period.max(a).max(b).max(c)
    }

    /// Length of one loop in seconds: the longest of the node's and its ancestors'.
    pub fn duration(&self) -> f64 {
        let up = self.parent_motion.as_ref().map_or(0.0, |a| a.duration());
        self.own_period().max(up)
    }

    /// The node's local transform at `time` seconds, looping over its own period.
    fn local_at(&self, time: f64) -> DMat4 {
        let t = looped(time, self.own_period());
        let tr =
            self.translation_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.translation);
        let r = self.rotation_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.rotation);
        let s = self.scale_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.scale);
        DMat4::from_scale_rotation_translation(s, r.normalize(), tr)
    }

    /// World transform at `time` seconds, looping.
    pub fn world_at(&self, time: f64) -> DMat4 {
        let above = match &self.parent_motion {
            Some(a) => a.world_at(time) * self.parent,
            None => self.parent,
        };
        let m = above * self.local_at(time);
        if m.is_finite() { m } else { above }
    }
}

impl Track<f64> {
    /// A morph target weight at `time` seconds, looping over `period` (or the last key).
    pub fn weight_at(&self, time: f64, period: f64) -> Option<f64> {
        self.sample(looped(time, period.max(self.end())))
    }
}

/// `time` within a loop of `period` seconds (0 for no loop or a time that is not finite).
fn looped(time: f64, period: f64) -> f64 {
    if period > 0.0 && time.is_finite() { time.rem_euclid(period) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_tracks_interpolate_and_loop() {
        let a = Animation {
            translation_track: Some(Track {
                times: vec![0.0, 2.0],
                values: vec![DVec3::ZERO, DVec3::new(4.0, 0.0, 0.0)],
                step: false,
                tangents: vec![],
            }),
            ..Animation::rigid(
                DMat4::from_translation(DVec3::new(0.0, 10.0, 0.0)),
                DVec3::ZERO,
                DQuat::IDENTITY,
                DVec3::ONE,
            )
        };
        assert_eq!(a.duration(), 2.0);
        let p = a.world_at(0.5).transform_point3(DVec3::ZERO);
        assert!((p - DVec3::new(1.0, 10.0, 0.0)).length() < 1e-12, "{p}");
        let q = a.world_at(2.5).transform_point3(DVec3::ZERO);
        assert!((q - p).length() < 1e-12, "loops: {q}");
        assert!(a.world_at(f64::NAN).is_finite());
    }

    /// A node under an animated parent follows it: parent turning about Y over 4 s, the child
    /// 2 m out along the parent's X and sliding along it over 2 s (each looping over its own
    /// animation's period), a static offset between them.
    #[test]
    fn nested_animations_compose_through_their_ancestors() {
        let quarter = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let parent = Animation {
            rotation_track: Some(Track {
                times: vec![0.0, 4.0],
                values: vec![DQuat::IDENTITY, quarter],
                step: false,
                tangents: vec![],
            }),
            ..Animation::rigid(DMat4::IDENTITY, DVec3::ZERO, DQuat::IDENTITY, DVec3::ONE)
        };
        let child = Animation {
            parent_motion: Some(Arc::new(parent.clone())),
            translation_track: Some(Track {
                times: vec![0.0, 2.0],
                values: vec![DVec3::X, DVec3::new(3.0, 0.0, 0.0)],
                step: false,
                tangents: vec![],
            }),
            ..Animation::rigid(
                DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0)),
                DVec3::ZERO,
                DQuat::IDENTITY,
                DVec3::ONE,
            )
        };
        assert_eq!(child.duration(), 4.0);
        // At 3 s the parent has turned 67.5 degrees; the child is at x = 2 in its frame
        // (its own 2 s loop, 1 s in), 1 m up.
        let t = 3.0;
        let angle = 0.75 * std::f64::consts::FRAC_PI_2;
        let want = DQuat::from_rotation_y(angle) * DVec3::new(2.0, 1.0, 0.0);
        let got = child.world_at(t).transform_point3(DVec3::ZERO);
        assert!((got - want).length() < 1e-12, "{got} against {want}");
        // A node carried without channels of its own.
        let carried = Animation::carried(parent, DMat4::from_translation(DVec3::Z));
        let got = carried.world_at(4.0 - 1e-9).transform_point3(DVec3::ZERO);
        assert!((got - DVec3::X).length() < 1e-6, "{got}");
    }

    /// CUBICSPLINE against glTF 2.0 Appendix C's formula, written out for one interval:
    /// p(s) = (2s^3 - 3s^2 + 1) p0 + (s^3 - 2s^2 + s) dt b0 + (-2s^3 + 3s^2) p1 + (s^3 - s^2) dt a1.
    #[test]
    fn cubic_splines_follow_the_hermite_formula() {
        let (p0, p1) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 0.0));
        let (b0, a1) = (DVec3::new(3.0, 0.0, 0.0), DVec3::new(0.0, -2.0, 1.0));
        let track = Track {
            times: vec![1.0, 3.0],
            values: vec![p0, p1],
            step: false,
            tangents: vec![[DVec3::ZERO, b0], [a1, DVec3::ZERO]],
        };
        for t in [1.0, 1.5, 2.0, 2.7, 3.0] {
            let (s, dt) = ((t - 1.0) / 2.0, 2.0);
            let want = p0 * (2.0 * s * s * s - 3.0 * s * s + 1.0)
                + b0 * dt * (s * s * s - 2.0 * s * s + s)
                + p1 * (-2.0 * s * s * s + 3.0 * s * s)
                + a1 * dt * (s * s * s - s * s);
            let got = track.sample(t).unwrap();
            assert!((got - want).length() < 1e-12, "t = {t}: {got} against {want}");
        }
        // Not the linear interpolation: the tangents bend the path.
        assert!((track.sample(2.0).unwrap() - p0.lerp(p1, 0.5)).length() > 0.5);
        // Rotations: normalised, and the keys themselves at the keys.
        let q1 = DQuat::from_rotation_y(1.0);
        let r = Track {
            times: vec![0.0, 1.0],
            values: vec![DQuat::IDENTITY, q1],
            step: false,
            tangents: vec![[DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0); 2]; 2],
        };
        assert!((r.sample(0.4).unwrap().length() - 1.0).abs() < 1e-12);
        assert!(r.sample(1.0).unwrap().abs_diff_eq(q1, 1e-12));
    }
}
