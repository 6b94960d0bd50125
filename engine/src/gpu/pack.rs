//! Packing lights, the environment map's sampling tables and textures into the layouts the
//! shaders read (`shaders/common/lights.wgsl`, `env_map.wgsl`, `textures.wgsl`).

use crate::scene::{Light, Scene, Wrap, mip_chain_texels};
use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

/// A light as shaders/common/lights.wgsl reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    pub pos: [f32; 3],
    pub kind: u32,
    pub dir: [f32; 3],
    pub cos_outer: f32,
    pub intensity: [f32; 3],
    pub cos_inner: f32,
}

pub(super) fn pack_light(l: &Light, origin: DVec3) -> GpuLight {
    match *l {
        Light::Directional { direction, irradiance } => GpuLight {
            pos: [0.0; 3],
            kind: 0,
            dir: direction.normalize_or(Vec3::NEG_Y).to_array(),
            cos_outer: 0.0,
            intensity: irradiance.to_array(),
            cos_inner: 0.0,
        },
        Light::Point { position, intensity } => GpuLight {
            pos: (position - origin).as_vec3().to_array(),
            kind: 1,
            dir: [0.0, 0.0, -1.0],
            cos_outer: 0.0,
            intensity: intensity.to_array(),
            cos_inner: 0.0,
        },
        Light::Spot { position, direction, intensity, inner_cone, outer_cone } => GpuLight {
            pos: (position - origin).as_vec3().to_array(),
            kind: 2,
            dir: direction.normalize_or(Vec3::NEG_Z).to_array(),
            cos_outer: outer_cone.cos(),
            intensity: intensity.to_array(),
            cos_inner: inner_cone.cos(),
        },
    }
}

#[derive(Default)]
pub(super) struct EnvPack {
    pub data: Vec<f32>,
    pub radiance: Vec3,
    pub size: [u32; 4],
    pub rotation: f32,
    pub pdf_norm: f32,
}

impl EnvPack {
    /// Texels, marginal CDF over rows, conditional CDFs over columns of luminance x sin(theta).
    /// Returns false for a map with no energy (rendered as no environment).
    pub fn pack_map(&mut self, map: &crate::scene::EnvMap) -> bool {
        let (w, h) = (map.width as usize, map.height as usize);
        let mut data: Vec<f32> = map.rgb.iter().flat_map(|c| c.to_array()).collect();
        let moff = data.len();
        let coff = moff + h + 1;
        let mut rows = vec![0f64; h];
        let mut cond = vec![0f32; h * (w + 1)];
        for r in 0..h {
            let s = (std::f64::consts::PI * (r as f64 + 0.5) / h as f64).sin();
            let mut acc = 0f64;
            let f: Vec<f64> =
                (0..w).map(|c| crate::quality::luminance(map.rgb[r * w + c]) as f64 * s).collect();
            let sum: f64 = f.iter().sum();
            for c in 0..w {
                acc += f[c];
                cond[r * (w + 1) + c + 1] =
                    if sum > 0.0 { (acc / sum) as f32 } else { (c + 1) as f32 / w as f32 };
            }
            cond[r * (w + 1) + w] = 1.0;
            rows[r] = sum;
        }
        let total: f64 = rows.iter().sum();
        if !(total > 0.0) || !total.is_finite() {
            log::warn!("environment map carries no light; rendering without it");
            return false;
        }
        data.push(0.0);
        let mut acc = 0f64;
        for (r, row) in rows.iter().enumerate().take(h) {
            acc += row;
            data.push(if r + 1 == h { 1.0 } else { (acc / total) as f32 });
        }
        data.extend_from_slice(&cond);
        self.data = data;
        self.size = [w as u32, h as u32, moff as u32, coff as u32];
        self.rotation = map.rotation_y_degrees;
        self.pdf_norm = ((w * h) as f64 / (total * 2.0 * std::f64::consts::PI.powi(2))) as f32;
        true
    }
}

