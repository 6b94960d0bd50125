//! Resources offered to a program by the name of the WGSL variable that binds them. A program's
//! bind groups are made from what it declares ([`crate::shader::reflect`]): each of its
//! resources is looked up here by name, so a stage may offer more than a program uses, and a
//! program that asks for a name nobody offers is an error that names it.

use super::ProgramBindings;
use anyhow::Result;

#[derive(Clone, Copy)]
pub enum Resource<'a> {
    Buffer(&'a wgpu::Buffer),
    Texture(&'a wgpu::TextureView),
}

/// Name -> resource; a later entry of the same name replaces an earlier one.
#[derive(Clone, Default)]
pub struct Bindings<'a> {
    entries: Vec<(&'a str, Resource<'a>)>,
}

impl<'a> Bindings<'a> {
    pub fn new() -> Self {
        Bindings::default()
    }

    pub fn buffer(mut self, name: &'a str, buf: &'a wgpu::Buffer) -> Self {
        self.set(name, Resource::Buffer(buf));
        self
    }

    pub fn texture(mut self, name: &'a str, view: &'a wgpu::TextureView) -> Self {
        self.set(name, Resource::Texture(view));
        self
    }

    /// `buffer` where `buf` exists (a feature of the scene).
    pub fn buffer_opt(self, name: &'a str, buf: Option<&'a wgpu::Buffer>) -> Self {
        match buf {
            Some(b) => self.buffer(name, b),
            None => self,
        }
    }

    /// `texture` where `view` exists (a feature of the scene).
    pub fn texture_opt(self, name: &'a str, view: Option<&'a wgpu::TextureView>) -> Self {
        match view {
            Some(v) => self.texture(name, v),
            None => self,
        }
    }

    /// Offer under `name` what is offered under `from` (nothing where that is not offered).
    pub fn alias(mut self, name: &'a str, from: &str) -> Self {
        if let Some(r) = self.get(from) {
            self.set(name, r);
        }
        self
    }

    /// Everything `other` offers, over what this offers.
    pub fn with(mut self, other: &Bindings<'a>) -> Self {
        for (n, r) in &other.entries {
            self.set(n, *r);
        }
        self
    }

    fn set(&mut self, name: &'a str, r: Resource<'a>) {
        match self.entries.iter_mut().find(|(n, _)| *n == name) {
            Some(e) => e.1 = r,
            None => self.entries.push((name, r)),
        }
    }

    pub fn get(&self, name: &str) -> Option<Resource<'a>> {
        self.entries.iter().find(|(n, _)| *n == name).map(|(_, r)| *r)
    }

    pub fn names(&self) -> impl Iterator<Item = &'a str> + '_ {
        self.entries.iter().map(|(n, _)| *n)
    }

    /// An error naming every resource of `program` that is not offered here.
    pub fn check(&self, label: &str, program: &ProgramBindings) -> Result<()> {
        program.check_offered(label, &self.names().collect::<Vec<_>>())
    }

    /// The bind groups of `program` (one per layout), each resource found by name.
    pub fn create_groups(
        &self,
        device: &wgpu::Device,
        label: &str,
        program: &ProgramBindings,
        layouts: &[wgpu::BindGroupLayout],
    ) -> Result<Vec<wgpu::BindGroup>> {
        self.check(label, program)?;
        let group = |(g, layout): (usize, &wgpu::BindGroupLayout)| {
            let entries = program
                .slots
                .iter()
                .filter(|s| s.group == g as u32)
                .map(|s| {
                    let resource = match self.get(&s.name) {
                        Some(Resource::Buffer(b)) => b.as_entire_binding(),
                        Some(Resource::Texture(v)) => wgpu::BindingResource::TextureView(v),
                        None => anyhow::bail!("{label}: nothing is offered as {:?}", s.name),
                    };
                    Ok(wgpu::BindGroupEntry { binding: s.binding, resource })
                })
                .collect::<Result<Vec<_>>>()?;
            let desc = wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries };
            Ok(device.create_bind_group(&desc))
        };
        layouts.iter().enumerate().map(group).collect()
    }
}

/// Bind `groups` from group 0 on.
pub fn set_compute_groups(pass: &mut wgpu::ComputePass, groups: &[wgpu::BindGroup]) {
    for (i, g) in groups.iter().enumerate() {
        pass.set_bind_group(i as u32, g, &[]);
    }
}

pub fn set_render_groups(pass: &mut wgpu::RenderPass, groups: &[wgpu::BindGroup]) {
    for (i, g) in groups.iter().enumerate() {
        pass.set_bind_group(i as u32, g, &[]);
    }
}

/// What a stage's bind groups depend on besides its pipeline: they are remade when any part
/// changes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BindKey {
    /// The scene's buffers' generation (bumped when one is reallocated).
    pub scene: u64,
    /// The frame targets' generation (bumped on resize and when a target is added).
    pub targets: u64,
    /// Which of the frame's made denoisers ran: the stages after it bind its outputs.
    pub denoiser: Option<usize>,
    /// The debug view the display shows (its index in the view list; 0: the final image).
    pub view: usize,
}

/// A pass's bind groups by variant `V` (the history parity, a level, what a program was made
/// for: any type with derived `Hash` and `Eq`; `()` where there is one), each made the first
/// time it is asked for, all remade when the key of what they bind or the pipeline's build
/// changes.
pub struct BindCache<V = ()> {
    made_for: Option<(BindKey, u32)>,
    groups: std::collections::HashMap<V, Vec<wgpu::BindGroup>>,
}

impl<V> Default for BindCache<V> {
    fn default() -> Self {
        BindCache { made_for: None, groups: Default::default() }
    }
}

impl<V: std::hash::Hash + Eq + Copy> BindCache<V> {
    /// Drop the groups (and with them what they bind), as when their resources are released.
    pub fn clear(&mut self) {
        self.groups.clear();
        self.made_for = None;
    }

    /// The groups of variant `v`, made with `make(v)` where this key and build have none yet.
    pub fn get(
        &mut self,
        key: BindKey,
        builds: u32,
        v: V,
        make: impl FnOnce(V) -> Result<Vec<wgpu::BindGroup>>,
    ) -> Result<&[wgpu::BindGroup]> {
        if self.made_for != Some((key, builds)) {
            self.groups.clear();
            self.made_for = Some((key, builds));
        }
        let groups = match self.groups.entry(v) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => e.insert(make(v)?),
        };
        Ok(groups.as_slice())
    }
}
