//! The governor against modelled devices: what it chooses, how fast it follows a change of
//! load, and what a still view makes it do.

use super::*;

/// A device whose frame costs `fixed + area * (rest + trace f)` ms, of which its passes'
/// timestamps show the scaled part.
fn run_fixed(
    g: &mut Governor,
    (fixed, rest, trace): (f64, f64, f64),
    frames: usize,
    moving: bool,
) -> Vec<(Choice, f64)> {
    run_filtered(g, (fixed, rest, 0.0, trace), frames, moving)
}

/// As [`run_fixed`], with a filter of `g.filter_levels` a-trous levels that each cost
/// `area * level` ms, of which a frame runs the choice's.
fn run_filtered(
    g: &mut Governor,
    (fixed, rest, level, trace): (f64, f64, f64, f64),
    frames: usize,
    moving: bool,
) -> Vec<(Choice, f64)> {
    let mut out = vec![];
    for _ in 0..frames {
        let c = g.choice();
        let area = (c.scale * c.scale) as f64;
        let t = area * trace / c.fraction.period() as f64;
        let filter = area * level * c.levels.min(g.filter_levels) as f64;
        let scaled = area * rest + filter + t;
        let wall = fixed + scaled;
        out.push((c, wall));
        g.record(FrameCost {
            wall_ms: wall,
            trace_ms: t,
            scaled_ms: scaled,
            filter_ms: filter,
            choice: c,
            moving,
        });
    }
    out
}

/// A device whose whole frame scales: `area * (rest + trace f)` ms.
fn run(g: &mut Governor, rest: f64, trace: f64, frames: usize, moving: bool) -> Vec<(Choice, f64)> {
    run_fixed(g, (0.0, rest, trace), frames, moving)
}

#[test]
fn holds_the_target_and_keeps_an_eighth_when_still() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    // A still view held to the target, as a moving one is.
    g.still_ratio = 1.0;
    // Full frame: 60 ms of raster/denoise/display, 1200 ms of trace.
    let frames = run(&mut g, 60.0, 1200.0, 20, false);
    let (c, t) = frames.last().copied().unwrap();
    assert!(t <= 100.0, "{c:?} takes {t} ms");
    // 1/8 fits at 0.625 (0.39 x (60 + 150) = 82 ms), not at 0.75 (118 ms); 1/4 fits nowhere
    // above that (0.625: 141 ms). Full scale would fit only at 1/32.
    assert_eq!((c.scale, c.fraction.period()), (0.625, 8), "{c:?}");
    // The first frame is over (nothing known yet); from the second on every frame fits.
    assert!(frames[1..].iter().all(|(_, t)| *t <= 100.0), "{frames:?}");
    // Where nothing fits at 1/8 even at the smallest scale, smaller fractions are taken.
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    g.still_ratio = 1.0;
    let (c, t) = run(&mut g, 60.0, 40000.0, 20, false).last().copied().unwrap();
    assert!(t <= 100.0 && c.fraction.period() > 8, "{c:?} {t}");
}

#[test]
fn a_moving_camera_keeps_fresh_samples() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    let (c, t) = run(&mut g, 60.0, 1200.0, 20, true).last().copied().unwrap();
    assert!(t <= 100.0 && c.fraction.period() <= 4 && c.scale < 1.0, "{c:?} {t}");
}

#[test]
fn without_fractions_only_the_scale_moves() {
    let mut g = Governor::new(100.0);
    // A still view that could rise would leave the target (tested below).
    g.keeps_history = false;
    let (c, t) = run(&mut g, 60.0, 300.0, 10, false).last().copied().unwrap();
    assert_eq!(c.fraction, SampleFraction::ONE);
    // 360 ms at full scale: 0.5^2 * 360 = 90 fits, 0.625^2 * 360 = 141 does not.
    assert_eq!(c.scale, 0.5, "{c:?} {t}");
}

#[test]
fn one_slow_frame_changes_nothing_a_lasting_load_is_followed() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    g.still_ratio = 1.0;
    run(&mut g, 60.0, 1200.0, 20, false);
    let settled = g.choice();
    // One frame ten times slower (a hitch).
    let c = g.choice();
    g.record(FrameCost {
        wall_ms: 1000.0,
        trace_ms: 400.0,
        scaled_ms: 1000.0,
        filter_ms: 0.0,
        choice: c,
        moving: false,
    });
    assert_eq!(g.choice(), settled, "one hitch moved the choice");
    let after = run(&mut g, 60.0, 1200.0, 5, false);
    assert!(after.iter().all(|(c, _)| *c == settled));
    // The device becomes twice as slow for good: within three frames the frames fit again.
    let slow = run(&mut g, 120.0, 2400.0, 8, false);
    let first_fit = slow.iter().position(|(_, t)| *t <= 100.0).expect("never fits again");
    assert!(first_fit <= 3, "{slow:?}");
    assert!(slow[first_fit..].iter().all(|(_, t)| *t <= 100.0), "{slow:?}");
}

