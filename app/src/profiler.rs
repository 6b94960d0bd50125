//! The viewer's profiler: a flame graph of the latest frame (CPU scopes and the GPU timeline),
//! N-frame captures to `.puffin` files, and puffin_http on request. puffin_egui is not used: its
//! newest release (0.30) is built on egui 0.33 and wgpu 27, and the viewer is on egui 0.37 and
//! wgpu 30; the graph below reads the same puffin frames.

use hush_engine::profile::{Capture, puffin};
use std::path::PathBuf;

pub struct Profiler {
    pub open: bool,
    /// Frames a capture collects.
    pub capture_frames: usize,
    capture: Option<(Capture, PathBuf)>,
    view: Option<puffin::GlobalFrameView>,
    _server: Option<puffin_http::Server>,
    pub message: String,
}

impl Profiler {
    /// `http`: also serve frames to puffin_viewer on 127.0.0.1:`port`.
    pub fn new(http: Option<u16>) -> anyhow::Result<Profiler> {
        let server = match http {
            Some(port) => {
                let addr = format!("127.0.0.1:{port}");
                let s = puffin_http::Server::new(&addr)
                    .map_err(|e| anyhow::anyhow!("starting the puffin server on {addr}: {e}"))?;
                log::warn!("puffin server on {addr} (connect with puffin_viewer --url {addr})");
                Some(s)
            }
            None => None,
        };
        let mut p = Profiler {
            open: false,
            capture_frames: 60,
            capture: None,
            view: None,
            _server: server,
            message: String::new(),
        };
        p.update_scopes();
        Ok(p)
    }

    /// Scopes are on only while something reads them (they cost little, but not nothing).
    fn update_scopes(&mut self) {
        let on = self.open || self.capture.is_some() || self._server.is_some();
        puffin::set_scopes_on(on);
        if self.open && self.view.is_none() {
            self.view = Some(puffin::GlobalFrameView::default());
        }
        if !self.open {
            self.view = None;
        }
    }

    pub fn toggle(&mut self) {
        self.open = !self.open;
        self.update_scopes();
    }

    /// Start capturing the next `capture_frames` frames to `hush_<time>.puffin`.
    pub fn start_capture(&mut self, stamp: u64) {
        if self.capture.is_some() {
            return;
        }
        let path = PathBuf::from(format!("hush_{stamp}.puffin"));
        self.capture = Some((Capture::start(self.capture_frames), path));
        self.message = format!("capturing {} frames", self.capture_frames);
        self.update_scopes();
    }

    /// Call after each frame was closed; writes a finished capture.
    pub fn after_frame(&mut self) {
        if self.capture.as_ref().is_some_and(|(c, _)| c.done()) {
            let (c, path) = self.capture.take().unwrap();
            self.message = match c.write(&path) {
                Ok(n) => format!("wrote {n} frames to {}", path.display()),
                Err(e) => format!("{e:#}"),
            };
            self.update_scopes();
        }
    }

    pub fn capturing(&self) -> Option<usize> {
        self.capture.as_ref().map(|(c, _)| c.captured())
    }

    pub fn window(&mut self, ctx: &egui::Context) {
        let mut open = self.open;
        egui::Window::new("profiler").open(&mut open).default_width(640.0).show(ctx, |ui| {
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut self.capture_frames).range(1..=10_000));
                ui.label("frames");
                if ui.button("capture (F10)").clicked() {
                    self.start_capture(crate::unix_seconds());
                }
                if let Some(n) = self.capturing() {
                    ui.label(format!("{n}/{}", self.capture_frames));
                }
            });
            if !self.message.is_empty() {
                ui.label(&self.message);
            }
            if let Some(view) = &self.view {
                flame_graph(ui, &view.lock());
            }
        });
        if open != self.open {
            self.toggle();
        }
    }
}

/// Rows of scopes per timeline, left to right in time, for the latest frame.
fn flame_graph(ui: &mut egui::Ui, view: &puffin::FrameView) {
    let Some(frame) = view.latest_frame() else {
        ui.label("no frame yet");
        return;
    };
    let Ok(unpacked) = frame.unpacked() else { return };
    let (t0, t1) = frame.range_ns();
    let span = (t1 - t0).max(1) as f32;
    ui.label(format!("frame {} : {:.2} ms", frame.frame_index(), span * 1e-6));
    let names = view.scope_collection();
    const ROW: f32 = 16.0;
    for (thread, info) in &unpacked.thread_streams {
        ui.label(egui::RichText::new(&thread.name).strong());
        let height = ROW * info.depth.max(1) as f32;
        let (rect, _) =
            ui.allocate_exact_size(egui::vec2(ui.available_width(), height), egui::Sense::hover());
        let painter = ui.painter_at(rect);
        let x = |ns: i64| rect.left() + rect.width() * ((ns - t0) as f32 / span);
        let mut stack = vec![];
        if let Ok(top) = puffin::Reader::from_start(&info.stream).read_top_scopes() {
            stack.extend(top.into_iter().map(|s| (s, 0usize)));
        }
        let pointer = ui.ctx().pointer_hover_pos();
        while let Some((s, depth)) = stack.pop() {
            let r = egui::Rect::from_min_max(
                egui::pos2(x(s.record.start_ns), rect.top() + depth as f32 * ROW),
                egui::pos2(
                    x(s.record.stop_ns()).max(x(s.record.start_ns) + 1.0),
                    rect.top() + (depth + 1) as f32 * ROW - 1.0,
                ),
            );
            let name = names.fetch_by_id(&s.id).map_or("?".to_string(), |d| d.name().to_string());
            let hue = (name.bytes().fold(0u32, |h, b| h.wrapping_mul(31).wrapping_add(b as u32))
                % 360) as f32
                / 360.0;
            painter.rect_filled(r, 2.0, egui::ecolor::Hsva::new(hue, 0.45, 0.75, 1.0));
            let ms = s.record.duration_ns as f64 * 1e-6;
            if r.width() > 40.0 {
                painter.with_clip_rect(r).text(
                    r.left_center() + egui::vec2(2.0, 0.0),
                    egui::Align2::LEFT_CENTER,
                    format!("{name} {ms:.2}"),
                    egui::FontId::monospace(10.0),
                    egui::Color32::BLACK,
                );
            }
            if pointer.is_some_and(|p| r.contains(p)) {
                egui::Tooltip::always_open(
                    ui.ctx().clone(),
                    ui.layer_id(),
                    egui::Id::unique("hush profiler scope tip"),
                    egui::PopupAnchor::Pointer,
                )
                .show(|ui| ui.label(format!("{}: {name}, {ms:.3} ms", thread.name)));
            }
            if let Ok(children) = puffin::Reader::with_offset(&info.stream, s.child_begin_position)
            {
                stack.extend(children.flatten().map(|c| (c, depth + 1)));
            }
        }
    }
}
