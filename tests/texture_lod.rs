//! Ray cones choosing texture mip levels after the primary hit (FrameSettings::texture_lod).
//!
//! A white wall lit only by what a sunlit floor reflects: the floor is a checkerboard of black
//! and white squares 8 mm wide (4 texels), so every indirect ray from the wall that lands on
//! the floor reads 0 or 1 without mips (a blend only near a square's edge), where the cone's
//! footprint (tens of centimetres) reads their mean. The
//! real-time frame's 1-spp noise must fall, and the converged image must not move.

use glam::{DMat4, DVec3, Vec2, Vec3};
use hush_engine::accel::BvhKind;
use hush_engine::quality::{Image, compare};
use hush_engine::scene::{
    Camera, Environment, Light, Material, Object, Scene, Texture, TextureRef, Wrap, quad,
};
use hush_engine::settings::{Denoiser, FrameSettings};

const N: u32 = 24;
const SIDE: u32 = 256;

fn scene() -> Scene {
    let rgba8 = (0..SIDE * SIDE)
        .flat_map(|i| {
            let v = if ((i % SIDE) / 4 + i / SIDE / 4).is_multiple_of(2) { 255 } else { 0 };
            [v, v, v, 255]
        })
        .collect();
    let checker = Texture {
        name: "checker".into(),
        width: SIDE,
        height: SIDE,
        rgba8,
        srgb: true,
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        nearest: false,
    };
    // Floor 8 x 8 m at y = 0, the texture repeated 16 times across it (2 mm texels).
    let mut floor = quad(Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -4.0), 0);
    floor.uvs = vec![Vec2::ZERO, Vec2::new(16.0, 0.0), Vec2::new(16.0, 16.0), Vec2::new(0.0, 16.0)];
    // The wall: 2 x 2 m facing +Z at z = -1.
    let wall =
        quad(Vec3::new(0.0, 1.0, -1.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 1);
    let lambert = |base: Vec3, texture: Option<TextureRef>| Material {
        base_color: base.extend(1.0),
        base_color_texture: texture,
        metallic: 0.0,
        specular_factor: 0.0,
        ..Default::default()
    };
    let object = |name: &str, mesh| Object {
        name: name.into(),
        mesh,
        transform: DMat4::IDENTITY,
        animation: None,
        deform: None,
    };
    Scene {
        name: "checker floor".into(),
        meshes: vec![floor, wall],
        objects: vec![object("floor", 0), object("wall", 1)],
        materials: vec![lambert(Vec3::ONE, Some(TextureRef::new(0))), lambert(Vec3::ONE, None)],
        textures: vec![checker],
        // Straight down: the floor is lit, the wall (vertical) only by the floor.
        lights: vec![Light::Directional { direction: -Vec3::Y, irradiance: Vec3::splat(3.0) }],
        camera: Some(Camera::look_at(DVec3::new(0.0, 1.0, 2.0), DVec3::new(0.0, 1.0, -1.0), 30.0)),
        environment: Environment::None,
        resolution: Some((N, N)),
        // Camera -> wall -> floor -> sun.
        max_depth: 3,
        warnings: vec![],
        procedural_sky: false,
        animations: vec![],
    }
}

/// Mean relMSE of `frames` independent 1-spp real-time frames against `reference`.
fn one_spp_relmse(scene: &Scene, texture_lod: bool, reference: &Image, frames: u32) -> f64 {
    let mut sum = 0.0;
    for seed in 0..frames {
        let settings = FrameSettings {
            max_depth: scene.max_depth,
            seed: 100 + seed,
            accumulate: true,
            denoiser: Denoiser::NONE,
            texture_lod,
            ..Default::default()
        };
        let frame = hush_tests::realtime_frames(scene, (N, N), &settings, 1).unwrap();
        sum += compare(&frame, reference).unwrap().relmse;
    }
    sum / frames as f64
}

#[test]
fn ray_cones_cut_indirect_texture_noise_and_keep_the_converged_image() {
    let scene = scene();
    let render =
        |lod: bool| hush_tests::render_lod(&scene, (N, N), 2048, 9, BvhKind::DEFAULT, lod).unwrap();
    let (fine, filtered) = (render(false), render(true));
    assert_eq!(fine.nonfinite_samples + filtered.nonfinite_samples, 0);

    // Converged: the two differ by their noise only. Expected relMSE between two independent
    // estimates is the sum of their variances of the mean over (y^2 + 0.01).
    let mut expected = 0.0;
    let (mut mean_fine, mut mean_filtered) = (0.0, 0.0);
    for i in 0..fine.mean.data.len() {
        for k in 0..3 {
            let y = fine.mean.data[i][k] as f64;
            let v =
                (fine.variance_of_mean.data[i][k] + filtered.variance_of_mean.data[i][k]) as f64;
            expected += v / (y * y + 0.01);
            mean_fine += y;
            mean_filtered += filtered.mean.data[i][k] as f64;
        }
    }
    expected /= (3 * fine.mean.data.len()) as f64;
    let converged = compare(&filtered.mean, &fine.mean).unwrap().relmse;
    let shift = mean_filtered / mean_fine - 1.0;
    println!(
        "converged with and without mips: relMSE {converged:.6} (noise predicts {expected:.6}), mean {shift:+.4}"
    );
    // 3x the prediction: the variance estimate is itself noisy. The means agree within 1%: the
    // coarse levels are stored as 8-bit sRGB like the base, and the floor's mean grey 0.5 reads
    // back as 188/255, 0.5029 in linear light (measured: +0.60%, the mean's standard error
    // 0.25%).
    assert!(
        converged < 3.0 * expected,
        "mips moved the converged image: {converged} > 3 x {expected}"
    );
    assert!(shift.abs() < 0.01, "mips moved the mean by {shift}");

    // One sample per pixel, against the converged image without mips.
    let without = one_spp_relmse(&scene, false, &fine.mean, 8);
    let with = one_spp_relmse(&scene, true, &fine.mean, 8);
    println!("1-spp relMSE over 8 frames: without mips {without:.4}, with ray cones {with:.4}");
    assert!(with < 0.8 * without, "ray cones: {with} against {without} without");
}
