//! GPU time per pass from timestamp queries: each pass writes a begin and an end timestamp; the
//! frame resolves them into one buffer. Benchmarks and tests read it back after the frame
//! (blocking); the viewer instead copies it into a small ring of mappable buffers and picks the
//! times up a frame or two later, so reading them never stalls the CPU on the GPU.

use super::Gpu;
use crate::profile::PassSpan;
use anyhow::{Result, anyhow};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    capacity: u32,
    labels: Vec<&'static str>,
    /// Passes of this frame that found the query set full.
    dropped: u32,
    period_ns: f64,
    /// puffin's clock when the frame was submitted (where its GPU timeline starts).
    pub submitted_ns: i64,
    ring: Vec<Slot>,
    /// The ring slot the frame being recorded copies into, if one was free.
    copying: Option<usize>,
}

/// Frames in flight the viewer's non-blocking readback keeps.
const RING: usize = 3;

struct Slot {
    buffer: wgpu::Buffer,
    labels: Vec<&'static str>,
    submitted_ns: i64,
    /// None: free. Some(flag): mapping requested; the flag is set once it completed.
    mapped: Option<Arc<AtomicBool>>,
}

impl GpuTimer {
    /// None when the device was created without TIMESTAMP_QUERY.
    pub fn new(gpu: &Gpu, passes: u32) -> Option<GpuTimer> {
        if !gpu.timestamps {
            return None;
        }
        let capacity = passes * 2;
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: capacity,
        });
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass timestamps"),
            size: capacity as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(GpuTimer {
            set,
            resolve,
            capacity,
            labels: vec![],
            dropped: 0,
            period_ns: gpu.queue.get_timestamp_period() as f64,
            submitted_ns: 0,
            ring: vec![],
            copying: None,
        })
    }

    pub fn begin_frame(&mut self) {
        self.labels.clear();
        self.dropped = 0;
    }

    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    fn next(&mut self, label: &'static str) -> Option<u32> {
        let i = self.labels.len() as u32 * 2;
        if i + 2 > self.capacity {
            self.dropped += 1;
            return None;
        }
        self.labels.push(label);
        Some(i)
    }

    pub fn compute(&mut self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let i = self.next(label)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    pub fn render(&mut self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let i = self.next(label)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        })
    }

    /// Resolve the frame's timestamps; with `ring`, also copy them into a free ring slot for
    /// [`GpuTimer::poll`] (a frame finds none free when the GPU is three frames behind).
    pub fn resolve(&mut self, device: &wgpu::Device, enc: &mut wgpu::CommandEncoder, ring: bool) {
        let n = self.labels.len() as u32 * 2;
        self.copying = None;
        if n == 0 {
            return;
        }
        enc.resolve_query_set(&self.set, 0..n, &self.resolve, 0);
        if !ring {
            return;
        }
        if self.ring.is_empty() {
            self.ring = (0..RING)
                .map(|_| Slot {
                    buffer: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("pass timestamps readback"),
                        size: self.capacity as u64 * 8,
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    }),
                    labels: vec![],
                    submitted_ns: 0,
                    mapped: None,
                })
                .collect();
        }
        if let Some(i) = self.ring.iter().position(|s| s.mapped.is_none()) {
            enc.copy_buffer_to_buffer(&self.resolve, 0, &self.ring[i].buffer, 0, n as u64 * 8);
            self.copying = Some(i);
        }
    }

    /// After the frame was submitted: ask for the ring slot it copied into to be mapped.
    pub fn submitted(&mut self) {
        let Some(i) = self.copying.take() else { return };
        let slot = &mut self.ring[i];
        slot.labels = self.labels.clone();
        slot.submitted_ns = self.submitted_ns;
        let done = Arc::new(AtomicBool::new(false));
        let flag = done.clone();
        slot.buffer
            .slice(..slot.labels.len() as u64 * 16)
            .map_async(wgpu::MapMode::Read, move |r| flag.store(r.is_ok(), Ordering::Release));
        slot.mapped = Some(done);
    }

    /// The oldest finished frame's passes and its submit time, without waiting; None while
    /// no frame has finished since the last call.
    pub fn poll(&mut self, gpu: &Gpu) -> Option<(i64, Vec<PassSpan>)> {
        let _ = gpu.device.poll(wgpu::PollType::Poll);
        let i = self
            .ring
            .iter()
            .enumerate()
            .filter(|(_, s)| s.mapped.as_ref().is_some_and(|f| f.load(Ordering::Acquire)))
            .min_by_key(|(_, s)| s.submitted_ns)
            .map(|(i, _)| i)?;
        let slot = &mut self.ring[i];
        let n = slot.labels.len() as u64 * 16;
        let period_ns = self.period_ns;
        let spans = slot
            .buffer
            .slice(..n)
            .get_mapped_range()
            .ok()
            .map(|data| spans(period_ns, &slot.labels, bytemuck::cast_slice(&data)));
        slot.buffer.unmap();
        slot.mapped = None;
        Some((slot.submitted_ns, spans?.ok()?))
    }

    /// Each pass of the last resolved frame with its start after the frame's first timestamp;
    /// blocks until the GPU is done with it.
    pub fn read_spans(&self, gpu: &Gpu) -> Result<Vec<PassSpan>> {
        let n = self.labels.len() as u64 * 2;
        if n == 0 {
            return Ok(vec![]);
        }
        let bytes = super::readback_buffer(&gpu.device, &gpu.queue, &self.resolve, n * 8)?;
        spans(self.period_ns, &self.labels, bytemuck::cast_slice(&bytes))
    }
}

/// Each pass's start after the first timestamp and its duration, from (begin, end) ticks.
fn spans(period_ns: f64, labels: &[&'static str], t: &[u64]) -> Result<Vec<PassSpan>> {
    let first = t.iter().step_by(2).copied().min().unwrap_or(0);
    let ms = |ticks: u64| ticks as f64 * period_ns * 1e-6;
    let mut out = vec![];
    for (k, label) in labels.iter().enumerate() {
        let (a, b) = (t[2 * k], t[2 * k + 1]);
        if b < a {
            return Err(anyhow!("timestamps of {label} run backwards ({a} > {b})"));
        }
        out.push(PassSpan { label, start_ms: ms(a - first), ms: ms(b - a) });
    }
    Ok(out)
}
