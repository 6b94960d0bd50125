use anyhow::{Context, Result, anyhow};

/// What to tell a user whose machine offers no adapter.
pub const NO_ADAPTER_HELP: &str = "no GPU adapter found. Hush needs a Vulkan, Metal, DX12 or GL \
driver; on a machine without a GPU install the software Vulkan driver (on Debian/Ubuntu: \
`apt-get install mesa-vulkan-drivers`). WGPU_BACKEND (vulkan, metal, dx12, gl) and \
WGPU_ADAPTER_NAME (a substring of the adapter's name) choose among several.";

/// The formats the real-time frame's passes write as storage textures (`texture_storage_2d` in
/// shaders/). A WebGPU-compliant adapter can write them all; wgpu's GL backend (what wgpu picks
/// on a machine with Mesa's GL but no Vulkan driver) cannot write the two-channel ones, where the
/// reference mode still runs.
pub const REALTIME_STORAGE_FORMATS: [wgpu::TextureFormat; 7] = [
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::R32Uint,
    wgpu::TextureFormat::Rg32Float,
    wgpu::TextureFormat::Rg32Uint,
    wgpu::TextureFormat::Rgba16Float,
    wgpu::TextureFormat::Rgba32Float,
    wgpu::TextureFormat::Rgba32Uint,
];

/// Features and limits a scene and its passes need. The device is created with exactly these,
/// so a pass that would exceed them fails validation on every machine, not only on small GPUs.
#[derive(Clone, Debug)]
pub struct GpuRequirements {
    pub features: wgpu::Features,
    /// Largest storage buffer the scene binds, in bytes.
    pub max_storage_buffer_binding_size: u64,
    /// Bytes and pixels of the largest per-pixel output buffer (the reference tracer's
    /// accumulation), so that an image too large for the adapter is named as such.
    pub output_bytes: u64,
    pub output_pixels: u64,
    /// Storage buffers bound at once by the busiest compute stage.
    pub max_storage_buffers_per_shader_stage: u32,
    /// Storage textures written at once by the busiest compute stage.
    pub max_storage_textures_per_shader_stage: u32,
    /// Sampled textures read at once by the busiest stage (the display's debug views).
    pub max_sampled_textures_per_shader_stage: u32,
    /// Render-target bytes per sample of the widest render pass (WebGPU's accounting).
    pub max_color_attachment_bytes_per_sample: u32,
    /// Rows of the tallest texel-row texture of the scene ([`super::scene::Texels`]).
    pub max_texture_dimension_2d: u32,
    /// Ask for everything the adapter offers (the viewer, which may load larger scenes later).
    pub adapter_limits: bool,
}

impl Default for GpuRequirements {
    fn default() -> Self {
        let d = wgpu::Limits::default();
        Self {
            features: wgpu::Features::empty(),
            max_storage_buffer_binding_size: d.max_storage_buffer_binding_size,
            output_bytes: 0,
            output_pixels: 0,
            max_storage_buffers_per_shader_stage: d.max_storage_buffers_per_shader_stage,
            max_storage_textures_per_shader_stage: d.max_storage_textures_per_shader_stage,
            max_color_attachment_bytes_per_sample: d.max_color_attachment_bytes_per_sample,
            max_sampled_textures_per_shader_stage: d.max_sampled_textures_per_shader_stage,
            max_texture_dimension_2d: d.max_texture_dimension_2d,
            adapter_limits: false,
        }
    }
}

/// A wgpu device and queue with the adapter they came from.
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Whether timestamp queries were granted (used by benchmarks when the adapter has them).
    pub timestamps: bool,
    /// Where shader text comes from (embedded unless `$HUSH_SHADERS` or the caller says).
    pub shaders: crate::shader::ShaderLibrary,
    /// Why the device was lost (reason, message), set once by wgpu's device-lost callback.
    lost: std::sync::Arc<std::sync::OnceLock<(String, String)>>,
}

