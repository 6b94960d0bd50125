//! The G-buffer's 8-bit material colours (shaders/realtime/gbuffer_dither.wgsl): over the
//! frames a pixel's stored base colour and F0 average to the material's own values, where
//! rounding to the nearest code would keep the same offset in every frame; the roughness, which
//! the glossy chains compare with thresholds, keeps its nearest code in every frame.

use glam::Vec3;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::quality::srgb_to_linear;
use hush_engine::settings::{FrameSettings, disable_stage};

const SIDE: u32 = 32;
const FRAMES: u32 = 64;
/// cornell_diffuse's white, given the default dielectric specular (F0 0.04 at IOR 1.5) and a
/// roughness between two codes (155.55: nearest 156).
const WHITE: Vec3 = Vec3::new(0.725, 0.71, 0.68);
const F0: f32 = 0.04;
const ROUGHNESS: f32 = 0.61;

#[test]
fn the_gbuffer_material_averages_to_the_material() {
    let dir = hush_tests::oracle("cornell_diffuse");
    let mut scene = hush_engine::scene::load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let white = scene.materials.iter_mut().find(|m| m.name == "white").unwrap();
    white.specular_factor = 1.0;
    white.specular_color = Vec3::ONE;
    white.ior = 1.5;
    white.roughness = ROUGHNESS;
    let camera = scene.camera_or_default();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (SIDE, SIDE)).unwrap();
    let mut s = FrameSettings::default();
    assert!(disable_stage(&mut s, "taa"));
    let n = (SIDE * SIDE) as usize;
    // Per pixel: the sums of the decoded base colour and F0, and whether every frame stored
    // white's codes or their neighbours (the walls, not an edge under the jitter).
    let mut base = vec![Vec3::ZERO; n];
    let mut f0 = vec![0f64; n];
    let mut on_white = vec![true; n];
    let rough_code = (ROUGHNESS * 255.0).round() as u8;
    let mut rough_codes = std::collections::BTreeSet::new();
    let code = |c: f32| (hush_engine::quality::linear_to_srgb(c) * 255.0).round();
    for _ in 0..FRAMES {
        r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &s, None).unwrap();
        let (b, _) = r.read_texture(&gpu, "gbuffer/base_color").unwrap();
        let (sp, _) = r.read_texture(&gpu, "gbuffer/specular").unwrap();
        for i in 0..n {
            let o = i * 4;
            let rgb = Vec3::new(b[o] as f32, b[o + 1] as f32, b[o + 2] as f32);
            let near = (rgb - Vec3::from(WHITE.to_array().map(code))).abs().max_element() <= 1.0;
            on_white[i] &= near && (sp[o + 3] as f32 - ROUGHNESS * 255.0).abs() <= 1.0;
            base[i] += Vec3::from(rgb.to_array().map(|c| srgb_to_linear(c / 255.0)));
            f0[i] += f64::from(sp[o]) / 255.0;
            if on_white[i] {
                rough_codes.insert(sp[o + 3]);
            }
        }
    }
    let pixels: Vec<usize> = (0..n).filter(|&i| on_white[i]).collect();
    assert!(pixels.len() > n / 4, "only {} of {n} pixels on the white walls", pixels.len());
    let frames = f64::from(FRAMES) * pixels.len() as f64;
    let mean_base: Vec3 = pixels.iter().map(|&i| base[i]).sum::<Vec3>() / frames as f32;
    let mean_f0 = pixels.iter().map(|&i| f0[i]).sum::<f64>() / frames;
    let rel_base = mean_base / WHITE - 1.0;
    let rel_f0 = mean_f0 / f64::from(F0) - 1.0;
    println!(
        "{} pixels x {FRAMES} frames: base colour {rel_base:+.5}, F0 {rel_f0:+.5} (relative); roughness codes {rough_codes:?}",
        pixels.len()
    );
    // Nearest rounding keeps base colour -0.27% / -0.23% / -0.07% (sRGB codes 220 / 218 / 214)
    // and F0 -2.0% (10 / 255) in every frame. Dithered, each frame stores one of two codes, so a
    // sample's standard deviation is at most half a code, and the mean of at least 256 pixels x
    // 64 frames is within 0.004 of a code: 0.004% of white (a code is 1% of it), 0.04% of F0 (a
    // code is 10%). The bounds are seven and five of those, a tenth of nearest rounding's offsets.
    assert!(rel_base.abs().max_element() < 3e-4, "base colour {rel_base}");
    assert!(rel_f0.abs() < 2e-3, "F0 {rel_f0}");
    assert_eq!(rough_codes.into_iter().collect::<Vec<_>>(), [rough_code], "roughness codes");
}