/// All textures share one storage buffer; it must fit the 128 MiB binding every WebGPU adapter
/// offers. Over that budget the largest textures are halved until the set fits.
pub const TEXTURE_BUDGET_BYTES: usize = 128 << 20;

/// Bits of a texture header's flags word (shaders/common/textures.wgsl) from which the number
/// of mip levels below the base is stored; the levels follow the base level's texels.
pub const TEX_MIPS_SHIFT: u32 = 6;

pub(super) fn pack_textures(scene: &Scene) -> Vec<u32> {
    let n = scene.textures.len();
    let mut textures: Vec<std::borrow::Cow<crate::scene::Texture>> =
        scene.textures.iter().map(std::borrow::Cow::Borrowed).collect();
    // Each texture with its mip chain (a third more).
    let bytes = |t: &[std::borrow::Cow<crate::scene::Texture>]| {
        n * 16 + t.iter().map(|t| mip_chain_texels(t.width, t.height) * 4).sum::<usize>()
    };
    let before = bytes(&textures);
    while bytes(&textures) > TEXTURE_BUDGET_BYTES {
        let largest = (0..n).max_by_key(|&i| textures[i].rgba8.len()).unwrap_or(0);
        if textures[largest].width <= 1 && textures[largest].height <= 1 {
            break;
        }
        let Some(half) = textures[largest].halved() else {
            log::error!("texture {:?}: its texels do not fill its size", textures[largest].name);
            break;
        };
        textures[largest] = std::borrow::Cow::Owned(half);
    }
    if bytes(&textures) != before {
        log::warn!(
            "textures need {} MiB; halved the largest to fit {} MiB",
            before >> 20,
            TEXTURE_BUDGET_BYTES >> 20
        );
    }
    let mut data = vec![0u32; n * 4];
    for (i, t) in textures.iter().enumerate() {
        let wrap = |w: Wrap| match w {
            Wrap::Repeat => 0u32,
            Wrap::Clamp => 1,
            Wrap::Mirror => 2,
        };
        data[i * 4] = data.len() as u32;
        data[i * 4 + 1] = t.width;
        data[i * 4 + 2] = t.height;
        let mips = t.mips();
        data[i * 4 + 3] = (t.srgb as u32)
            | (wrap(t.wrap_s) << 1)
            | (wrap(t.wrap_t) << 3)
            | ((t.nearest as u32) << 5)
            | ((mips.len() as u32) << TEX_MIPS_SHIFT);
        let words = |b: &[u8]| {
            b.chunks_exact(4)
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect::<Vec<_>>()
        };
        data.extend(words(&t.rgba8));
        for (_, _, level) in &mips {
            data.extend(words(level));
        }
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Texture, Wrap};

    #[test]
    fn textures_over_the_binding_budget_are_halved_to_fit() {
        let side = 5800u32; // 5800² x 4 bytes = 134.6 MB > 128 MiB
        let big = Texture {
            name: "big".into(),
            width: side,
            height: side,
            rgba8: vec![128; (side * side * 4) as usize],
            srgb: true,
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            nearest: false,
        };
        let small = Texture {
            name: "small".into(),
            width: 4,
            height: 2,
            rgba8: vec![7; 32],
            ..big.clone()
        };
        let scene = Scene { textures: vec![big, small], ..Default::default() };
        let data = pack_textures(&scene);
        assert!(data.len() * 4 <= TEXTURE_BUDGET_BYTES, "{} bytes", data.len() * 4);
        // The large one was halved, the small one kept; headers point at the texels.
        assert_eq!((data[1], data[2]), (side / 2, side / 2));
        assert_eq!((data[5], data[6]), (4, 2));
        assert_eq!(data[4] as usize, 8 + mip_chain_texels(side / 2, side / 2));
        assert_eq!(data[data[4] as usize], u32::from_le_bytes([7; 4]));
    }
}