#[test]
fn a_cut_to_a_heavier_view_is_followed_after_two_frames() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    run(&mut g, 30.0, 300.0, 20, false);
    // The new view costs four times as much; the median of five would take three frames.
    let after = run(&mut g, 120.0, 1200.0, 6, true);
    assert!(after[0].1 > 150.0 && after[1].1 > 150.0, "{after:?}");
    assert!(after[2..].iter().all(|(_, t)| *t <= 100.0), "{after:?}");
}

#[test]
fn a_slow_first_frame_does_not_hold_a_still_view_at_a_small_scale() {
    for keeps_history in [true, false] {
        let mut g = Governor::new(100.0);
        g.keeps_history = keeps_history;
        // The first frame compiles its shaders: 20 times its later cost.
        let c = g.choice();
        g.record(FrameCost {
            wall_ms: 1200.0,
            trace_ms: 0.0,
            scaled_ms: 0.0,
            filter_ms: 0.0,
            choice: c,
            moving: false,
        });
        assert!(g.choice().scale < 0.5);
        // Resampled: a step each STILL_RISE_SAMPLES frames, six steps from 0.25. Restarted:
        // the young scale rises at once after RISE_FRAMES frames with room.
        let frames = run(&mut g, 60.0, 0.0, 30, false);
        assert_eq!(frames.last().unwrap().0.scale, 1.0, "{keeps_history} {frames:?}");
    }
}

#[test]
fn the_scale_rises_only_after_lasting_room() {
    let mut g = Governor::new(100.0);
    // Histories restart at a change of scale.
    g.keeps_history = false;
    run(&mut g, 60.0, 300.0, 10, false);
    assert_eq!(g.choice().scale, 0.5);
    // The load halves: a settled still view keeps its scale (a rise would restart the
    // history).
    run(&mut g, 60.0, 300.0, YOUNG_FRAMES as usize, false);
    let still = run(&mut g, 30.0, 150.0, 20, false);
    assert!(still.iter().all(|(c, _)| c.scale == 0.5), "{still:?}");
    // Once it moves, the scale rises, but not before RISE_FRAMES frames.
    let frames = run(&mut g, 30.0, 150.0, 20, true);
    let rose = frames.iter().position(|(c, _)| c.scale > 0.5).expect("never rose");
    assert!(rose >= RISE_FRAMES as usize, "rose after {rose} frames");
    assert!(frames.iter().all(|(_, t)| *t <= 100.0));
}

#[test]
fn a_still_view_rises_a_step_each_time_its_pixels_gather_their_samples() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    // Full frame 60 ms + 300 ms of trace at f = 1: moving, 0.75 at f = 1/4 (76 ms) holds
    // the target.
    let moving = run(&mut g, 60.0, 300.0, 10, true);
    let start = moving.last().unwrap().0.scale;
    assert_eq!(start, 0.75, "{moving:?}");
    // Still: a step up once the pixels hold STILL_RISE_SAMPLES at a scale, each at the
    // fraction with the most samples per second within 5x the target, up to full scale
    // (360 ms at f = 1).
    let still = run(&mut g, 60.0, 300.0, 60, false);
    assert!(still.iter().all(|(_, t)| *t <= 500.0), "{still:?}");
    let scales: Vec<f32> = still.iter().map(|(c, _)| c.scale).collect();
    assert!(scales.windows(2).all(|w| w[1] >= w[0]), "{scales:?}");
    assert_eq!(*scales.last().unwrap(), 1.0, "{still:?}");
    // The moving frames' samples at the scale count too.
    let at_start = moving.iter().rev().take_while(|(c, _)| c.scale == start);
    let mut samples: f64 = at_start.map(|(c, _)| 1.0 / c.fraction.period() as f64).sum();
    for w in still.windows(2) {
        samples += 1.0 / w[0].0.fraction.period() as f64;
        if w[1].0.scale > w[0].0.scale {
            assert!(samples >= STILL_RISE_SAMPLES, "rose after {samples} samples: {still:?}");
            samples = 0.0;
        }
    }
    // A move brings the target back at once.
    let (c, t) = run(&mut g, 60.0, 300.0, 2, true)[1];
    assert!(t <= 100.0, "{c:?} {t}");
    // Without resampled histories the still view keeps its scale.
    let mut g = Governor::new(100.0);
    (g.fractions_allowed, g.keeps_history) = (true, false);
    run(&mut g, 60.0, 300.0, 10, true);
    let still = run(&mut g, 60.0, 300.0, 60, false);
    assert!(still.iter().all(|(c, _)| c.scale == start), "{still:?}");
}

