//! The side panel: frame time, resolution scale, sun, animation clock, the frame's chain of
//! passes with their GPU time and settings, presets, screenshots, camera paths and the profiler.

use crate::settings_ui;
use hush_engine::frame::View;
use hush_engine::settings::FrameSettings;

pub struct Panel {
    pub settings: FrameSettings,
    /// Fraction of the window's pixels the frame renders (0.25 .. 1 per side).
    pub resolution_scale: f32,
    /// Sun azimuth and elevation in degrees (None: the scene has no directional light).
    pub sun: Option<(f32, f32)>,
    pub paused: bool,
    pub time: f64,
    /// The scene's loop length in seconds (the scrub slider's range; 0: nothing moves).
    pub animation_length: f64,
    /// The file's animations and which one plays (None: all of them); a different choice in
    /// the panel sets `animation_request`, which reloads the scene with it.
    pub animations: Vec<String>,
    pub animation: Option<usize>,
    pub animation_request: Option<Option<usize>>,
    pub glossy: bool,
    pub frame_ms: f64,
    pub pass_ms: Vec<(&'static str, f64)>,
    pub report: String,
    pub message: String,
    pub recording: bool,
    pub playing: bool,
    /// Where presets are saved and loaded (TOML).
    pub preset_path: String,
    /// The frame-time governor (hush_engine::governor): on, its target, the knobs the user
    /// pinned, and what it chose for the last frame.
    pub governor: GovernorPanel,
    pub lens: LensPanel,
}

/// The camera's thin lens (depth of field), in scene units.
pub struct LensPanel {
    /// Motion blur: the fraction of the frame interval the shutter stays open (0: none).
    pub shutter: f32,
    pub on: bool,
    pub aperture_radius: f32,
    pub focus_distance: f32,
    /// The scene's extent, which bounds both sliders.
    pub extent: f32,
}

impl LensPanel {
    /// The scene camera's lens, or (off) a small aperture focused at a quarter of the scene.
    pub fn new(lens: Option<hush_engine::scene::ThinLens>, extent: f64) -> LensPanel {
        let extent = (extent as f32).max(1e-6);
        match lens {
            Some(l) => LensPanel {
                shutter: 0.0,
                on: true,
                aperture_radius: l.aperture_radius,
                focus_distance: l.focus_distance,
                extent,
            },
            None => LensPanel {
                shutter: 0.0,
                on: false,
                aperture_radius: extent * 2e-3,
                focus_distance: extent * 0.25,
                extent,
            },
        }
    }

