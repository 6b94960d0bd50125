//! `accel/raycast`: closest (or any) hits for a batch of rays; checks the GPU BVH against the
//! CPU and measures rays per second.

use crate::gpu::{Bindings, Gpu, GpuMemory, GpuScene, readback_buffer};
use crate::shader::FixedCompute;
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
    compute: FixedCompute,
}

impl Raycaster {
    pub fn new(gpu: &Gpu, scene: &GpuScene) -> Result<Raycaster> {
        let [tree, top] = scene.traversal_modules();
        let modules = [
            "common/math.wgsl",
            "common/geometry.wgsl",
            "common/motion_none.wgsl",
            scene.instance_module(),
            tree,
            top,
            "common/alpha_none.wgsl",
            "accel/raycast.wgsl",
        ];
        // The per-cast buffers are made by each cast: offer the scene's and their names.
        let mut offered: Vec<&str> = scene.bindings().names().collect();
        offered.extend(CAST_BUFFERS);
        Ok(Raycaster {
            compute: FixedCompute::new(gpu, LABEL, &scene.traversal_prelude(), &modules, &offered)?,
        })
    }

    /// Trace `rays` (origin, direction, tmax) in scene-relative coordinates. Returns the hits
    /// (None for a miss) and the GPU wall time of the dispatches alone. Rays go in batches whose
    /// buffers (32 bytes a ray) fit the device's storage binding.
    pub fn cast(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        rays: &[(Vec3, Vec3, f32)],
        any_hit: bool,
    ) -> Result<(Vec<Option<RayHit>>, std::time::Duration)> {
        let most = (gpu.device.limits().max_storage_buffer_binding_size as usize / 32).max(1);
        let mut hits = Vec::with_capacity(rays.len());
        let mut time = std::time::Duration::ZERO;
        for chunk in rays.chunks(most) {
            let (h, t) = self.cast_batch(gpu, scene, chunk, any_hit)?;
            hits.extend(h);
            time += t;
        }
        Ok((hits, time))
    }

    fn cast_batch(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        rays: &[(Vec3, Vec3, f32)],
        any_hit: bool,
    ) -> Result<(Vec<Option<RayHit>>, std::time::Duration)> {
        let mut mem = GpuMemory::default();
        let n = rays.len() as u32;
        let ray_data: Vec<[f32; 4]> = rays
            .iter()
            .flat_map(|(o, d, t)| [o.extend(*t).to_array(), d.extend(0.0).to_array()])
            .collect();
        let params = [n, any_hit as u32, 0, 0];
        let d = &gpu.device;
        let pbuf = mem.buffer_init(
            d,
            "raycast/params",
            bytemuck::cast_slice(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let rbuf = mem.buffer_init(
            d,
            "raycast/rays",
            bytemuck::cast_slice(&ray_data),
            wgpu::BufferUsages::STORAGE,
        );
        let hbuf = mem.buffer(
            d,
            "raycast/hits",
            n as u64 * 16,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        // A refused binding or dispatch is an error here, not a silently empty result.
        let groups = gpu.validated(&format!("binding {n} rays"), || {
            self.compute.bind_groups(d, &cast_bindings(scene, &pbuf, &rbuf, &hbuf))
        })?;
        gpu.wait()?;
        let start = std::time::Instant::now();
        gpu.validated(&format!("casting {n} rays"), || {
            let mut enc =
                d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(LABEL) });
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(LABEL),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.compute.pipeline);
                crate::gpu::set_compute_groups(&mut pass, &groups);
                let groups = n.div_ceil(64);
                pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })?;
        gpu.wait()?;
        let elapsed = start.elapsed();
        let bytes = readback_buffer(d, &gpu.queue, &hbuf, n as u64 * 16)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let hits = v
            .iter()
            .map(|h| {
                (h[0] >= 0.0).then(|| RayHit {
                    t: h[0],
                    triangle: h[1].to_bits(),
                    b1: h[2],
                    b2: h[3],
                })
            })
            .collect();
        Ok((hits, elapsed))
    }
}

/// What each cast binds beside the scene (accel/raycast.wgsl).
const CAST_BUFFERS: [&str; 3] = ["params", "rays", "hits"];

fn cast_bindings<'a>(
    scene: &'a GpuScene,
    params: &'a wgpu::Buffer,
    rays: &'a wgpu::Buffer,
    hits: &'a wgpu::Buffer,
) -> Bindings<'a> {
    let [p, r, h] = CAST_BUFFERS;
    scene.bindings().buffer(p, params).buffer(r, rays).buffer(h, hits)
}
