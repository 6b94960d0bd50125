//! Rigid node animation: glTF's translation / rotation / scale channels, sampled in f64 and looped
//! over the longest channel. Only what moves an object is modelled (no skins, no morph targets).

use glam::{DMat4, DQuat, DVec3};

/// One keyframed property. `step` is glTF's STEP interpolation; otherwise LINEAR (slerp for
/// rotations). CUBICSPLINE input is reduced to its keyframe values on import.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    pub times: Vec<f64>,
    pub values: Vec<T>,
    pub step: bool,
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
}

impl Lerp for DVec3 {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        self.lerp(other, t)
    }
}

impl Lerp for DQuat {
    fn lerp_to(self, other: Self, t: f64) -> Self {
        self.slerp(other, t).normalize()
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
        Some(self.values[k - 1].lerp_to(self.values[k], (t - t0) / (t1 - t0)))
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
}