#[test]
fn a_still_view_that_outgrows_its_limit_steps_down_only_as_far_as_it_must() {
    // Scale alone (Mara, SVGF): 360 ms a full frame, so a still view rises to full scale.
    let mut g = Governor::new(100.0);
    run(&mut g, 60.0, 300.0, 10, true);
    let still = run(&mut g, 60.0, 300.0, 60, false);
    assert_eq!(still.last().unwrap().0.scale, 1.0, "{still:?}");
    // The view gets 60% heavier (576 ms at full scale, over the 500 ms still limit):
    // 0.875 fits (441 ms). The moving target's choice would be 0.375 (81 ms).
    let heavier = run(&mut g, 96.0, 480.0, 12, false);
    let scales: Vec<f32> = heavier.iter().map(|(c, _)| c.scale).collect();
    assert!(scales.iter().all(|&s| s >= 0.875), "{heavier:?}");
    assert_eq!(*scales.last().unwrap(), 0.875, "{heavier:?}");
    let mut after = heavier.iter().skip_while(|(c, _)| c.scale == 1.0);
    assert!(after.all(|(_, t)| *t <= 500.0), "{heavier:?}");
    // With sample fractions the still view keeps its scale and takes a smaller fraction.
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    run(&mut g, 60.0, 300.0, 10, true);
    run(&mut g, 60.0, 300.0, 60, false);
    let heavier = run(&mut g, 96.0, 480.0, 12, false);
    let (c, t) = *heavier.last().unwrap();
    assert!(c.scale == 1.0 && t <= 500.0, "{heavier:?}");
}

#[test]
fn filter_levels_are_turned_down_only_where_nothing_else_fits() {
    // Scale pinned at 1, every pixel (SVGF): 40 ms of raster and the rest, 25 of trace and
    // 10 a level of the filter's 5: 115 ms against a 100 ms target. Three levels fit (95).
    let mut g = Governor::new(100.0);
    (g.pinned_scale, g.filter_levels) = (Some(1.0), 5);
    let frames = run_filtered(&mut g, (0.0, 40.0, 10.0, 25.0), 12, true);
    let (c, t) = *frames.last().unwrap();
    assert_eq!((c.scale, c.levels), (1.0, 3), "{frames:?}");
    assert!(frames[1..].iter().all(|(_, t)| *t <= 100.0), "{frames:?}");
    assert!(t > 90.0, "{c:?} {t}: no more levels were dropped than needed");
    // A lighter load brings every level back.
    let frames = run_filtered(&mut g, (0.0, 30.0, 10.0, 15.0), 6, true);
    assert_eq!(frames.last().unwrap().0.levels, ALL_LEVELS, "{frames:?}");
    // Where the scale is free, it is the scale that gives way (0.875: 88 ms).
    let mut g = Governor::new(100.0);
    g.filter_levels = 5;
    let frames = run_filtered(&mut g, (0.0, 40.0, 10.0, 25.0), 12, true);
    let (c, t) = *frames.last().unwrap();
    assert!(c.levels == ALL_LEVELS && c.scale == 0.875 && t <= 100.0, "{frames:?}");
    // Below one sample per pixel the levels keep reaching across the fraction's tile: at
    // 1/16 (4x4 pixels) three (steps 1, 2 and 4) however far over the target.
    let mut g = Governor::new(100.0);
    g.pinned_scale = Some(1.0);
    g.pinned_fraction = Some(SampleFraction::one_in(16).unwrap());
    (g.fractions_allowed, g.filter_levels) = (true, 5);
    let frames = run_filtered(&mut g, (0.0, 80.0, 10.0, 25.0), 12, true);
    assert_eq!(frames.last().unwrap().0.levels, 3, "{frames:?}");
    let reach = |f: u32| min_levels(SampleFraction::one_in(f).unwrap());
    assert_eq!([1, 2, 4, 16, 64, 128].map(reach), [1, 2, 2, 3, 4, 5]);
    // A still view's frames may take 5x the target: every level.
    let mut g = Governor::new(100.0);
    (g.pinned_scale, g.filter_levels) = (Some(1.0), 5);
    let frames = run_filtered(&mut g, (0.0, 40.0, 10.0, 25.0), 12, false);
    assert_eq!(frames.last().unwrap().0.levels, ALL_LEVELS, "{frames:?}");
}

#[test]
fn pins_are_kept_and_bad_timings_do_not_break_it() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    g.pinned_scale = Some(0.75);
    run(&mut g, 60.0, 1200.0, 10, false);
    assert_eq!(g.choice().scale, 0.75);
    g.pinned_scale = None;
    g.pinned_fraction = Some(SampleFraction::ONE);
    run(&mut g, 60.0, 1200.0, 10, false);
    assert_eq!(g.choice().fraction, SampleFraction::ONE);
    for wall in [f64::NAN, f64::INFINITY, -5.0, 0.0] {
        let c = g.choice();
        let next = g.record(FrameCost {
            wall_ms: wall,
            trace_ms: f64::NAN,
            scaled_ms: f64::NAN,
            filter_ms: 0.0,
            choice: c,
            moving: false,
        });
        assert!(next.scale > 0.0 && next.scale <= 1.0);
    }
}