impl Gpu {
    /// A device with no window: tests, the CLI, benchmarks.
    pub fn headless(req: &GpuRequirements) -> Result<Gpu> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(choose_adapter(&instance, None))?;
        Self::from_adapter(instance, adapter, req)
    }

    /// A device that can present to `surface` (created from `instance`).
    pub fn for_surface(
        instance: wgpu::Instance,
        surface: &wgpu::Surface<'_>,
        req: &GpuRequirements,
    ) -> Result<Gpu> {
        let adapter = pollster::block_on(choose_adapter(&instance, Some(surface)))?;
        Self::from_adapter(instance, adapter, req)
    }

    fn from_adapter(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        req: &GpuRequirements,
    ) -> Result<Gpu> {
        let info = adapter.get_info();
        let have = adapter.limits();
        let mut limits = if req.adapter_limits {
            have.clone()
        } else {
            wgpu::Limits::default().using_resolution(have.clone())
        };
        limits.max_storage_buffer_binding_size =
            limits.max_storage_buffer_binding_size.max(req.max_storage_buffer_binding_size);
        limits.max_buffer_size = limits.max_buffer_size.max(req.max_storage_buffer_binding_size);
        limits.max_storage_buffers_per_shader_stage = limits
            .max_storage_buffers_per_shader_stage
            .max(req.max_storage_buffers_per_shader_stage);
        limits.max_storage_textures_per_shader_stage = limits
            .max_storage_textures_per_shader_stage
            .max(req.max_storage_textures_per_shader_stage);
        limits.max_color_attachment_bytes_per_sample = limits
            .max_color_attachment_bytes_per_sample
            .max(req.max_color_attachment_bytes_per_sample);
        limits.max_sampled_textures_per_shader_stage = limits
            .max_sampled_textures_per_shader_stage
            .max(req.max_sampled_textures_per_shader_stage);
        limits.max_texture_dimension_2d =
            limits.max_texture_dimension_2d.max(req.max_texture_dimension_2d);
        if limits.max_texture_dimension_2d > have.max_texture_dimension_2d {
            return Err(anyhow!(
                "adapter {:?} allows textures of {} rows; the scene's geometry and materials need {} rows of {} texels",
                info.name,
                have.max_texture_dimension_2d,
                req.max_texture_dimension_2d,
                super::scene::TEXEL_ROW
            ));
        }
        if limits.max_sampled_textures_per_shader_stage > have.max_sampled_textures_per_shader_stage
        {
            return Err(anyhow!(
                "adapter {:?} allows {} sampled textures per stage; the real-time frame's debug views need {}",
                info.name,
                have.max_sampled_textures_per_shader_stage,
                req.max_sampled_textures_per_shader_stage
            ));
        }
        if limits.max_storage_textures_per_shader_stage > have.max_storage_textures_per_shader_stage
            || limits.max_color_attachment_bytes_per_sample
                > have.max_color_attachment_bytes_per_sample
        {
            return Err(anyhow!(
                "adapter {:?} is too small for the real-time frame: it needs {} storage textures per \
                 stage and {} render-target bytes per sample; it allows {} and {}",
                info.name,
                req.max_storage_textures_per_shader_stage,
                req.max_color_attachment_bytes_per_sample,
                have.max_storage_textures_per_shader_stage,
                have.max_color_attachment_bytes_per_sample
            ));
        }
        if req.output_bytes > have.max_storage_buffer_binding_size && req.output_pixels > 0 {
            let per_pixel = req.output_bytes / req.output_pixels;
            let most = have.max_storage_buffer_binding_size / per_pixel.max(1);
            return Err(anyhow!(
                "a {} pixel image needs an output buffer of {} bytes ({per_pixel} a pixel); adapter {:?} allows {} bytes a buffer, \
                 so at most {most} pixels (about {side}x{side}): use a smaller --width and --height",
                req.output_pixels,
                req.output_bytes,
                info.name,
                have.max_storage_buffer_binding_size,
                side = (most as f64).sqrt() as u64
            ));
        }
        if limits.max_storage_buffer_binding_size > have.max_storage_buffer_binding_size
            || limits.max_storage_buffers_per_shader_stage
                > have.max_storage_buffers_per_shader_stage
        {
            return Err(anyhow!(
                "adapter {:?} cannot hold this scene: it needs storage buffers of {} bytes \
                 ({} bound at once); the adapter allows {} bytes ({} at once). Try a smaller \
                 scene or a smaller texture budget (--max-texture-size)",
                info.name,
                req.max_storage_buffer_binding_size,
                req.max_storage_buffers_per_shader_stage,
                have.max_storage_buffer_binding_size,
                have.max_storage_buffers_per_shader_stage
            ));
        }
        let mut features = req.features;
        // Timestamps are optional: benchmarks use them where the adapter has them.
        let ts = wgpu::Features::TIMESTAMP_QUERY;
        let timestamps = adapter.features().contains(ts);
        if timestamps {
            features |= ts;
        }
        let missing = features - adapter.features();
        if !missing.is_empty() {
            return Err(anyhow!("adapter {:?} lacks the features {missing:?}", info.name));
        }
        log::info!(
            "adapter: {} ({:?}, {:?}); features requested: {:?}; limits raised above the WebGPU \
             defaults: max_storage_buffer_binding_size={} max_buffer_size={} \
             max_storage_buffers_per_shader_stage={}",
            info.name,
            info.device_type,
            info.backend,
            features,
            limits.max_storage_buffer_binding_size,
            limits.max_buffer_size,
            limits.max_storage_buffers_per_shader_stage
        );
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("hush"),
            required_features: features,
            required_limits: limits,
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .with_context(|| format!("requesting a device from adapter {:?}", info.name))?;
        device.on_uncaptured_error(std::sync::Arc::new(|e| {
            log::error!("wgpu: {e}");
        }));
        let lost = std::sync::Arc::new(std::sync::OnceLock::new());
        let on_lost = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            log::error!("wgpu: device lost ({reason:?}): {message}");
            // Only the first loss is kept: a device is lost once.
            let _ = on_lost.set((format!("{reason:?}"), message));
        });
        let shaders = crate::shader::ShaderLibrary::from_env_or(None)?;
        Ok(Gpu { instance, adapter, device, queue, info, timestamps, shaders, lost })
    }

    /// An error naming the adapter and what it lacks when it cannot write every format of
    /// [`REALTIME_STORAGE_FORMATS`], before any pass fails on one with a validation message.
    pub fn check_realtime_formats(&self) -> Result<()> {
        let storage = wgpu::TextureUsages::STORAGE_BINDING;
        let missing: Vec<wgpu::TextureFormat> = REALTIME_STORAGE_FORMATS
            .into_iter()
            .filter(|f| {
                !self.adapter.get_texture_format_features(*f).allowed_usages.contains(storage)
            })
            .collect();
        if missing.is_empty() {
            return Ok(());
        }
        Err(anyhow!(
            "adapter {:?} ({:?} backend) cannot write the storage textures {missing:?} that the \
             real-time frame needs (the reference mode runs on it). On a machine without a GPU \
             install the software Vulkan driver (on Debian/Ubuntu: `apt-get install \
             mesa-vulkan-drivers`); WGPU_BACKEND and WGPU_ADAPTER_NAME choose another adapter",
            self.info.name,
            self.info.backend
        ))
    }

    /// Run `f` inside a validation error scope: what wgpu would only log becomes an error with
    /// `what` as its context.
    pub fn validated<T>(&self, what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        crate::shader::validated(self, what, f)
    }

    /// [`crate::Error::DeviceLost`] once the device is lost: nothing it records will run.
    pub fn check_lost(&self) -> Result<()> {
        match self.lost.get() {
            Some((reason, message)) => {
                let (reason, message) = (reason.clone(), message.clone());
                Err(crate::Error::DeviceLost { reason, message }.into())
            }
            None => Ok(()),
        }
    }

    /// Block until all submitted work has finished.
    pub fn wait(&self) -> Result<()> {
        self.check_lost()?;
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| anyhow!("waiting for the GPU: {e}"))
    }
}

