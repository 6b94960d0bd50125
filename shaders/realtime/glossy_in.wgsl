// Glossy trace outputs as read by the composite and the debug views.
var tr_glossy: texture_2d<f32>;
var tr_reflection: texture_2d<f32>;
var tr_mirror: texture_2d<u32>;
// What the glossy path hit first: reflectance (rgba8) and normal (octahedral snorm16x2).
var tr_mirror_hit: texture_2d<u32>;

fn glossy_light(p: vec2i) -> vec3f {
    return textureLoad(tr_glossy, p, 0).rgb;
}

// Debug views of the glossy buffers (engine/src/frame/views.rs).
fn glossy_view(view: u32, p: vec2i) -> vec3f {
    switch view {
        case 12u: {
            return textureLoad(tr_glossy, p, 0).rgb;
        }
        case 13u: {
            // Secondary hit distance over the scene's extent (white: escaped).
            let t = textureLoad(tr_glossy, p, 0).a;
            return vec3f(select(t / (frame.cam_pos.w * 131072.0), 1.0, t >= 65000.0));
        }
        case 14u: {
            let v = textureLoad(tr_reflection, p, 0);
            return select(fract(v.xyz / (frame.cam_pos.w * 131072.0) * 8.0), vec3f(0.0), v.w >= 3.0e38);
        }
        case 15u: {
            return oct_decode(unpack2x16snorm(textureLoad(tr_mirror, p, 0).x)) * 0.5 + 0.5;
        }
        default: {
            return vec3f(0.0);
        }
    }
}
