use anyhow::{Context, Result, bail};
use glam::Vec3;

/// Light arriving from infinitely far away.
#[derive(Clone, Debug, Default)]
pub enum Environment {
    #[default]
    None,
    /// Uniform radiance from every direction.
    Constant(Vec3),
    /// An equirectangular (latitude-longitude) map.
    Map(EnvMap),
}

/// Equirectangular radiance, Mitsuba's mapping (README "Environment map orientation"):
/// column u from the left, row v from the top, local l = (sin 2πu sin πv, cos πv, -cos 2πu sin πv),
/// world = R_y(rotation) l.
#[derive(Clone, Debug)]
pub struct EnvMap {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major from the top row; already multiplied by `intensity`.
    pub rgb: Vec<Vec3>,
    pub rotation_y_degrees: f32,
}

impl EnvMap {
    /// An equirectangular map from EXR bytes, decoded within `budget` (see
    /// [`crate::image_io::decode_exr`]).
    pub fn from_exr(
        name: &str,
        bytes: &[u8],
        intensity: f32,
        rotation_y_degrees: f32,
        budget: &mut crate::limits::Budget,
    ) -> Result<EnvMap> {
        let (width, height, rgb) = crate::image_io::decode_exr(name, bytes, budget)
            .with_context(|| format!("reading environment map {name}"))?;
        if width == 0 || height == 0 {
            bail!("environment map {name} is empty");
        }
        let rgb = rgb
            .into_iter()
            .map(|c| {
                let c = c * intensity;
                // Non-finite or negative texels would poison importance sampling: treat as black.
                if c.is_finite() { c.max(Vec3::ZERO) } else { Vec3::ZERO }
            })
            .collect();
        Ok(EnvMap { width, height, rgb, rotation_y_degrees })
    }
}
