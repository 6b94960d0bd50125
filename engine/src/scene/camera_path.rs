//! Camera paths: what the viewer records (one key per frame) and what `hush-cli render
//! --camera-path` and the viewer play back. JSON:
//! `{"keys": [{"time": 0.0, "eye": [x, y, z], "target": [x, y, z], "yfov_degrees": 45.0}, ...]}`
//! with `time` in seconds (the scene's animation clock) and positions in scene units; a key may
//! add `"lens": {"aperture_radius": r, "focus_distance": d}` (meters) for a thin lens.

use super::Camera;
use anyhow::{Context, Result, bail};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CameraKey {
    pub time: f64,
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub yfov_degrees: f32,
    /// The thin lens the camera had (depth of field); absent: a pinhole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens: Option<KeyLens>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KeyLens {
    pub aperture_radius: f32,
    pub focus_distance: f32,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CameraPath {
    pub keys: Vec<CameraKey>,
}

impl CameraKey {
    pub fn from_camera(camera: &Camera, time: f64) -> CameraKey {
        let eye = camera.eye();
        let fwd = -camera.world.z_axis.truncate().normalize_or(DVec3::NEG_Z);
        let lens = camera.lens.map(|l| KeyLens {
            aperture_radius: l.aperture_radius,
            focus_distance: l.focus_distance,
        });
        CameraKey {
            time,
            eye: eye.to_array(),
            target: (eye + fwd).to_array(),
            yfov_degrees: camera.yfov.to_degrees(),
            lens,
        }
    }

    /// The key's camera (a lens that [`CameraPath::validate`] would refuse is left out).
    pub fn camera(&self) -> Camera {
        let lens = self.lens.and_then(|l| {
            super::ThinLens::new(l.aperture_radius as f64, l.focus_distance as f64).ok()
        });
        Camera {
            lens,
            ..Camera::look_at(
                DVec3::from_array(self.eye),
                DVec3::from_array(self.target),
                self.yfov_degrees,
            )
        }
    }
}

impl CameraPath {
    pub fn load(path: &Path) -> Result<CameraPath> {
        let ctx = || format!("reading camera path {}", path.display());
        let text = crate::limits::read_text_file(path).with_context(ctx)?;
        let p: CameraPath = serde_json::from_str(&text).with_context(ctx)?;
        p.validate().with_context(ctx)?;
        Ok(p)
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)?;
        std::fs::write(path, text)
            .with_context(|| format!("writing camera path {}", path.display()))
    }

    pub fn validate(&self) -> Result<()> {
        if self.keys.is_empty() {
            bail!("the camera path has no keys");
        }
        for (i, k) in self.keys.iter().enumerate() {
            let finite = k.time.is_finite() && k.eye.iter().chain(&k.target).all(|x| x.is_finite());
            if !finite {
                bail!("key {i}: non-finite time or position");
            }
            if k.eye == k.target {
                bail!("key {i}: eye and target coincide");
            }
            if !(k.yfov_degrees > 0.0 && k.yfov_degrees < 180.0) {
                bail!("key {i}: yfov_degrees must be in (0, 180), got {}", k.yfov_degrees);
            }
            if let Some(l) = k.lens {
                super::ThinLens::new(l.aperture_radius as f64, l.focus_distance as f64)
                    .with_context(|| format!("key {i}: lens"))?;
            }
        }
        Ok(())
    }

    /// The camera at `time`: eye, target and field of view interpolated linearly between the
    /// two keys around it (held before the first and after the last). Motion blur asks for the
    /// camera at the shutter's open, between keys.
    pub fn camera_at(&self, time: f64) -> Camera {
        let i = self.keys.partition_point(|k| k.time <= time);
        if i == 0 || i == self.keys.len() {
            return self.keys[i.min(self.keys.len() - 1)].camera();
        }
        let (a, b) = (&self.keys[i - 1], &self.keys[i]);
        let t = if b.time > a.time { (time - a.time) / (b.time - a.time) } else { 1.0 };
        let mix = |p: [f64; 3], q: [f64; 3]| DVec3::from_array(p).lerp(DVec3::from_array(q), t);
        Camera {
            lens: a.camera().lens,
            ..Camera::look_at(
                mix(a.eye, b.eye),
                mix(a.target, b.target),
                a.yfov_degrees + (b.yfov_degrees - a.yfov_degrees) * t as f32,
            )
        }
    }

    /// The key for frame `i` (the last key holds once the path has ended).
    pub fn frame(&self, i: usize) -> &CameraKey {
        &self.keys[i.min(self.keys.len() - 1)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A key keeps the camera's thin lens through JSON; between keys the camera moves linearly
    /// in time (motion blur asks for it there); a bad lens is an error naming the key.
    #[test]
    fn keys_keep_the_lens_and_interpolate_in_time() {
        let lens = crate::scene::ThinLens::new(0.05, 2.5).unwrap();
        let a = Camera {
            lens: Some(lens),
            ..Camera::look_at(DVec3::new(0.0, 1.0, 4.0), DVec3::new(0.0, 1.0, 0.0), 45.0)
        };
        let b = Camera {
            lens: Some(lens),
            ..Camera::look_at(DVec3::new(2.0, 1.0, 4.0), DVec3::new(2.0, 1.0, 0.0), 45.0)
        };
        let path = CameraPath {
            keys: vec![CameraKey::from_camera(&a, 1.0), CameraKey::from_camera(&b, 2.0)],
        };
        let back: CameraPath =
            serde_json::from_str(&serde_json::to_string(&path).unwrap()).unwrap();
        assert_eq!(back, path);
        assert_eq!(back.keys[0].camera().lens, Some(lens));
        let mid = back.camera_at(1.25);
        assert!((mid.eye() - DVec3::new(0.5, 1.0, 4.0)).length() < 1e-9, "{}", mid.eye());
        assert_eq!(mid.lens, Some(lens));
        assert!(
            (back.camera_at(0.0).eye() - a.eye()).length() < 1e-9
                && (back.camera_at(9.0).eye() - b.eye()).length() < 1e-9
        );
        let mut bad = path.clone();
        bad.keys[1].lens = Some(KeyLens { aperture_radius: 0.05, focus_distance: -1.0 });
        assert!(format!("{:#}", bad.validate().unwrap_err()).contains("key 1"));
    }
}
