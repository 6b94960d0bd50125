//! Posing deforming meshes on the GPU each frame: their vertices morphed and skinned
//! (shaders/accel/pose.wgsl), written into the moving part's triangle slots (pose_slots.wgsl),
//! the moving tree refit level by level from its deepest (refit.wgsl) and its surface-area cost
//! summed (refit_cost.wgsl) and read back a frame or two later; where the refit has degraded
//! the tree past [`crate::accel::REFIT_LIMIT`] times its built cost, the next frame flattens and
//! rebuilds on the CPU ([`PreparedScene::rebuild_posing`]) and the GPU takes over again from
//! there. The previous frame's vertices (motion vectors) are the current ones copied before the
//! pose; the shutter's open end is posed beside the close.
//!
//! What the CPU keeps per frame is the joint matrices and morph weights. A 50,000-triangle
//! skinned tube on an NVIDIA H200 costs 0.6-0.7 ms a frame so, against 23-24 ms posed, refit
//! and uploaded by the CPU (`docs/decisions.md`, Animation).

use super::prepare::posing::{MATRIX_TEXELS, PosingLayout};
use super::scene::TEXEL_ROW;
use super::{Bindings, Gpu, GpuMemory, GpuScene, PreparedScene, Recorder};
use crate::scene::Scene;
use crate::shader::FixedCompute;
use anyhow::Result;
use glam::Vec4;
use std::mem::take;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

pub const LABEL: &str = "pose";

/// Its programs: label and module (each one module alone).
pub const PROGRAMS: [(&str, &str); 4] = [
    ("pose/vertices", "accel/pose.wgsl"),
    ("pose/slots", "accel/pose_slots.wgsl"),
    ("pose/refit", "accel/refit.wgsl"),
    ("pose/refit cost", "accel/refit_cost.wgsl"),
];

const POSE: [&str; 8] = [
    "pose_params",
    "rest",
    "influences",
    "pose_objects",
    "deltas",
    "joint_mats",
    "morph_weights",
    "posed",
];
const SLOTS: [&str; 7] =
    ["slot_params", "slot_verts", "posed", "tris", "posed_shading", "posed_tangents", "posed_open"];
const REFIT: [&str; 7] =
    ["refit_params", "level_nodes", "tris", "posed_open", "refit_nodes", "exact", "node_cost"];
const COST: [&str; 4] = ["cost_params", "node_cost", "exact", "cost_out"];

/// The cost readback's state: idle, copied this frame, mapping, mapped.
const IDLE: u8 = 0;
const COPIED: u8 = 1;
const MAPPING: u8 = 2;
const MAPPED: u8 = 3;

pub struct GpuPosing {
    programs: Programs,
    state: Option<State>,
    /// The refit tree's last cost read back, relative to its built cost.
    pub last_cost_ratio: Option<f32>,
    /// CPU rebuilds the refit's cost asked for.
    pub rebuilds: u32,
    matrices: Vec<Vec4>,
    weights: Vec<f32>,
}

struct Programs {
    pose: FixedCompute,
    slots: FixedCompute,
    refit: FixedCompute,
    cost: FixedCompute,
}

/// The buffers of one layout (one CPU flattening of the moving part).
struct State {
    epoch: u64,
    generation: u64,
    layout: PosingLayout,
    mem: GpuMemory,
    vertex_count: u32,
    slot_count: u32,
    node_count: u32,
    pose_params: wgpu::Buffer,
    slot_params: wgpu::Buffer,
    rest: wgpu::Buffer,
    influences: wgpu::Buffer,
    objects: wgpu::Buffer,
    deltas: wgpu::Buffer,
    joint_mats: wgpu::Buffer,
    morph_weights: wgpu::Buffer,
    posed: wgpu::Buffer,
    slot_verts: wgpu::Buffer,
    posed_shading: wgpu::Buffer,
    no_tangents: wgpu::Buffer,
    posed_open: wgpu::Buffer,
    level_params: Vec<wgpu::Buffer>,
    level_nodes: wgpu::Buffer,
    refit_nodes: wgpu::Buffer,
    exact: wgpu::Buffer,
    node_cost: wgpu::Buffer,
    cost_params: wgpu::Buffer,
    cost_out: wgpu::Buffer,
    cost_read: wgpu::Buffer,
    read_state: Arc<AtomicU8>,
    groups: Option<Groups>,
    /// Shutter ends of the pose to record this frame (0: none).
    ends: u32,
    /// The ends the passes' parameters were last written for (0: not yet).
    written_ends: u32,
}

