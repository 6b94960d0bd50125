//! Mitsuba parity: the reference mode against Mitsuba 3 renders of the same scenes
//! (`tests/oracle`, copied from `../shared/oracle`), at a box-downsampled resolution small
//! enough for CI.
//!
//! Thresholds come from the noise of both images rather than from a guess:
//! - relMSE: its expectation for two unbiased estimators is the sum of their per-pixel variances
//!   over (y² + 0.01). Hush's variance of the mean is measured from its own samples; Mitsuba's is
//!   taken as the same per-sample variance over its larger sample count (ref spp x factor²
//!   samples per downsampled pixel). A bias would add to this; the test allows `RELMSE_SLACK`
//!   times the expectation because the variance estimate itself is noisy where caustics and tiny
//!   highlights make the per-sample distribution heavy-tailed.
//! - mean bias per channel, after leaving out the 0.1% of pixels with the largest difference
//!   (caustic and highlight pixels whose means are dominated by a few rare samples in either
//!   image): within 5 standard errors of the trimmed mean, or within the worst channel mean bias
//!   the oracle measured between two independent Mitsuba renders at 256 spp (its README), as the
//!   README asks: never tighter than the references' own noise.

use hush_engine::quality::{Image, compare};
use hush_engine::scene::load_gltf;
use hush_tests::{mitsuba_scene, oracle, render, trimmed_bias};

const RELMSE_SLACK: f64 = 3.0;

struct Case {
    name: &'static str,
    /// In tests/mitsuba (Hush's own scenes) rather than tests/oracle (copies of ../shared).
    own: bool,
    factor: u32,
    spp: u32,
    ref_spp: u32,
    /// Worst channel mean bias of an independent 256-spp Mitsuba render (oracle README table).
    mitsuba_bias_256: f64,
}

/// The reference mode against the case's Mitsuba render; returns the measured relMSE.
fn parity(c: Case) -> f64 {
    let dir = if c.own { mitsuba_scene(c.name) } else { oracle(c.name) };
    let scene = load_gltf(&dir.join(format!("{}.gltf", c.name))).unwrap();
    let reference =
        Image::load(&dir.join("reference.exr")).unwrap().box_downsample(c.factor).unwrap();
    let (w, h) = (reference.width, reference.height);
    let acc = render(&scene, w, h, c.spp, 7).unwrap();
    assert_eq!(acc.nonfinite_samples, 0, "{}: NaN/Inf samples", c.name);
    let m = compare(&acc.mean, &reference).unwrap();
    assert_eq!(m.nonfinite_pixels, 0);

    // Expected relMSE from the two images' noise.
    let ref_share = c.spp as f64 / (c.ref_spp as f64 * (c.factor * c.factor) as f64);
    let mut expected = 0.0;
    for (v, y) in acc.variance_of_mean.data.iter().zip(&reference.data) {
        for k in 0..3 {
            expected += v[k] as f64 * (1.0 + ref_share) / (y[k] as f64 * y[k] as f64 + 0.01);
        }
    }
    expected /= (3 * reference.data.len()) as f64;

    // Trimmed per-channel bias and its standard error; never tighter than the oracle's own bias.
    let (bias, five_se) = trimmed_bias(&acc.mean, &reference, |i, k| {
        acc.variance_of_mean.data[i][k] as f64 * (1.0 + ref_share)
    });
    let allowed = five_se.map(|a| a.max(c.mitsuba_bias_256));
    println!(
        "{}: {}x{} {} spp (reference {} spp, box /{}): relMSE {:.5} (noise predicts {:.5}), FLIP {:.4}, SSIM {:.4}, \
         RMSE {:.4}, mean bias {:+.4} {:+.4} {:+.4}, trimmed bias {:+.4} {:+.4} {:+.4} (allowed {:.4} {:.4} {:.4})",
        c.name,
        w,
        h,
        c.spp,
        c.ref_spp,
        c.factor,
        m.relmse,
        expected,
        m.flip,
        m.ssim,
        m.rmse,
        m.mean_rel_bias[0],
        m.mean_rel_bias[1],
        m.mean_rel_bias[2],
        bias[0],
        bias[1],
        bias[2],
        allowed[0],
        allowed[1],
        allowed[2]
    );
    assert!(
        m.relmse <= RELMSE_SLACK * expected,
        "{}: relMSE {} > {} x predicted {}",
        c.name,
        m.relmse,
        RELMSE_SLACK,
        expected
    );
    for k in 0..3 {
        assert!(
            bias[k].abs() <= allowed[k],
            "{}: channel {k} biased by {:+.4} (allowed {:.4})",
            c.name,
            bias[k],
            allowed[k]
        );
    }
    m.relmse
}

