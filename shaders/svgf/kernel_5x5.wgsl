// The a-trous kernel with `svgf.kernel_5x5` on: SVGF's 5x5 B3 spline (1/16, 1/4, 3/8, 1/4, 1/16
// per axis; Schied et al. §4.3, after Dammertz et al. 2010). A constant radius, as the 3x3's
// (svgf/kernel_3x3.wgsl).

const KERNEL_RADIUS: i32 = 2;

// The kernel's weight along one axis at d taps from the centre.
fn kernel(d: i32) -> f32 {
    return select(select(0.0625, 0.25, d == 1), 0.375, d == 0);
}
