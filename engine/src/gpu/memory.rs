use anyhow::{Result, anyhow};
use wgpu::util::DeviceExt;

/// Creates buffers and textures and remembers what each cost, so the renderer can report what
/// it allocated; its textures can be found again by label (readback, debug views).
#[derive(Default, Debug, Clone)]
pub struct GpuMemory {
    /// (label, bytes) of every buffer and texture made through this tracker.
    pub allocations: Vec<(String, u64)>,
    /// Every texture made through this tracker, by label (a ping-pong pair is "name 0" and
    /// "name 1").
    pub textures: Vec<(String, wgpu::Texture)>,
    /// Every buffer made through this tracker that can be copied from, by label.
    pub buffers: Vec<(String, wgpu::Buffer)>,
    /// Labels of the allocations that are transient pool slots ([`super::graph`]): memory that
    /// lives within a frame, shared by textures whose lives do not overlap.
    pub transient: Vec<String>,
    /// Transient textures that still hold what their pass wrote after the frame (nothing later
    /// shares their slot), by name: debug views and readbacks find them here.
    pub named: Vec<(String, wgpu::Texture)>,
}

impl GpuMemory {
    /// The texture labelled `label`, if this tracker made one.
    pub fn find_texture(&self, label: &str) -> Option<&wgpu::Texture> {
        let named = || self.named.iter().find(|(l, _)| l == label);
        self.textures.iter().find(|(l, _)| l == label).or_else(named).map(|(_, t)| t)
    }

    /// Forget what was made under labels starting with `prefix` (it was replaced).
    pub fn forget(&mut self, prefix: &str) {
        self.forget_where(|l| l.starts_with(prefix));
    }

    /// Forget what was made under `labels` (their owner was dropped or made them again).
    pub fn forget_labels(&mut self, labels: &[String]) {
        self.forget_where(|l| labels.iter().any(|x| x == l));
    }

    fn forget_where(&mut self, gone: impl Fn(&str) -> bool) {
        self.allocations.retain(|(l, _)| !gone(l));
        self.textures.retain(|(l, _)| !gone(l));
        self.buffers.retain(|(l, _)| !gone(l));
        self.transient.retain(|l| !gone(l));
        self.named.retain(|(l, _)| !gone(l));
    }

    /// Every label made or named here.
    pub fn labels(&self) -> Vec<String> {
        let named = self.named.iter().map(|(l, _)| l.clone());
        self.allocations.iter().map(|(l, _)| l.clone()).chain(named).collect()
    }

    /// Bytes of the transient pool slots (the rest outlives a frame).
    pub fn transient_bytes(&self) -> u64 {
        let t = |l: &String| self.transient.contains(l);
        self.allocations.iter().filter(|(l, _)| t(l)).map(|(_, b)| b).sum()
    }

    /// A transient pool slot: a texture as [`GpuMemory::texture`] makes, counted as transient
    /// and not found by label (its textures are named by [`GpuMemory::name_transient`]).
    pub fn transient_texture(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> (wgpu::Texture, wgpu::TextureView) {
        let made = self.texture(device, label, size, format, usage);
        self.textures.pop();
        self.transient.push(label.to_string());
        made
    }

    /// Find the pool slot `texture` by the transient texture's `name` that it holds after the
    /// frame.
    pub fn name_transient(&mut self, name: &str, texture: &wgpu::Texture) {
        self.named.push((name.to_string(), texture.clone()));
    }

    /// The buffer labelled `label`, if this tracker made one with COPY_SRC.
    pub fn find_buffer(&self, label: &str) -> Option<&wgpu::Buffer> {
        self.buffers.iter().find(|(l, _)| l == label).map(|(_, b)| b)
    }

    pub fn total_bytes(&self) -> u64 {
        self.allocations.iter().map(|(_, b)| b).sum()
    }

    /// A buffer initialised with `contents`. Empty contents get 16 zero bytes: WGSL has no empty
    /// runtime arrays, and a scene without (say) emitters still binds a valid buffer.
    pub fn buffer_init(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        contents: &[u8],
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let zeros = [0u8; 16];
        let contents = if contents.is_empty() { &zeros[..] } else { contents };
        self.allocations.push((label.to_string(), contents.len() as u64));
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage,
        })
    }

    /// A 2D texture and its default view; its bytes are width x height x the format's block size.
    pub fn texture(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        (width, height): (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> (wgpu::Texture, wgpu::TextureView) {
        let bytes = format.block_copy_size(Some(wgpu::TextureAspect::All)).unwrap_or(4) as u64;
        self.allocations.push((label.to_string(), width as u64 * height as u64 * bytes));
        let t = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        });
        let v = t.create_view(&Default::default());
        self.textures.push((label.to_string(), t.clone()));
        (t, v)
    }

    pub fn buffer(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        size: u64,
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let size = size.max(16);
        self.allocations.push((label.to_string(), size));
        let b = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        });
        if usage.contains(wgpu::BufferUsages::COPY_SRC) {
            self.buffers.push((label.to_string(), b.clone()));
        }
        b
    }
}

/// Copy `src` (which must have COPY_SRC) into a mappable buffer and read it back.
pub fn readback_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    src: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    enc.copy_buffer_to_buffer(src, 0, &staging, 0, size);
    queue.submit([enc.finish()]);
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| anyhow!("waiting for readback: {e}"))?;
    rx.recv()
        .map_err(|_| anyhow!("readback callback never ran"))?
        .map_err(|e| anyhow!("mapping readback buffer: {e}"))?;
    let data = slice.get_mapped_range().map_err(|e| anyhow!("reading mapped range: {e}"))?.to_vec();
    staging.unmap();
    Ok(data)
}

/// Copy a 2D texture (COPY_SRC) into memory, rows tightly packed.
pub fn readback_texture(gpu: &super::Gpu, tex: &wgpu::Texture) -> Result<Vec<u8>> {
    let (w, h) = (tex.width(), tex.height());
    let bpp = tex
        .format()
        .block_copy_size(Some(wgpu::TextureAspect::All))
        .ok_or_else(|| anyhow!("texture format {:?} cannot be copied", tex.format()))?;
    let row = w * bpp;
    let padded = row.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture readback"),
        size: padded as u64 * h as u64,
        usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        tex.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([enc.finish()]);
    let bytes = readback_buffer(&gpu.device, &gpu.queue, &staging, padded as u64 * h as u64)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for y in 0..h as usize {
        out.extend_from_slice(&bytes[y * padded as usize..y * padded as usize + row as usize]);
    }
    Ok(out)
}
