// The mixed glossy light, with the guide's secondary hit distance (tr_glossy's alpha) kept.
var out_glossy: texture_storage_2d<rgba16float, write>;

fn store_glossy(p: vec2i, c: vec3f) {
    textureStore(out_glossy, p, vec4f(half_safe(c), textureLoad(tr_glossy, p, 0).a));
}
