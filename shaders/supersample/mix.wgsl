// Voorhuis eq. (7): a guide's light becomes the mean of its own sample and of the extra samples
// that chose it (assign.wgsl), gathered from the 3x3 pixels whose samples may have (a sample's
// candidates are within one pixel of its own). Per signal: matte, direct and, in scenes with a
// specular lobe, glossy light (mix_glossy.wgsl).

var out_matte: texture_storage_2d<rgba16float, write>;
var out_direct: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if any(gid.xy >= frame.size) {
        return;
    }
    let pixel = gid.y * frame.size.x + gid.x;
    let extra = extra_samples();
    var matte = textureLoad(tr_matte, p, 0).rgb;
    var direct = textureLoad(tr_direct, p, 0).rgb;
    var glossy = glossy_light(p);
    var n = 1.0;
    for (var k = 0; k < 9; k++) {
        let q = p + vec2i(k % 3 - 1, k / 3 - 1);
        if any(q < vec2i(0)) || any(q >= vec2i(frame.size)) {
            continue;
        }
        let base = (u32(q.y) * frame.size.x + u32(q.x)) * extra;
        for (var j = 0u; j < extra; j++) {
            let r = ss_samples[base + j];
            if r.guide == pixel {
                matte += unpack_light(r.matte);
                direct += unpack_light(r.direct);
                glossy += unpack_light(r.glossy);
                n += 1.0;
            }
        }
    }
    textureStore(out_matte, p, vec4f(half_safe(matte / n), 1.0));
    textureStore(out_direct, p, vec4f(half_safe(direct / n), 1.0));
    store_glossy(p, glossy / n);
}
