//! A scene on the GPU: the buffers of a [`PreparedScene`] and what they cost.

use super::prepare::{Draw, EnvKind, PreparedScene, SceneFeatures};
pub use super::texels::{TEXEL_ROW, Texels, texel_row_count};
use super::{Bindings, Gpu, GpuMemory, GpuRequirements};
use crate::accel::BvhKind;

/// The shading modules' `path_end` that never ends a path (common/path.wgsl); a program with a
/// radiance cache puts cache/path_end.wgsl in its place.
pub const PATH_END_NONE: &str = "common/path_end_none.wgsl";

pub struct GpuScene {
    pub features: SceneFeatures,
    pub bvh_kind: BvhKind,
    /// [`PreparedScene::traversal_stack`].
    pub traversal_stack: u32,
    /// [`PreparedScene::dynamic_root`].
    pub dynamic_root: Option<u32>,
    /// The BVH nodes as texel rows ([`Texels`]): traversal reads them with textureLoad.
    pub nodes: Texels,
    /// Triangle vertices, three vec4 each: a buffer for the raster pass and shading, and the
    /// same as texel rows for the intersection tests.
    pub tris: wgpu::Buffer,
    pub tri_texels: Texels,
    /// Animated scenes: the vertices at the shutter's open ([`PreparedScene::tris_open`]).
    pub tri_open_texels: Option<Texels>,
    /// Deforming scenes: the vertices at the previous frame ([`PreparedScene::tris_prev`]).
    pub tri_prev_texels: Option<Texels>,
    /// Per-triangle normals and UVs (four texels a triangle) and the materials (five texels
    /// each), as texel rows like the nodes.
    pub shading: Texels,
    pub materials: Texels,
    /// [`PreparedScene::extras`] and [`PreparedScene::tex_uses`], where the scene has them.
    pub extras: Option<Texels>,
    pub tex_uses: Option<Texels>,
    /// [`PreparedScene::glass`], where some material transmits.
    pub glass: Option<Texels>,
    pub lights: Option<wgpu::Buffer>,
    /// The light tree's nodes (four texels each: shaders/common/light_tree.wgsl).
    pub emitters: Option<Texels>,
    pub env: Option<wgpu::Buffer>,
    /// The scene's textures as words in texel rows (`tex_words` in shaders/common/textures.wgsl).
    pub textures: Option<Texels>,
    pub tangents: Option<wgpu::Buffer>,
    /// Per object: rebased previous-from-current transform (animated scenes only).
    pub objects: Option<wgpu::Buffer>,
    /// [`SceneFeatures::instances`]: the instances' transforms, the top-level tree and its
    /// leaves' objects, and the raster's draw list ([`PreparedScene::instances`] and after).
    pub instancing: Option<InstanceTexels>,
    /// [`PreparedScene::tlas_stack`].
    pub tlas_stack: u32,
    /// The raster's instanced draws and the slots they cover ([`PreparedScene::draws`]).
    pub draws: Vec<Draw>,
    pub proto_slots: std::ops::Range<u32>,
    pub memory: GpuMemory,
    pub triangle_count: u32,
    /// Bumped whenever a buffer is replaced, so passes know to rebuild their bind groups.
    pub generation: u64,
}

/// The GPU half of a scene's instances (shaders/common/instances.wgsl and tlas.wgsl).
pub struct InstanceTexels {
    pub instances: Texels,
    pub tlas: Texels,
    pub tlas_order: Texels,
    pub draw_list: Texels,
}

impl InstanceTexels {
    fn new(gpu: &Gpu, mem: &mut GpuMemory, p: &PreparedScene) -> InstanceTexels {
        use wgpu::TextureFormat::{Rgba32Float, Rgba32Uint};
        let b = bytemuck::cast_slice::<u32, u8>;
        InstanceTexels {
            instances: Texels::new(
                gpu,
                mem,
                "scene/instances",
                bytemuck::cast_slice(&p.instances),
                Rgba32Float,
            ),
            tlas: Texels::new(gpu, mem, "scene/top-level nodes", &p.tlas, Rgba32Uint),
            tlas_order: Texels::new(
                gpu,
                mem,
                "scene/top-level order",
                b(&p.tlas_order),
                Rgba32Uint,
            ),
            draw_list: Texels::new(gpu, mem, "scene/draw list", b(&p.draw_list), Rgba32Uint),
        }
    }

