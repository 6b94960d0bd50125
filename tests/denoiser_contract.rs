//! The denoiser contract (hush_engine::denoise): a denoiser written only for this test, a plain
//! temporal accumulator of the matte light, is registered by name and renders through the frame
//! with TAA after it, and shows a debug view of its own. Everything it needed is in this file
//! and its one `register` call.

use anyhow::Context;
use glam::DVec3;

use hush_engine::denoise::{
    Bindings, ChainStage, Denoised, Denoiser, DenoiserInfo, DenoiserScene, Entry, Field,
    FrameContext, FrameIo, FrameSettings, Gpu, GpuMemory, Kind, Outputs, Parity, PingPong,
    Recorder, Section, Stage, Tex, ViewMap, ViewSpec, made,
};
use hush_engine::frame::{BvhKind, DenoiserName, FrameInput, Renderer, View};
use hush_engine::quality::{Image, compare};
use hush_engine::scene::Camera;
use std::sync::Once;

const NAME: &str = "accumulate-test";
const MODULE: &str = "test/accumulate.wgsl";
/// Its settings' section: `[accumulate_test]` in a preset.
const SECTION: &str = "accumulate_test";

/// Reprojects its history with the G-buffer's motion vectors and keeps a running mean of up to
/// `max_frames` frames (the history's alpha counts them; with `temporal` off, one); off screen
/// or without a surface it starts over.
const WGSL: &str = r#"
struct AccumulateParams {
    max_frames: f32,
    temporal: u32,
    _pad: vec2u,
}
var<uniform> acc: AccumulateParams;
var history: texture_2d<f32>;
var out_history: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if any(gid.xy >= frame.size) {
        return;
    }
    let current = half_safe(textureLoad(tr_matte, p, 0).rgb);
    let prev = vec2f(p) + 0.5 + textureLoad(gb_motion, p, 0).xy;
    var n = 0.0;
    var mean = vec3f(0.0);
    let inside = all(prev >= vec2f(0.0)) && all(prev < vec2f(frame.size));
    if acc.temporal != 0u && gbuffer_at(p).hit && inside {
        let h = textureLoad(history, vec2i(prev), 0);
        n = min(h.a, acc.max_frames - 1.0);
        mean = half_safe(h.rgb);
    }
    textureStore(out_history, p, vec4f(mix(mean, current, 1.0 / (n + 1.0)), n + 1.0));
}
"#;

/// Mirror of `AccumulateParams`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct AccumulateParams {
    max_frames: f32,
    temporal: u32,
    _pad: [u32; 2],
}

impl AccumulateParams {
    /// From its section of the frame's settings (complete: presets fill in the defaults).
    fn new(s: &FrameSettings) -> anyhow::Result<AccumulateParams> {
        let section = s.sections.get(SECTION).context("no accumulate_test settings")?;
        let max_frames = section["max_frames"].as_u64().context("max_frames")? as f32;
        let temporal = section["temporal"].as_bool().context("temporal")? as u32;
        Ok(AccumulateParams { max_frames, temporal, _pad: [0; 2] })
    }
}

struct Accumulate {
    motion: hush_engine::gpu::Motion,
    params: wgpu::Buffer,
    history: Option<PingPong<Tex>>,
    stage: Option<ChainStage>,
}

fn make(gpu: &Gpu, scene: &DenoiserScene) -> anyhow::Result<Box<dyn Denoiser>> {
    gpu.shaders.add(MODULE, WGSL)?;
    let params = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("accumulate/params"),
        size: size_of::<AccumulateParams>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    Ok(Box::new(Accumulate { motion: scene.motion, params, history: None, stage: None }))
}

fn bindings<'a>(
    io: &FrameIo<'a>,
    params: &'a wgpu::Buffer,
    h: &'a PingPong<Tex>,
    p: Parity,
) -> Bindings<'a> {
    io.bindings()
        .buffer("acc", params)
        .texture("history", &h.history(p).1)
        .texture("out_history", &h.output(p).1)
}

impl Denoiser for Accumulate {
    fn needs_previous_gbuffer(&self) -> bool {
        false
    }

    fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        _kept: &[String],
        _settings: &FrameSettings,
    ) -> anyhow::Result<()> {
        let usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut t =
            |l: &str| memory.texture(&gpu.device, l, size, wgpu::TextureFormat::Rgba32Float, usage);
        self.history = Some(PingPong::new(|i| t(&format!("accumulate/history {i}"))));
        Ok(())
    }

    fn release(&mut self) {
        self.history = None;
        self.stage = None;
    }

    fn record<'s>(
        &'s mut self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
    ) -> anyhow::Result<Outputs<'s>> {
        let h = self.history.as_ref().context("recording before allocating")?;
        let params = AccumulateParams::new(cx.settings)?;
        rec.gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let motion = self.motion.module();
        let modules =
            ["common/math.wgsl", "realtime/frame.wgsl", "realtime/gbuffer_in.wgsl", motion, MODULE];
        let offered = bindings(io, &self.params, h, Parity::default());
        let stage = made(&mut self.stage, || {
            ChainStage::new(rec.gpu, "accumulate", &modules, "main", &offered)
        })?;
        stage.record(rec, cx.key, cx.parity, io.size, |p| bindings(io, &self.params, h, p))?;
        // The composite reads what this frame wrote; TAA averages the composite alone.
        let light = Parity::BOTH.map(|p| Denoised {
            matte: Some(&h.output(p).1),
            glossy: None,
            direct: None,
        });
        Ok(Outputs { light, follow: Default::default() })
    }

    fn pipelines(&mut self) -> Vec<&mut dyn hush_engine::shader::Reload> {
        self.stage
            .iter_mut()
            .map(|s| &mut s.pipeline as &mut dyn hush_engine::shader::Reload)
            .collect()
    }
}

/// Its one debug view: the history's length (32 frames white), with a map the display has.
const VIEWS: &[ViewSpec] = &[ViewSpec {
    name: "accumulate/length",
    texture: "accumulate/history 0",
    map: ViewMap::Grey { channel: 3, divisor: 32.0 },
}];

/// Its settings, as the viewer draws them and presets check them.
const FIELDS: &[Field] = &[
    Field {
        path: "accumulate_test.temporal",
        group: "accumulate",
        unit: "",
        kind: Kind::Bool,
        help: "Keep a history (off: each frame alone).",
    },
    Field {
        path: "accumulate_test.max_frames",
        group: "accumulate",
        unit: "frames",
        kind: Kind::Int(1, 1024),
        help: "The most frames the running mean holds.",
    },
];

/// What `--disable` may switch off: its history.
const STAGES: &[Stage] = &[Stage::named("accumulate", "accumulate_test.temporal")];

fn defaults() -> serde_json::Value {
    serde_json::json!({ "temporal": true, "max_frames": 32 })
}

fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        hush_engine::denoise::register(Entry {
            info: DenoiserInfo {
                name: NAME,
                summary: "a running mean of the matte light (test only)",
                fields: &[FIELDS],
                section: Some(Section { name: SECTION, defaults }),
                stages: STAGES,
                views: VIEWS,
                fractions: false,
                levels: None,
            },
            make: Some(make),
        })
        .unwrap()
    });
}

const SIZE: (u32, u32) = (96, 54);

/// The courtyard of the default level, with the animated cube out of view.
fn view() -> FrameInput {
    FrameInput {
        camera: Camera::look_at(DVec3::new(-3.0, 1.7, 4.0), DVec3::new(-2.0, 1.2, -6.0), 60.0),
        time: 0.0,
        shutter: None,
    }
}

fn render(r: &mut Renderer, gpu: &Gpu, s: &FrameSettings, frames: u32) -> Image {
    for _ in 0..frames {
        r.render(gpu, &view(), s, None).unwrap();
    }
    r.read_hdr(gpu).unwrap()
}

