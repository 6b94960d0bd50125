//! Running one WGSL function of Hush's shaders on the GPU against a CPU computation: a test
//! program (its own bindings and entry point) composed with the embedded modules it exercises.

use hush_engine::gpu::Gpu;
use hush_engine::gpu::scene::Texels;
use wgpu::util::DeviceExt;

/// What the test program reads: a uniform, a read-only storage buffer, or 16-byte records as
/// texel rows of an `Rgba32Uint` texture (`hush_engine::gpu::scene::Texels`, as the scene's
/// tables are kept).
pub enum Input<'a> {
    Uniform(&'a [u8]),
    Storage(&'a [u8]),
    Texels(&'a [u8]),
}

/// Compose `program` (the test's WGSL: bindings and `main`) after `modules`, bind `inputs` to
/// group 0's bindings 0, 1, ... and a read-write storage buffer of `out_bytes` bytes to the
/// next, dispatch `groups` workgroups and return the output's bytes.
pub fn run_compute(
    gpu: &Gpu,
    program: &str,
    modules: &[&'static str],
    inputs: &[Input],
    out_bytes: u64,
    groups: (u32, u32),
) -> Vec<u8> {
    let composed = hush_engine::shader::compose("test program", program, modules).unwrap();
    let module = composed.create(&gpu.device).unwrap();
    let d = &gpu.device;
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("test program"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let mut memory = hush_engine::gpu::GpuMemory::default();
    let mut buffers = vec![];
    let mut texels = vec![];
    for input in inputs {
        let (contents, usage) = match input {
            Input::Uniform(b) => (*b, wgpu::BufferUsages::UNIFORM),
            Input::Storage(b) => (*b, wgpu::BufferUsages::STORAGE),
            Input::Texels(b) => {
                let format = wgpu::TextureFormat::Rgba32Uint;
                texels.push((
                    buffers.len() + texels.len(),
                    Texels::new(gpu, &mut memory, "test texels", b, format),
                ));
                continue;
            }
        };
        let init = wgpu::util::BufferInitDescriptor { label: None, contents, usage };
        buffers.push((buffers.len() + texels.len(), d.create_buffer_init(&init)));
    }
    let out = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    buffers.push((inputs.len(), out));
    let mut entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .map(|(i, b)| wgpu::BindGroupEntry { binding: *i as u32, resource: b.as_entire_binding() })
        .collect();
    entries.extend(texels.iter().map(|(i, t)| wgpu::BindGroupEntry {
        binding: *i as u32,
        resource: wgpu::BindingResource::TextureView(&t.view),
    }));
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
    gpu.queue.submit([enc.finish()]);
    let out = &buffers.last().unwrap().1;
    hush_engine::gpu::readback_buffer(&gpu.device, &gpu.queue, out, out_bytes).unwrap()
}
