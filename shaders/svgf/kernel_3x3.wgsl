// The a-trous kernel with `svgf.kernel_5x5` off: 3x3, (1/4, 1/2, 1/4) per axis. The radius is a
// constant of the program, not a uniform, so that the compiler unrolls the taps' loop: on
// lavapipe that took the level's a-trous at 640x360 from 313 to 200 ms (matte) and 362 to 262 ms
// (glossy).

const KERNEL_RADIUS: i32 = 1;

// The kernel's weight along one axis at d taps from the centre.
fn kernel(d: i32) -> f32 {
    return select(0.25, 0.5, d == 0);
}
