// Per-frame parameters of the real-time frame (engine/src/frame/params.rs: FrameParams).
// Positions are in the GPU scene's rebased world space (see PreparedScene::origin).
struct Frame {
    // World -> clip with this frame's sub-pixel jitter (reversed, infinite Z).
    view_proj: mat4x4f,
    // The same without jitter, and the previous frame's (motion vectors compare these two).
    unjittered_view_proj: mat4x4f,
    prev_view_proj: mat4x4f,
    // Camera rays as in common/params.wgsl: fwd + x right + y up, x, y in [-1, 1].
    cam_pos: vec4f,
    cam_right: vec4f,
    cam_up: vec4f,
    cam_fwd: vec4f,
    // Where in the pixel this frame samples, in [0, 1)^2 (0.5, 0.5 = the centre).
    jitter: vec2f,
    size: vec2u,
    index: u32,
    // Exposure multiplier 2^EV.
    exposure: f32,
    // Frames summed in the accumulation buffer (accumulate mode), 0 when off.
    accumulated: u32,
    // Matte and glossy paths traced per pixel (their results are averaged).
    paths: u32,
    // Glossy surfaces below this roughness also trace their representative (mirror) ray.
    representative_roughness: f32,
    // Samples per pixel k (Voorhuis §5): the raster's guide and k - 1 traced samples.
    samples: u32,
    // Frames between two samples of a pixel (1 / f; 1: every pixel every frame).
    period: u32,
    // Primary samples per pixel of the traced primaries (realtime/primaries.wgsl); 0: raster.
    primary_samples: u32,
    // On the first frame after a change of size whose histories were resampled to it
    // (realtime/rescale.wgsl): the most frames a history may count (0 on every other frame).
    rescaled_frames: f32,
    // Paths per pixel where the surface was not on screen last frame (realtime/uncovered.wgsl;
    // 0 where there is no history to restart or nothing moved).
    uncovered_paths: u32,
    // The last frame's jitter: its depth texel t holds the surface at pixel position t + this.
    prev_jitter_x: f32,
    prev_jitter_y: f32,
    // What every denoiser's temporal stages and TAA read of the two frames (the frame owns it;
    // engine/src/frame/params.rs: ChainView). Rebased world from clip, this frame and the
    // previous one, both with their jitter, as their depth buffers were rasterised.
    inv_view_proj: mat4x4f,
    prev_inv_view_proj: mat4x4f,
    // The previous frame's sub-pixel jitter minus this frame's, pixels: what separates the two
    // frames' samples of one pixel in a still view.
    jitter_shift: vec2f,
    // 0 when there is no usable history (first denoised frame, a change of denoiser, a cut):
    // temporal stages then start over.
    history_valid: u32,
    // 1 when neither the camera nor any object moved since the last frame.
    static_view: u32,
    // Eq. (11)'s reprojection test (Mara et al. 2017), in pixel footprints at the surface: full
    // confidence within d0, none beyond d1 (ReprojectionSettings).
    d0_px: f32,
    d1_px: f32,
    // Tests: the matte light entering a denoiser is NaN / +Inf / -Inf on 1 pixel in 7.
    inject_nonfinite: u32,
    // Light candidates resampled for a matte light sample (realtime/area_light.wgsl); 1: none.
    light_candidates: u32,
}

var<uniform> frame: Frame;

// Frames `n` of a history as a temporal stage counts them: on the first frame after a change of
// size, whose histories were resampled to it (blurred by the resampling), at most
// frame.rescaled_frames, so that the new size's samples replace them within a few frames.
fn rescaled_length(n: f32) -> f32 {
    if frame.rescaled_frames > 0.0 {
        return min(n, frame.rescaled_frames);
    }
    return n;
}

// Sub-1-spp tracing (Dundr et al. §5; engine/src/frame/schedule.rs, which documents and tests
// it): with period N = 2^k the image is cut into 2^ceil(k/2) x 2^floor(k/2) tiles and each
// frame traces one pixel per tile, in the Bayer order from a phase hashed per tile.
fn schedule_tile() -> vec2u {
    let k = countTrailingZeros(max(frame.period, 1u));
    return vec2u(1u << ((k + 1u) / 2u), 1u << (k / 2u));
}