/// 24 still frames through the test denoiser and TAA against one raw frame, both against 128
/// accumulated frames. A running mean of n frames divides the matte light's variance by n, so
/// its relMSE should fall several times below the raw frame's (measured: raw 0.151, test
/// denoiser 0.0258); the bound, half the raw error, fails for a denoiser whose output the
/// composite ignores or that TAA replaces, while leaving room for another driver's noise.
#[test]
fn a_denoiser_written_for_a_test_renders_through_the_contract_with_taa() {
    register();
    assert!(hush_engine::denoise::entries().iter().any(|e| e.info.name == NAME));
    let preset: FrameSettings = toml_settings(&format!("denoiser = \"{NAME}\""));
    assert_eq!(preset.denoiser, DenoiserName::named(NAME));
    let (gpu, mut r) =
        Renderer::headless(hush_engine::scene::default_level(), BvhKind::DEFAULT, SIZE).unwrap();
    let reference =
        render(&mut r, &gpu, &FrameSettings { accumulate: true, ..Default::default() }, 128);
    let raw = render(&mut r, &gpu, &FrameSettings::default(), 1);
    let s = FrameSettings { denoiser: DenoiserName::named(NAME), ..Default::default() };
    let denoised = render(&mut r, &gpu, &s, 24);
    let (e_raw, e_denoised) =
        (compare(&raw, &reference).unwrap().relmse, compare(&denoised, &reference).unwrap().relmse);
    println!("relMSE raw {e_raw:.4}, test denoiser + TAA {e_denoised:.4}");
    assert!(
        e_denoised < 0.5 * e_raw,
        "the test denoiser's output did not reach the image: relMSE {e_denoised} against raw {e_raw}"
    );
    // Its history and TAA's are labelled textures of the frame.
    let (history, _) = r.read_texture(&gpu, "accumulate/history 0").unwrap();
    let n = f32::from_le_bytes(history[12..16].try_into().unwrap());
    assert!(n > 1.0, "history length {n}");
    r.read_texture(&gpu, "taa/history 0").expect("TAA ran after the test denoiser");
    // Its debug view is shown by name, from its texture's label.
    let shown = r
        .display_image(&gpu, &FrameSettings { view: View::named("accumulate/length"), ..s.clone() })
        .unwrap();
    let grey = shown.pixels().map(|p| p.0[0] as u32).max().unwrap();
    assert!(
        grey > 200,
        "the history-length view peaks at {grey}, expected near white after 24 frames"
    );
    let passes: Vec<&str> = r.pass_times(&gpu).unwrap().into_iter().map(|(l, _)| l).collect();
    if !passes.is_empty() {
        for p in ["accumulate", "composite", "taa"] {
            assert!(passes.contains(&p), "{p} did not run: {passes:?}");
        }
        assert!(!passes.iter().any(|p| p.starts_with("matte/")), "the Mara chain ran: {passes:?}");
    }
}

/// A registered denoiser's settings go where the built-in ones go: a TOML preset sets them (what
/// it leaves out keeps its default), an out-of-range or unknown one is refused by name,
/// `--disable` (`disable_stage`) switches its stage off, the viewer's field list holds them, a
/// saved preset round-trips them, and the frame reads them: `max_frames` caps the history's
/// length at 4, `temporal` off keeps it at one frame.
#[test]
fn a_registered_denoisers_settings_reach_presets_disable_and_the_frame() {
    use serde_json::json;
    register();
    let preset = format!("denoiser = \"{NAME}\"\n[{SECTION}]\nmax_frames = 4\n");
    let s = toml_settings(&preset);
    assert_eq!(s.sections[SECTION], json!({ "temporal": true, "max_frames": 4 }));
    for (bad, needle) in [
        ("max_frames = 0", "accumulate_test.max_frames"),
        ("max_frame = 3", "accumulate_test.max_frame"),
        ("temporal = 2", "accumulate_test.temporal"),
    ] {
        let e = FrameSettings::from_toml(&format!("[{SECTION}]\n{bad}\n")).unwrap_err();
        assert!(format!("{e:#}").contains(needle), "{bad}: {e:#}");
    }
    assert!(hush_engine::denoise::fields().any(|f| f.path == "accumulate_test.max_frames"));
    assert!(hush_engine::denoise::stage_names().contains(&"accumulate"));
    let mut off = s.clone();
    assert!(hush_engine::denoise::disable_stage(&mut off, "accumulate"));
    assert_eq!(off.sections[SECTION], json!({ "temporal": false, "max_frames": 4 }));
    assert_eq!(FrameSettings::from_toml(&off.to_toml().unwrap()).unwrap(), off);
    let scene = hush_engine::scene::default_level();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (32, 18)).unwrap();
    for (settings, want) in [(s, 4.0), (off, 1.0)] {
        for _ in 0..8 {
            r.render(&gpu, &view(), &settings, None).unwrap();
        }
        let mut longest = 0.0f32;
        for slot in 0..2 {
            let (texels, _) = r.read_texture(&gpu, &format!("accumulate/history {slot}")).unwrap();
            let texels: &[f32] = bytemuck::cast_slice(&texels);
            longest = texels.chunks_exact(4).map(|t| t[3]).fold(longest, f32::max);
        }
        assert_eq!(longest, want, "history length with {:?}", settings.sections[SECTION]);
    }
}

