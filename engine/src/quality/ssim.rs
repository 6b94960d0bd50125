//! SSIM exactly as the oracle scores it: scikit-image's `structural_similarity` with
//! `gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1` on the Rec.709
//! luminance of T(x) = clamp(x,0,1)^(1/2.2). Written here (rather than taken from a crate) because
//! the crates we found use other windows or colour handling, and the numbers must agree with the
//! oracle's tables.

use super::Image;
use super::metrics::display;

pub fn ssim_luma(x: &Image, y: &Image) -> f64 {
    let (w, h) = (x.width as usize, x.height as usize);
    let luma = |img: &Image| -> Vec<f64> {
        img.data
            .iter()
            .map(|p| {
                0.2126 * display(p.x) as f64
                    + 0.7152 * display(p.y) as f64
                    + 0.0722 * display(p.z) as f64
            })
            .collect()
    };
    let (a, b) = (luma(x), luma(y));
    // skimage: truncate = 3.5, radius = int(3.5 * sigma + 0.5) = 5 (an 11x11 window).
    let sigma = 1.5f64;
    let r = 5usize;
    let k: Vec<f64> = (0..=2 * r)
        .map(|i| (-((i as f64 - r as f64).powi(2)) / (2.0 * sigma * sigma)).exp())
        .collect();
    let ks: f64 = k.iter().sum();
    let k: Vec<f64> = k.iter().map(|v| v / ks).collect();
    // scipy.ndimage.gaussian_filter with mode 'reflect' (d c b a | a b c d | d c b a).
    let reflect = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let mut i = i;
        loop {
            if i < 0 {
                i = -i - 1;
            } else if i >= n {
                i = 2 * n - i - 1;
            } else {
                return i as usize;
            }
        }
    };
    let blur = |src: &[f64]| -> Vec<f64> {
        let mut tmp = vec![0.0; w * h];
        for yy in 0..h {
            for xx in 0..w {
                let mut s = 0.0;
                for (i, kv) in k.iter().enumerate() {
                    s += kv * src[yy * w + reflect(xx as isize + i as isize - r as isize, w)];
                }
                tmp[yy * w + xx] = s;
            }
        }
        let mut out = vec![0.0; w * h];
        for yy in 0..h {
            for xx in 0..w {
                let mut s = 0.0;
                for (i, kv) in k.iter().enumerate() {
                    s += kv * tmp[reflect(yy as isize + i as isize - r as isize, h) * w + xx];
                }
                out[yy * w + xx] = s;
            }
        }
        out
    };
    let mul = |p: &[f64], q: &[f64]| -> Vec<f64> { p.iter().zip(q).map(|(u, v)| u * v).collect() };
    let (ux, uy) = (blur(&a), blur(&b));
    let (uxx, uyy, uxy) = (blur(&mul(&a, &a)), blur(&mul(&b, &b)), blur(&mul(&a, &b)));
    let (c1, c2) = ((0.01f64).powi(2), (0.03f64).powi(2));
    // skimage averages over the image cropped by the window radius.
    let (x0, x1, y0, y1) = if w > 2 * r && h > 2 * r { (r, w - r, r, h - r) } else { (0, w, 0, h) };
    let mut sum = 0.0;
    let mut n = 0usize;
    for yy in y0..y1 {
        for xx in x0..x1 {
            let i = yy * w + xx;
            let (mx, my) = (ux[i], uy[i]);
            let vx = uxx[i] - mx * mx;
            let vy = uyy[i] - my * my;
            let cxy = uxy[i] - mx * my;
            sum += ((2.0 * mx * my + c1) * (2.0 * cxy + c2))
                / ((mx * mx + my * my + c1) * (vx + vy + c2));
            n += 1;
        }
    }
    sum / n as f64
}
