//! Rigid node animation: glTF's translation / rotation / scale channels, sampled in f64 and looped
//! over the longest channel. Only what moves an object is modelled (no skins, no morph targets).

use glam::{DMat4, DQuat, DVec3};

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

/// A node's animated local transform and the static transform of its parents.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub parent: DMat4,
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
    /// Length of one loop in seconds (the last key of any channel).
    pub fn duration(&self) -> f64 {
        let a = self.translation_track.as_ref().map_or(0.0, |t| t.end());
        let b = self.rotation_track.as_ref().map_or(0.0, |t| t.end());
        let c = self.scale_track.as_ref().map_or(0.0, |t| t.end());
        a.max(b).max(c)
    }

    /// World transform at `time` seconds, looping.
    pub fn world_at(&self, time: f64) -> DMat4 {
        let d = self.duration();
        let t = if d > 0.0 && time.is_finite() { time.rem_euclid(d) } else { 0.0 };
        let tr =
            self.translation_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.translation);
        let r = self.rotation_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.rotation);
        let s = self.scale_track.as_ref().and_then(|k| k.sample(t)).unwrap_or(self.scale);
        let local = DMat4::from_scale_rotation_translation(s, r.normalize(), tr);
        let m = self.parent * local;
        if m.is_finite() { m } else { self.parent }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_tracks_interpolate_and_loop() {
        let a = Animation {
            parent: DMat4::from_translation(DVec3::new(0.0, 10.0, 0.0)),
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
            translation_track: Some(Track {
                times: vec![0.0, 2.0],
                values: vec![DVec3::ZERO, DVec3::new(4.0, 0.0, 0.0)],
                step: false,
                tangents: vec![],
            }),
            rotation_track: None,
            scale_track: None,
        };
        assert_eq!(a.duration(), 2.0);
        let p = a.world_at(0.5).transform_point3(DVec3::ZERO);
        assert!((p - DVec3::new(1.0, 10.0, 0.0)).length() < 1e-12, "{p}");
        let q = a.world_at(2.5).transform_point3(DVec3::ZERO);
        assert!((q - p).length() < 1e-12, "loops: {q}");
        assert!(a.world_at(f64::NAN).is_finite());
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