struct Groups {
    pose: Vec<wgpu::BindGroup>,
    slots: Vec<wgpu::BindGroup>,
    refit: Vec<Vec<wgpu::BindGroup>>,
    cost: Vec<wgpu::BindGroup>,
}

impl GpuPosing {
    /// The programs; None where the scene's moving part cannot be posed on the GPU.
    pub fn new(gpu: &Gpu, prepared: &PreparedScene) -> Result<Option<GpuPosing>> {
        if !prepared.posing_supported() {
            return Ok(None);
        }
        let make = |(label, module): (&str, &'static str), offered: &[&str]| {
            FixedCompute::new(gpu, label, "", &[module], offered)
        };
        let programs = Programs {
            pose: make(PROGRAMS[0], &POSE)?,
            slots: make(PROGRAMS[1], &SLOTS)?,
            refit: make(PROGRAMS[2], &REFIT)?,
            cost: make(PROGRAMS[3], &COST)?,
        };
        Ok(Some(GpuPosing {
            programs,
            state: None,
            last_cost_ratio: None,
            rebuilds: 0,
            matrices: vec![],
            weights: vec![],
        }))
    }

    /// After [`PreparedScene::expose`] and [`GpuScene::update_geometry`]: take up a new CPU
    /// flattening, pick up the last cost read back (asking for a rebuild where it has grown
    /// too far), and write this frame's matrices where `prepared` asks for a pose.
    pub fn prepare(
        &mut self,
        gpu: &Gpu,
        scene: &Scene,
        prepared: &mut PreparedScene,
        gpu_scene: &GpuScene,
    ) -> Result<()> {
        if self.state.as_ref().is_none_or(|s| s.epoch != prepared.posing_epoch) {
            self.state = prepared.posing_layout(scene).map(|l| State::new(gpu, l, prepared));
        }
        let Some(s) = self.state.as_mut() else { return Ok(()) };
        s.ends = 0;
        if s.generation != gpu_scene.generation || s.groups.is_none() {
            s.groups = Some(s.bind(gpu, &self.programs, gpu_scene)?);
            s.generation = gpu_scene.generation;
        }
        if let Some(cost) = s.take_cost(gpu) {
            let ratio = cost / s.layout.built_cost.max(f32::MIN_POSITIVE);
            self.last_cost_ratio = Some(ratio);
            if !(ratio <= crate::accel::REFIT_LIMIT) {
                prepared.rebuild_posing = true;
                self.rebuilds += 1;
            }
        }
        let Some((close, open)) = prepared.pose_request else { return Ok(()) };
        self.matrices.clear();
        self.weights.clear();
        let mut rewound =
            prepared.posing_pose(scene, &s.layout, close, &mut self.matrices, &mut self.weights);
        let ends = if let Some(open) = open {
            rewound |=
                prepared.posing_pose(scene, &s.layout, open, &mut self.matrices, &mut self.weights);
            2
        } else {
            1
        };
        if rewound {
            prepared.rebuild_posing = true;
        }
        gpu.queue.write_buffer(&s.joint_mats, 0, bytemuck::cast_slice(&self.matrices));
        if !self.weights.is_empty() {
            gpu.queue.write_buffer(&s.morph_weights, 0, bytemuck::cast_slice(&self.weights));
        }
        // The passes' parameters change only with the shutter's ends.
        if ends != s.written_ends {
            let l = &s.layout;
            let params = [s.vertex_count, ends, l.matrices, l.weights];
            gpu.queue.write_buffer(&s.pose_params, 0, bytemuck::cast_slice(&params));
            let params = [s.slot_count, l.slot_base, ends, s.vertex_count];
            gpu.queue.write_buffer(&s.slot_params, 0, bytemuck::cast_slice(&params));
            for (buf, &(first, count)) in s.level_params.iter().zip(&l.levels) {
                let p = [first, count, l.node_base, l.slot_base, (ends > 1) as u32, 0, 0, 0];
                gpu.queue.write_buffer(buf, 0, bytemuck::cast_slice(&p));
            }
            s.written_ends = ends;
        }
        s.ends = ends;
        Ok(())
    }

