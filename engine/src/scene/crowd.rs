//! `crowd:N`: N copies of one 1,000-triangle figure on a square grid over a floor, each turning
//! about its vertical at its own phase: a scene where every instance moves every frame, for
//! measuring instancing (`hush-cli bench crowd:10000 --mode animate`).

use super::default_scene::{lambert, quad, uv_sphere};
use super::{Animation, Camera, Environment, Object, Scene, Track, sky};
use glam::{DMat4, DQuat, DVec3, Vec3};

/// The most copies `crowd:N` makes.
pub const MAX_CROWD: usize = 1_000_000;

pub fn parse_crowd(name: &str) -> Option<Scene> {
    let n: usize = name.strip_prefix("crowd:")?.replace('_', "").parse().ok()?;
    (1..=MAX_CROWD).contains(&n).then(|| crowd(n))
}

/// The figure: an off-centre sphere of 25 x 21 segments (1,000 triangles), so that turning it
/// moves its surface.
fn figure() -> super::Mesh {
    uv_sphere(Vec3::new(0.15, 0.5, 0.0), 0.35, 1, 25, 21)
}

pub fn crowd(n: usize) -> Scene {
    let side = (n as f64).sqrt().ceil() as usize;
    let spacing = 1.0;
    let half = side as f32 * spacing as f32 * 0.5 + 1.0;
    let meshes =
        vec![quad(Vec3::ZERO, Vec3::new(half, 0.0, 0.0), Vec3::new(0.0, 0.0, -half), 0), figure()];
    let mut objects = vec![Object::new("floor", 0, DMat4::IDENTITY)];
    for i in 0..n {
        let (x, z) = ((i % side) as f64, (i / side) as f64);
        let at =
            DVec3::new((x - side as f64 / 2.0) * spacing, 0.0, (z - side as f64 / 2.0) * spacing);
        let phase = i as f64 * 0.37;
        let turn = |k: f64| DQuat::from_rotation_y(phase + k * std::f64::consts::FRAC_PI_2);
        let mut a = Animation::rigid(DMat4::IDENTITY, at, turn(0.0), DVec3::ONE);
        // A quarter turn a second, looping every 4 s.
        a.rotation_track = Some(Track {
            times: (0..=4).map(f64::from).collect(),
            values: (0..=4).map(|k| turn(k as f64)).collect(),
            step: false,
            tangents: vec![],
        });
        let mut o =
            Object::new(format!("figure {i}"), 1, DMat4::from_rotation_translation(turn(0.0), at));
        o.animation = Some(a);
        objects.push(o);
    }
    let (sun, sky) = sky::sun_and_sky(Vec3::new(0.4, -0.7, -0.3).normalize());
    let eye = DVec3::new(0.0, half as f64 * 0.6 + 2.0, half as f64 * 0.9 + 2.0);
    Scene {
        name: format!("crowd:{n}"),
        meshes,
        objects,
        materials: vec![
            lambert("floor", Vec3::new(0.6, 0.6, 0.55)),
            lambert("figure", Vec3::new(0.7, 0.35, 0.2)),
        ],
        lights: vec![sun],
        camera: Some(Camera::look_at(eye, DVec3::ZERO, 50.0)),
        environment: Environment::Map(sky),
        procedural_sky: true,
        max_depth: super::DEFAULT_MAX_DEPTH,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn crowd_names_its_size() {
        let s = super::parse_crowd("crowd:10").unwrap();
        assert_eq!(s.objects.len(), 11);
        assert_eq!(s.meshes[1].indices.len() / 3, 1000);
        assert!(s.objects[1..].iter().all(|o| o.moves() && o.mesh == 1));
        assert!(super::parse_crowd("crowd:0").is_none() && super::parse_crowd("crowd:x").is_none());
    }
}
