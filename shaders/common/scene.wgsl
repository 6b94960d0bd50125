// Shading data and materials (engine/src/gpu/scene.rs mirrors these layouts).

// Four vec4 per triangle: (n0, uv0.x), (n1, uv1.x), (n2, uv2.x), (uv0.y, uv1.y, uv2.y, object),
// read as texels (see tri_texels in geometry.wgsl).
var shading_texels: texture_2d<f32>;

fn shading_at(i: u32) -> vec4f {
    return textureLoad(shading_texels, texel_at(i), 0);
}

struct Material {
    base_color: vec4f,
    emission: vec3f,
    metallic: f32,
    specular_color: vec3f,
    roughness: f32,
    specular_factor: f32,
    alpha_cutoff: f32,
    normal_scale: f32,
    flags: u32,
    // Texture indices: base colour, metallic-roughness, normal, emissive (-1: none).
    tex: vec4i,
}

const MAT_DOUBLE_SIDED: u32 = 1u;
const MAT_ALPHA_MASK: u32 = 2u;
const MAT_ALPHA_BLEND: u32 = 4u;
// Bits 8 and up of the flags: the material's own index (common/texcoords.wgsl's table row).
const MAT_INDEX_SHIFT: u32 = 8u;

// Five texels per material (engine/src/gpu/prepare.rs, GpuMaterial).
var material_texels: texture_2d<u32>;

fn material(i: u32) -> Material {
    let a = textureLoad(material_texels, texel_at(i * 5u), 0);
    let b = textureLoad(material_texels, texel_at(i * 5u + 1u), 0);
    let c = textureLoad(material_texels, texel_at(i * 5u + 2u), 0);
    let d = textureLoad(material_texels, texel_at(i * 5u + 3u), 0);
    let e = textureLoad(material_texels, texel_at(i * 5u + 4u), 0);
    return Material(bitcast<vec4f>(a), bitcast<vec3f>(b.xyz), bitcast<f32>(b.w), bitcast<vec3f>(c.xyz), bitcast<f32>(c.w),
        bitcast<f32>(d.x), bitcast<f32>(d.y), bitcast<f32>(d.z), d.w, bitcast<vec4i>(e));
}

fn tri_uv(slot: u32, b: vec2f) -> vec2f {
    let s0 = shading_at(slot * 4u);
    let s1 = shading_at(slot * 4u + 1u);
    let s2 = shading_at(slot * 4u + 2u);
    let s3 = shading_at(slot * 4u + 3u);
    let w = vec3f(1.0 - b.x - b.y, b.x, b.y);
    return vec2f(dot(w, vec3f(s0.w, s1.w, s2.w)), dot(w, s3.xyz));
}

// The vertex attributes a material reads at a surface point: TEXCOORD_0, TEXCOORD_1 and COLOR_0
// (common/attributes.wgsl, or TEXCOORD_0 and white in a scene without the other two).
// lod and xi choose the mip level of every texture read there (common/textures.wgsl): a ray
// cone's footprint after the primary hit (cone_lod), the finest level before it.
struct TexCoords {
    uv0: vec2f,
    uv1: vec2f,
    color: vec4f,
    lod: f32,
    xi: f32,
}

const FINEST_LOD: f32 = -1e30;

fn tri_tex_coords(slot: u32, b: vec2f) -> TexCoords {
    return TexCoords(tri_uv(slot, b), tri_uv1(slot, b), tri_color(slot, b), FINEST_LOD, 0.0);
}

// Ray cones (Akenine-Moller et al. 2019, "Texture Level of Detail Strategies for Real-Time Ray
// Tracing", §20.3.4, eq. (20.39)): a cone of width w meeting triangle slot at cos_i covers a
// footprint whose side in TEXCOORD_0 units is w / |cos_i| x sqrt(uv area / world area);
// returned as its log2 (textures add log2 of their size in texels). A TEXCOORD_1 read or a
// KHR_texture_transform's scale uses the same footprint.
fn cone_lod(hit: Hit, width: f32, cos_i: f32) -> f32 {
    let slot = hit.tri;
    let v0 = tri_vertex(slot * 3u);
    let world = length(cross(inst_vector(hit.inst, tri_vertex(slot * 3u + 1u) - v0), inst_vector(hit.inst, tri_vertex(slot * 3u + 2u) - v0)));
    let s0 = shading_at(slot * 4u).w;
    let s1 = shading_at(slot * 4u + 1u).w;
    let s2 = shading_at(slot * 4u + 2u).w;
    let t = shading_at(slot * 4u + 3u).xyz;
    let a = vec2f(s1 - s0, t.y - t.x);
    let b = vec2f(s2 - s0, t.z - t.x);
    let uv_area = abs(a.x * b.y - a.y * b.x);
    return 0.5 * log2(max(uv_area, 1e-30) / max(world, 1e-30)) + log2(max(width, 1e-30) / max(abs(cos_i), 1e-3));
}