    /// Record this frame's pose, refit and copies, where [`GpuPosing::prepare`] asked for one.
    pub fn record(&mut self, rec: &mut Recorder, scene: &GpuScene) {
        let Some(s) = self.state.as_mut().filter(|s| s.ends > 0) else { return };
        let Some(g) = s.groups.as_ref() else { return };
        let p = &self.programs;
        let l = &s.layout;
        // The previous vertices are this frame's before the pose.
        if let Some(prev) = &scene.tri_prev_texels {
            for seg in segments(l.slot_base * 3, s.slot_count * 3) {
                rec.enc.copy_texture_to_texture(
                    seg.at(&scene.tri_texels.texture),
                    seg.at(&prev.texture),
                    seg.extent(),
                );
            }
        }
        {
            let mut pass = rec.compute_pass(LABEL);
            let groups = |n: u32| (n.div_ceil(64).min(65535), n.div_ceil(64).div_ceil(65535));
            pass.set_pipeline(&p.pose.pipeline);
            crate::gpu::set_compute_groups(&mut pass, &g.pose);
            let (x, y) = groups(s.vertex_count * s.ends);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&p.slots.pipeline);
            crate::gpu::set_compute_groups(&mut pass, &g.slots);
            let (x, y) = groups(s.slot_count);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&p.refit.pipeline);
            for (level, &(_, count)) in g.refit.iter().zip(&l.levels) {
                crate::gpu::set_compute_groups(&mut pass, level);
                pass.dispatch_workgroups(count.div_ceil(64), 1, 1);
            }
            pass.set_pipeline(&p.cost.pipeline);
            crate::gpu::set_compute_groups(&mut pass, &g.cost);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let copies = [
            (
                &scene.tris,
                l.slot_base as u64 * 48,
                &scene.tri_texels.texture,
                l.slot_base * 3,
                s.slot_count * 3,
            ),
            (&s.posed_shading, 0, &scene.shading.texture, l.slot_base * 4, s.slot_count * 4),
            (&s.refit_nodes, 0, &scene.nodes.texture, l.node_base * 5, s.node_count * 5),
        ];
        for (buf, offset, tex, first, count) in copies {
            copy_to_texels(rec.enc, buf, offset, tex, first, count);
        }
        if let Some(open) = &scene.tri_open_texels {
            copy_to_texels(
                rec.enc,
                &s.posed_open,
                0,
                &open.texture,
                l.slot_base * 3,
                s.slot_count * 3,
            );
        }
        if s.read_state.load(Ordering::Acquire) == IDLE {
            rec.enc.copy_buffer_to_buffer(&s.cost_out, 0, &s.cost_read, 0, 4);
            s.read_state.store(COPIED, Ordering::Release);
        }
    }

    /// After the frame's submission: start mapping the cost it copied.
    pub fn submitted(&mut self) {
        let Some(s) = self.state.as_mut() else { return };
        if s.read_state.load(Ordering::Acquire) != COPIED {
            return;
        }
        s.read_state.store(MAPPING, Ordering::Release);
        let flag = s.read_state.clone();
        s.cost_read.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            flag.store(if r.is_ok() { MAPPED } else { IDLE }, Ordering::Release);
        });
    }

    /// GPU memory of the posing buffers.
    pub fn memory_bytes(&self) -> u64 {
        self.state.as_ref().map_or(0, |s| s.mem.total_bytes())
    }
}

