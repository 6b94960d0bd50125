//! What a composed program binds, read from naga's module of it: every resource's name, group,
//! number and binding type. Layouts are made from this, and bind groups by looking each name up
//! among the resources a stage offers ([`super::Bindings`]), so the numbers the composer
//! gave never reach Rust.

use anyhow::{Result, bail};

/// One resource of a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    /// The WGSL variable's name.
    pub name: String,
    pub group: u32,
    pub binding: u32,
    pub ty: wgpu::BindingType,
}

/// Every resource of a program, in group then binding order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProgramBindings {
    pub slots: Vec<Slot>,
}

/// Read the resources of `module` (the program `label`) that one of its entry points uses
/// (naga's `info` says which). A resource a module declares but the entry point never reaches
/// (a helper module's texture that this stage does not read) is left out of the layout, so a
/// stage binds only what it reads and need not be offered the rest.
pub fn reflect(
    label: &str,
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
) -> Result<ProgramBindings> {
    let used = |h: naga::Handle<naga::GlobalVariable>| {
        (0..module.entry_points.len()).any(|i| !info.get_entry_point(i)[h].is_empty())
    };
    let mut slots = vec![];
    for (h, var) in module.global_variables.iter() {
        let Some(rb) = &var.binding else { continue };
        if !used(h) {
            continue;
        }
        let name = var.name.clone().unwrap_or_default();
        let ty = match binding_type(var.space, &module.types[var.ty].inner) {
            Ok(ty) => ty,
            Err(e) => bail!("{label}: resource `{name}`: {e}"),
        };
        slots.push(Slot { name, group: rb.group, binding: rb.binding, ty });
    }
    slots.sort_by_key(|s| (s.group, s.binding));
    for w in slots.windows(2) {
        if w[0].name == w[1].name {
            bail!("{label}: resource `{}` is declared twice", w[0].name);
        }
    }
    Ok(ProgramBindings { slots })
}

fn binding_type(space: naga::AddressSpace, inner: &naga::TypeInner) -> Result<wgpu::BindingType> {
    use naga::{AddressSpace, ImageClass, ScalarKind, StorageAccess, TypeInner};
    let buffer =
        |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
    Ok(match (space, inner) {
        (AddressSpace::Uniform, _) => buffer(wgpu::BufferBindingType::Uniform),
        (AddressSpace::Storage { access }, _) => buffer(wgpu::BufferBindingType::Storage {
            read_only: !access.contains(StorageAccess::STORE),
        }),
        (
            AddressSpace::Handle,
            TypeInner::Image { dim: naga::ImageDimension::D2, arrayed: false, class },
        ) => match class {
            // Every texture is read with textureLoad: no sampler, so no filtering requirement.
            ImageClass::Sampled { kind, multi: false } => {
                let sample_type = match kind {
                    ScalarKind::Float => wgpu::TextureSampleType::Float { filterable: false },
                    ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                    ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                    k => bail!("textures of {k:?} are not supported"),
                };
                wgpu::BindingType::Texture {
                    sample_type,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                }
            }
            ImageClass::Depth { multi: false } => wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            ImageClass::Storage { format, access } => {
                let access = match (
                    access.contains(StorageAccess::LOAD),
                    access.contains(StorageAccess::STORE),
                ) {
                    (true, true) => wgpu::StorageTextureAccess::ReadWrite,
                    (true, false) => wgpu::StorageTextureAccess::ReadOnly,
                    _ => wgpu::StorageTextureAccess::WriteOnly,
                };
                wgpu::BindingType::StorageTexture {
                    access,
                    format: storage_format(*format)?,
                    view_dimension: wgpu::TextureViewDimension::D2,
                }
            }
            c => bail!("image class {c:?} is not supported"),
        },
        (space, inner) => bail!("{space:?} {inner:?} is not a supported resource"),
    })
}

/// The storage formats WGSL names that Hush's stages use.
fn storage_format(f: naga::StorageFormat) -> Result<wgpu::TextureFormat> {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    Ok(match f {
        S::Rgba32Float => T::Rgba32Float,
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::R32Float => T::R32Float,
        S::R32Uint => T::R32Uint,
        S::R32Sint => T::R32Sint,
        S::Rg32Uint => T::Rg32Uint,
        S::Rg32Float => T::Rg32Float,
        S::Rgba32Uint => T::Rgba32Uint,
        f => bail!("storage format {f:?} is not supported"),
    })
}

