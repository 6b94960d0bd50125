//! What can be read back of the last frame: its image, any labelled texture, pass times.

use super::{DisplayTarget, Renderer};
use crate::gpu::Gpu;
use crate::quality::Image;
use crate::settings::FrameSettings;
use anyhow::{Context, Result};
use glam::Vec3;

impl Renderer {
    /// The display's image of the last frame (tone-mapped or the chosen debug view) as 8-bit
    /// sRGB, at the size it was shown at.
    pub fn display_image(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
    ) -> Result<image::RgbaImage> {
        let (w, h) = self.shown_image_size();
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("display image"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = tex.create_view(&Default::default());
        self.redisplay(gpu, settings, &DisplayTarget { view: &view, format, size: (w, h) })?;
        let bytes = crate::gpu::readback_texture(gpu, &tex)?;
        image::RgbaImage::from_raw(w, h, bytes).context("display image has the wrong size")
    }

    /// GPU milliseconds per pass label of the last frame, passes of one label summed (blocks
    /// until it finished); empty without timestamp queries.
    pub fn pass_times(&self, gpu: &Gpu) -> Result<Vec<(&'static str, f64)>> {
        Ok(crate::profile::per_label(&self.pass_spans(gpu)?))
    }

    /// Passes of the last recorded frame that found no timestamp slot left (their time is
    /// missing from [`Renderer::pass_spans`]); 0 unless a frame runs more passes than the timer holds.
    pub fn untimed_passes(&self) -> u32 {
        self.timer.as_ref().map_or(0, |t| t.dropped())
    }

    /// Each pass of the last frame with its start and duration (blocks until it finished); when
    /// puffin's scopes are on, also reported as the frame's GPU timeline.
    pub fn pass_spans(&self, gpu: &Gpu) -> Result<Vec<crate::profile::PassSpan>> {
        let Some(t) = &self.timer else { return Ok(vec![]) };
        let spans = t.read_spans(gpu)?;
        crate::profile::report_gpu(t.submitted_ns, &spans);
        Ok(spans)
    }

    /// Keep per-pass times for [`Renderer::poll_pass_spans`] instead of [`Renderer::pass_spans`]
    /// (the viewer: reading times back never waits for the GPU).
    pub fn set_async_timings(&mut self, on: bool) {
        self.async_timings = on;
    }

    /// The passes of the oldest frame that finished since the last call, without waiting
    /// (frames with async timings on); reported to puffin as that frame's GPU timeline.
    pub fn poll_pass_spans(&mut self, gpu: &Gpu) -> Option<Vec<crate::profile::PassSpan>> {
        let (submitted, spans) = self.timer.as_mut()?.poll(gpu)?;
        crate::profile::report_gpu(submitted, &spans);
        Some(spans)
    }

    /// Frames summed in accumulate mode (0 when off).
    pub fn accumulated(&self) -> u32 {
        self.history.accumulated
    }

    /// The last frame's linear HDR image (after composite, TAA or the upscaler, at the size it
    /// was shown at), or in accumulate mode the mean.
    pub fn read_hdr(&self, gpu: &Gpu) -> Result<Image> {
        let (w, h) = self.shown_image_size();
        let n = w as u64 * h as u64 * 16;
        let s = &self.stages;
        let shown = super::record::after_taa(&s.taa, &s.converge, &s.upscale, &self.targets.hdr)
            .filter(|_| self.history.denoised_last.is_some())
            .unwrap_or(&self.targets.hdr);
        let (buf, scale) = match (&self.targets.accumulation, self.history.accumulated) {
            (Some(a), k) if k > 0 => (a, 1.0 / k as f32),
            _ => (shown, 1.0),
        };
        let bytes = crate::gpu::readback_buffer(&gpu.device, &gpu.queue, buf, n)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let mut img = Image::new(w, h);
        for (d, s) in img.data.iter_mut().zip(v) {
            *d = Vec3::new(s[0], s[1], s[2]) * scale;
        }
        Ok(img)
    }

    /// Read any texture of the frame back by its label (as the allocation report and debug
    /// views name it: `gbuffer/depth`, `trace/matte`, `matte/history 0`, `taa/history 1`, ...),
    /// raw bytes with rows tightly packed.
    pub fn read_texture(&self, gpu: &Gpu, name: &str) -> Result<(Vec<u8>, wgpu::TextureFormat)> {
        let tex = self.targets.memory.find_texture(name).with_context(|| {
            let labels: Vec<&str> = self.targets.memory.textures.iter().map(|(l, _)| l.as_str()).collect();
            format!("no texture {name:?} in this frame (its textures: {}; a denoiser's appear once it has run, and one that shares its memory with a later texture of the frame once `Renderer::keep` names it)", labels.join(", "))
        })?;
        Ok((crate::gpu::readback_texture(gpu, tex)?, tex.format()))
    }

    /// The view depth (scene units along the view axis) of the last frame's surface at `pixel`,
    /// from the G-buffer's depth (with a thin lens, the mean over the pixel's primary samples);
    /// None where there is no surface. The viewer's click-to-focus.
    pub fn view_depth_at(&self, gpu: &Gpu, pixel: (u32, u32)) -> Result<Option<f64>> {
        let (w, h) = self.targets.size;
        if pixel.0 >= w || pixel.1 >= h {
            return Ok(None);
        }
        let (bytes, _) = self.read_texture(gpu, "gbuffer/depth")?;
        let i = (pixel.1 * w + pixel.0) as usize * 4;
        let Some(d) = bytes.get(i..i + 4).map(bytemuck::pod_read_unaligned::<f32>) else {
            return Ok(None);
        };
        // Reversed infinite Z: depth = near / view depth, 0 where nothing was drawn.
        Ok((d > 0.0 && d.is_finite()).then(|| self.near() as f64 / d as f64))
    }

    /// The bytes of the frame's buffer labelled `name` (`supersample/samples`, the radiance
    /// cache's `cache/cells`, ...).
    pub fn read_buffer(&self, gpu: &Gpu, name: &str) -> Result<Vec<u8>> {
        let cache = self.stages.cache.cells().map(|c| &c.memory);
        let found = self.targets.memory.find_buffer(name);
        let b = found.or_else(|| cache.and_then(|m| m.find_buffer(name))).with_context(|| {
            let labels: Vec<&str> =
                self.targets.memory.buffers.iter().map(|(l, _)| l.as_str()).collect();
            format!("no buffer {name:?} in this frame (its buffers: {})", labels.join(", "))
        })?;
        crate::gpu::readback_buffer(&gpu.device, &gpu.queue, b, b.size())
    }

    /// The scene's triangle vertices as the GPU holds them now (three vec4 a slot, as
    /// [`crate::gpu::PreparedScene::tris`] lays them out): where deforming meshes are posed on
    /// the GPU, the CPU's copy keeps their last CPU flattening.
    pub fn read_triangles(&self, gpu: &Gpu) -> Result<Vec<glam::Vec4>> {
        let n = self.gpu_scene.triangle_count as u64 * 48;
        let b = crate::gpu::readback_buffer(&gpu.device, &gpu.queue, &self.gpu_scene.tris, n)?;
        Ok(bytemuck::cast_slice(&b).to_vec())
    }

    /// The scene's triangle vertices at the shutter's open as the GPU holds them now (the
    /// current ones while nothing moves during the shutter); None in a scene that never moves.
    pub fn read_triangles_at_open(&self, gpu: &Gpu) -> Result<Option<Vec<glam::Vec4>>> {
        let Some(t) = &self.gpu_scene.tri_open_texels else { return Ok(None) };
        let b = crate::gpu::readback_texture(gpu, &t.texture)?;
        let v: &[glam::Vec4] = bytemuck::cast_slice(&b);
        Ok(Some(v[..self.gpu_scene.triangle_count as usize * 3].to_vec()))
    }

    /// The scene's BVH nodes as the GPU holds them now, in [`crate::gpu::PreparedScene::accel`]'s
    /// layout.
    pub fn read_bvh_nodes(&self, gpu: &Gpu) -> Result<Vec<u8>> {
        let mut b = crate::gpu::readback_texture(gpu, &self.gpu_scene.nodes.texture)?;
        b.truncate(self.prepared.accel.nodes.len());
        Ok(b)
    }
}