    pub fn lens(&self) -> Option<hush_engine::scene::ThinLens> {
        self.on
            .then(|| {
                hush_engine::scene::ThinLens::new(
                    self.aperture_radius as f64,
                    self.focus_distance as f64,
                )
                .ok()
            })
            .flatten()
    }
}

pub struct GovernorPanel {
    pub on: bool,
    pub target_ms: f64,
    /// A still view's frames may take this multiple of the target (Governor::still_ratio).
    pub still_ratio: f64,
    pub pin_scale: bool,
    pub pin_fraction: bool,
    pub choice: String,
}

#[derive(Default)]
pub struct Actions {
    pub sun_changed: bool,
    pub screenshot: bool,
    pub toggle_record: bool,
    pub toggle_play: bool,
    pub toggle_profiler: bool,
    pub save_preset: bool,
    pub load_preset: bool,
}

impl Panel {
    pub fn show(&mut self, ui: &mut egui::Ui) -> Actions {
        let mut a = Actions::default();
        ui.heading("Hush");
        ui.label(format!("frame {:.1} ms (CPU, whole loop)", self.frame_ms));
        let g = &mut self.governor;
        ui.horizontal(|ui| {
            ui.checkbox(&mut g.on, "frame-time governor");
            ui.add(
                egui::DragValue::new(&mut g.target_ms).range(5.0..=2000.0).speed(1.0).suffix(" ms"),
            );
        });
        if g.on {
            ui.label(&g.choice).on_hover_text("The resolution scale and sample fraction the governor chose to hold the target; pin either to keep it and let the governor turn the other.");
            ui.add(
                egui::Slider::new(&mut g.still_ratio, 1.0..=10.0)
                    .text("still view: x target")
                    .suffix("x"),
            )
            .on_hover_text("While the camera stands still the samples accumulate, so the governor picks the sample fraction that traces the most samples per second, letting a frame take up to this multiple of the target, and (where the histories are resampled across a change of size) raises the resolution a step each time the pixels have gathered 4 samples: a larger multiple converges sooner and sharper, and a move waits longer for the frame in flight. 1 holds the target.");
            ui.horizontal(|ui| {
                ui.checkbox(&mut g.pin_scale, "pin scale");
                ui.checkbox(&mut g.pin_fraction, "pin sample fraction");
            });
        }
        let governed = g.on && !g.pin_scale;
        ui.add_enabled(
            !governed,
            egui::Slider::new(&mut self.resolution_scale, 0.25..=1.0).text("resolution scale"),
        );
        if let Some((az, el)) = &mut self.sun {
            let c1 =
                ui.add(egui::Slider::new(az, -180.0..=180.0).text("sun azimuth (deg)")).changed();
            let c2 =
                ui.add(egui::Slider::new(el, 1.0..=89.0).text("sun elevation (deg)")).changed();
            a.sun_changed = c1 || c2;
        }
        let l = &mut self.lens;
        ui.add(egui::Slider::new(&mut l.shutter, 0.0..=1.0).text("motion blur shutter")).on_hover_text("The fraction of the frame interval the shutter stays open: each primary sample sees the camera and the animation at a random time in it (the G-buffer is then traced, as with a lens).");
        ui.checkbox(&mut l.on, "depth of field (thin lens)").on_hover_text("The frame then traces k primary rays per pixel through the lens (gbuffer/primaries) and pre-filters their features (prefilter). Middle-click the image to focus on the surface there.");
        if l.on {
            ui.add(
                egui::Slider::new(&mut l.aperture_radius, l.extent * 1e-5..=l.extent * 0.05)
                    .logarithmic(true)
                    .text("aperture radius"),
            );
            ui.add(
                egui::Slider::new(&mut l.focus_distance, l.extent * 1e-4..=l.extent * 2.0)
                    .logarithmic(true)
                    .text("focus distance"),
            );
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.paused, "pause animation");
            ui.label(format!("t = {:.2} s", self.time));
        });
        if self.paused && self.animation_length > 0.0 {
            // Scrub: the clock within one loop of the animation.
            let mut t = self.time.rem_euclid(self.animation_length);
            if ui.add(egui::Slider::new(&mut t, 0.0..=self.animation_length).text("time")).changed()
            {
                self.time = t;
            }
        }
        if self.animations.len() > 1 {
            let name = |a: Option<usize>| match a {
                None => "all animations".to_string(),
                Some(i) => self.animations.get(i).cloned().unwrap_or_default(),
            };
            let mut choice = self.animation;
            egui::ComboBox::from_label("plays").selected_text(name(choice)).show_ui(ui, |ui| {
                ui.selectable_value(&mut choice, None, name(None));
                for i in 0..self.animations.len() {
                    ui.selectable_value(&mut choice, Some(i), name(Some(i)));
                }
            });
            if choice != self.animation {
                self.animation_request = Some(choice);
            }
        }
        ui.separator();
        self.chain(ui);
        ui.separator();
        ui.horizontal(|ui| {
            ui.label("preset");
            ui.text_edit_singleline(&mut self.preset_path);
        });
        ui.horizontal(|ui| {
            a.save_preset = ui.button("save").clicked();
            a.load_preset = ui.button("load").clicked();
        });
        ui.separator();
        a.screenshot = ui.button("screenshot (F12)").clicked();
        let rec = if self.recording { "stop recording (R)" } else { "record camera path (R)" };
        a.toggle_record = ui.button(rec).clicked();
        let play = if self.playing { "stop playback (P)" } else { "play camera path (P)" };
        a.toggle_play = ui.button(play).clicked();
        a.toggle_profiler = ui.button("profiler (F9)").clicked();
        if !self.message.is_empty() {
            ui.separator();
            ui.label(&self.message);
        }
        ui.separator();
        ui.collapsing("allocations", |ui| ui.label(&self.report));
        a
    }

    /// The frame as a list of its stages in the order they ran, each with its GPU time and the
    /// settings of that stage; settings groups with no pass this frame (the frame's own, and
    /// the chains while the denoiser is off) follow.
    fn chain(&mut self, ui: &mut egui::Ui) {
        let gpu_total: f64 = self.pass_ms.iter().map(|p| p.1).sum();
        ui.label(format!("frame chain: GPU {gpu_total:.2} ms"));
        let defaults = settings_ui::defaults();
        let mut v = self.settings.to_value();
        let mut changed = false;
        let groups = settings_ui::groups();
        let glossy = self.glossy;
        let relevant = |g: &str| glossy || !g.starts_with("glossy/");
        // Scenes without a glossy lobe have no glossy buffers to show.
        let offered = |path: &str, choice: &str| {
            path != "view" || glossy || View::named(choice).spec().is_none_or(|v| !v.needs_glossy())
        };
        let group_of = |pass: &str| {
            groups
                .iter()
                .copied()
                .find(|g| pass == *g || pass.strip_prefix(*g).is_some_and(|r| r.starts_with('_')))
        };
        let mut shown: Vec<&str> = vec![];
        let mut rows: Vec<(String, f64, Option<&'static str>)> = vec![];
        // A stage's passes share one row: its name, then what tells them apart (`_h`/`_v`,
        // `_matte`/`_glossy`), their times summed.
        for (pass, ms) in &self.pass_ms {
            match group_of(pass) {
                Some(g) => {
                    let part = pass.trim_start_matches(g).trim_start_matches('_');
                    match rows.iter_mut().find(|r| r.2 == Some(g)) {
                        Some(row) => {
                            row.0 = match row.0.strip_suffix(')') {
                                Some(open) => format!("{open}, {part})"),
                                None => format!("{g} ({part})"),
                            };
                            row.1 += ms;
                        }
                        None => {
                            shown.push(g);
                            let label = if part.is_empty() {
                                g.to_string()
                            } else {
                                format!("{g} ({part})")
                            };
                            rows.push((label, *ms, Some(g)));
                        }
                    }
                }
                None => rows.push((pass.to_string(), *ms, None)),
            }
        }
        for (label, ms, g) in &rows {
            let frac = if gpu_total > 0.0 { (ms / gpu_total) as f32 } else { 0.0 };
            let title = format!("{label}  {ms:.2} ms");
            match g {
                Some(g) => {
                    egui::CollapsingHeader::new(title).id_salt(*g).show(ui, |ui| {
                        changed |= settings_ui::group(ui, g, &mut v, defaults, &offered)
                    });
                }
                None => {
                    ui.label(title);
                }
            }
            ui.add(egui::ProgressBar::new(frac).desired_height(3.0));
        }
        for g in groups.iter().filter(|g| !shown.contains(g) && relevant(g)) {
            egui::CollapsingHeader::new(*g)
                .id_salt(*g)
                .show(ui, |ui| changed |= settings_ui::group(ui, g, &mut v, defaults, &offered));
        }
        if changed && let Err(e) = settings_ui::apply(&mut self.settings, &v) {
            self.message = e;
        }
    }
}

/// Sun direction (the way the light travels) from azimuth/elevation in degrees.
pub fn sun_dir(az: f32, el: f32) -> glam::Vec3 {
    let (a, e) = (az.to_radians(), el.to_radians());
    -glam::Vec3::new(a.sin() * e.cos(), e.sin(), -a.cos() * e.cos())
}

pub fn sun_angles(dir: glam::Vec3) -> (f32, f32) {
    let to_sun = -dir.normalize();
    (to_sun.x.atan2(-to_sun.z).to_degrees(), to_sun.y.clamp(-1.0, 1.0).asin().to_degrees())
}