impl ProgramBindings {
    /// How many bind groups the pipeline layout has (empty ones below the highest included).
    pub fn group_count(&self) -> u32 {
        self.slots.iter().map(|s| s.group + 1).max().unwrap_or(0)
    }

    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.slots.iter().map(|s| s.name.as_str())
    }

    /// An error naming every resource of the program that is not among `offered`.
    pub fn check_offered(&self, label: &str, offered: &[&str]) -> Result<()> {
        let missing: Vec<&str> = self.names().filter(|n| !offered.contains(n)).collect();
        if !missing.is_empty() {
            bail!(
                "{label} binds {}, which the stage does not offer (it offers {})",
                missing.join(", "),
                offered.join(", ")
            );
        }
        Ok(())
    }

    /// One bind group layout per group, visible to `visibility`.
    pub fn layouts(
        &self,
        device: &wgpu::Device,
        label: &str,
        visibility: wgpu::ShaderStages,
    ) -> Vec<wgpu::BindGroupLayout> {
        (0..self.group_count())
            .map(|g| {
                let entries: Vec<_> = self
                    .slots
                    .iter()
                    .filter(|s| s.group == g)
                    .map(|s| wgpu::BindGroupLayoutEntry {
                        binding: s.binding,
                        visibility,
                        ty: s.ty,
                        count: None,
                    })
                    .collect();
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(&format!("{label} group {g}")),
                    entries: &entries,
                })
            })
            .collect()
    }
}

/// A compute pipeline that is built once (the reference tracer, the raycaster), with the
/// layouts its program's resources need.
pub struct FixedCompute {
    pub pipeline: wgpu::ComputePipeline,
    label: String,
    bindings: ProgramBindings,
    layouts: Vec<wgpu::BindGroupLayout>,
}

impl FixedCompute {
    /// `offered`: what the caller will bind (checked by name now, so that a program asking for
    /// more fails here rather than at the first dispatch).
    pub fn new(
        gpu: &dyn super::ShaderHost,
        label: &str,
        prelude: &str,
        modules: &[&'static str],
        offered: &[&str],
    ) -> Result<FixedCompute> {
        let program = gpu.shaders().compose(label, prelude, modules)?;
        let (module, info) = program.validate_with_info()?;
        let bindings = reflect(label, &module, &info)?;
        bindings.check_offered(label, offered)?;
        let layouts = bindings.layouts(gpu.device(), label, wgpu::ShaderStages::COMPUTE);
        let refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
        let pl = gpu.device().create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &refs,
            immediate_size: 0,
        });
        let module = super::create_module(gpu.device(), label, &program.text);
        let pipeline = super::compute_pipeline(gpu.device(), label, &module, &pl, "main");
        Ok(FixedCompute { pipeline, label: label.to_string(), bindings, layouts })
    }

    /// Bind groups of `resources`, each found by name.
    pub fn bind_groups(
        &self,
        device: &wgpu::Device,
        resources: &super::Bindings,
    ) -> Result<Vec<wgpu::BindGroup>> {
        resources.create_groups(device, &self.label, &self.bindings, &self.layouts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn program(text: &str) -> ProgramBindings {
        let p = crate::shader::compose_with("t", "", &["common/a.wgsl", "stage/b.wgsl"], |m| {
            Ok(std::sync::Arc::from(if m == "common/a.wgsl" {
                "var<uniform> u: vec4f;\nvar<private> p: f32;\n"
            } else {
                text
            }))
        })
        .unwrap();
        let (m, info) = p.validate_with_info().unwrap();
        reflect("t", &m, &info).unwrap()
    }

    #[test]
    fn resources_are_numbered_by_group_in_order() {
        let b = program(
            "var t: texture_2d<u32>;\nvar<storage, read_write> s: array<u32>;\nvar o: texture_storage_2d<rgba16float, write>;\nvar<workgroup> w: array<f32, 4>;\n@compute @workgroup_size(1) fn main() { s[0] = textureLoad(t, vec2i(0), 0).x + u32(u.x + p + w[0]); textureStore(o, vec2i(0), vec4f(0.0)); }\n",
        );
        let got: Vec<_> = b.slots.iter().map(|s| (s.name.as_str(), s.group, s.binding)).collect();
        assert_eq!(got, [("u", 0, 0), ("t", 1, 0), ("s", 1, 1), ("o", 1, 2)]);
        assert_eq!(
            b.slots[1].ty,
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false
            }
        );
        assert_eq!(
            b.slots[2].ty,
            wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None
            }
        );
        assert!(matches!(
            b.slots[3].ty,
            wgpu::BindingType::StorageTexture {
                format: wgpu::TextureFormat::Rgba16Float,
                access: wgpu::StorageTextureAccess::WriteOnly,
                ..
            }
        ));
        assert_eq!(b.group_count(), 2);
    }

    #[test]
    fn an_indented_var_is_not_a_resource() {
        let b = program(
            "fn f() -> f32 {\n    var x = 1.0;\n    return x;\n}\n@compute @workgroup_size(1) fn main() { let y = f() + u.x; }\n",
        );
        assert_eq!(b.names().collect::<Vec<_>>(), ["u"]);
    }

    #[test]
    fn a_resource_no_entry_point_reaches_is_left_out() {
        let b = program(
            "var t: texture_2d<f32>;\nvar unused: texture_2d<u32>;\nfn g() -> f32 { return textureLoad(t, vec2i(0), 0).x; }\nfn h() -> u32 { return textureLoad(unused, vec2i(0), 0).x; }\n@compute @workgroup_size(1) fn main() { let y = g(); }\n",
        );
        assert_eq!(
            b.names().collect::<Vec<_>>(),
            ["t"],
            "u and `unused` are declared but never reached"
        );
    }
}