#[test]
fn cornell_diffuse_matches_mitsuba() {
    parity(Case {
        name: "cornell_diffuse",
        own: false,
        factor: 4,
        spp: 256,
        ref_spp: 1024,
        mitsuba_bias_256: 0.0,
    });
}

#[test]
fn cornell_mirror_matches_mitsuba() {
    parity(Case {
        name: "cornell_mirror",
        own: false,
        factor: 4,
        spp: 512,
        ref_spp: 4096,
        mitsuba_bias_256: 0.001,
    });
}

#[test]
fn point_glossy_matches_mitsuba() {
    parity(Case {
        name: "point_glossy",
        own: false,
        factor: 2,
        spp: 256,
        ref_spp: 4096,
        mitsuba_bias_256: 0.015,
    });
}

/// Thin lens (aperture 0.15 m, focus 3.2 m). relMSE alone cannot tell depth of field from a
/// pinhole (the oracle's README: a pinhole render is 1.6x the peer's relMSE but 1.5x its FLIP),
/// so the same view through a pinhole must also score a FLIP at least 1.2x Hush's: measured at
/// 64x64 and 512 spp, 0.0445 with the lens against 0.0737 without (relMSE 0.00609, noise
/// predicts 0.00620; mean bias +0.23%, +0.15%, +0.12%).
#[test]
fn cornell_dof_matches_mitsuba() {
    parity(Case {
        name: "cornell_dof",
        own: false,
        factor: 4,
        spp: 512,
        ref_spp: 4096,
        mitsuba_bias_256: 0.001,
    });
    let dir = oracle("cornell_dof");
    let reference = Image::load(&dir.join("reference.exr")).unwrap().box_downsample(4).unwrap();
    let mut scene = load_gltf(&dir.join("cornell_dof.gltf")).unwrap();
    let lens =
        scene.camera.as_ref().and_then(|c| c.lens).expect("cornell_dof's camera has a thin lens");
    assert_eq!((lens.aperture_radius, lens.focus_distance), (0.15, 3.2));
    let (w, h) = (reference.width, reference.height);
    let with_lens = compare(&render(&scene, w, h, 512, 7).unwrap().mean, &reference).unwrap().flip;
    scene.camera.as_mut().unwrap().lens = None;
    let pinhole = compare(&render(&scene, w, h, 512, 7).unwrap().mean, &reference).unwrap().flip;
    println!("cornell_dof FLIP: thin lens {with_lens:.4}, pinhole {pinhole:.4}");
    assert!(
        pinhole >= 1.2 * with_lens,
        "the pinhole's FLIP {pinhole} is not clearly worse than the lens's {with_lens}"
    );
}

/// Glass (tests/mitsuba/cornell_glass, tools/scripts/make_glass_scene.py): cornell_mirror with a
/// smooth glass ball and a rough glass block (GGX roughness 0.3), ior 1.5, 8 path segments,
/// against Mitsuba's dielectric and roughdielectric at 8192 spp. Refraction caustics make the
/// error heavy-tailed, as in cornell_mirror. An independent 1024-spp Mitsuba render lands
/// relMSE 0.0041, FLIP 0.0352, mean bias +0.01%/-0.00%/-0.01% from the reference.
#[test]
fn cornell_glass_matches_mitsuba() {
    parity(Case {
        name: "cornell_glass",
        own: true,
        factor: 4,
        spp: 512,
        ref_spp: 8192,
        mitsuba_bias_256: 0.001,
    });
}

/// The many-lamp hall (96 small one-sided wall lamps behind pillars, max_depth 4), where the light
/// tree chooses each light sample. Mitsuba picks its emitters uniformly; an independent 256-spp
/// Mitsuba render's mean lies 0.12-0.16% from the reference's (its render_info), so 0.2% is the
/// bias floor. At 80x45 and 256 spp, choosing lamps by area x luminance alone (as Hush did
/// before the tree) measured relMSE 0.0267, 0.0291 and 0.0299 over three seeds; the tree must
/// stay under 0.7x the best of those (measured with the tree: 0.01382, noise predicts 0.01383;
/// FLIP 0.0519; trimmed bias under 0.31%), or the
/// walk has stopped preferring the lamps that light the point.
#[test]
fn many_lights_matches_mitsuba() {
    let relmse = parity(Case {
        name: "many_lights",
        own: false,
        factor: 4,
        spp: 256,
        ref_spp: 8192,
        mitsuba_bias_256: 0.002,
    });
    assert!(relmse < 0.7 * 0.0267, "relMSE {relmse}: no better than a uniform choice of lamp");
}

