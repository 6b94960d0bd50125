//! Images, files and the metrics every comparison in Hush uses (the oracle's definitions).

mod metrics;
mod ssim;
mod timeline;
mod uncovered;

pub use crate::image_io::{
    Image, decode_exr, linear_to_srgb, srgb_to_linear, tonemap_srgb8, write_exr, write_png,
};
pub use metrics::{
    Metrics, compare, compare_with_flip_map, flip_ldr, flip_map, flip_over, luminance, region_mean,
    relmse, rmse, save_flip_heatmap,
};
pub use ssim::ssim_luma;
pub use timeline::Timeline;
pub use uncovered::{DepthView, Visibility, uncovered, visibility};
