//! Arrays of 16-byte records kept as 2D textures for the shaders to read with textureLoad.

use super::{Gpu, GpuMemory};

/// Texels per row of [`Texels`] (`TEXEL_ROW_SHIFT` in shaders/common/geometry.wgsl).
pub const TEXEL_ROW: u32 = 4096;

/// Rows of [`Texels`] that hold `bytes`.
pub fn texel_row_count(bytes: usize) -> u32 {
    (bytes.div_ceil(16) as u32).div_ceil(TEXEL_ROW).max(1)
}

/// An array of 16-byte records as a 2D texture, [`TEXEL_ROW`] texels to a row, read with
/// textureLoad (the BVH nodes, vertices, shading records, materials, texture words and the light
/// tree's nodes).
/// Lavapipe reads a storage buffer at per-lane addresses one lane and one word at a time with a
/// bounds check each, and a texel with one 16-byte load per lane: with the BVH nodes and the
/// vertices the intersection tests read in texels, the reference tracer made 0.66 M samples/s
/// on cornell_diffuse instead of 0.56 (living room rays/s +10%). On an H100 texels cost the
/// real-time trace 2% against buffers.
pub struct Texels {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    label: String,
    format: wgpu::TextureFormat,
}

impl Texels {
    pub fn new(
        gpu: &Gpu,
        mem: &mut GpuMemory,
        label: &str,
        bytes: &[u8],
        format: wgpu::TextureFormat,
    ) -> Texels {
        let (texture, view) = Self::make(gpu, mem, label, texel_row_count(bytes.len()), format);
        let t = Texels { texture, view, label: label.to_string(), format };
        t.upload(gpu, bytes);
        t
    }

    fn make(
        gpu: &Gpu,
        mem: &mut GpuMemory,
        label: &str,
        rows: u32,
        format: wgpu::TextureFormat,
    ) -> (wgpu::Texture, wgpu::TextureView) {
        mem.texture(
            &gpu.device,
            label,
            (TEXEL_ROW, rows),
            format,
            // COPY_SRC: posing on the GPU copies the current vertices to the previous ones.
            wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
        )
    }

    fn upload(&self, gpu: &Gpu, bytes: &[u8]) {
        self.upload_from(gpu, bytes, 0);
    }

    /// Write `bytes[from..]` (`from` a multiple of 16) at its texels: the rest of the first row
    /// it starts in, then whole rows, then the start of the last.
    fn upload_from(&self, gpu: &Gpu, bytes: &[u8], from: usize) {
        let row = TEXEL_ROW as usize;
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(TEXEL_ROW * 16),
            rows_per_image: None,
        };
        let mut texel = from / 16;
        let mut rest = &bytes[(texel * 16).min(bytes.len())..];
        while !rest.is_empty() {
            let (y, x) = (texel / row, texel % row);
            // A partial row (at either end) or every whole row at once.
            let (count, rows) = if x == 0 && rest.len() >= row * 16 {
                let rows = rest.len() / (row * 16);
                (rows * row, rows)
            } else {
                ((row - x).min(rest.len().div_ceil(16)), 1)
            };
            let n = (count * 16).min(rest.len());
            let mut data = rest[..n].to_vec();
            data.resize(count * 16, 0);
            let mut at = self.texture.as_image_copy();
            at.origin.x = x as u32;
            at.origin.y = y as u32;
            let width = if rows > 1 { TEXEL_ROW } else { count as u32 };
            let extent = wgpu::Extent3d { width, height: rows as u32, depth_or_array_layers: 1 };
            gpu.queue.write_texture(at, &data, layout, extent);
            rest = &rest[n..];
            texel += count;
        }
    }

    /// Write `bytes` from texel 0, in a larger texture where they no longer fit (true then:
    /// bind groups must be remade).
    pub fn write(&mut self, gpu: &Gpu, mem: &mut GpuMemory, bytes: &[u8]) -> bool {
        self.write_from(gpu, mem, bytes, 0)
    }

    /// [`Texels::write`] of `bytes`, of which the first `from` are already in the texture:
    /// only the rest is written, unless a larger texture takes them all.
    pub fn write_from(
        &mut self,
        gpu: &Gpu,
        mem: &mut GpuMemory,
        bytes: &[u8],
        from: usize,
    ) -> bool {
        let rows = texel_row_count(bytes.len());
        let replaced = rows > self.texture.height();
        if replaced {
            mem.forget(&self.label);
            // Headroom, so that a BVH a few nodes larger next frame does not reallocate again,
            // within what the device allows.
            let most = gpu.device.limits().max_texture_dimension_2d.max(rows);
            (self.texture, self.view) =
                Self::make(gpu, mem, &self.label, (rows + rows / 4 + 1).min(most), self.format);
        }
        self.upload_from(gpu, bytes, if replaced { 0 } else { from });
        replaced
    }
}
