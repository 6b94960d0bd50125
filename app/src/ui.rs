//! The side panel: frame time, per-pass GPU time, resolution scale, mode, sun, exposure, debug
//! views, animation clock, screenshots and camera paths.

use hush_engine::frame::View;
use hush_engine::settings::{Denoiser, FrameSettings, ReflectionMv};

pub struct Panel {
    pub settings: FrameSettings,
    /// Fraction of the window's pixels the frame renders (0.25 .. 1 per side).
    pub resolution_scale: f32,
    /// Sun azimuth and elevation in degrees (None: the scene has no directional light).
    pub sun: Option<(f32, f32)>,
    pub paused: bool,
    pub time: f64,
    pub glossy: bool,
    pub frame_ms: f64,
    pub pass_ms: Vec<(&'static str, f64)>,
    pub report: String,
    pub message: String,
    pub recording: bool,
    pub playing: bool,
}

#[derive(Default)]
pub struct Actions {
    pub sun_changed: bool,
    pub screenshot: bool,
    pub toggle_record: bool,
    pub toggle_play: bool,
}

impl Panel {
    pub fn show(&mut self, ui: &mut egui::Ui) -> Actions {
        let mut a = Actions::default();
        ui.heading("Hush");
        ui.label(format!("frame {:.1} ms (CPU, whole loop)", self.frame_ms));
        let gpu_total: f64 = self.pass_ms.iter().map(|p| p.1).sum();
        if !self.pass_ms.is_empty() {
            ui.label(format!("GPU {gpu_total:.2} ms"));
            for (name, ms) in &self.pass_ms {
                ui.label(format!("  {name}: {ms:.2} ms"));
            }
        }
        ui.separator();
        ui.add(egui::Slider::new(&mut self.resolution_scale, 0.25..=1.0).text("resolution scale"));
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.settings.accumulate, false, "real-time");
            ui.radio_value(&mut self.settings.accumulate, true, "accumulate");
        });
        ui.horizontal(|ui| {
            ui.label("denoiser");
            ui.radio_value(&mut self.settings.denoiser, Denoiser::None, "none");
            ui.radio_value(&mut self.settings.denoiser, Denoiser::Mara, "Mara et al. 2017");
        });
        if self.settings.denoiser == Denoiser::Mara {
            let m = &mut self.settings.matte;
            ui.collapsing("matte chain and TAA", |ui| {
                ui.checkbox(&mut m.temporal, "matte/temporal (3)");
                ui.checkbox(&mut m.history_bilateral, "matte/history_bilateral (4)");
                ui.checkbox(&mut m.disocclusion, "matte/disocclusion (5)");
                ui.checkbox(&mut m.firefly, "matte/firefly (6)");
                ui.checkbox(&mut m.bilateral, "matte/bilateral (7)");
                ui.checkbox(&mut m.taa, "taa");
                ui.add(egui::Slider::new(&mut m.hysteresis, 0.5..=0.999).text("hysteresis h"));
                ui.add(egui::Slider::new(&mut m.clamp_sigma, 0.5..=16.0).text("history clamp (sigma)"));
                ui.add(egui::Slider::new(&mut m.d0_px, 0.5..=32.0).text("d0 (pixel footprints)"));
                ui.add(egui::Slider::new(&mut m.d1_px, 0.5..=48.0).text("d1 (pixel footprints)"));
                ui.add(egui::Slider::new(&mut m.taps, 4..=128).text("bilateral taps"));
                ui.add(egui::Slider::new(&mut m.history_diameter_fraction, 0.001..=0.05).text("history disk (fraction of width)"));
                ui.add(egui::Slider::new(&mut m.disocclusion_fraction, 0.005..=0.2).text("R (fraction of width)"));
                ui.add(egui::Slider::new(&mut m.taa_alpha, 0.02..=1.0).text("TAA current-frame weight"));
            });
            if self.glossy {
                let g = &mut self.settings.glossy;
                ui.collapsing("glossy chain", |ui| {
                    ui.checkbox(&mut g.temporal, "glossy/temporal (8; off: no reprojection)");
                    ui.checkbox(&mut g.clipping, "glossy/temporal neighbourhood clipping");
                    ui.checkbox(&mut g.bilateral, "glossy/bilateral (9, 10)");
                    egui::ComboBox::from_label("reflection motion vectors").selected_text(g.reflection_mv.name()).show_ui(ui, |ui| {
                        for mv in ReflectionMv::ALL {
                            ui.selectable_value(&mut g.reflection_mv, mv, mv.name());
                        }
                    });
                    ui.add(egui::Slider::new(&mut g.roughness_threshold, 0.0..=1.0).text("reflection MV roughness threshold"));
                    ui.add(egui::Slider::new(&mut g.initial_step, 1..=16).text("diamond first step (px)"));
                    ui.add(egui::Slider::new(&mut g.hysteresis, 0.5..=0.999).text("hysteresis h"));
                    ui.add(egui::Slider::new(&mut g.sigma_scale, 0.0..=12.0).text("sigma scale (px)"));
                    ui.add(egui::Slider::new(&mut g.sigma_epsilon_px, 0.0..=4.0).text("sigma epsilon (px)"));
                    ui.add(egui::Slider::new(&mut g.ray_differential_omega, 1.0..=64.0).text("ray differential omega (footprints)"));
                });
            }
        }
        ui.add(egui::Slider::new(&mut self.settings.exposure_ev, -8.0..=8.0).text("exposure (EV)"));
        ui.add(egui::Slider::new(&mut self.settings.max_depth, 2..=16).text("max depth"));
        if let Some((az, el)) = &mut self.sun {
            let c1 = ui.add(egui::Slider::new(az, -180.0..=180.0).text("sun azimuth (deg)")).changed();
            let c2 = ui.add(egui::Slider::new(el, 1.0..=89.0).text("sun elevation (deg)")).changed();
            a.sun_changed = c1 || c2;
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.paused, "pause animation");
            ui.label(format!("t = {:.2} s", self.time));
        });
        ui.separator();
        egui::ComboBox::from_label("view").selected_text(self.settings.view.name()).show_ui(ui, |ui| {
            for v in View::ALL {
                if self.glossy || !v.needs_glossy() {
                    ui.selectable_value(&mut self.settings.view, v, v.name());
                }
            }
        });
        ui.separator();
        a.screenshot = ui.button("screenshot (F12)").clicked();
        let rec = if self.recording { "stop recording (R)" } else { "record camera path (R)" };
        a.toggle_record = ui.button(rec).clicked();
        let play = if self.playing { "stop playback (P)" } else { "play camera path (P)" };
        a.toggle_play = ui.button(play).clicked();
        if !self.message.is_empty() {
            ui.separator();
            ui.label(&self.message);
        }
        ui.separator();
        ui.collapsing("allocations", |ui| ui.label(&self.report));
        a
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
