//! GPU time per pass from timestamp queries: each pass writes a begin and an end timestamp; the
//! frame resolves them into one buffer that is read back after the frame.

use super::Gpu;
use crate::profile::PassSpan;
use anyhow::{Result, anyhow};

pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    capacity: u32,
    labels: Vec<&'static str>,
    period_ns: f64,
    /// puffin's clock when the frame was submitted (where its GPU timeline starts).
    pub submitted_ns: i64,
}

impl GpuTimer {
    /// None when the device was created without TIMESTAMP_QUERY.
    pub fn new(gpu: &Gpu, passes: u32) -> Option<GpuTimer> {
        if !gpu.timestamps {
            return None;
        }
        let capacity = passes * 2;
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("pass timestamps"), ty: wgpu::QueryType::Timestamp, count: capacity });
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass timestamps"),
            size: capacity as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(GpuTimer { set, resolve, capacity, labels: vec![], period_ns: gpu.queue.get_timestamp_period() as f64, submitted_ns: 0 })
    }

    pub fn begin_frame(&mut self) {
        self.labels.clear();
    }

    fn next(&mut self, label: &'static str) -> Option<u32> {
        let i = self.labels.len() as u32 * 2;
        if i + 2 > self.capacity {
            return None;
        }
        self.labels.push(label);
        Some(i)
    }

    pub fn compute(&mut self, label: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let i = self.next(label)?;
        Some(wgpu::ComputePassTimestampWrites { query_set: &self.set, beginning_of_pass_write_index: Some(i), end_of_pass_write_index: Some(i + 1) })
    }

    pub fn render(&mut self, label: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let i = self.next(label)?;
        Some(wgpu::RenderPassTimestampWrites { query_set: &self.set, beginning_of_pass_write_index: Some(i), end_of_pass_write_index: Some(i + 1) })
    }

    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        let n = self.labels.len() as u32 * 2;
        if n > 0 {
            enc.resolve_query_set(&self.set, 0..n, &self.resolve, 0);
        }
    }

    /// (pass, milliseconds) of the last resolved frame; blocks until the GPU is done with it.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<(&'static str, f64)>> {
        Ok(self.read_spans(gpu)?.into_iter().map(|s| (s.label, s.ms)).collect())
    }

    /// Each pass of the last resolved frame with its start after the frame's first timestamp.
    pub fn read_spans(&self, gpu: &Gpu) -> Result<Vec<PassSpan>> {
        let n = self.labels.len() as u64 * 2;
        if n == 0 {
            return Ok(vec![]);
        }
        let bytes = super::readback_buffer(&gpu.device, &gpu.queue, &self.resolve, n * 8)?;
        let t: &[u64] = bytemuck::cast_slice(&bytes);
        let first = t.iter().step_by(2).copied().min().unwrap_or(0);
        let ms = |ticks: u64| ticks as f64 * self.period_ns * 1e-6;
        let mut out = vec![];
        for (k, label) in self.labels.iter().enumerate() {
            let (a, b) = (t[2 * k], t[2 * k + 1]);
            if b < a {
                return Err(anyhow!("timestamps of {label} run backwards ({a} > {b})"));
            }
            out.push(PassSpan { label, start_ms: ms(a - first), ms: ms(b - a) });
        }
        Ok(out)
    }
}
