//! The scene built into Hush: a simple room lit by a ceiling panel and, through an opening in the
//! back wall, by the sun and the sky. It exercises the matte and glossy lobes, an area light, a
//! directional light and the environment map, with no files to load.

use super::{Camera, Environment, Material, Mesh, Object, Scene, sky};
use glam::{DMat4, DVec3, Vec2, Vec3, Vec4};

pub(super) fn lambert(name: &str, c: Vec3) -> Material {
    Material {
        name: name.into(),
        base_color: c.extend(1.0),
        metallic: 0.0,
        roughness: 1.0,
        specular_factor: 0.0,
        ..Default::default()
    }
}

pub(super) fn metal(name: &str, c: Vec3, roughness: f32) -> Material {
    Material {
        name: name.into(),
        base_color: c.extend(1.0),
        metallic: 1.0,
        roughness,
        ..Default::default()
    }
}

/// The quad centre ± u ± v, facing u x v (CCW winding seen from that side). Also for tests'
/// synthetic scenes.
pub fn quad(center: Vec3, u: Vec3, v: Vec3, material: u32) -> Mesh {
    let n = u.cross(v).normalize();
    let positions = vec![center - u - v, center + u - v, center + u + v, center - u + v];
    Mesh {
        positions,
        normals: vec![n; 4],
        uvs: vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Default::default()
    }
}

/// An axis-aligned box: `center` ± `half`, six quads facing out.
pub fn cuboid(center: Vec3, half: Vec3, material: u32) -> Mesh {
    let mut m = Mesh { material, ..Default::default() };
    let faces = [
        (Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (n, u, v) in faces {
        // u x v must equal n for CCW winding seen from outside.
        let (u, v) = if u.cross(v).dot(n) > 0.0 { (u, v) } else { (v, u) };
        let q = quad(center + n * half, u * half, v * half, material);
        let base = m.positions.len() as u32;
        m.positions.extend(q.positions);
        m.normals.extend(q.normals);
        m.uvs.extend(q.uvs);
        m.indices.extend(q.indices.iter().map(|i| i + base));
    }
    m
}

pub fn uv_sphere(center: Vec3, r: f32, material: u32, seg: u32, rings: u32) -> Mesh {
    let mut m = Mesh { material, ..Default::default() };
    for j in 0..=rings {
        let th = std::f32::consts::PI * j as f32 / rings as f32;
        for i in 0..=seg {
            let ph = 2.0 * std::f32::consts::PI * i as f32 / seg as f32;
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin());
            m.positions.push(center + n * r);
            m.normals.push(n);
            m.uvs.push(Vec2::new(i as f32 / seg as f32, j as f32 / rings as f32));
        }
    }
    for j in 0..rings {
        for i in 0..seg {
            let a = j * (seg + 1) + i;
            let b = a + seg + 1;
            // The rings at the poles collapse to a point: one triangle per quad there.
            if j > 0 {
                m.indices.extend([a, b, a + 1]);
            }
            if j + 1 < rings {
                m.indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// The built-in scene (`hush-cli render default`, and the viewer with no argument).
pub fn default_scene() -> Scene {
    let materials = vec![
        lambert("white", Vec3::new(0.75, 0.73, 0.7)),
        lambert("terracotta", Vec3::new(0.65, 0.25, 0.12)),
        lambert("teal", Vec3::new(0.1, 0.4, 0.38)),
        Material { emission: Vec3::new(12.0, 11.0, 9.0), ..lambert("panel", Vec3::splat(0.8)) },
        metal("brass", Vec3::new(0.95, 0.78, 0.45), 0.25),
        metal("mirror", Vec3::ONE, 0.0),
        Material {
            name: "glossy floor".into(),
            base_color: Vec4::new(0.35, 0.32, 0.3, 1.0),
            metallic: 0.0,
            roughness: 0.15,
            ..Default::default()
        },
    ];
    let (w, h, d) = (2.5f32, 1.5f32, 2.5f32);
    let mut meshes = vec![
        quad(Vec3::new(0.0, 0.0, 0.0), Vec3::new(w, 0.0, 0.0), Vec3::new(0.0, 0.0, -d), 6),
        quad(Vec3::new(0.0, 2.0 * h, 0.0), Vec3::new(w, 0.0, 0.0), Vec3::new(0.0, 0.0, d), 0),
        quad(Vec3::new(-w, h, 0.0), Vec3::new(0.0, 0.0, -d), Vec3::new(0.0, h, 0.0), 1),
        quad(Vec3::new(w, h, 0.0), Vec3::new(0.0, 0.0, d), Vec3::new(0.0, h, 0.0), 2),
        // Ceiling panel facing down, just below the ceiling.
        quad(
            Vec3::new(0.0, 2.0 * h - 0.01, 0.3),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.3),
            3,
        ),
        cuboid(Vec3::new(-1.0, 0.6, -0.8), Vec3::new(0.4, 0.6, 0.4), 0),
        uv_sphere(Vec3::new(0.9, 0.55, -0.4), 0.55, 4, 48, 24),
        uv_sphere(Vec3::new(-0.1, 0.3, 0.6), 0.3, 5, 32, 16),
    ];
    // The back wall has a window: four quads around a 1.6 x 1.0 opening.
    let (wx, wy0, wy1) = (0.8f32, 1.2f32, 2.2f32);
    let back = |x0: f32, x1: f32, y0: f32, y1: f32| {
        let c = Vec3::new((x0 + x1) * 0.5, (y0 + y1) * 0.5, -d);
        quad(c, Vec3::new((x1 - x0) * 0.5, 0.0, 0.0), Vec3::new(0.0, (y1 - y0) * 0.5, 0.0), 0)
    };
    meshes.push(back(-w, -wx, 0.0, 2.0 * h));
    meshes.push(back(wx, w, 0.0, 2.0 * h));
    meshes.push(back(-wx, wx, 0.0, wy0));
    meshes.push(back(-wx, wx, wy1, 2.0 * h));
    // Sun from behind the room, through the window, onto the floor.
    let (sun, sky) = sky::sun_and_sky(Vec3::new(0.3, -0.55, 0.78).normalize());
    let objects = (0..meshes.len())
        .map(|i| Object {
            name: format!("part{i}"),
            mesh: i,
            transform: DMat4::IDENTITY,
            animation: None,
            deform: None,
        })
        .collect();
    Scene {
        name: "default".into(),
        meshes,
        objects,
        materials,
        textures: vec![],
        lights: vec![sun],
        camera: Some(Camera::look_at(DVec3::new(0.0, 1.4, 4.8), DVec3::new(0.0, 1.1, 0.0), 55.0)),
        environment: Environment::Map(sky),
        resolution: Some((640, 360)),
        max_depth: super::DEFAULT_MAX_DEPTH,
        warnings: vec![],
        procedural_sky: true,
        animations: vec![],
    }
}
