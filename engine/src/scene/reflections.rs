//! Built-in scenes for reflections: `reflections`, a mirror floor under a glossy sphere, a mirror
//! sphere, textured pillars and a box sliding back and forth (the reflected object that moves);
//! `spheres`, the same with a matte floor, so that the two spheres are the only specular
//! surfaces (the setting of Voorhuis §7.4's motion-vector measurement).

use super::default_scene::{cuboid, lambert, metal, quad, uv_sphere};
use super::level::{bricks, checker, texture, tiled};
use super::{
    Animation, Camera, Environment, Material, Mesh, Object, Scene, TextureRef, Track, sky,
};
use glam::{DMat4, DQuat, DVec3, Vec2, Vec3};

/// Names `Scene::load` and the command line accept besides files.
pub const BUILTIN_SCENES: [&str; 4] = ["default", "level", "reflections", "spheres"];

pub fn builtin_scene(name: &str) -> Option<Scene> {
    match name {
        "default" => Some(super::default_scene()),
        "level" => Some(super::default_level()),
        "reflections" => Some(reflection_scene(true)),
        "spheres" => Some(reflection_scene(false)),
        _ => super::terrain::parse_terrain(name).or_else(|| super::crowd::parse_crowd(name)),
    }
}

/// `mirror_floor`: the floor is a perfect mirror (else a matte checkerboard).
pub fn reflection_scene(mirror_floor: bool) -> Scene {
    let materials = vec![
        if mirror_floor {
            metal("mirror floor", Vec3::splat(0.9), 0.0)
        } else {
            Material {
                base_color_texture: Some(TextureRef::new(0)),
                ..lambert("checker floor", Vec3::ONE)
            }
        },
        Material { base_color_texture: Some(TextureRef::new(1)), ..lambert("brick", Vec3::ONE) },
        Material { base_color_texture: Some(TextureRef::new(0)), ..lambert("checker", Vec3::ONE) },
        metal("glossy sphere r0.2", Vec3::new(0.95, 0.7, 0.45), 0.2),
        metal("mirror sphere", Vec3::splat(0.95), 0.0),
        lambert("red", Vec3::new(0.75, 0.1, 0.08)),
        lambert("blue", Vec3::new(0.1, 0.25, 0.8)),
        lambert("green", Vec3::new(0.15, 0.6, 0.2)),
    ];
    let textures =
        vec![texture("checker", 256, true, checker), texture("bricks", 128, true, bricks)];
    let mut meshes: Vec<Mesh> = vec![
        tiled(
            quad(Vec3::ZERO, Vec3::new(8.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -8.0), 0),
            Vec2::splat(8.0),
        ),
        tiled(cuboid(Vec3::new(0.0, 2.0, -8.2), Vec3::new(8.0, 2.0, 0.2), 1), Vec2::new(8.0, 2.0)),
        tiled(cuboid(Vec3::new(-8.2, 2.0, 0.0), Vec3::new(0.2, 2.0, 8.0), 1), Vec2::new(8.0, 2.0)),
        uv_sphere(Vec3::new(-1.4, 1.0, -1.5), 1.0, 3, 48, 24),
        uv_sphere(Vec3::new(1.6, 0.8, -0.5), 0.8, 4, 48, 24),
    ];
    for (i, (x, z)) in
        [(-4.0f32, -5.0f32), (0.5, -5.5), (4.5, -4.0), (-5.5, 1.0)].into_iter().enumerate()
    {
        meshes.push(tiled(
            cuboid(Vec3::new(x, 1.25, z), Vec3::new(0.35, 1.25, 0.35), 2),
            Vec2::new(1.0, 3.0),
        ));
        meshes.push(cuboid(Vec3::new(x, 2.7, z), Vec3::new(0.5, 0.2, 0.5), 5 + (i as u32 % 3)));
    }
    let moving = meshes.len();
    meshes.push(cuboid(Vec3::ZERO, Vec3::new(0.4, 0.4, 0.4), 5));
    let mut objects: Vec<Object> = (0..moving)
        .map(|i| Object {
            name: format!("reflections part {i}"),
            mesh: i,
            transform: DMat4::IDENTITY,
            animation: None,
            deform: None,
        })
        .collect();
    // The box slides 3 m along x and back every 4 s, between the spheres and the back wall.
    let animation = Animation {
        translation_track: Some(Track {
            times: vec![0.0, 2.0, 4.0],
            values: vec![
                DVec3::new(-1.5, 0.4, -3.2),
                DVec3::new(1.5, 0.4, -3.2),
                DVec3::new(-1.5, 0.4, -3.2),
            ],
            step: false,
            tangents: vec![],
        }),
        rotation_track: None,
        ..Animation::rigid(DMat4::IDENTITY, DVec3::new(0.0, 0.4, -3.2), DQuat::IDENTITY, DVec3::ONE)
    };
    objects.push(Object {
        name: "sliding box".into(),
        mesh: moving,
        transform: animation.world_at(0.0),
        animation: Some(animation),
        deform: None,
    });
    let (sun, sky) = sky::sun_and_sky(Vec3::new(0.4, -0.6, -0.7).normalize());
    Scene {
        name: if mirror_floor { "reflections" } else { "spheres" }.into(),
        meshes,
        objects,
        materials,
        textures,
        lights: vec![sun],
        camera: Some(Camera::look_at(DVec3::new(0.0, 1.8, 5.5), DVec3::new(0.0, 0.8, -1.5), 55.0)),
        environment: Environment::Map(sky),
        resolution: Some((640, 360)),
        max_depth: super::DEFAULT_MAX_DEPTH,
        warnings: vec![],
        procedural_sky: true,
        animations: vec![],
    }
}
