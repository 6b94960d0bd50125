//! `accel/raycast`: closest (or any) hits for a batch of rays; checks the GPU BVH against the
//! CPU and measures rays per second.

use crate::gpu::scene::{binding, compute_pipeline, storage_entry, uniform_entry};
use crate::gpu::{Gpu, GpuMemory, GpuScene, readback_buffer};
use anyhow::Result;
use glam::Vec3;

pub const LABEL: &str = "accel/raycast";

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    pub t: f32,
    /// Index of the triangle in the scene's input (flattened) order.
    pub triangle: u32,
    /// Barycentrics of v1 and v2.
    pub b1: f32,
    pub b2: f32,
}

pub struct Raycaster {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl Raycaster {
    pub fn new(gpu: &Gpu, scene: &GpuScene) -> Result<Raycaster> {
        let modules = [
            "common/math.wgsl",
            "common/geometry.wgsl",
            scene.traversal_module(),
            "common/alpha_none.wgsl",
            "accel/raycast.wgsl",
        ];
        let program = gpu.shaders.compose(LABEL, "", &modules)?;
        let module = program.create(&gpu.device)?;
        let entries = [
            uniform_entry(0),
            storage_entry(binding::NODES, true),
            storage_entry(binding::TRIS, true),
            storage_entry(3, true),
            storage_entry(4, false),
        ];
        let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(LABEL), entries: &entries });
        let pipeline = compute_pipeline(&gpu.device, LABEL, &module, &layout);
        Ok(Raycaster { pipeline, layout })
    }

    /// Trace `rays` (origin, direction, tmax) in scene-relative coordinates. Returns the hits
    /// (None for a miss) and the GPU wall time of the dispatch alone.
    pub fn cast(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        rays: &[(Vec3, Vec3, f32)],
        any_hit: bool,
    ) -> Result<(Vec<Option<RayHit>>, std::time::Duration)> {
        let mut mem = GpuMemory::default();
        let n = rays.len() as u32;
        let ray_data: Vec<[f32; 4]> = rays.iter().flat_map(|(o, d, t)| [o.extend(*t).to_array(), d.extend(0.0).to_array()]).collect();
        let params = [n, any_hit as u32, 0, 0];
        let d = &gpu.device;
        let pbuf = mem.buffer_init(d, "raycast/params", bytemuck::cast_slice(&params), wgpu::BufferUsages::UNIFORM);
        let rbuf = mem.buffer_init(d, "raycast/rays", bytemuck::cast_slice(&ray_data), wgpu::BufferUsages::STORAGE);
        let hbuf = mem.buffer(d, "raycast/hits", n as u64 * 16, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(LABEL),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: pbuf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: binding::NODES, resource: scene.nodes.as_entire_binding() },
                wgpu::BindGroupEntry { binding: binding::TRIS, resource: scene.tris.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: rbuf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: hbuf.as_entire_binding() },
            ],
        });
        gpu.wait()?;
        let start = std::time::Instant::now();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(LABEL) });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(LABEL), timestamp_writes: None });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            let groups = n.div_ceil(64);
            pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        let elapsed = start.elapsed();
        let bytes = readback_buffer(d, &gpu.queue, &hbuf, n as u64 * 16)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let hits = v
            .iter()
            .map(|h| {
                (h[0] >= 0.0).then(|| RayHit { t: h[0], triangle: h[1].to_bits(), b1: h[2], b2: h[3] })
            })
            .collect();
        Ok((hits, elapsed))
    }
}