    fn write(&mut self, gpu: &Gpu, mem: &mut GpuMemory, p: &PreparedScene) -> bool {
        let b = bytemuck::cast_slice::<u32, u8>;
        let mut replaced = self.instances.write(gpu, mem, bytemuck::cast_slice(&p.instances));
        replaced |= self.tlas.write(gpu, mem, &p.tlas);
        replaced |= self.tlas_order.write(gpu, mem, b(&p.tlas_order));
        replaced |= self.draw_list.write(gpu, mem, b(&p.draw_list));
        replaced
    }
}

impl PreparedScene {
    /// Storage buffers the reference tracer binds, and the largest of them (plus `extra` bytes of
    /// per-pixel output), for [`Gpu::headless`].
    /// What the scene's buffers and an output of `output_pixels` x `bytes_per_pixel` need.
    pub fn requirements(&self, output_pixels: u64, bytes_per_pixel: u64) -> GpuRequirements {
        let output_bytes = output_pixels * bytes_per_pixel;
        let f = &self.features;
        let sizes = [
            (self.tris.len() * 16) as u64,
            (self.tangents.len() * 16) as u64,
            (self.env_data.len() * 4) as u64,
            output_bytes,
        ];
        let count =
            2 + f.punctual_lights as u32 + (f.env == EnvKind::Map) as u32 + f.normal_maps as u32;
        let d = GpuRequirements::default();
        GpuRequirements {
            // A shading program may bind every one of the scene's texel tables (the reference
            // tracer binds no texture of its own).
            max_sampled_textures_per_shader_stage: self
                .sampled_texture_count()
                .max(d.max_sampled_textures_per_shader_stage),
            max_storage_buffer_binding_size: sizes
                .into_iter()
                .max()
                .unwrap_or(0)
                .max(d.max_storage_buffer_binding_size),
            max_storage_buffers_per_shader_stage: count.max(d.max_storage_buffers_per_shader_stage),
            output_bytes,
            output_pixels,
            max_texture_dimension_2d: [
                self.accel.nodes.len(),
                self.tris.len() * 16,
                self.tex_data.len() * 4,
                self.shading.len() * 16,
                self.materials.len() * 80,
                self.extras.len() * 16,
                self.tex_uses.len() * 16,
                self.glass.len() * 16,
                self.instances.len() * 16,
                self.tlas.len(),
                self.tlas_order.len() * 4,
                self.draw_list.len() * 4,
                std::mem::size_of_val(self.emitters.as_slice()),
            ]
            .into_iter()
            .map(texel_row_count)
            .max()
            .unwrap_or(1)
            .max(d.max_texture_dimension_2d),
            ..d
        }
    }

    /// Texel tables the scene's shading modules declare (`shaders/common`, every sampled
    /// texture a program that shades may bind): the BVH, vertices, shading records and
    /// materials, and those only some scenes have.
    pub fn sampled_texture_count(&self) -> u32 {
        let f = &self.features;
        4 + f.animated as u32
            + 2 * f.deforming as u32
            + f.vertex_extras as u32
            + f.texture_uses as u32
            + f.transmission as u32
            + f.textures as u32
            + 4 * f.instances as u32
            + f.emitters as u32
    }

