//! The default level of the viewer: a small courtyard with an arcade of pillars and arches, a
//! closed hall behind it lit mostly indirectly (sun and sky through its doorway and windows, as
//! in the hard case of Mara et al. §4), a polished floor, a mirror, rough metals at four
//! roughnesses, emissive strips, procedural textures and one animated object. Built in code (no
//! files), so it loads in milliseconds; `hush-cli level` writes it as glTF.

use super::default_scene::{cuboid, lambert, metal, quad, uv_sphere};
use super::{
    Animation, Camera, Environment, Material, Mesh, Object, Scene, Texture, TextureRef, Track,
    Wrap, sky,
};
use glam::{DMat4, DQuat, DVec3, Vec2, Vec3};

/// A procedural texture: `f(x, y)` -> sRGB bytes.
pub(super) fn texture(
    name: &str,
    size: u32,
    srgb: bool,
    f: impl Fn(u32, u32) -> [u8; 4],
) -> Texture {
    let mut rgba8 = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            rgba8.extend_from_slice(&f(x, y));
        }
    }
    Texture {
        name: name.into(),
        width: size,
        height: size,
        rgba8,
        srgb,
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        nearest: false,
    }
}

pub(super) fn checker(x: u32, y: u32) -> [u8; 4] {
    // Two marble-ish tones with a thin grout line.
    let (cx, cy) = (x / 32, y / 32);
    if x.is_multiple_of(32) || y.is_multiple_of(32) {
        return [70, 66, 60, 255];
    }
    if (cx + cy).is_multiple_of(2) { [210, 204, 192, 255] } else { [120, 112, 100, 255] }
}

pub(super) fn bricks(x: u32, y: u32) -> [u8; 4] {
    let row = y / 16;
    let off = if row.is_multiple_of(2) { 0 } else { 16 };
    let mortar = y.is_multiple_of(16) || (x + off).is_multiple_of(32);
    // A little per-brick variation from a hash of the brick's index.
    let id = row * 131 + (x + off) / 32;
    let v = ((id.wrapping_mul(2654435761) >> 24) % 30) as u8;
    if mortar { [185, 180, 170, 255] } else { [150 + v, 78 + v / 2, 56, 255] }
}

/// Scale a mesh's texture coordinates (tiling).
pub(super) fn tiled(mut m: Mesh, s: Vec2) -> Mesh {
    for uv in &mut m.uvs {
        *uv *= s;
    }
    m
}

