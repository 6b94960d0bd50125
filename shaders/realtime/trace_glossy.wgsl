// Glossy outputs of the trace pass (only in scenes with a specular lobe).
var out_glossy: texture_storage_2d<rgba16float, write>;
var out_reflection: texture_storage_2d<rgba32float, write>;
// Octahedral direction as pack2x16snorm (Rg16 is not a core storage format).
var out_mirror: texture_storage_2d<r32uint, write>;
// What the glossy path hit first: reflectance as rgba8 and shading normal as octahedral snorm16
// (the features and albedo a mirror's chain filters and demodulates with, Voorhuis §4.1).
var out_mirror_hit: texture_storage_2d<rg32uint, write>;

const HAS_GLOSSY: bool = true;

// light: eq. (10) over F(w_s, w_o). t: the glossy path's secondary hit distance (INF: it left the
// scene). primary: camera-relative primary hit. mirror: the representative ray's direction
// (Voorhuis §4.2.1), the reflection a perfect mirror would take. The virtual position of what
// the glossy path saw lies along the camera ray at primary + t (Mara et al. §3.4, after Zimmer
// et al. 2015); w holds t, and a miss stores the camera ray direction with w = INF. The virtual
// position uses representative_t, the mirror ray's hit distance where it was traced (glossy
// surfaces under the chain's roughness threshold), else the sample's.
fn write_glossy(px: vec2u, light: vec3f, t: f32, primary: vec3f, mirror: vec3f, hit_reflectance: vec3f, hit_normal: vec3f, representative_t: f32) {
    textureStore(out_glossy, px, vec4f(half_safe(light), min(t, 65000.0)));
    var virtual_pos = vec4f(normalize(primary), INF);
    if representative_t < INF {
        virtual_pos = vec4f(frame.cam_pos.xyz + primary + normalize(primary) * representative_t, representative_t);
    }
    textureStore(out_reflection, px, virtual_pos);
    textureStore(out_mirror, px, vec4u(pack2x16snorm(oct_encode(mirror)), 0u, 0u, 0u));
    textureStore(out_mirror_hit, px, vec4u(pack4x8unorm(vec4f(hit_reflectance, 1.0)), pack2x16snorm(oct_encode(hit_normal)), 0u, 0u));
}