    pub fn upload(&self, gpu: &Gpu) -> GpuScene {
        let mut mem = GpuMemory::default();
        // Animated scenes rewrite their geometry every frame (posed on the GPU: copied from the
        // triangles into their texels, gpu/posing.rs).
        let s = if self.features.animated {
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC
        } else {
            wgpu::BufferUsages::STORAGE
        };
        let d = &gpu.device;
        fn b<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
            bytemuck::cast_slice(v)
        }
        let f = self.features;
        let nodes = Texels::new(
            gpu,
            &mut mem,
            "scene/bvh nodes",
            &self.accel.nodes,
            wgpu::TextureFormat::Rgba32Uint,
        );
        let tris = mem.buffer_init(d, "scene/triangles", b(&self.tris), s);
        let tri_texels = Texels::new(
            gpu,
            &mut mem,
            "scene/triangle texels",
            b(&self.tris),
            wgpu::TextureFormat::Rgba32Float,
        );
        let tri_open_texels = self.features.animated.then(|| {
            Texels::new(
                gpu,
                &mut mem,
                "scene/triangle texels at shutter open",
                b(&self.tris_open),
                wgpu::TextureFormat::Rgba32Float,
            )
        });
        let tri_prev_texels = self.features.deforming.then(|| {
            Texels::new(
                gpu,
                &mut mem,
                "scene/triangle texels at the previous frame",
                b(&self.tris_prev),
                wgpu::TextureFormat::Rgba32Float,
            )
        });
        let shading = Texels::new(
            gpu,
            &mut mem,
            "scene/shading",
            b(&self.shading),
            wgpu::TextureFormat::Rgba32Float,
        );
        let materials = Texels::new(
            gpu,
            &mut mem,
            "scene/materials",
            b(&self.materials),
            wgpu::TextureFormat::Rgba32Uint,
        );
        // Tables only some scenes have (SceneFeatures): none is allocated where it is off.
        let mut table = |on: bool, name: &str, data: &[u8], format| {
            on.then(|| Texels::new(gpu, &mut mem, name, data, format))
        };
        use wgpu::TextureFormat::{Rgba32Float, Rgba32Uint};
        let extras = table(f.vertex_extras, "scene/vertex extras", b(&self.extras), Rgba32Uint);
        let tex_uses = table(f.texture_uses, "scene/texture uses", b(&self.tex_uses), Rgba32Float);
        let glass = table(f.transmission, "scene/glass", b(&self.glass), Rgba32Float);
        let emitters = table(f.emitters, "scene/emitters", b(&self.emitters), Rgba32Uint);
        let copy = s | wgpu::BufferUsages::COPY_DST;
        // Lights and environment are rewritten when the user moves the sun.
        let lights =
            f.punctual_lights.then(|| mem.buffer_init(d, "scene/lights", b(&self.lights), copy));
        let env = (f.env == EnvKind::Map)
            .then(|| mem.buffer_init(d, "scene/environment", b(&self.env_data), copy));
        let textures = f.textures.then(|| {
            Texels::new(
                gpu,
                &mut mem,
                "scene/textures",
                b(&self.tex_data),
                wgpu::TextureFormat::Rgba32Uint,
            )
        });
        let tangents =
            f.normal_maps.then(|| mem.buffer_init(d, "scene/tangents", b(&self.tangents), s));
        let objects = f
            .animated
            .then(|| mem.buffer_init(d, "scene/object motion", b(&self.prev_from_current), copy));
        let instancing = f.instances.then(|| InstanceTexels::new(gpu, &mut mem, self));
        log::info!(
            "scene on the GPU: {} triangles, {} BVH nodes ({}), features {:?}, {} bytes: {}",
            self.triangle_count(),
            self.accel.node_count,
            self.accel.kind.name(),
            f,
            mem.total_bytes(),
            mem.allocations.iter().map(|(l, b)| format!("{l}={b}")).collect::<Vec<_>>().join(" ")
        );
        GpuScene {
            features: f,
            bvh_kind: self.accel.kind,
            traversal_stack: self.traversal_stack,
            dynamic_root: self.dynamic_root(),
            nodes,
            tris,
            tri_texels,
            tri_open_texels,
            tri_prev_texels,
            shading,
            materials,
            extras,
            tex_uses,
            glass,
            lights,
            emitters,
            env,
            textures,
            tangents,
            objects,
            instancing,
            tlas_stack: self.tlas_stack,
            draws: self.draws.clone(),
            proto_slots: self.proto_slots(),
            memory: mem,
            triangle_count: self.triangle_count() as u32,
            generation: 0,
        }
    }
}

impl GpuScene {
    /// After [`PreparedScene::repack_lighting`].
    pub fn update_lighting(&self, gpu: &Gpu, p: &PreparedScene) {
        if let Some(l) = &self.lights {
            gpu.queue.write_buffer(l, 0, bytemuck::cast_slice(&p.lights));
        }
        if let Some(e) = self.env.as_ref().filter(|e| e.size() >= (p.env_data.len() * 4) as u64) {
            gpu.queue.write_buffer(e, 0, bytemuck::cast_slice(&p.env_data));
        }
    }

