//! The Mara et al. 2017 denoiser as the registry knows it (`crate::denoise::mara`): its
//! settings are the matte chain's ([`super::MatteSettings`]) and the glossy chain's
//! ([`super::GlossySettings`]); TAA's belong to the frame, which runs TAA after any denoiser.

use super::denoiser_info::{DenoiserInfo, Stage};
use super::view_spec::v;
use super::{Denoiser, ViewMap, ViewSpec};
use std::borrow::Cow;

impl Denoiser {
    /// Mara et al. 2017: the matte and glossy chains, then TAA.
    pub const MARA: Denoiser = Denoiser(Cow::Borrowed(INFO.name));
}

pub const INFO: DenoiserInfo = DenoiserInfo {
    name: "mara",
    summary: "Mara et al. 2017: the matte and glossy chains, then TAA",
    fields: &[super::matte::FIELDS, super::glossy::FIELDS],
    section: None,
    stages: &[
        Stage::named("matte/temporal", "matte.temporal"),
        Stage::named("matte/history_bilateral", "matte.history_bilateral"),
        Stage::named("matte/disocclusion", "matte.disocclusion"),
        Stage::named("matte/firefly", "matte.firefly"),
        Stage::named("matte/bilateral", "matte.bilateral"),
        Stage::named("glossy/temporal", "glossy.temporal"),
        Stage::switch("glossy.clipping"),
        Stage::switch("glossy.hit_test"),
        Stage::named("glossy/bilateral", "glossy.bilateral"),
    ],
    views: VIEWS,
    fractions: false,
    levels: None,
};

/// The views of the Mara denoiser's chains (`crate::denoise::mara`), kept beside their settings
/// so that presets can name them before any denoiser exists.
pub const VIEWS: &[ViewSpec] = &[
    v("matte/temporal", "matte/temporal", ViewMap::Light),
    v("matte/confidence", "matte/temporal", ViewMap::Grey { channel: 3, divisor: 1.0 }),
    v("matte/history rejection", "matte/reason", ViewMap::Flags),
    // The radius over R (the disocclusion radius at full strength is white).
    v(
        "matte/disocclusion radius",
        "matte/radius",
        ViewMap::GreyPerWidth { channel: 0, fraction: 0.05 },
    ),
    v("matte/firefly", "matte/firefly", ViewMap::Light),
    v("matte/bilateral", "matte/bilateral", ViewMap::Light),
    v("glossy/motion", "glossy/motion", ViewMap::Motion { channel: 0 }),
    v("glossy/virtual motion", "glossy/motion", ViewMap::Motion { channel: 2 }),
    // Pixels between the diamond search and the virtual position (or the brute-force search
    // when it runs); 4 px is white.
    v("glossy/motion disagreement", "glossy/search", ViewMap::Grey { channel: 1, divisor: 4.0 }),
    // Large-pattern iterations; 16 is white.
    v("glossy/search steps", "glossy/search", ViewMap::Grey { channel: 0, divisor: 16.0 }),
    v("glossy/confidence", "glossy/info", ViewMap::Grey { channel: 0, divisor: 1.0 }),
    v("glossy/clipping", "glossy/info", ViewMap::Grey { channel: 1, divisor: 1.0 }),
    // The bilateral's sigma over 9 px (GlossySettings' largest).
    v("glossy/sigma", "glossy/scratch", ViewMap::Grey { channel: 3, divisor: 9.0 }),
    v("glossy/bilateral", "glossy/denoised", ViewMap::Light),
];