/// The default level. `sun_dir` is the direction the sunlight travels.
pub fn default_level_with_sun(sun_dir: Vec3) -> Scene {
    let mut materials = vec![
        Material {
            base_color_texture: Some(TextureRef::new(0)),
            roughness: 0.12,
            ..lambert("polished floor", Vec3::ONE)
        },
        Material { base_color_texture: Some(TextureRef::new(1)), ..lambert("brick", Vec3::ONE) },
        lambert("plaster", Vec3::new(0.78, 0.75, 0.7)),
        lambert("stone", Vec3::new(0.55, 0.52, 0.48)),
        metal("mirror", Vec3::ONE, 0.0),
        metal("gold r0.05", Vec3::new(1.0, 0.78, 0.34), 0.05),
        metal("copper r0.2", Vec3::new(0.95, 0.64, 0.54), 0.2),
        metal("steel r0.4", Vec3::new(0.56, 0.57, 0.58), 0.4),
        metal("iron r0.7", Vec3::new(0.53, 0.51, 0.49), 0.7),
        Material { emission: Vec3::new(6.0, 4.2, 2.4), ..lambert("warm strip", Vec3::splat(0.9)) },
        Material { emission: Vec3::new(2.0, 4.0, 6.5), ..lambert("cool strip", Vec3::splat(0.9)) },
        Material { roughness: 0.35, ..lambert("red lacquer", Vec3::new(0.6, 0.08, 0.06)) },
    ];
    // Lacquer and floor are dielectrics with the default 4% specular lobe.
    for m in &mut materials {
        if m.name == "red lacquer" || m.name == "polished floor" {
            m.specular_factor = 1.0;
        }
    }
    let textures =
        vec![texture("checker", 256, true, checker), texture("bricks", 128, true, bricks)];
    let (floor, brick, plaster, stone, mirror) = (0, 1, 2, 3, 4);
    let mut meshes: Vec<Mesh> = vec![];
    let mut add = |m: Mesh| meshes.push(m);

    // Courtyard floor (12 x 12 m) and the hall's floor behind it (z from -6 to -14).
    add(tiled(
        quad(Vec3::new(0.0, 0.0, 0.0), Vec3::new(6.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -6.0), floor),
        Vec2::splat(6.0),
    ));
    add(tiled(
        quad(
            Vec3::new(0.0, 0.0, -10.0),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -4.0),
            floor,
        ),
        Vec2::new(6.0, 4.0),
    ));
    // Arcade: pillars along the courtyard's east and west sides, a roof slab over each.
    for side in [-1.0f32, 1.0] {
        for k in 0..4 {
            let z = 4.5 - k as f32 * 3.0;
            add(cuboid(Vec3::new(side * 5.0, 1.75, z), Vec3::new(0.25, 1.75, 0.25), stone));
        }
        add(cuboid(Vec3::new(side * 5.0, 3.7, 0.0), Vec3::new(0.5, 0.2, 6.0), plaster));
        // Back walls of the arcade, in brick.
        add(tiled(
            cuboid(Vec3::new(side * 6.2, 2.0, 0.0), Vec3::new(0.2, 2.0, 6.0), brick),
            Vec2::new(6.0, 2.0),
        ));
    }
    // Hall: walls and a ceiling; its front wall (z = -6) has a doorway and two windows.
    add(cuboid(Vec3::new(0.0, 4.2, -10.0), Vec3::new(6.4, 0.2, 4.2), plaster));
    add(tiled(
        cuboid(Vec3::new(0.0, 2.0, -14.2), Vec3::new(6.4, 2.0, 0.2), brick),
        Vec2::new(6.0, 2.0),
    ));
    for side in [-1.0f32, 1.0] {
        add(tiled(
            cuboid(Vec3::new(side * 6.2, 2.0, -10.0), Vec3::new(0.2, 2.0, 4.0), brick),
            Vec2::new(4.0, 2.0),
        ));
        // Front wall pieces beside the doorway (|x| < 1.2) with a window at 3.0 < |x| < 4.4.
        add(cuboid(Vec3::new(side * 2.1, 2.0, -6.0), Vec3::new(0.9, 2.0, 0.2), plaster));
        add(cuboid(Vec3::new(side * 5.2, 2.0, -6.0), Vec3::new(0.8, 2.0, 0.2), plaster));
        add(cuboid(Vec3::new(side * 3.7, 0.75, -6.0), Vec3::new(0.7, 0.75, 0.2), plaster));
        add(cuboid(Vec3::new(side * 3.7, 3.5, -6.0), Vec3::new(0.7, 0.5, 0.2), plaster));
    }
    // Lintel over the doorway.
    add(cuboid(Vec3::new(0.0, 3.4, -6.0), Vec3::new(1.2, 0.6, 0.2), plaster));
    // A mirror on the hall's back wall, facing the doorway.
    add(quad(
        Vec3::new(0.0, 1.8, -13.98),
        Vec3::new(1.2, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        mirror,
    ));
    // Rough metal spheres in the hall, roughness 0.05 .. 0.7.
    for (i, m) in (5u32..9).enumerate() {
        add(uv_sphere(Vec3::new(-3.0 + i as f32 * 2.0, 0.6, -11.0), 0.6, m, 32, 16));
    }
    // Emissive strips along the hall's side walls, near the ceiling.
    add(cuboid(Vec3::new(-5.95, 3.6, -10.0), Vec3::new(0.05, 0.05, 3.5), 9));
    add(cuboid(Vec3::new(5.95, 3.6, -10.0), Vec3::new(0.05, 0.05, 3.5), 10));
    // A lacquered plinth in the courtyard for the animated object.
    add(cuboid(Vec3::new(0.0, 0.4, 0.0), Vec3::new(0.6, 0.4, 0.6), 11));
    let animated_mesh = meshes.len();
    meshes.push(cuboid(Vec3::ZERO, Vec3::splat(0.35), 6));

    let mut objects: Vec<Object> = (0..animated_mesh)
        .map(|i| Object {
            name: format!("level part {i}"),
            mesh: i,
            transform: DMat4::IDENTITY,
            animation: None,
            deform: None,
        })
        .collect();
    // Arches between the pillars: eight tilted voussoirs per arch, from one shared block mesh.
    let block = meshes.len();
    meshes.push(cuboid(Vec3::ZERO, Vec3::new(0.25, 0.18, 0.25), stone));
    for side in [-1.0f64, 1.0] {
        for k in 0..3 {
            let zc = 3.0 - k as f64 * 3.0;
            for s in 0..8 {
                let a = std::f64::consts::PI * (s as f64 + 0.5) / 8.0;
                let p = DVec3::new(side * 5.0, 2.25 + 1.25 * a.sin(), zc + 1.25 * a.cos());
                let r = DQuat::from_rotation_x(-(std::f64::consts::FRAC_PI_2 - a));
                objects.push(Object {
                    name: format!("arch {side} {k} {s}"),
                    mesh: block,
                    transform: DMat4::from_rotation_translation(r, p),
                    animation: None,
                    deform: None,
                });
            }
        }
    }
    // The animated object: a copper cube turning above the plinth and bobbing up and down.
    let turn: Vec<DQuat> =
        (0..=4).map(|i| DQuat::from_rotation_y(i as f64 * std::f64::consts::FRAC_PI_2)).collect();
    let animation = Animation {
        translation_track: Some(Track {
            times: vec![0.0, 2.0, 4.0],
            values: vec![
                DVec3::new(0.0, 1.3, 0.0),
                DVec3::new(0.0, 1.7, 0.0),
                DVec3::new(0.0, 1.3, 0.0),
            ],
            step: false,
            tangents: vec![],
        }),
        rotation_track: Some(Track {
            times: vec![0.0, 1.0, 2.0, 3.0, 4.0],
            values: turn,
            step: false,
            tangents: vec![],
        }),
        ..Animation::rigid(DMat4::IDENTITY, DVec3::new(0.0, 1.4, 0.0), DQuat::IDENTITY, DVec3::ONE)
    };
    objects.push(Object {
        name: "spinning cube".into(),
        mesh: animated_mesh,
        transform: animation.world_at(0.0),
        animation: Some(animation),
        deform: None,
    });

    let (sun, sky) = sky::sun_and_sky(sun_dir);
    Scene {
        name: "level".into(),
        meshes,
        objects,
        materials,
        textures,
        lights: vec![sun],
        camera: Some(Camera::look_at(DVec3::new(0.0, 1.7, 8.5), DVec3::new(0.0, 1.4, -6.0), 60.0)),
        environment: Environment::Map(sky),
        resolution: Some((640, 360)),
        max_depth: super::DEFAULT_MAX_DEPTH,
        warnings: vec![],
        procedural_sky: true,
        animations: vec![],
    }
}

/// The sun's default direction: low in the south-west, so it reaches into the hall's doorway.
pub const DEFAULT_SUN: Vec3 = Vec3::new(0.35, -0.5, -0.8);

pub fn default_level() -> Scene {
    default_level_with_sun(DEFAULT_SUN.normalize())
}