#[test]
fn furnace_matches_mitsuba() {
    parity(Case {
        name: "furnace",
        own: false,
        factor: 4,
        spp: 64,
        ref_spp: 1024,
        mitsuba_bias_256: 0.0,
    });
}

/// White furnace: a Lambertian sphere of albedo 1 under uniform radiance 1 reflects exactly 1.
/// Full resolution (256²) so the sphere mask from the oracle's normal image applies pixel for pixel.
#[test]
fn white_furnace_is_one() {
    let dir = oracle("furnace");
    let scene = load_gltf(&dir.join("furnace.gltf")).unwrap();
    let normals = Image::load(&dir.join("normal.exr")).unwrap();
    let spp = 32;
    let acc = render(&scene, normals.width, normals.height, spp, 3).unwrap();
    assert_eq!(acc.nonfinite_samples, 0);
    // Sphere pixels: every pixel whose first-hit normal is set, less a 1-pixel rim whose
    // footprint straddles the silhouette (those mix sphere and sky, both 1 anyway).
    let (w, hgt) = (normals.width as i32, normals.height as i32);
    let on = |x: i32, y: i32| {
        x >= 0 && y >= 0 && x < w && y < hgt && normals.at(x as u32, y as u32).length() > 0.5
    };
    let mut sum = 0f64;
    let mut count = 0usize;
    let mut worst_z = 0f64;
    let mut worst_dev = 0f64;
    for y in 0..hgt {
        for x in 0..w {
            if !(on(x, y) && on(x - 1, y) && on(x + 1, y) && on(x, y - 1) && on(x, y + 1)) {
                continue;
            }
            let i = (y * w + x) as usize;
            let v = acc.mean.data[i];
            let s = acc.variance_of_mean.data[i];
            sum += (v.x + v.y + v.z) as f64 / 3.0;
            count += 1;
            for k in 0..3 {
                let dev = (v[k] as f64 - 1.0).abs();
                worst_dev = worst_dev.max(dev);
                // A pixel whose samples all came out identical has no measurable variance; its
                // deviation must then be at f32 rounding level.
                let se = (s[k] as f64).sqrt().max(1e-4);
                worst_z = worst_z.max(dev / se);
            }
        }
    }
    let mean = sum / count as f64;
    println!(
        "furnace: {count} sphere pixels at {spp} spp, mean {mean:.5}, worst pixel |x-1| {worst_dev:.4} = {worst_z:.2} standard errors"
    );
    assert!(count > 20_000, "sphere mask too small: {count}");
    // Mitsuba measured 0.99967 (the tessellated sphere loses 0.03%); the bound is 0.5%.
    assert!((mean - 1.0).abs() < 0.005, "furnace sphere mean {mean}");
    // With ~30k pixels x 3 channels, a Gaussian deviation beyond 6 standard errors has a chance
    // of about 2e-4 in the whole image; anything beyond is a real error, not noise.
    assert!(worst_z < 6.0, "a furnace pixel is {worst_z:.2} standard errors from 1");
}

/// The repository's copies of the oracle scenes (`tests/oracle`, what a bare clone tests against)
/// are byte for byte the files in `../shared/oracle`, where that is present.
#[test]
#[cfg_attr(not(hush_shared_oracle), ignore = "needs ../shared/oracle, absent beside this checkout")]
fn oracle_copies_match_shared() {
    let ours = oracle("");
    let mut checked = 0;
    for scene in std::fs::read_dir(&ours).unwrap() {
        let scene = scene.unwrap().path();
        for file in std::fs::read_dir(&scene).unwrap() {
            let file = file.unwrap().path();
            let rel = file.strip_prefix(&ours).unwrap();
            let theirs = hush_tests::shared().join("oracle").join(rel);
            let same = std::fs::read(&theirs).is_ok_and(|t| t == std::fs::read(&file).unwrap());
            assert!(same, "tests/oracle/{} differs from {}", rel.display(), theirs.display());
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} oracle files");
}
