//! Which pixels a frame traces below one sample per pixel (Dundr et al. §5; mirrored by
//! shaders/realtime/frame.wgsl: `scheduled_pixel`, `traced_this_frame`).
//!
//! With period N = 1/f the image is cut into tiles of N pixels (2^ceil(k/2) x 2^floor(k/2) for
//! N = 2^k) and every frame traces one pixel of each tile, so the trace dispatches only the
//! tiles: its cost falls as f. Inside a tile the pixels take turns in the order of a Bayer
//! matrix (each frame's pixel as far as the tile allows from the last ones), so that every
//! pixel is traced exactly once in N frames. Each tile starts that order at its own phase (a
//! hash of the tile): neighbouring tiles trace different cells in a frame, and the samples
//! of a frame carry no screen-wide grid.

/// The tile of period `period` (a power of two): width and height in pixels.
pub fn tile(period: u32) -> (u32, u32) {
    let k = period.max(1).trailing_zeros();
    (1 << k.div_ceil(2), 1 << (k / 2))
}

/// Cell of the tile traced at `rank` (0..period) of the Bayer order: the rank's bits reversed,
/// dealt alternately to x and y, then x ^= y.
pub fn cell(rank: u32, period: u32) -> (u32, u32) {
    let k = period.max(1).trailing_zeros();
    let v = if k == 0 { 0 } else { rank.reverse_bits() >> (32 - k) };
    let (mut x, mut y) = (0, 0);
    for i in 0..k {
        let bit = (v >> i) & 1;
        if i % 2 == 0 {
            x |= bit << (i / 2);
        } else {
            y |= bit << (i / 2);
        }
    }
    (x ^ y, y)
}

/// The tile's phase in the Bayer order.
pub fn phase(tile_x: u32, tile_y: u32, period: u32) -> u32 {
    hash(tile_x.wrapping_mul(0x8da6_b343) ^ tile_y.wrapping_mul(0xd816_3841)) & (period - 1)
}

/// The pixel of tile (tile_x, tile_y) traced in frame `index`.
pub fn scheduled_pixel(tile_x: u32, tile_y: u32, index: u32, period: u32) -> (u32, u32) {
    let (w, h) = tile(period);
    let rank = index.wrapping_add(phase(tile_x, tile_y, period)) & (period - 1);
    let (cx, cy) = cell(rank, period);
    (tile_x * w + cx, tile_y * h + cy)
}

/// A 32-bit integer hash (the lowbias32 of Chris Wellons' hash prospector).
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pixel_is_traced_once_per_period() {
        let (w, h): (u32, u32) = (37, 23);
        for period in [1, 2, 4, 8, 16, 32, 64, 128] {
            let (tw, th) = tile(period);
            assert_eq!(tw * th, period);
            // Start anywhere: frame indices wrap.
            let start = u32::MAX - 5;
            let mut count = vec![0u32; (w * h) as usize];
            for f in 0..period {
                for ty in 0..h.div_ceil(th) {
                    for tx in 0..w.div_ceil(tw) {
                        let (x, y) = scheduled_pixel(tx, ty, start.wrapping_add(f), period);
                        assert!(x / tw == tx && y / th == ty, "the pixel stays in its tile");
                        if x < w && y < h {
                            count[(y * w + x) as usize] += 1;
                        }
                    }
                }
            }
            assert!(count.iter().all(|&c| c == 1), "period {period}: {count:?}");
        }
    }

    #[test]
    fn consecutive_cells_are_spread() {
        // The 2x2 Bayer order: diagonal first.
        let order: Vec<_> = (0..4).map(|r| cell(r, 4)).collect();
        assert_eq!(order, [(0, 0), (1, 1), (1, 0), (0, 1)]);
        // Stratified: any run of period / 4 consecutive ranks from a multiple of it puts one
        // sample in each 2x2 block of the tile (square tiles).
        for period in [16u32, 64] {
            let (w, _) = tile(period);
            let q = period / 4;
            for start in (0..period).step_by(q as usize) {
                let mut blocks: Vec<_> = (start..start + q)
                    .map(|r| cell(r, period))
                    .map(|(x, y)| y / 2 * (w / 2) + x / 2)
                    .collect();
                blocks.sort();
                blocks.dedup();
                assert_eq!(blocks.len() as u32, q, "period {period}, ranks {start}..");
            }
        }
    }
}