    /// After [`PreparedScene::animate`]: write the rebuilt geometry and object motion, replacing
    /// a buffer (and bumping `generation`) only where the new data no longer fits.
    pub fn update_geometry(&mut self, gpu: &Gpu, p: &PreparedScene, moved: bool) {
        fn b<T: bytemuck::Pod>(v: &[T]) -> &[u8] {
            bytemuck::cast_slice(v)
        }
        let mut replaced = false;
        let mem = &mut self.memory;
        // An animated scene's static part leads every array and never changes: only what
        // follows it is written (PreparedScene::static_prefix).
        let (slots, node_bytes) = p.static_prefix();
        if moved && let Some(t) = self.instancing.as_mut() {
            replaced |= t.write(gpu, mem, p);
            self.draws.clone_from(&p.draws);
        }
        let moved = moved && p.geometry_moved;
        if moved {
            replaced |= self.nodes.write_from(gpu, mem, &p.accel.nodes, node_bytes);
            replaced |= self.tri_texels.write_from(gpu, mem, b(&p.tris), slots * 48);
            if let Some(t) = self.tri_open_texels.as_mut() {
                replaced |= t.write_from(gpu, mem, b(&p.tris_open), slots * 48);
            }
            if let Some(t) = self.tri_prev_texels.as_mut() {
                replaced |= t.write_from(gpu, mem, b(&p.tris_prev), slots * 48);
            }
            replaced |= self.shading.write_from(gpu, mem, b(&p.shading), slots * 64);
            if let Some(t) = self.extras.as_mut() {
                replaced |= t.write_from(gpu, mem, b(&p.extras), slots * 48);
            }
            if let Some(t) = self.emitters.as_mut() {
                replaced |= t.write(gpu, mem, b(&p.emitters));
            }
        }
        let mut put = |buf: &mut wgpu::Buffer, label: &str, data: &[u8], from: usize| {
            if data.is_empty() {
                return;
            }
            if (data.len() as u64) <= buf.size()
                && buf.usage().contains(wgpu::BufferUsages::COPY_DST)
            {
                let from = from.min(data.len());
                if from < data.len() {
                    gpu.queue.write_buffer(buf, from as u64, &data[from..]);
                }
            } else {
                mem.allocations.retain(|(l, _)| l != label);
                let usage = wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC;
                // Headroom, so that a BVH a few nodes larger next frame does not reallocate again.
                let size = (data.len() as u64 * 5 / 4).next_multiple_of(16);
                *buf = mem.buffer(&gpu.device, label, size, usage);
                gpu.queue.write_buffer(buf, 0, data);
                replaced = true;
            }
        };
        if moved {
            put(&mut self.tris, "scene/triangles", b(&p.tris), slots * 48);
            if let Some(t) = self.tangents.as_mut() {
                put(t, "scene/tangents", b(&p.tangents), slots * 48);
            }
        }
        if let Some(o) = self.objects.as_mut() {
            put(o, "scene/object motion", b(&p.prev_from_current), 0);
        }
        self.triangle_count = p.triangle_count() as u32;
        if replaced {
            self.generation += 1;
        }
    }

