// What every denoiser's temporal stages and TAA share: world positions from depth, the pixel
// footprint, eq. (11)'s reprojection of Mara et al. 2017 against the previous depth buffer (its
// thresholds are the frame's, frame.d0_px and frame.d1_px), the bilinear history taps and their
// tests, history lengths, and the matte light entering a denoiser. Reads only the frame's
// uniform (realtime/frame.wgsl) and the G-buffer; each denoiser's own parameters stay in its
// own uniform.

// History rejection reasons (the matte/reason debug view).
const REASON_DISOCCLUDED: u32 = 1u;
const REASON_LOW_CONFIDENCE: u32 = 2u;
const REASON_CLAMPED: u32 = 4u;
// The history came from a neighbouring texel (the raster's jitter moved the surface off this
// pixel's last sample): the matte light may jump between frames there.
const REASON_NEIGHBOUR: u32 = 8u;

fn in_bounds(p: vec2i) -> bool {
    return all(p >= vec2i(0)) && all(p < vec2i(frame.size));
}

fn has_surface(p: vec2i) -> bool {
    return textureLoad(gb_object, p, 0).y != NO_SURFACE;
}

// Rebased world position of pixel p's sample, from a depth buffer.
fn world_from_depth(inv: mat4x4f, p: vec2i, depth: f32) -> vec3f {
    let uv = (vec2f(p) + 0.5) / vec2f(frame.size);
    let clip = vec4f(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = inv * clip;
    return w.xyz / w.w;
}

fn position_at(p: vec2i) -> vec3f {
    return world_from_depth(frame.inv_view_proj, p, textureLoad(gb_depth, p, 0));
}

// The previous frame's object index and triangle slot (SVGF's and the progressive filter's
// object test; bound only where a stage reads it).
var prev_object: texture_2d<u32>;

// Schied et al. §4.1's object test: previous texel t showed the object pixel p shows. Depth
// and normal alone pass history between two objects that touch in one plane (a box on the
// floor, a door in its frame), and a moving object's history onto what it uncovers.
fn same_object(p: vec2i, t: vec2i) -> bool {
    return textureLoad(prev_object, t, 0).x == textureLoad(gb_object, p, 0).x;
}

// `ok` and showing p's object, tap by tap (taps off the image are not ok already).
fn same_object_taps(p: vec2i, b: BilinearTaps, ok: vec4<bool>) -> vec4<bool> {
    var both = ok;
    for (var k = 0; k < 4; k++) {
        both[k] = ok[k] && same_object(p, bilinear_tap(b, k));
    }
    return both;
}

// Linear view depth of a rebased world position.
fn linear_depth(x: vec3f) -> f32 {
    return dot(x - frame.cam_pos.xyz, frame.cam_fwd.xyz) / length(frame.cam_fwd.xyz);
}

// Linear depth of pixel q (or -1 off the surface).
fn depth_at(q: vec2i) -> f32 {
    if !in_bounds(q) || !has_surface(q) {
        return -1.0;
    }
    return linear_depth(position_at(q));
}

// The smaller one-sided difference along an axis (a silhouette on one side does not count).
fn one_sided_gradient(z: f32, a: f32, b: f32) -> f32 {
    var g = 1e30;
    if a >= 0.0 {
        g = abs(a - z);
    }
    if b >= 0.0 {
        g = min(g, abs(b - z));
    }
    return select(g, 0.0, g >= 1e30);
}

// SVGF's fwidth of the depth z at pixel p: |dz/dx| + |dz/dy|, each one-sided.
fn depth_gradient(p: vec2i, z: f32) -> f32 {
    return one_sided_gradient(z, depth_at(p - vec2i(1, 0)), depth_at(p + vec2i(1, 0))) + one_sided_gradient(z, depth_at(p - vec2i(0, 1)), depth_at(p + vec2i(0, 1)));
}

// Size of one pixel, in scene units, at the distance of x.
fn footprint(x: vec3f) -> f32 {
    let z = max(dot(x - frame.cam_pos.xyz, frame.cam_fwd.xyz), 1e-6);
    return 2.0 * z * length(frame.cam_up.xyz) / f32(frame.size.y);
}

// The frame in which eq. (11)'s distance is measured at pixel p: the surface normal, the pixel
// footprint and how far the view's slant stretches it along the surface (to at most 10x, 84
// degrees from the normal).
struct SurfaceFrame {
    n: vec3f,
    footprint: f32,
    stretch: f32,
}

fn surface_frame(p: vec2i, x: vec3f) -> SurfaceFrame {
    let n = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let cosine = abs(dot(n, normalize(frame.cam_pos.xyz - x)));
    return SurfaceFrame(n, footprint(x), 1.0 / max(cosine, 0.1));
}

// Eq. (11)'s reprojection, made robust to the raster's jitter. The previous frame sampled each
// pixel at another sub-pixel position, so at a silhouette the texel under the motion vector often
// holds the other surface, although a neighbour holds this one: testing that texel alone reset
// the history of every edge pixel of a still view about every other frame (tests/denoise.rs:
// still_view_keeps_its_history), and stage (5) then blurred a band R wide around each one. When
// the texel under the motion vector fails, its 3x3 neighbours are tried and the one closest to
// the expected position is read instead (point sampled; the history moves by at most a pixel,
// on the same surface).
// The distance is in footprints, split by the surface: off the surface's plane it is the pixel
// footprint (a sample of another surface is rejected), along it the footprint stretched by the
// slant (a jittered sample of a ledge or a far floor seen at a grazing angle lies many frontal
// footprints away, on the same surface).
// Returns the texel, whether to sample bilinearly at `prev` (the texel under the vector passed),
// and the distance (-1: no texel held a surface).
struct Reprojection {
    texel: vec2i,
    bilinear: bool,
    distance: f32,
}

fn previous_distance(depth: texture_depth_2d, normals: texture_2d<f32>, t: vec2i, expected: vec3f, s: SurfaceFrame, min_cos: f32) -> f32 {
    // min_cos <= -1 passes every normal: skip the fetch (the matte default).
    if in_bounds(t) && min_cos > -1.0 && dot(oct_decode(textureLoad(normals, t, 0).xy), s.n) < min_cos {
        return -1.0;
    }
    return previous_plane_distance(depth, t, expected, s);
}

// previous_distance without the normal test: eq. (11)'s distance from the expected point to
// the previous depth buffer's point at texel t, in footprints (-1: none there).
fn previous_plane_distance(depth: texture_depth_2d, t: vec2i, expected: vec3f, s: SurfaceFrame) -> f32 {
    if !in_bounds(t) {
        return -1.0;
    }
    let d = textureLoad(depth, t, 0);
    if d <= 0.0 {
        return -1.0;
    }
    let delta = world_from_depth(frame.prev_inv_view_proj, t, d) - expected;
    let off_plane = dot(s.n, delta);
    let along = length(delta - s.n * off_plane);
    return max(abs(off_plane), along / s.stretch) / s.footprint;
}

// History length n (this frame included) of a history read bilinearly at `prev`: at most
// `cap` frames of history when `prev` falls between texel centres (0: no cap). Reading a texel
// at its centre is exact.
fn resampled_length(n: f32, prev: vec2f, cap: f32) -> f32 {
    let off = prev - floor(prev) - 0.5;
    if cap > 0.0 && dot(off, off) > 1e-6 {
        return min(n, cap + 1.0);
    }
    return n;
}

// Bilinear fetch of a history at pixel coordinates `at` (texel centres at +0.5), edges clamped.
// The histories are 32-bit floats, which WebGPU does not filter without an optional feature.
fn load_bilinear(t: texture_2d<f32>, at: vec2f) -> vec4f {
    let b = bilinear_taps(at);
    return load_taps(t, b, b.w);
}

// The taps of `b` read with weights `w` (which sum to 1), edges clamped.
fn load_taps(t: texture_2d<f32>, b: BilinearTaps, w: vec4f) -> vec4f {
    let hi = vec2i(frame.size) - 1;
    var sum = vec4f(0.0);
    for (var k = 0; k < 4; k++) {
        sum += w[k] * textureLoad(t, clamp(bilinear_tap(b, k), vec2i(0), hi), 0);
    }
    return sum;
}

// The bilinear weights of the taps that are `ok`, renormalised over them (SVGF §4.1: each tap of
// the bilinear read is tested for consistency and the rejected taps' weight goes to the
// others). Untested, a read beside a silhouette took up to 3/4 of its history from the surface
// behind it. None passing: zero weights.
fn passing_weights(b: BilinearTaps, ok: vec4<bool>) -> vec4f {
    let w = select(vec4f(0.0), b.w, ok);
    let sum = w.x + w.y + w.z + w.w;
    if sum <= 0.0 {
        return vec4f(0.0);
    }
    return w / sum;
}

// Which taps of a bilinear read show the expected surface: eq. (11)'s distance within d1
// footprints (and the normal test), as `reproject` judges one texel.
fn surface_taps(depth: texture_depth_2d, normals: texture_2d<f32>, b: BilinearTaps, expected: vec3f, s: SurfaceFrame, min_cos: f32) -> vec4<bool> {
    var ok = vec4<bool>(false);
    for (var k = 0; k < 4; k++) {
        let d = previous_distance(depth, normals, bilinear_tap(b, k), expected, s, min_cos);
        ok[k] = d >= 0.0 && d <= frame.d1_px;
    }
    return ok;
}

// Offset k of a 3x3 neighbourhood, its centre first (k = 0).
fn neighbour_3x3(k: i32) -> vec2i {
    return vec2i((k + 4) % 3 - 1, (k + 4) / 3 % 3 - 1);
}

fn reproject(depth: texture_depth_2d, normals: texture_2d<f32>, prev: vec2f, expected: vec3f, s: SurfaceFrame, min_cos: f32) -> Reprojection {
    let q = vec2i(floor(prev));
    var best = Reprojection(q, true, -1.0);
    for (var k = 0; k < 9; k++) {
        let t = q + neighbour_3x3(k);
        let d = previous_distance(depth, normals, t, expected, s, min_cos);
        if d >= 0.0 && (best.distance < 0.0 || d < best.distance) {
            best = Reprojection(t, k == 0, d);
        }
        // The texel under the vector passed: keep it, sampled bilinearly.
        if k == 0 && d >= 0.0 && d <= frame.d0_px {
            break;
        }
    }
    return best;
}

// History lengths: frames since the history restarted, at most 1024 while anything moves and
// 2^24 in a still view (frame counts stay whole numbers in f32).
const MOVING_FRAMES_MAX: f32 = 1024.0;
const STILL_FRAMES_MAX: f32 = 16777216.0;

// A history's length with this frame, from the length stored with it.
fn next_length(stored: f32, still: bool) -> f32 {
    return min(max(stored, 1.0) + 1.0, select(MOVING_FRAMES_MAX, STILL_FRAMES_MAX, still));
}


// The matte light entering the chain (with the test's fault injection, when asked for).
fn matte_input(p: vec2i) -> vec3f {
    let v = textureLoad(tr_matte, p, 0).rgb;
    if frame.inject_nonfinite != 0u {
        let k = u32(p.x * 3 + p.y * 5) % 7u;
        let zero = f32(frame.index & 0u);
        if k == 0u {
            return vec3f(zero / zero);
        }
        if k == 1u {
            return vec3f(1.0 / zero, v.g, -1.0 / zero);
        }
    }
    return v;
}

// YCoCg, where TAA's box and the glossy chain's neighbourhood clip are drawn (Karis 2014).
fn to_ycocg(c: vec3f) -> vec3f {
    return vec3f(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

fn from_ycocg(c: vec3f) -> vec3f {
    return vec3f(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}
