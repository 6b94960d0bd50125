//! Time to quality: a stream's error against wall-clock time, as a person watching it sees it.
//! A frame is on screen from the moment it finishes until the next one finishes; before the
//! first frame of a view the screen still shows what came before (the last frame of the
//! previous view after a cut, the last frame rendered while the camera moved before a stop).
//! So a slow frame is charged the old image's error for as long as it takes, which a
//! per-frame score hides.

/// The scores of the frames rendered since the camera stopped, with the time each finished.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timeline {
    /// The score of what the screen showed when the camera stopped (t = 0).
    pub before: f64,
    /// (seconds since the stop at which the frame finished, its score), in order.
    pub frames: Vec<(f64, f64)>,
}

impl Timeline {
    pub fn new(before: f64) -> Timeline {
        Timeline { before, frames: vec![] }
    }

    /// Record a frame that finished `end_s` seconds after the stop (not before the last one).
    pub fn push(&mut self, end_s: f64, score: f64) {
        let last = self.frames.last().map_or(0.0, |f| f.0);
        self.frames.push((end_s.max(last), score));
    }

    /// The score of the image on screen `t` seconds after the stop: the last frame finished
    /// by then, else the image from before.
    pub fn shown_at(&self, t: f64) -> f64 {
        let finished = self.frames.partition_point(|f| f.0 <= t);
        if finished == 0 { self.before } else { self.frames[finished - 1].1 }
    }

    /// Seconds the timeline covers (when its last frame finished).
    pub fn span(&self) -> f64 {
        self.frames.last().map_or(0.0, |f| f.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_screen_holds_each_frame_until_the_next() {
        let mut t = Timeline::new(0.9);
        t.push(0.4, 0.5);
        t.push(1.2, 0.3);
        t.push(1.3, 0.2);
        assert_eq!(t.shown_at(0.0), 0.9);
        assert_eq!(t.shown_at(0.39), 0.9);
        assert_eq!(t.shown_at(0.4), 0.5);
        assert_eq!(t.shown_at(1.0), 0.5);
        assert_eq!(t.shown_at(1.25), 0.3);
        assert_eq!(t.shown_at(5.0), 0.2);
        assert_eq!(t.span(), 1.3);
    }

    #[test]
    fn a_frame_never_finishes_before_the_last() {
        let mut t = Timeline::new(1.0);
        t.push(0.5, 0.4);
        t.push(0.2, 0.1);
        assert_eq!(t.frames[1].0, 0.5);
        assert_eq!(t.shown_at(0.3), 1.0);
        assert_eq!(t.shown_at(0.5), 0.1);
    }
}