impl crate::shader::ShaderHost for Gpu {
    fn device(&self) -> &wgpu::Device {
        &self.device
    }

    fn shaders(&self) -> &crate::shader::ShaderLibrary {
        &self.shaders
    }

    fn check_lost(&self) -> Result<()> {
        Gpu::check_lost(self)
    }
}

/// Honour `WGPU_ADAPTER_NAME` (a case-insensitive substring) and `WGPU_POWER_PREF`, as wgpu's
/// own tools do, without panicking when the name matches nothing.
async fn choose_adapter(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
) -> Result<wgpu::Adapter> {
    if let Ok(name) = std::env::var("WGPU_ADAPTER_NAME") {
        let want = name.to_lowercase();
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
        for a in adapters {
            let ok = a.get_info().name.to_lowercase().contains(&want)
                && surface.is_none_or(|s| a.is_surface_supported(s));
            if ok {
                return Ok(a);
            }
        }
        return Err(anyhow!(
            "WGPU_ADAPTER_NAME={name:?} matches none of the adapters {names:?}; {NO_ADAPTER_HELP}"
        ));
    }
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env().unwrap_or_default(),
            compatible_surface: surface,
            force_fallback_adapter: false,
            ..Default::default()
        })
        .await
        .map_err(|e| anyhow!("{NO_ADAPTER_HELP} ({e})"))
}
