//! `terrain:N`: a generated height field of about N triangles under the sun and sky, the scene
//! the trace benchmarks scale over (10k to millions of triangles) with nothing to load. Rolling
//! hills of summed sines plus a hashed jitter per vertex, so that no two triangles are coplanar
//! and the BVH has real work; the camera looks across it from above one corner, so rays meet
//! near and far triangles and grazing ones.

use super::default_scene::lambert;
use super::{Camera, Environment, Mesh, Object, Scene, sky};
use glam::{DMat4, DVec3, Vec2, Vec3};

/// The most triangles `terrain:N` makes (the scene limit is 2^24 - 1).
pub const MAX_TERRAIN_TRIANGLES: usize = 16_000_000;

/// `terrain:N` for N in 2..=MAX_TERRAIN_TRIANGLES, else None.
pub fn parse_terrain(name: &str) -> Option<Scene> {
    let n: usize = name.strip_prefix("terrain:")?.replace('_', "").parse().ok()?;
    (2..=MAX_TERRAIN_TRIANGLES).contains(&n).then(|| terrain(n))
}

/// A square grid of k x k quads (2k^2 triangles, k = round(sqrt(n / 2))) over 100 m x 100 m.
pub fn terrain(n: usize) -> Scene {
    let k = ((n as f64 / 2.0).sqrt().round() as u32).max(1);
    let size = 100.0f32;
    let height = |x: f32, z: f32, i: u32, j: u32| {
        let hills = 6.0 * (x * 0.07).sin() * (z * 0.05).cos()
            + 2.5 * (x * 0.23 + z * 0.17).sin()
            + 0.8 * (z * 0.61 - x * 0.4).cos();
        // A small hashed jitter per vertex (a tenth of the cell) so that neighbours differ.
        let mut h = i.wrapping_mul(0x9e37_79b9) ^ j.wrapping_mul(0x85eb_ca6b);
        h ^= h >> 15;
        h = h.wrapping_mul(0x2c1b_3c6d);
        h ^= h >> 12;
        hills + (h as f32 / u32::MAX as f32 - 0.5) * 0.1 * size / k as f32
    };
    let mut positions = Vec::with_capacity(((k + 1) * (k + 1)) as usize);
    let mut uvs = Vec::with_capacity(positions.capacity());
    for j in 0..=k {
        for i in 0..=k {
            let (u, v) = (i as f32 / k as f32, j as f32 / k as f32);
            let (x, z) = ((u - 0.5) * size, (v - 0.5) * size);
            positions.push(Vec3::new(x, height(x, z, i, j), z));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut indices = Vec::with_capacity((k * k * 6) as usize);
    for j in 0..k {
        for i in 0..k {
            let a = j * (k + 1) + i;
            let (b, c, d) = (a + 1, a + k + 1, a + k + 2);
            // Counter-clockwise seen from above (+Y).
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    // Smooth normals: the area-weighted sum of the faces around each vertex.
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let (a, b, c) =
            (positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]);
        let n = (b - a).cross(c - a);
        for &v in t {
            normals[v as usize] += n;
        }
    }
    let normals = normals.into_iter().map(|n| n.normalize_or(Vec3::Y)).collect();
    let mesh = Mesh { positions, normals, uvs, indices, material: 0, ..Default::default() };
    let (sun, sky) = sky::sun_and_sky(Vec3::new(0.4, -0.6, 0.5).normalize());
    Scene {
        name: format!("terrain:{n}"),
        meshes: vec![mesh],
        objects: vec![Object {
            name: "terrain".into(),
            mesh: 0,
            transform: DMat4::IDENTITY,
            animation: None,
            deform: None,
        }],
        materials: vec![lambert("ground", Vec3::new(0.45, 0.4, 0.3))],
        textures: vec![],
        lights: vec![sun],
        camera: Some(Camera::look_at(
            DVec3::new(-45.0, 25.0, 45.0),
            DVec3::new(10.0, 0.0, -10.0),
            60.0,
        )),
        environment: Environment::Map(sky),
        resolution: Some((640, 360)),
        max_depth: super::DEFAULT_MAX_DEPTH,
        warnings: vec![],
        procedural_sky: true,
        animations: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terrain_has_about_the_triangles_asked_for() {
        for n in [2usize, 10_000, 100_000] {
            let s = parse_terrain(&format!("terrain:{n}")).unwrap();
            let t = s.triangle_count();
            assert!((t as f64 - n as f64).abs() <= 0.02 * n as f64 + 2.0, "{n}: {t}");
            assert_eq!(s.meshes[0].normals.len(), s.meshes[0].positions.len());
        }
        assert!(
            parse_terrain("terrain:1").is_none()
                && parse_terrain("terrain:x").is_none()
                && parse_terrain("terrain:20000000").is_none()
        );
    }
}
