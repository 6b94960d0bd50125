//! Bind group layouts and bind groups described once, entry by entry.

/// Entries of one bind group: the layout half is fixed when a pass is created, the resource half
/// is filled whenever its inputs change (resize, a scene whose buffers were reallocated).
pub struct Bindings<'a> {
    visibility: wgpu::ShaderStages,
    pub layout: Vec<wgpu::BindGroupLayoutEntry>,
    pub resources: Vec<wgpu::BindGroupEntry<'a>>,
}

impl<'a> Bindings<'a> {
    pub fn new(visibility: wgpu::ShaderStages) -> Self {
        Bindings { visibility, layout: vec![], resources: vec![] }
    }

    fn push(&mut self, binding: u32, ty: wgpu::BindingType, resource: wgpu::BindingResource<'a>) {
        self.layout.push(wgpu::BindGroupLayoutEntry { binding, visibility: self.visibility, ty, count: None });
        self.resources.push(wgpu::BindGroupEntry { binding, resource });
    }

    pub fn uniform(mut self, binding: u32, buf: &'a wgpu::Buffer) -> Self {
        let ty = wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None };
        self.push(binding, ty, buf.as_entire_binding());
        self
    }

    pub fn storage(mut self, binding: u32, buf: &'a wgpu::Buffer, read_only: bool) -> Self {
        let ty = wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None };
        self.push(binding, ty, buf.as_entire_binding());
        self
    }

    pub fn storage_all(mut self, buffers: &[(u32, &'a wgpu::Buffer)]) -> Self {
        for (b, buf) in buffers {
            self = self.storage(*b, buf, true);
        }
        self
    }

    /// A sampled texture read with textureLoad (no sampler, so no filtering requirement).
    pub fn texture(mut self, binding: u32, view: &'a wgpu::TextureView, sample_type: wgpu::TextureSampleType) -> Self {
        let ty = wgpu::BindingType::Texture { sample_type, view_dimension: wgpu::TextureViewDimension::D2, multisampled: false };
        self.push(binding, ty, wgpu::BindingResource::TextureView(view));
        self
    }

    pub fn float_texture(self, binding: u32, view: &'a wgpu::TextureView) -> Self {
        self.texture(binding, view, wgpu::TextureSampleType::Float { filterable: false })
    }

    pub fn storage_texture(mut self, binding: u32, view: &'a wgpu::TextureView, format: wgpu::TextureFormat) -> Self {
        let ty = wgpu::BindingType::StorageTexture { access: wgpu::StorageTextureAccess::WriteOnly, format, view_dimension: wgpu::TextureViewDimension::D2 };
        self.push(binding, ty, wgpu::BindingResource::TextureView(view));
        self
    }

    pub fn create_layout(&self, device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &self.layout })
    }

    pub fn create_group(&self, device: &wgpu::Device, label: &str, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &self.resources })
    }
}