/// The viewer on a software rasterizer, the default level in a 1600x900 window, as measured
/// at scale 0.25 and 1/8 spp: a 472 ms frame, 170 ms of it in the passes that run at the
/// frame's resolution, the trace's 76.5 ms among them. Per full-resolution frame at 1 spp:
/// 300 ms fixed, 1500 ms of raster and denoiser, 9800 ms of trace; target 100 ms.
const VIEWER: (f64, f64, f64) = (300.0, 1500.0, 9800.0);

#[test]
fn the_fixed_cost_is_not_scaled() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    run_fixed(&mut g, (40.0, 400.0, 2000.0), 10, true);
    // Its prediction holds for a choice it has not run: 40 + 0.25 (400 + 500) = 265 ms,
    // where a model that scales everything would say 0.25 x 4 x the frame it ran.
    let c = Choice { scale: 0.5, fraction: SampleFraction::one_in(4).unwrap(), levels: ALL_LEVELS };
    let t = g.predict(c).unwrap();
    assert!((t - 265.0).abs() < 1e-6, "{t}");
    // The fixed part alone over the target: the frame still gets SCALABLE_FLOOR of it for
    // the image, not the smallest choice at 1/128 spp.
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    let frames = run_fixed(&mut g, (110.0, 100.0, 200.0), 20, true);
    let (c, t) = frames.last().copied().unwrap();
    assert!(t <= 110.0 + SCALABLE_FLOOR * 100.0 + 1e-9, "{c:?} {t}");
    // 0.5: 110 + 0.25 (100 + 200 f) > 135 at every f; 0.375: 110 + 0.14 (100 + 50) = 131
    // fits at 1/4.
    assert_eq!((c.scale, c.fraction.period()), (0.375, 4), "{c:?} {t}");
}

#[test]
fn a_still_view_traces_the_most_samples_per_second_within_its_limit() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    // Moving, nothing fits the target: the smallest scale and fraction, about 400 ms.
    let moving = run_fixed(&mut g, VIEWER, 12, true);
    let (c, t) = moving.last().copied().unwrap();
    assert_eq!((c.scale, c.fraction.period()), (0.25, 128), "{c:?} {t}");
    let rate_moving = g.samples_per_second(c).unwrap();
    // Stopped: after STILL_AFTER frames the scale stays and the fraction rises to the one
    // that traces the most samples per second within still_ratio x the target (500 ms):
    // 300 + 93.75 + 612.5 f <= 500 allows 1/8 (470.3 ms, the viewer measured 472 ms).
    let still = run_fixed(&mut g, VIEWER, 12, false);
    assert!(still[..STILL_AFTER as usize].iter().all(|(s, _)| *s == c), "{still:?}");
    let (s, t) = still.last().copied().unwrap();
    assert_eq!((s.scale, s.fraction.period()), (0.25, 8), "{s:?} {t}");
    assert!(t <= STILL_RATIO * 100.0, "{t}");
    let rate_still = g.samples_per_second(s).unwrap();
    // 13.6x: 1 / (8 x 470.3 ms) against 1 / (128 x 398.5 ms).
    assert!(rate_still > 13.0 * rate_moving, "{rate_still} against {rate_moving}");
    // No other fraction within the limit traces more.
    for f in SampleFraction::all() {
        let o = Choice { scale: 0.25, fraction: f, levels: ALL_LEVELS };
        if g.predict(o).unwrap() <= STILL_RATIO * 100.0 {
            assert!(g.samples_per_second(o).unwrap() <= rate_still, "{o:?}");
        }
    }
    // A move: the next frame is back under the moving budget.
    let moved = run_fixed(&mut g, VIEWER, 2, true);
    assert!(moved[1].1 <= 300.0 + SCALABLE_FLOOR * 100.0 + 93.75, "{moved:?}");
    // still_ratio 1 keeps the target's choice in a still view.
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    g.still_ratio = 1.0;
    run_fixed(&mut g, VIEWER, 12, true);
    let held = run_fixed(&mut g, VIEWER, 12, false);
    assert_eq!(held.last().unwrap().0, c, "{held:?}");
}

#[test]
fn a_pinned_fraction_stays_in_a_still_view() {
    let mut g = Governor::new(100.0);
    g.fractions_allowed = true;
    g.pinned_fraction = Some(SampleFraction::one_in(16).unwrap());
    run_fixed(&mut g, VIEWER, 20, false);
    assert_eq!(g.choice().fraction.period(), 16);
}
