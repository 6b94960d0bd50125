//! Per-frame profiling with puffin. CPU work is marked with scopes (the frame's phases and one
//! per pass); the GPU's passes, measured with timestamp queries, are reported as a second
//! timeline named "GPU" in the same frame, so a capture shows both. GPU timestamps live in
//! another clock: the GPU timeline starts where the CPU submitted the frame, and each pass keeps
//! its measured offset and duration from the first timestamp.
//!
//! Scopes cost nothing measurable while off (`puffin::are_scopes_on`); they are turned on by
//! a capture, the viewer's profiler window or `--profile`.

pub use puffin;

use anyhow::{Context, Result};
use puffin::{
    FrameData, FrameSinkId, FrameView, GlobalProfiler, ScopeDetails, ScopeId, StreamInfo,
    ThreadInfo,
};
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

/// Name of the GPU timeline in captures.
pub const GPU_THREAD: &str = "GPU";
/// The scope that spans one frame's GPU work; the passes are its children.
pub const GPU_FRAME: &str = "gpu frame";

/// One pass of a frame on the GPU: when it began after the frame's first timestamp, and for how
/// long it ran.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSpan {
    pub label: &'static str,
    pub start_ms: f64,
    pub ms: f64,
}

/// GPU milliseconds per label, summed over the frame's passes of that label (an a-trous stage
/// runs one pass per level under one label), in the order the labels first ran.
pub fn per_label(spans: &[PassSpan]) -> Vec<(&'static str, f64)> {
    let mut out: Vec<(&'static str, f64)> = vec![];
    for s in spans {
        match out.iter_mut().find(|p| p.0 == s.label) {
            Some(p) => p.1 += s.ms,
            None => out.push((s.label, s.ms)),
        }
    }
    out
}

/// A CPU scope named `label` (puffin's macros take one name per call site; passes share a call
/// site, so their ids are registered here by name).
pub fn scope(label: &'static str) -> Option<puffin::ProfilerScope> {
    if !puffin::are_scopes_on() {
        return None;
    }
    static IDS: OnceLock<Mutex<HashMap<&'static str, ScopeId>>> = OnceLock::new();
    let id =
        *crate::sync::lock(IDS.get_or_init(Default::default)).entry(label).or_insert_with(|| {
            puffin::ThreadProfiler::call(|tp| tp.register_named_scope(label, "pass", "hush", 0))
        });
    Some(puffin::ProfilerScope::new(id, ""))
}

/// Report a frame's GPU passes as the "GPU" timeline of the current puffin frame, starting at
/// `submit_ns` (puffin's clock).
pub fn report_gpu(submit_ns: i64, spans: &[PassSpan]) {
    if !puffin::are_scopes_on() || spans.is_empty() {
        return;
    }
    let mut details = vec![ScopeDetails::from_scope_name(GPU_FRAME)];
    details.extend(
        spans.iter().map(|s| ScopeDetails::from_scope_name(s.label).with_function_name("gpu pass")),
    );
    let mut profiler = GlobalProfiler::lock();
    let ids = profiler.register_user_scopes(&details);
    let ns = |ms: f64| (ms * 1e6).round() as i64;
    let end = submit_ns + spans.iter().map(|s| ns(s.start_ms + s.ms)).max().unwrap_or(0).max(1);
    let mut stream = puffin::Stream::default();
    let (frame, _) = stream.begin_scope(|| submit_ns, ids[0], "");
    for (s, id) in spans.iter().zip(&ids[1..]) {
        let start = submit_ns + ns(s.start_ms);
        let (offset, _) = stream.begin_scope(|| start, *id, "");
        stream.end_scope(offset, start + ns(s.ms).max(1));
    }
    stream.end_scope(frame, end);
    let info =
        StreamInfo { stream, num_scopes: spans.len() + 1, depth: 2, range_ns: (submit_ns, end) };
    profiler.report_user_scopes(
        ThreadInfo { start_time_ns: None, name: GPU_THREAD.into() },
        &info.as_stream_into_ref(),
    );
}

/// Close the current puffin frame (call once per rendered frame, after its scopes ended).
pub fn end_frame() {
    if puffin::are_scopes_on() {
        GlobalProfiler::lock().new_frame();
    }
}

/// Collects the next `frames` puffin frames for a `.puffin` file (opened by puffin_viewer).
pub struct Capture {
    frames: Arc<Mutex<Vec<Arc<FrameData>>>>,
    sink: FrameSinkId,
    want: usize,
}

impl Capture {
    /// Turn scopes on and start collecting.
    pub fn start(frames: usize) -> Capture {
        puffin::set_scopes_on(true);
        let collected = Arc::new(Mutex::new(vec![]));
        let c = collected.clone();
        let mut profiler = GlobalProfiler::lock();
        let sink = profiler.add_sink(Box::new(move |f| crate::sync::lock(&c).push(f)));
        // The first collected frame then carries every scope's name, so the file stands alone.
        profiler.emit_scope_snapshot();
        Capture { frames: collected, sink, want: frames.max(1) }
    }

    pub fn captured(&self) -> usize {
        crate::sync::lock(&self.frames).len().min(self.want)
    }

    pub fn done(&self) -> bool {
        self.captured() >= self.want
    }

    /// Stop collecting and write what was captured; returns the number of frames written.
    pub fn write(self, path: &Path) -> Result<usize> {
        GlobalProfiler::lock().remove_sink(self.sink);
        let frames = crate::sync::lock(&self.frames);
        let mut view = FrameView::default();
        view.set_max_recent(usize::MAX);
        for f in frames.iter().take(self.want) {
            view.add_frame(f.clone());
        }
        let file =
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let mut w = std::io::BufWriter::new(file);
        view.write(&mut w).with_context(|| format!("writing the profile {}", path.display()))?;
        Ok(frames.len().min(self.want))
    }
}

/// Every scope of a `.puffin` file: (timeline, scope name, total ns over all frames, count).
pub fn read_capture(path: &Path) -> Result<Vec<(String, String, i64, usize)>> {
    let mut file = std::io::BufReader::new(
        std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?,
    );
    let view = FrameView::read(&mut file)
        .with_context(|| format!("reading the profile {}", path.display()))?;
    let names = view.scope_collection();
    let mut totals: HashMap<(String, String), (i64, usize)> = HashMap::new();
    for frame in view.recent_frames() {
        let unpacked = frame.unpacked().map_err(|e| anyhow::anyhow!("{e}"))?;
        for (thread, info) in &unpacked.thread_streams {
            let mut stack = puffin::Reader::from_start(&info.stream)
                .read_top_scopes()
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            while let Some(s) = stack.pop() {
                let name = names
                    .fetch_by_id(&s.id)
                    .map_or(format!("{:?}", s.id), |d| d.name().to_string());
                let t = totals.entry((thread.name.clone(), name)).or_default();
                t.0 += s.record.duration_ns;
                t.1 += 1;
                let children = puffin::Reader::with_offset(&info.stream, s.child_begin_position)
                    .map_err(|e| anyhow::anyhow!("{e:?}"))?;
                for c in children {
                    let c = c.map_err(|e| anyhow::anyhow!("{e:?}"))?;
                    stack.push(c);
                }
            }
        }
    }
    let mut v: Vec<_> = totals.into_iter().map(|((t, n), (ns, k))| (t, n, ns, k)).collect();
    v.sort();
    Ok(v)
}
