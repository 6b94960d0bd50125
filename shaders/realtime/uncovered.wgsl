// Paths the trace shoots at a pixel (engine/src/passes/trace.rs): frame.uncovered_paths where
// its surface was not on screen last frame (a move uncovered it), frame.paths elsewhere. The
// pixel's matte light carries the count in its alpha, and a temporal stage whose history
// restarts there counts the sample as that many frames (FrameSettings::uncovered_paths).

fn pixel_paths(p: vec3f) -> u32 {
    if frame.uncovered_paths > frame.paths && !seen_last_frame(p) {
        return frame.uncovered_paths;
    }
    return frame.paths;
}
