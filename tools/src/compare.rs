use anyhow::{Context, Result};
use clap::Args;
use hush_engine::quality::{Image, compare};
use std::path::PathBuf;

#[derive(Args)]
pub struct CompareArgs {
    /// The image under test (.exr, or .png holding sRGB display values).
    pub test: PathBuf,
    /// The reference image.
    pub reference: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also write the per-pixel FLIP error as a heat-map PNG (magma), to see where the error is.
    #[arg(long)]
    pub flip_map: Option<PathBuf>,
}

/// A reference for a render of `size`: box-downsampled by the factor between them where the render
/// is at an integer fraction of the reference's resolution (each pixel is the mean over its
/// footprint), else as it is; and that factor (1: as it is).
pub fn at_render_size(y: Image, size: (u32, u32)) -> Result<(Image, u32)> {
    let (w, h) = size;
    if y.width > w && w > 0 && y.width.is_multiple_of(w) && y.height == h * (y.width / w) {
        let f = y.width / w;
        return Ok((y.box_downsample(f)?, f));
    }
    Ok((y, 1))
}

pub fn run(a: CompareArgs) -> Result<()> {
    let x = Image::load(&a.test).with_context(|| format!("test image {}", a.test.display()))?;
    let y = Image::load(&a.reference)
        .with_context(|| format!("reference image {}", a.reference.display()))?;
    let (y, f) = at_render_size(y, (x.width, x.height))?;
    if f > 1 {
        eprintln!("reference box-downsampled by {f} to {}x{}", x.width, x.height);
    }
    let m = compare(&x, &y)?;
    if let Some(path) = &a.flip_map {
        hush_engine::quality::save_flip_heatmap(&x, &y, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&m)?);
    } else {
        println!("rmse              {:.6}", m.rmse);
        println!("relmse            {:.6}", m.relmse);
        println!("mae               {:.6}", m.mae);
        println!(
            "mean_rel_bias     {:+.4} {:+.4} {:+.4}",
            m.mean_rel_bias[0], m.mean_rel_bias[1], m.mean_rel_bias[2]
        );
        println!("ssim              {:.4}", m.ssim);
        println!("flip              {:.4}", m.flip);
        println!("nonfinite_pixels  {}", m.nonfinite_pixels);
    }
    Ok(())
}
