//! The screen's strata (`FrameSettings::screen_strata`, shaders/common/rng.wgsl): each pixel's
//! raw frame is as noisy as with independent random numbers, while the mean of a block of
//! pixels lies closer to the converged light, which is what the strata are for.

use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::quality::{Image, luminance};
use hush_engine::settings::{FrameSettings, disable_stage};

const SIDE: u32 = 64;
const BLOCK: u32 = 8;
const FRAMES: u32 = 24;

/// The variance across FRAMES raw frames (no denoiser, no TAA) of each pixel's luminance and
/// of each BLOCK x BLOCK block's mean luminance, relative to the squared mean, averaged over
/// pixels and blocks; and the frames' mean luminance relative to Mitsuba's.
fn variances(screen_strata: bool) -> (f64, f64, f64) {
    let dir = hush_tests::oracle("cornell_diffuse");
    let scene = hush_engine::scene::load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let camera = scene.camera_or_default();
    let reference =
        Image::load(&dir.join("reference.exr")).unwrap().box_downsample(256 / SIDE).unwrap();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (SIDE, SIDE)).unwrap();
    let mut s = FrameSettings { screen_strata, ..Default::default() };
    assert!(disable_stage(&mut s, "taa"));
    let lum = |v: glam::Vec3| f64::from(luminance(v));
    let n = SIDE / BLOCK;
    let mut pixels = vec![Vec::new(); (SIDE * SIDE) as usize];
    let mut blocks = vec![Vec::new(); (n * n) as usize];
    for _ in 0..FRAMES {
        r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &s, None).unwrap();
        let img = r.read_hdr(&gpu).unwrap();
        let mut b = vec![0.0; blocks.len()];
        for (i, v) in img.data.iter().enumerate() {
            let (x, y) = (i as u32 % SIDE, i as u32 / SIDE);
            pixels[i].push(lum(*v));
            b[((y / BLOCK) * n + x / BLOCK) as usize] += lum(*v) / f64::from(BLOCK * BLOCK);
        }
        for (list, v) in blocks.iter_mut().zip(b) {
            list.push(v);
        }
    }
    // Sample variance over the frames relative to the squared mean (0.01 keeps black pixels
    // from dividing by zero).
    let rel_var = |v: &Vec<f64>| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64 / (m * m + 0.01)
    };
    let mean = |l: &[Vec<f64>]| l.iter().map(rel_var).sum::<f64>() / l.len() as f64;
    let total: f64 = pixels.iter().flatten().sum::<f64>() / f64::from(FRAMES);
    let ref_total: f64 = reference.data.iter().map(|v| lum(*v)).sum();
    (mean(&pixels), mean(&blocks), total / ref_total - 1.0)
}

#[test]
fn strata_keep_each_pixel_and_lower_the_error_of_a_block() {
    let (pixel_off, block_off, bias_off) = variances(false);
    let (pixel_on, block_on, bias_on) = variances(true);
    println!(
        "relative variance over frames, off / on: pixels {pixel_off:.5} / {pixel_on:.5}, {BLOCK}x{BLOCK} blocks \
         {block_off:.6} / {block_on:.6}; mean luminance against Mitsuba {bias_off:+.4} / {bias_on:+.4}"
    );
    // A pixel's sample is uniform either way: its variance may move by the spread of a
    // 24-frame estimate, not by a factor (measured 0.182 off, 0.176 on).
    assert!(pixel_on < 1.2 * pixel_off && pixel_on > pixel_off / 1.2, "{pixel_on} / {pixel_off}");
    // Measured 0.60x (0.00316 off, 0.00191 on); an estimate from 24 frames x 64 blocks
    // spreads by a few percent.
    assert!(block_on < 0.8 * block_off, "block variance {block_on} against {block_off}");
    // Whatever the raw frame's offset from Mitsuba's image (-6% here, the same either way),
    // the strata must not move the mean beyond its noise (about 0.2% over 24 x 4096 samples).
    assert!((bias_on - bias_off).abs() < 0.01, "{bias_on} against {bias_off}");
}
