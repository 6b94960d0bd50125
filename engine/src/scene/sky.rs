//! The sun + sky preset a scene without lights gets.

use super::{EnvMap, Light};
use glam::Vec3;

/// A directional sun travelling along `sun_dir` and a sky dome map: blue at the zenith, brighter
/// towards the horizon and around the sun, a dim ground below. Radiometric values are chosen so
/// the sun's irradiance (5 W/m^2) dominates the sky's (about 1 W/m^2 on a horizontal surface), as
/// on a clear day.
pub fn sun_and_sky(sun_dir: Vec3) -> (Light, EnvMap) {
    let sun = Light::Directional { direction: sun_dir, irradiance: Vec3::new(5.0, 4.7, 4.2) };
    let (w, h) = (128u32, 64u32);
    let to_sun = -sun_dir;
    let mut rgb = Vec::with_capacity((w * h) as usize);
    for row in 0..h {
        for col in 0..w {
            let u = (col as f32 + 0.5) / w as f32;
            let v = (row as f32 + 0.5) / h as f32;
            let (st, ct) = (std::f32::consts::PI * v).sin_cos();
            let (sp, cp) = (2.0 * std::f32::consts::PI * u).sin_cos();
            let d = Vec3::new(sp * st, ct, -cp * st);
            let c = if d.y >= 0.0 {
                let zenith = Vec3::new(0.12, 0.22, 0.45);
                let horizon = Vec3::new(0.45, 0.5, 0.55);
                let t = (1.0 - d.y).powi(3);
                let glow = d.dot(to_sun).max(0.0).powi(16) * 0.6;
                zenith.lerp(horizon, t) + Vec3::new(1.0, 0.85, 0.6) * glow
            } else {
                Vec3::new(0.08, 0.07, 0.06)
            };
            rgb.push(c);
        }
    }
    (sun, EnvMap { width: w, height: h, rgb, rotation_y_degrees: 0.0 })
}
