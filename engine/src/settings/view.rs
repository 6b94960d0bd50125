//! What the display shows: the image or one buffer of the frame (shaders/realtime/display.wgsl).

/// Debug views, numbered as the display shader's `frame.view`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum View {
    #[default]
    Final = 0,
    Depth = 1,
    Normal = 2,
    BaseColor = 3,
    Metallic = 4,
    Roughness = 5,
    SpecularF0 = 6,
    Emission = 7,
    ObjectId = 8,
    Motion = 9,
    MatteLight = 10,
    DirectLight = 11,
    GlossyLight = 12,
    GlossyHitDistance = 13,
    VirtualPosition = 14,
    MirrorDirection = 15,
    MatteTemporal = 16,
    MatteConfidence = 17,
    MatteRejection = 18,
    MatteRadius = 19,
    MatteFirefly = 20,
    MatteDenoised = 21,
    GlossyMotion = 22,
    GlossyVirtualMotion = 23,
    GlossyMotionDisagreement = 24,
    GlossySearchSteps = 25,
    GlossyConfidence = 26,
    GlossyClipping = 27,
    GlossySigma = 28,
    GlossyDenoised = 29,
}

impl View {
    pub const ALL: [View; 30] = [
        View::Final,
        View::Depth,
        View::Normal,
        View::BaseColor,
        View::Metallic,
        View::Roughness,
        View::SpecularF0,
        View::Emission,
        View::ObjectId,
        View::Motion,
        View::MatteLight,
        View::DirectLight,
        View::GlossyLight,
        View::GlossyHitDistance,
        View::VirtualPosition,
        View::MirrorDirection,
        View::MatteTemporal,
        View::MatteConfidence,
        View::MatteRejection,
        View::MatteRadius,
        View::MatteFirefly,
        View::MatteDenoised,
        View::GlossyMotion,
        View::GlossyVirtualMotion,
        View::GlossyMotionDisagreement,
        View::GlossySearchSteps,
        View::GlossyConfidence,
        View::GlossyClipping,
        View::GlossySigma,
        View::GlossyDenoised,
    ];

    /// The pass output it shows, as named in labels and the profiler.
    pub fn name(self) -> &'static str {
        match self {
            View::Final => "final",
            View::Depth => "gbuffer/depth",
            View::Normal => "gbuffer/normal",
            View::BaseColor => "gbuffer/base_color",
            View::Metallic => "gbuffer/metallic",
            View::Roughness => "gbuffer/roughness",
            View::SpecularF0 => "gbuffer/specular F0",
            View::Emission => "gbuffer/emission",
            View::ObjectId => "gbuffer/object id",
            View::Motion => "gbuffer/motion",
            View::MatteLight => "trace/matte",
            View::DirectLight => "trace/direct",
            View::GlossyLight => "trace/glossy",
            View::GlossyHitDistance => "trace/glossy hit distance",
            View::VirtualPosition => "trace/virtual position",
            View::MirrorDirection => "trace/mirror direction",
            View::MatteTemporal => "matte/temporal",
            View::MatteConfidence => "matte/confidence",
            View::MatteRejection => "matte/history rejection",
            View::MatteRadius => "matte/disocclusion radius",
            View::MatteFirefly => "matte/firefly",
            View::MatteDenoised => "matte/bilateral",
            View::GlossyMotion => "glossy/motion",
            View::GlossyVirtualMotion => "glossy/virtual motion",
            View::GlossyMotionDisagreement => "glossy/motion disagreement",
            View::GlossySearchSteps => "glossy/search steps",
            View::GlossyConfidence => "glossy/confidence",
            View::GlossyClipping => "glossy/clipping",
            View::GlossySigma => "glossy/sigma",
            View::GlossyDenoised => "glossy/bilateral",
        }
    }

    /// Views of buffers that exist only in scenes with a specular lobe.
    pub fn needs_glossy(self) -> bool {
        (View::GlossyLight as u32..=View::MirrorDirection as u32).contains(&(self as u32)) || self as u32 >= View::GlossyMotion as u32
    }

    /// Views of the denoiser's intermediates (black until it has run).
    pub fn needs_denoiser(self) -> bool {
        (self as u32) >= View::MatteTemporal as u32
    }
}