// A cone's spread after scattering into a direction of solid-angle pdf `pdf`: the sample
// stands for about 1 / pdf steradians, a cone of apex angle 2 sqrt(1 / (pi pdf)) (the
// footprint a path differential gives a sampled direction, Suykens & Willems 2001), capped at
// one radian; a delta direction (pdf 0 here) keeps the spread it had.
fn cone_spread_after(spread: f32, pdf: f32) -> f32 {
    if pdf <= 0.0 {
        return spread;
    }
    return spread + min(2.0 * sqrt(1.0 / (PI * pdf)), 1.0);
}

// Texture slot k of material m (0 base colour, 1 metallic-roughness, 2 normal, 3 emissive; the
// slot must hold a texture), read at the coordinates its texture info names
// (common/texcoords.wgsl: TEXCOORD set and KHR_texture_transform).
fn material_texture(m: Material, k: u32, t: TexCoords) -> vec4f {
    return tex_sample(u32(m.tex[k]), texture_uv(m, k, t), t.lod, t.xi);
}

fn tri_normal(slot: u32, b: vec2f) -> vec3f {
    let w = vec3f(1.0 - b.x - b.y, b.x, b.y);
    return w.x * shading_at(slot * 4u).xyz + w.y * shading_at(slot * 4u + 1u).xyz + w.z * shading_at(slot * 4u + 2u).xyz;
}

// The object a hit belongs to: the instance's, or the world-space triangle's own.
fn hit_object(hit: Hit) -> u32 {
    if hit.inst != NO_INSTANCE {
        return hit.inst;
    }
    return bitcast<u32>(shading_at(hit.tri * 4u + 3u).w);
}

// What a path needs at a hit.
struct Surface {
    p: vec3f,
    // Geometric and shading normals, both turned to the side the ray came from.
    ng: vec3f,
    ns: vec3f,
    tc: TexCoords,
    // The ray hit the counter-clockwise (front) side.
    front: bool,
    material: u32,
}

fn surface_at(hit: Hit, rd: vec3f) -> Surface {
    let slot = hit.tri;
    let v0 = tri_vertex(slot * 3u);
    let e1 = tri_vertex(slot * 3u + 1u) - v0;
    let e2 = tri_vertex(slot * 3u + 2u) - v0;
    var s: Surface;
    s.material = tri_material(slot);
    // An instance's triangle is in its mesh's space: its point and normals are carried to the
    // world, the shading normal after the normal map (exact for rotations, mirrors and uniform
    // scales; a non-uniform scale turns the mapped normal as it turns the mesh's normal).
    s.p = inst_point(hit.inst, v0 + hit.b.x * e1 + hit.b.y * e2);
    let face = cross(e1, e2);
    var ng = normalize(inst_normal(hit.inst, face));
    s.front = dot(ng, rd) < 0.0;
    var ns = tri_normal(slot, hit.b);
    let len = length(ns);
    let stored = len > 1e-12 && len < 1e30;
    ns = select(normalize(face), ns / len, stored);
    if !s.front {
        ng = -ng;
        ns = -ns;
    }
    s.tc = tri_tex_coords(slot, hit.b);
    s.ng = ng;
    s.ns = inst_shading_normal(hit.inst, apply_normal_map(slot, hit.b, ns, s.tc, material(s.material)));
    if stored {
        // The stored normals (and tangents) are the close's: the mapped normal turns with the
        // triangle to the ray's time where objects move during the shutter.
        s.ns = normal_at_ray_time(slot, s.ns);
    }
    return s;
}

// A material's parameters at a surface point, with its textures applied (glTF metallic-roughness:
// roughness in G, metallic in B).
struct MaterialSample {
    base: vec4f,
    metallic: f32,
    roughness: f32,
    emission: vec3f,
}

// COLOR_0 multiplies the base colour (glTF 2.0 §3.7.2.1), alpha included.
fn material_at(m: Material, t: TexCoords) -> MaterialSample {
    var r: MaterialSample;
    r.base = m.base_color * t.color;
    r.metallic = m.metallic;
    r.roughness = m.roughness;
    r.emission = m.emission;
    if m.tex.x >= 0 {
        r.base *= material_texture(m, 0u, t);
    }
    if m.tex.y >= 0 {
        let mr = material_texture(m, 1u, t);
        r.roughness *= mr.g;
        r.metallic *= mr.b;
    }
    if m.tex.w >= 0 {
        r.emission *= material_texture(m, 3u, t).rgb;
    }
    return r;
}

fn material_bsdf(m: Material, ms: MaterialSample) -> Bsdf {
    return make_bsdf(ms.base.rgb, ms.metallic, ms.roughness, m.specular_factor, m.specular_color);
}