    /// The scene's buffers by the names `shaders/common` binds them by.
    pub fn bindings(&self) -> Bindings<'_> {
        Bindings::new()
            .texture("bvh_texels", &self.nodes.view)
            .texture("tri_texels", &self.tri_texels.view)
            .texture_opt("tri_open_texels", self.tri_open_texels.as_ref().map(|t| &t.view))
            .texture_opt("tri_prev_texels", self.tri_prev_texels.as_ref().map(|t| &t.view))
            .texture_opt(
                "tri_now_texels",
                self.tri_prev_texels.as_ref().map(|_| &self.tri_texels.view),
            )
            .buffer("tris", &self.tris)
            .texture("shading_texels", &self.shading.view)
            .texture("material_texels", &self.materials.view)
            .texture_opt("extra_texels", self.extras.as_ref().map(|t| &t.view))
            .texture_opt("tex_use_texels", self.tex_uses.as_ref().map(|t| &t.view))
            .texture_opt("glass_texels", self.glass.as_ref().map(|t| &t.view))
            .buffer_opt("lights", self.lights.as_ref())
            .texture_opt("emitter_texels", self.emitters.as_ref().map(|t| &t.view))
            .buffer_opt("env_data", self.env.as_ref())
            .texture_opt("tex_words", self.textures.as_ref().map(|t| &t.view))
            .buffer_opt("tangents", self.tangents.as_ref())
            .buffer_opt("prev_from_current", self.objects.as_ref())
            .texture_opt("instance_texels", self.instancing.as_ref().map(|t| &t.instances.view))
            .texture_opt("tlas_texels", self.instancing.as_ref().map(|t| &t.tlas.view))
            .texture_opt("tlas_order_texels", self.instancing.as_ref().map(|t| &t.tlas_order.view))
            .texture_opt("draw_list_texels", self.instancing.as_ref().map(|t| &t.draw_list.view))
    }

    /// The module that carries an instance's hits to world space
    /// (shaders/common/instances.wgsl), or its identity where nothing is instanced.
    pub fn instance_module(&self) -> &'static str {
        if self.features.instances { "common/instances.wgsl" } else { "common/instances_none.wgsl" }
    }

    /// Program modules that match this scene's features, for a program that shades.
    /// Paths never end in a radiance cache there ([`PATH_END_NONE`]).
    pub fn shading_modules(&self) -> Vec<&'static str> {
        self.shading_modules_for(false)
    }

    /// The shading modules with geometry that moves during the shutter (`moving`: an animated
    /// scene's objects move while it is open; common/motion_blur.wgsl) or not. The moving
    /// variant costs the level's real-time trace 15% on the software driver (1107-1157 against
    /// 962-985 ms at 640x360), so programs use it only while something moves.
    pub fn shading_modules_for(&self, moving: bool) -> Vec<&'static str> {
        let f = &self.features;
        let mut m = vec![
            "common/math.wgsl",
            "common/rng.wgsl",
            "common/geometry.wgsl",
            if moving && f.animated {
                "common/motion_blur.wgsl"
            } else {
                "common/motion_none.wgsl"
            },
            self.instance_module(),
        ];
        m.extend(self.traversal_modules());
        m.extend([
            "common/scene.wgsl",
            "common/bsdf.wgsl",
            "common/params.wgsl",
            "common/camera.wgsl",
            "common/path.wgsl",
            // Programs with a radiance cache swap in cache/path_end.wgsl.
            PATH_END_NONE,
        ]);
        m.extend(self.material_modules());
        m.push(if f.punctual_lights { "common/lights.wgsl" } else { "common/lights_none.wgsl" });
        if f.emitters {
            m.extend(["common/light_tree.wgsl", "common/emitters.wgsl"]);
        } else {
            m.push("common/emitters_none.wgsl");
        }
        m.push(match f.env {
            EnvKind::None => "common/env_none.wgsl",
            EnvKind::Constant => "common/env_constant.wgsl",
            EnvKind::Map => "common/env_map.wgsl",
        });
        m
    }

    /// The modules that read materials at a surface point: textures, normal maps, alpha masks,
    /// texture coordinate maps and vertex attributes, each as the scene needs it.
    pub fn material_modules(&self) -> [&'static str; 6] {
        let f = &self.features;
        [
            if f.alpha_mask { "common/alpha_mask.wgsl" } else { "common/alpha_none.wgsl" },
            if f.textures { "common/textures.wgsl" } else { "common/textures_none.wgsl" },
            if f.normal_maps { "common/tangents.wgsl" } else { "common/tangents_none.wgsl" },
            if f.texture_uses { "common/texcoords.wgsl" } else { "common/texcoords_none.wgsl" },
            if f.vertex_extras { "common/attributes.wgsl" } else { "common/attributes_none.wgsl" },
            if f.transmission {
                "common/transmission.wgsl"
            } else {
                "common/transmission_none.wgsl"
            },
        ]
    }

    /// The trees' traversal (in the scene's layout) and the `traverse` over them: the scene's
    /// trees alone, or with the instances' top-level tree (shaders/common/tlas.wgsl, which
    /// needs [`GpuScene::instance_module`]).
    pub fn traversal_modules(&self) -> [&'static str; 2] {
        [
            match self.bvh_kind {
                BvhKind::Bvh2 => "common/bvh2.wgsl",
                BvhKind::Cwbvh => "common/cwbvh.wgsl",
            },
            if self.features.instances { "common/tlas.wgsl" } else { "common/tlas_none.wgsl" },
        ]
    }

    /// `const` flags the shading modules branch on, and the traversal's stack size.
    pub fn prelude(&self) -> String {
        let f = &self.features;
        format!(
            "const HAS_EMITTERS: bool = {};\nconst HAS_ENV: bool = {};\n{}",
            f.emitters,
            f.env != EnvKind::None,
            self.traversal_prelude()
        )
    }

    /// What a program that only traverses needs before its modules.
    pub fn traversal_prelude(&self) -> String {
        format!(
            "const TRAVERSAL_STACK: u32 = {}u;\nconst DYNAMIC_ROOT: u32 = {}u;\nconst TLAS_STACK: u32 = {}u;\n",
            self.traversal_stack,
            self.dynamic_root.unwrap_or(u32::MAX),
            self.tlas_stack
        )
    }
}
