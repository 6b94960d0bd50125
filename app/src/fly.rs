//! Fly camera: WASD to move, Q/E down/up, right-drag to look, wheel for speed, shift to run.

use glam::DVec3;
use hush_engine::scene::{Camera, ThinLens};
use std::collections::HashSet;
use winit::keyboard::KeyCode;

pub struct FlyCamera {
    pub pos: DVec3,
    /// Radians; yaw 0 looks down -Z, pitch 0 is level.
    pub yaw: f64,
    pub pitch: f64,
    pub yfov: f32,
    /// Scene units per second; starts at a tenth of the scene's extent.
    pub speed: f64,
    pub held: HashSet<KeyCode>,
    pub looking: bool,
    /// Depth of field (the side panel sets it; None: a pinhole).
    pub lens: Option<ThinLens>,
}

impl FlyCamera {
    pub fn from_camera(c: &Camera, extent: f64) -> FlyCamera {
        let fwd = -c.world.z_axis.truncate().normalize_or(DVec3::NEG_Z);
        FlyCamera {
            pos: c.eye(),
            yaw: fwd.x.atan2(-fwd.z),
            pitch: fwd.y.clamp(-1.0, 1.0).asin(),
            yfov: c.yfov,
            speed: (extent * 0.1).max(1e-6),
            held: HashSet::new(),
            looking: false,
            lens: c.lens,
        }
    }

    pub fn forward(&self) -> DVec3 {
        DVec3::new(
            self.yaw.sin() * self.pitch.cos(),
            self.pitch.sin(),
            -self.yaw.cos() * self.pitch.cos(),
        )
    }

    pub fn camera(&self) -> Camera {
        Camera {
            lens: self.lens,
            ..Camera::look_at(self.pos, self.pos + self.forward(), self.yfov.to_degrees())
        }
    }

    /// Position, yaw and pitch: what a frame's motion blur interpolates.
    pub fn pose(&self) -> (DVec3, f64, f64) {
        (self.pos, self.yaw, self.pitch)
    }

    /// The camera a fraction `s` of the way from `from` (an earlier pose) to this one.
    pub fn camera_between(&self, from: (DVec3, f64, f64), s: f64) -> Camera {
        let f = FlyCamera {
            pos: from.0.lerp(self.pos, s),
            yaw: from.1 + (self.yaw - from.1) * s,
            pitch: from.2 + (self.pitch - from.2) * s,
            yfov: self.yfov,
            speed: self.speed,
            held: HashSet::new(),
            looking: false,
            lens: self.lens,
        };
        f.camera()
    }

    /// Right-drag: radians per pixel of mouse motion.
    pub fn look(&mut self, dx: f64, dy: f64) {
        self.yaw += dx * 0.003;
        self.pitch = (self.pitch - dy * 0.003).clamp(-1.55, 1.55);
    }

    pub fn wheel(&mut self, steps: f64) {
        self.speed = (self.speed * 1.2f64.powf(steps)).clamp(1e-9, 1e9);
    }

    /// Move for `dt` seconds; returns whether the camera moved.
    pub fn update(&mut self, dt: f64) -> bool {
        let k = |c: KeyCode| if self.held.contains(&c) { 1.0 } else { 0.0 };
        let f = self.forward();
        let right = f.cross(DVec3::Y).normalize_or(DVec3::X);
        let dir = f * (k(KeyCode::KeyW) - k(KeyCode::KeyS))
            + right * (k(KeyCode::KeyD) - k(KeyCode::KeyA))
            + DVec3::Y * (k(KeyCode::KeyE) - k(KeyCode::KeyQ));
        if dir == DVec3::ZERO {
            return false;
        }
        let run = if self.held.contains(&KeyCode::ShiftLeft)
            || self.held.contains(&KeyCode::ShiftRight)
        {
            4.0
        } else {
            1.0
        };
        self.pos += dir.normalize() * self.speed * run * dt.min(0.25);
        true
    }
}