fn toml_settings(text: &str) -> FrameSettings {
    FrameSettings::from_toml(text).unwrap()
}

/// The module the test denoiser brings is composed like one of `shaders/`.
#[test]
fn a_denoisers_own_wgsl_joins_the_library() {
    let gpu = Gpu::headless(&Default::default()).unwrap();
    gpu.shaders.add(MODULE, WGSL).unwrap();
    gpu.shaders.add(MODULE, WGSL).expect("adding the same text again is harmless");
    assert!(gpu.shaders.add(MODULE, "fn f() {}").is_err(), "a module path holds one text");
    assert!(
        gpu.shaders.add("matte/temporal.wgsl", WGSL).is_err(),
        "a module of shaders/ cannot be replaced"
    );
    let p = gpu
        .shaders
        .compose(
            "t",
            "",
            &[
                "common/math.wgsl",
                "realtime/frame.wgsl",
                "realtime/gbuffer_in.wgsl",
                "realtime/motion_static.wgsl",
                MODULE,
            ],
        )
        .unwrap();
    let names: Vec<String> = {
        let (m, info) = p.validate_with_info().unwrap();
        hush_engine::shader::reflect("t", &m, &info).unwrap()
    }
    .names()
    .map(str::to_string)
    .collect();
    assert!(
        names.contains(&"history".to_string()) && names.contains(&"frame".to_string()),
        "{names:?}"
    );
}

fn level() -> (Gpu, Renderer) {
    let scene = hush_engine::scene::default_level();
    Renderer::headless(scene, BvhKind::DEFAULT, SIZE).unwrap()
}

fn with(denoiser: DenoiserName) -> FrameSettings {
    FrameSettings { denoiser, ..Default::default() }
}

fn labels(r: &Renderer) -> Vec<String> {
    r.allocations().into_iter().map(|(l, _)| l).collect()
}

/// Only the denoiser that runs holds textures: switching from SVGF to Mara forgets every one of
/// SVGF's and leaves the frame with what a frame that only ever ran Mara holds; switching back
/// holds SVGF's again, and the raw frame holds no denoiser's (TAA's, the frame's own, stay).
#[test]
fn only_the_active_denoiser_holds_memory() {
    let (svgf, mara) = (with(DenoiserName::SVGF), with(DenoiserName::MARA));
    let (gpu, mut only_mara) = level();
    render(&mut only_mara, &gpu, &mara, 2);
    let (gpu, mut r) = level();
    render(&mut r, &gpu, &svgf, 2);
    let svgf_bytes = r.bytes_per_pixel();
    assert!(labels(&r).iter().any(|l| l.starts_with("svgf/")), "{:?}", labels(&r));
    render(&mut r, &gpu, &mara, 2);
    assert!(!labels(&r).iter().any(|l| l.starts_with("svgf/")), "{:?}", labels(&r));
    assert_eq!(r.bytes_per_pixel(), only_mara.bytes_per_pixel(), "{:?}", labels(&r));
    render(&mut r, &gpu, &svgf, 2);
    assert_eq!(r.bytes_per_pixel(), svgf_bytes);
    render(&mut r, &gpu, &with(DenoiserName::NONE), 1);
    let held = labels(&r);
    assert!(!held.iter().any(|l| l.starts_with("svgf/") || l.starts_with("matte/")), "{held:?}");
}

