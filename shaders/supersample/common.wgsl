// Supersampling with guide rays (Voorhuis §5, after Bauszat et al.): each pixel's raster sample
// is its guide; frame.samples - 1 more samples per pixel are traced at random positions in it
// (supersample/samples.wgsl). Before denoising, each extra sample is mixed into the most similar
// of the four guides nearest to it (assign.wgsl, mix.wgsl: eq. (7)); after the composite, each
// pixel is the mean of its guide and its extra samples' guides (resolve.wgsl).

// One extra sample: its light (three floats each; a vec3f would pad the record to 64 bytes),
// its linear depth (< 0: it saw the environment), its shading normal (octahedral snorm16x2),
// its material, its position in its pixel (unorm16x2) and the guide pixel it was mixed into
// (assign.wgsl; NO_GUIDE until then).
struct SampleLight {
    r: f32,
    g: f32,
    b: f32,
}

struct SampleRecord {
    matte: SampleLight,
    glossy: SampleLight,
    direct: SampleLight,
    depth: f32,
    normal: u32,
    material: u32,
    pos: u32,
    guide: u32,
}

const NO_GUIDE: u32 = 0xffffffffu;

// Extra samples, frame.samples - 1 per pixel, pixel-major.
var<storage, read_write> ss_samples: array<SampleRecord>;
// Each guide's linear depth (bitcast; < 0: environment), octahedral normal and material.
var<storage, read_write> ss_guides: array<vec4u>;

fn extra_samples() -> u32 {
    return max(frame.samples, 1u) - 1u;
}

fn pack_light(c: vec3f) -> SampleLight {
    let h = half_safe(c);
    return SampleLight(h.r, h.g, h.b);
}

fn unpack_light(v: SampleLight) -> vec3f {
    return vec3f(v.r, v.g, v.b);
}

// Depth along the view axis of a hit at distance t along camera ray direction rd.
fn view_depth(rd: vec3f, t: f32) -> f32 {
    return t * dot(rd, normalize(frame.cam_fwd.xyz));
}
