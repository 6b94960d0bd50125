use anyhow::{Result, anyhow};
use wgpu::util::DeviceExt;

/// Creates buffers and remembers what each cost, so the renderer can report what it allocated.
#[derive(Default, Debug, Clone)]
pub struct GpuMemory {
    /// (label, bytes) of every buffer made through this tracker.
    pub allocations: Vec<(String, u64)>,
}

impl GpuMemory {
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

    pub fn buffer(
        &mut self,
        device: &wgpu::Device,
        label: &str,
        size: u64,
        usage: wgpu::BufferUsages,
    ) -> wgpu::Buffer {
        let size = size.max(16);
        self.allocations.push((label.to_string(), size));
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        })
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
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("readback"),
    });
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
    let data = slice
        .get_mapped_range()
        .map_err(|e| anyhow!("reading mapped range: {e}"))?
        .to_vec();
    staging.unmap();
    Ok(data)
}
