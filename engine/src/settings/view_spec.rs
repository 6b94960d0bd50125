//! What a debug view shows: the texture (by label) and the map from texel to colour, and the
//! frame's own views.

/// How the display turns a texel into a colour (`display.map` in shaders/realtime/display.wgsl;
/// the numbers are that shader's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewMap {
    /// Radiance in rgb: exposed and tone-mapped like the image.
    Light,
    /// Data in rgb, clamped to [0, 1].
    Color,
    /// One channel divided by `divisor`, as grey.
    Grey { channel: u32, divisor: f32 },
    /// One channel over this fraction of the frame's width (at least 1), as grey.
    GreyPerWidth { channel: u32, fraction: f32 },
    /// One channel as frames' worth of samples, white at `frames`: the upscaler's history
    /// weight over the kernel weight one frame brings a shown pixel (`UpscaleParams::frame_weight`,
    /// which depends on the scale).
    UpscaleFrames { channel: u32, frames: f32 },
    /// Two channels from `channel` as pixels of motion: hue = direction, brightness = length
    /// (1 px = 0.25).
    Motion { channel: u32 },
    /// The G-buffer's octahedral normal, black off the surface.
    Normal,
    /// The G-buffer's reversed-Z depth, near bright (depth^0.25).
    Depth,
    /// A u32 id (channel 0) hashed to a colour, black off the surface.
    Id,
    /// History rejection flags in the low bits of a u32 (`matte/reason`): red disoccluded,
    /// yellow low confidence, plus blue where clamped.
    Flags,
    /// An octahedral direction packed as two snorm16 in a u32.
    PackedDirection,
    /// A distance in alpha over 2^17 ray offsets (the scene's extent), white from 65000 on.
    Distance,
    /// A position in rgb over the scene's extent, as bands (black where alpha marks a miss).
    Position,
}

impl ViewMap {
    /// (map, channel, parameter) as the display's uniform carries them, for a frame `width`
    /// render pixels wide whose upscaler (if it runs) brings a shown pixel `frame_weight` of
    /// kernel weight a frame.
    pub fn encode(self, width: u32, frame_weight: f32) -> (u32, u32, f32) {
        match self {
            ViewMap::Light => (1, 0, 0.0),
            ViewMap::Color => (2, 0, 0.0),
            ViewMap::Grey { channel, divisor } => (3, channel, divisor),
            ViewMap::GreyPerWidth { channel, fraction } => {
                (3, channel, (width as f32 * fraction).max(1.0))
            }
            ViewMap::UpscaleFrames { channel, frames } => {
                (3, channel, (frame_weight * frames).max(1e-6))
            }
            ViewMap::Motion { channel } => (4, channel, 0.0),
            ViewMap::Normal => (5, 0, 0.0),
            ViewMap::Depth => (6, 0, 0.0),
            ViewMap::Id => (7, 0, 0.0),
            ViewMap::Flags => (8, 0, 0.0),
            ViewMap::PackedDirection => (9, 0, 0.0),
            ViewMap::Distance => (10, 3, 0.0),
            ViewMap::Position => (11, 0, 0.0),
        }
    }
}

/// A debug view: a name, the label of the texture it shows, and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSpec {
    pub name: &'static str,
    pub texture: &'static str,
    pub map: ViewMap,
}

impl ViewSpec {
    /// Views of the pre-filter's textures, which exist once a thin lens or an open shutter has
    /// been rendered.
    pub fn needs_traced_primaries(&self) -> bool {
        self.texture.starts_with("prefilter/")
    }

    /// Views of the radiance cache's outputs (`cache/...`): black unless the cache runs and a
    /// move uncovered pixels it holds light for.
    pub fn needs_cache(&self) -> bool {
        self.texture.starts_with("cache/")
    }

    /// Views of the temporal upscaler's textures (`upscale/...`): black unless it runs (the
    /// frame shown above the size it is traced at, with a denoiser).
    pub fn needs_upscaler(&self) -> bool {
        self.texture.starts_with(crate::passes::upscale::PREFIX)
    }

