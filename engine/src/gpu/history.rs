//! Histories that trade places with the frame, in the manner of kajiya's
//! `PingPongTemporalResource`: a temporal stage reads what the last frame wrote and writes what
//! the next frame will read, and no caller indexes the pair by hand.

/// A texture and its view, as [`crate::gpu::GpuMemory::texture`] makes them.
pub type Tex = (wgpu::Texture, wgpu::TextureView);

/// Which way round this frame's histories are: the frame index's parity. A stage makes its bind
/// groups once for each of [`Parity::BOTH`] and the frame picks one, so a history swaps without
/// remaking anything.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Parity(bool);

impl Parity {
    pub const BOTH: [Parity; 2] = [Parity(false), Parity(true)];

    /// The parity of frame `index`.
    pub fn of_frame(index: u32) -> Parity {
        Parity(index % 2 == 1)
    }

    /// 0 or 1: the bind-group variant of this parity.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Two slots that trade places every frame: the history (what the last frame wrote) and the
/// output (what this frame writes, the next frame's history).
pub struct PingPong<T> {
    slots: [T; 2],
}

impl<T> PingPong<T> {
    /// `make(i)` makes slot i (its label may carry i: the slots are separate allocations).
    pub fn new(mut make: impl FnMut(usize) -> T) -> PingPong<T> {
        let first = make(0);
        PingPong { slots: [first, make(1)] }
    }

    /// What the last frame wrote: this frame's history.
    pub fn history(&self, p: Parity) -> &T {
        &self.slots[p.index()]
    }

    /// What this frame writes: the next frame's history.
    pub fn output(&self, p: Parity) -> &T {
        &self.slots[1 - p.index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_frames_output_is_the_next_frames_history() {
        let h = PingPong::new(|i| i);
        for frame in 0..4u32 {
            let (now, next) = (Parity::of_frame(frame), Parity::of_frame(frame + 1));
            assert_eq!(h.output(now), h.history(next));
            assert_ne!(h.output(now), h.history(now));
        }
    }
}