/// SVGF's transient textures share memory (the glossy signal's passes reuse the matte
/// signal's), and the image is the same, bit for bit, as with every texture of its own
/// (`keep(["svgf/"])`): no pass reads a texture another one overwrote. An intermediate a later
/// texture shares memory with is not readable after the frame unless kept.
#[test]
fn svgf_shares_its_transients_memory_without_changing_the_image() {
    let svgf = with(DenoiserName::SVGF);
    let (gpu, mut pooled) = level();
    let a = render(&mut pooled, &gpu, &svgf, 6);
    let (gpu, mut own) = level();
    own.keep(&["svgf/"]);
    let b = render(&mut own, &gpu, &svgf, 6);
    let same = a.data.iter().zip(&b.data).all(|(x, y)| x.to_array() == y.to_array());
    assert!(same, "the pool changed the image");
    assert!(pooled.transient_bytes_per_pixel() < own.transient_bytes_per_pixel());
    assert!(pooled.read_texture(&gpu, "svgf/matte integrated").is_err());
    let (kept, _) = own.read_texture(&gpu, "svgf/matte integrated").unwrap();
    let floats: &[f32] = bytemuck::cast_slice(&kept);
    assert!(floats.iter().all(|v| v.is_finite()) && floats.iter().any(|v| *v > 0.0));
}

/// The trace writes the glossy path's reflection data (the virtual position, the mirror
/// direction, what the glossy path hit: 28 bytes a pixel) only while a stage reads it: the raw
/// frame and the progressive filter hold none, Mara makes it, a switch back drops it, and a
/// kept `trace/reflection` brings it back to the raw frame. The image does not depend on it:
/// the raw frame's is the same, bit for bit, with the data written and without.
#[test]
fn the_reflection_data_is_written_only_while_something_reads_it() {
    // The trace's outputs: their count and bytes a pixel.
    let trace = |r: &Renderer| {
        let a: Vec<(String, u64)> =
            r.allocations().into_iter().filter(|(l, _)| l.starts_with("trace/")).collect();
        let bytes: u64 = a.iter().map(|(_, b)| b).sum();
        (a.len(), bytes as f64 / (SIZE.0 * SIZE.1) as f64)
    };
    let none = with(DenoiserName::NONE);
    let (gpu, mut r) = level();
    let plain = render(&mut r, &gpu, &none, 2);
    // Matte, direct and glossy light, 8 bytes each.
    assert_eq!(trace(&r), (3, 24.0), "{:?}", labels(&r));
    render(&mut r, &gpu, &with(DenoiserName::PROGRESSIVE), 1);
    assert_eq!(trace(&r), (3, 24.0), "{:?}", labels(&r));
    render(&mut r, &gpu, &with(DenoiserName::MARA), 1);
    assert_eq!(trace(&r), (6, 52.0), "{:?}", labels(&r));
    render(&mut r, &gpu, &none, 1);
    assert_eq!(trace(&r), (3, 24.0), "{:?}", labels(&r));
    let (gpu, mut kept) = level();
    kept.keep(&["trace/reflection"]);
    let written = render(&mut kept, &gpu, &none, 2);
    assert_eq!(trace(&kept), (6, 52.0));
    let same = plain.data.iter().zip(&written.data).all(|(x, y)| x.to_array() == y.to_array());
    assert!(same, "writing the reflection data changed the raw frame");
}

/// The progressive filter's signals share the variance stage's output and the levels' scratch
/// texture (each keeps its last level, which the composite reads), through level counts of
/// both parities and none, switched on one renderer: the image is the same, bit for bit, as
/// with every texture of its own, and with one level or more it holds 48 bytes a pixel less
/// (one variance texture and one scratch texture for three signals).
#[test]
fn the_progressive_filter_shares_its_textures_without_changing_the_image() {
    let (gpu, mut shared) = level();
    let (gpu2, mut own) = level();
    own.keep(&["progressive/"]);
    for levels in [2, 1, 0, 3] {
        let mut s = with(DenoiserName::PROGRESSIVE);
        s.progressive.levels = levels;
        let a = render(&mut shared, &gpu, &s, 3);
        let b = render(&mut own, &gpu2, &s, 3);
        let same = a.data.iter().zip(&b.data).all(|(x, y)| x.to_array() == y.to_array());
        assert!(same, "sharing changed the image at {levels} levels");
        let saved = own.bytes_per_pixel() - shared.bytes_per_pixel();
        assert_eq!(saved, if levels == 0 { 0.0 } else { 48.0 }, "{levels} levels");
    }
}