    /// Views of buffers that exist only in scenes with a specular lobe: the glossy chain's
    /// (`glossy/...`), a denoiser's glossy signal (`name/glossy ...`) and the trace's glossy
    /// outputs.
    pub fn needs_glossy(&self) -> bool {
        let mut parts = self.texture.split('/');
        let (first, second) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
        first == "glossy"
            || second.starts_with("glossy")
            || matches!(self.texture, "trace/reflection" | "trace/mirror")
    }
}

pub(super) const fn v(name: &'static str, texture: &'static str, map: ViewMap) -> ViewSpec {
    ViewSpec { name, texture, map }
}

/// The frame's own views: the G-buffer and the trace's outputs.
pub const FRAME_VIEWS: &[ViewSpec] = &[
    v("gbuffer/depth", "gbuffer/depth", ViewMap::Depth),
    v("gbuffer/normal", "gbuffer/normal", ViewMap::Normal),
    v("gbuffer/base_color", "gbuffer/base_color", ViewMap::Color),
    v("gbuffer/metallic", "gbuffer/base_color", ViewMap::Grey { channel: 3, divisor: 1.0 }),
    v("gbuffer/roughness", "gbuffer/specular", ViewMap::Grey { channel: 3, divisor: 1.0 }),
    v("gbuffer/specular F0", "gbuffer/specular", ViewMap::Color),
    v("gbuffer/emission", "gbuffer/emission", ViewMap::Light),
    v("gbuffer/object id", "gbuffer/ids", ViewMap::Id),
    v("gbuffer/motion", "gbuffer/motion", ViewMap::Motion { channel: 0 }),
    // The pre-filter's (Moon et al. 2017), with a thin lens: the bandwidth after smoothing
    // (white: h = 2), the world positions' spread (white: 8 pixels), the filtered normal's and
    // view depth's variances from dual buffers (white: 0.05, and 1e-4 relative), the raw normal
    // (gbuffer/normal shows the filtered).
    v("prefilter/bandwidth", "prefilter/view", ViewMap::Grey { channel: 1, divisor: 2.0 }),
    v("prefilter/position spread", "prefilter/view", ViewMap::Grey { channel: 2, divisor: 8.0 }),
    v("prefilter/normal variance", "prefilter/view", ViewMap::Grey { channel: 3, divisor: 0.05 }),
    v("prefilter/depth variance", "prefilter/normals", ViewMap::Grey { channel: 2, divisor: 1e-4 }),
    v("prefilter/raw normal", "prefilter/normals", ViewMap::Normal),
    v("trace/matte", "trace/matte", ViewMap::Light),
    v("trace/direct", "trace/direct", ViewMap::Light),
    v("trace/glossy", "trace/glossy", ViewMap::Light),
    v("trace/glossy hit distance", "trace/glossy", ViewMap::Distance),
    v("trace/virtual position", "trace/reflection", ViewMap::Position),
    v("trace/mirror direction", "trace/mirror", ViewMap::PackedDirection),
    // The radiance cache's, where it runs: the prior an uncovered pixel starts from, and the
    // frames' worth of samples it stands for (white: 4, the default `cache.prior_frames`).
    v("cache/prior", "cache/prior", ViewMap::Light),
    v("cache/prior frames", "cache/prior", ViewMap::Grey { channel: 3, divisor: 4.0 }),
    // The temporal upscaler's, where it runs (passes/upscale.rs). Its inputs: each render
    // pixel's light divided by its material, and the shown size's raster's materials averaged
    // over its jitter. Its history: the kernel-weighted mean of the samples, and its weight in
    // frames' worth of samples (white: 32; while anything moves it is capped at
    // `taa.upscale_moving_frames`, 10 by default); the still view's mean of the raw samples.
    v("upscale/samples", "upscale/samples", ViewMap::Light),
    v("upscale/materials", "upscale/albedo 0", ViewMap::Color),
    v("upscale/shown base_color", "upscale/gbuffer/base_color", ViewMap::Color),
    v("upscale/history", "upscale/history 0", ViewMap::Light),
    v("upscale/history frames", "upscale/history 0", UPSCALE_FRAMES),
    v("upscale/still-view mean", "upscale/raw 0", ViewMap::Light),
    v("upscale/still-view frames", "upscale/raw 0", UPSCALE_FRAMES),
];

const UPSCALE_FRAMES: ViewMap = ViewMap::UpscaleFrames { channel: 3, frames: 32.0 };