fn schedule_hash(v: u32) -> u32 {
    var x = v;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

// The pixel of tile t traced this frame.
fn scheduled_pixel(t: vec2u) -> vec2u {
    let n = max(frame.period, 1u);
    let k = countTrailingZeros(n);
    let phase = schedule_hash((t.x * 0x8da6b343u) ^ (t.y * 0xd8163841u)) & (n - 1u);
    let rank = (frame.index + phase) & (n - 1u);
    var v = 0u;
    if k > 0u {
        v = reverseBits(rank) >> (32u - k);
    }
    var c = vec2u(0u);
    for (var i = 0u; i < k; i++) {
        let bit = (v >> i) & 1u;
        if i % 2u == 0u {
            c.x |= bit << (i / 2u);
        } else {
            c.y |= bit << (i / 2u);
        }
    }
    c.x ^= c.y;
    return t * schedule_tile() + c;
}

// Whether pixel px was traced this frame (every pixel at one sample per pixel).
fn traced_this_frame(px: vec2u) -> bool {
    return frame.period <= 1u || all(scheduled_pixel(px / schedule_tile()) == px);
}

// A clip-space position in pixels of this frame's image (x right, y down): motion vectors
// compare two of them.
fn to_pixels(clip: vec4f) -> vec2f {
    let ndc = clip.xy / clip.w;
    return vec2f(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * vec2f(frame.size);
}

// The camera ray through this frame's sample position in pixel px.
fn camera_ray(px: vec2u) -> vec3f {
    return camera_ray_at(vec2f(px) + frame.jitter);
}

// The camera ray through image position x (pixels; pixel (i, j) spans [i, i + 1) x [j, j + 1)).
fn camera_ray_at(x: vec2f) -> vec3f {
    let ndc = vec2f(
        x.x / f32(frame.size.x) * 2.0 - 1.0,
        1.0 - x.y / f32(frame.size.y) * 2.0,
    );
    return normalize(frame.cam_fwd.xyz + ndc.x * frame.cam_right.xyz + ndc.y * frame.cam_up.xyz);
}

// Octahedral encoding of a unit vector into [-1, 1]^2 (Cigolle et al. 2014).
fn oct_encode(n: vec3f) -> vec2f {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    return (1.0 - abs(p.yx)) * select(vec2f(-1.0), vec2f(1.0), p >= vec2f(0.0));
}

fn oct_decode(e: vec2f) -> vec3f {
    var n = vec3f(e, 1.0 - abs(e.x) - abs(e.y));
    if n.z < 0.0 {
        let xy = (1.0 - abs(n.yx)) * select(vec2f(-1.0), vec2f(1.0), n.xy >= vec2f(0.0));
        n = vec3f(xy, n.z);
    }
    return normalize(n);
}

// Largest finite half float is 65504: clamp below it and drop NaN/Inf so that nothing a pass
// writes can poison a later one (or, in later chains, the history).
fn half_safe(v: vec3f) -> vec3f {
    return select(vec3f(0.0), clamp(v, vec3f(-65000.0), vec3f(65000.0)), (v == v) & (abs(v) <= vec3f(3.0e38)));
}

// Schlick's Fresnel at the mirror direction (Mara et al. eq. (4) with w_h = n): F(w_s) for a
// material of reflectance f0 at normal incidence and f90 at grazing, cos_o = n . w_o. The
// composite's and the trace's (realtime/gbuffer_in.wgsl, realtime/trace.wgsl).
fn schlick_mirror(f0: vec3f, f90: f32, cos_o: f32) -> vec3f {
    let m = 1.0 - clamp(cos_o, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (vec3f(f90) - f0) * (m2 * m2 * m);
}

// What the composite multiplies the matte light by: m (1 - F(w_s))^2 with m = base colour x
// (1 - metallic), Mara et al. eq. (9) and (10).
fn remodulated_matte(base: vec3f, metallic: f32, f_s: vec3f) -> vec3f {
    let one_minus_f = vec3f(1.0) - f_s;
    return base * (1.0 - metallic) * one_minus_f * one_minus_f;
}