impl State {
    /// Upload `layout`; its per-vertex, per-slot and per-node arrays go to the GPU and are not
    /// kept.
    fn new(gpu: &Gpu, mut layout: PosingLayout, prepared: &PreparedScene) -> State {
        use wgpu::BufferUsages as U;
        let mut mem = GpuMemory::default();
        let d = &gpu.device;
        // Bindings may not be empty: a scene without morph targets binds one zero record.
        fn bytes<T: bytemuck::Pod>(v: &[T]) -> Vec<u8> {
            let mut b = bytemuck::cast_slice(v).to_vec();
            b.resize(b.len().max(16), 0);
            b
        }
        let vertex_count = layout.rest.len() as u32 / 3;
        let slot_count = layout.slot_verts.len() as u32;
        let node_count = (layout.nodes.len() / 80) as u32;
        let storage = U::STORAGE;
        let mut init = |label: &str, b: &[u8], usage: U| mem.buffer_init(d, label, b, usage);
        let slots_from = layout.slot_base as usize;
        let shading = bytes(&prepared.shading[slots_from * 4..]);
        let rest = init("pose/rest", &bytes(&take(&mut layout.rest)), storage);
        let influences = init("pose/influences", &bytes(&take(&mut layout.influences)), storage);
        let objects = init("pose/objects", &bytes(&take(&mut layout.object_records)), storage);
        let deltas = init("pose/deltas", &bytes(&take(&mut layout.deltas)), storage);
        let slot_verts = init("pose/slot vertices", &bytes(&take(&mut layout.slot_verts)), storage);
        let posed_shading = init("pose/shading", &shading, storage | U::COPY_SRC);
        let level_nodes = init("pose/level nodes", &bytes(&take(&mut layout.level_nodes)), storage);
        let refit_nodes =
            init("pose/nodes", &bytes(&take(&mut layout.nodes)), storage | U::COPY_SRC);
        let node_params = [node_count, 0, 0, 0];
        let cost_params = init("pose/cost params", bytemuck::cast_slice(&node_params), U::UNIFORM);
        let mut buffer =
            |label: &str, size: u64, usage: U| mem.buffer(d, label, size.max(16), usage);
        let ends = 2u64;
        let joint_mats = buffer(
            "pose/joint matrices",
            ends * layout.matrices as u64 * MATRIX_TEXELS as u64 * 16,
            storage | U::COPY_DST,
        );
        let morph_weights =
            buffer("pose/morph weights", ends * layout.weights as u64 * 4, storage | U::COPY_DST);
        let posed = buffer("pose/posed", ends * vertex_count as u64 * 48, storage);
        let no_tangents = buffer("pose/no tangents", 16, storage);
        let posed_open = buffer("pose/open", slot_count as u64 * 48, storage | U::COPY_SRC);
        let exact = buffer("pose/exact boxes", node_count as u64 * 32, storage);
        let node_cost = buffer("pose/node cost", node_count as u64 * 4, storage);
        let cost_out = buffer("pose/cost", 16, storage | U::COPY_SRC);
        let cost_read = buffer("pose/cost readback", 16, U::MAP_READ | U::COPY_DST);
        let pose_params = buffer("pose/params", 16, U::UNIFORM | U::COPY_DST);
        let slot_params = buffer("pose/slot params", 16, U::UNIFORM | U::COPY_DST);
        let level_params = (0..layout.levels.len())
            .map(|_| buffer("pose/level params", 32, U::UNIFORM | U::COPY_DST))
            .collect();
        State {
            epoch: prepared.posing_epoch,
            generation: u64::MAX,
            layout,
            mem,
            vertex_count,
            slot_count,
            node_count,
            pose_params,
            slot_params,
            rest,
            influences,
            objects,
            deltas,
            joint_mats,
            morph_weights,
            posed,
            slot_verts,
            posed_shading,
            no_tangents,
            posed_open,
            level_params,
            level_nodes,
            refit_nodes,
            exact,
            node_cost,
            cost_params,
            cost_out,
            cost_read,
            read_state: Arc::new(AtomicU8::new(IDLE)),
            groups: None,
            ends: 0,
            written_ends: 0,
        }
    }

    fn bind(&self, gpu: &Gpu, p: &Programs, scene: &GpuScene) -> Result<Groups> {
        let d = &gpu.device;
        let shared = Bindings::new()
            .buffer("posed", &self.posed)
            .buffer("tris", &scene.tris)
            .buffer("posed_open", &self.posed_open)
            .buffer("node_cost", &self.node_cost)
            .buffer("exact", &self.exact);
        let pose = shared
            .clone()
            .buffer("pose_params", &self.pose_params)
            .buffer("rest", &self.rest)
            .buffer("influences", &self.influences)
            .buffer("pose_objects", &self.objects)
            .buffer("deltas", &self.deltas)
            .buffer("joint_mats", &self.joint_mats)
            .buffer("morph_weights", &self.morph_weights);
        let slots = shared
            .clone()
            .buffer("slot_params", &self.slot_params)
            .buffer("slot_verts", &self.slot_verts)
            .buffer("posed_shading", &self.posed_shading)
            .buffer("posed_tangents", scene.tangents.as_ref().unwrap_or(&self.no_tangents));
        let refit = self
            .level_params
            .iter()
            .map(|lp| {
                let b = shared
                    .clone()
                    .buffer("refit_params", lp)
                    .buffer("level_nodes", &self.level_nodes)
                    .buffer("refit_nodes", &self.refit_nodes);
                p.refit.bind_groups(d, &b)
            })
            .collect::<Result<Vec<_>>>()?;
        let cost = shared
            .clone()
            .buffer("cost_params", &self.cost_params)
            .buffer("cost_out", &self.cost_out);
        Ok(Groups {
            pose: p.pose.bind_groups(d, &pose)?,
            slots: p.slots.bind_groups(d, &slots)?,
            refit,
            cost: p.cost.bind_groups(d, &cost)?,
        })
    }

    /// The cost a finished readback holds, relative to the root's area.
    fn take_cost(&mut self, gpu: &Gpu) -> Option<f32> {
        if self.read_state.load(Ordering::Acquire) == MAPPING {
            let _ = gpu.device.poll(wgpu::PollType::Poll);
        }
        if self.read_state.load(Ordering::Acquire) != MAPPED {
            return None;
        }
        let cost = self
            .cost_read
            .slice(..4)
            .get_mapped_range()
            .ok()
            .map(|b| bytemuck::pod_read_unaligned::<f32>(&b[..4]));
        self.cost_read.unmap();
        self.read_state.store(IDLE, Ordering::Release);
        cost
    }
}

/// One rectangle of a texel-row range: its first texel's place, width and rows, and its
/// first texel's index from the range's start.
struct Segment {
    x: u32,
    y: u32,
    width: u32,
    rows: u32,
    from: u32,
}

impl Segment {
    fn at<'t>(&self, t: &'t wgpu::Texture) -> wgpu::TexelCopyTextureInfo<'t> {
        let mut c = t.as_image_copy();
        c.origin.x = self.x;
        c.origin.y = self.y;
        c
    }

    fn extent(&self) -> wgpu::Extent3d {
        wgpu::Extent3d { width: self.width, height: self.rows, depth_or_array_layers: 1 }
    }
}

/// Texels `first..first + count` of a texel-row texture as rectangles: the rest of the first
/// row, the whole rows, the start of the last.
fn segments(first: u32, count: u32) -> Vec<Segment> {
    let mut out = vec![];
    let (mut t, end) = (first, first + count);
    while t < end {
        let (x, y) = (t % TEXEL_ROW, t / TEXEL_ROW);
        let s = if x == 0 && end - t >= TEXEL_ROW {
            let rows = (end - t) / TEXEL_ROW;
            Segment { x, y, width: TEXEL_ROW, rows, from: t - first }
        } else {
            Segment { x, y, width: (TEXEL_ROW - x).min(end - t), rows: 1, from: t - first }
        };
        t += s.width * s.rows;
        out.push(s);
    }
    out
}

/// Copy `count` 16-byte records from `buf` at `offset` into texels `first..` of `tex`.
fn copy_to_texels(
    enc: &mut wgpu::CommandEncoder,
    buf: &wgpu::Buffer,
    offset: u64,
    tex: &wgpu::Texture,
    first: u32,
    count: u32,
) {
    for seg in segments(first, count) {
        let src = wgpu::TexelCopyBufferInfo {
            buffer: buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: offset + seg.from as u64 * 16,
                bytes_per_row: Some(TEXEL_ROW * 16),
                rows_per_image: None,
            },
        };
        enc.copy_buffer_to_texture(src, seg.at(tex), seg.extent());
    }
}
