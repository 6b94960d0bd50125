// Debug views of the glossy chain (engine/src/frame/views.rs, 22 and up).
var gv_motion: texture_2d<f32>;
var gv_search: texture_2d<f32>;
var gv_info: texture_2d<f32>;
var gv_sigma: texture_2d<f32>;
var gv_denoised: texture_2d<f32>;

// As the surface motion view: hue = direction, brightness = length (1 px = 0.25).
fn motion_colour(mv: vec2f) -> vec3f {
    return vec3f(0.5 + mv.x * 0.125, 0.5 - mv.y * 0.125, 0.5 + length(mv) * 0.25);
}

fn glossy_chain_view(view: u32, p: vec2i) -> vec4f {
    switch view {
        case 22u: {
            return vec4f(motion_colour(textureLoad(gv_motion, p, 0).xy), 0.0);
        }
        case 23u: {
            return vec4f(motion_colour(textureLoad(gv_motion, p, 0).zw), 0.0);
        }
        case 24u: {
            // Pixels between the diamond search and the virtual position (or the brute-force
            // search when it runs); 4 px is white.
            return vec4f(vec3f(textureLoad(gv_search, p, 0).y * 0.25), 0.0);
        }
        case 25u: {
            // Large-pattern iterations; 16 is white.
            return vec4f(vec3f(textureLoad(gv_search, p, 0).x / 16.0), 0.0);
        }
        case 26u: {
            return vec4f(vec3f(textureLoad(gv_info, p, 0).x), 0.0);
        }
        case 27u: {
            return vec4f(vec3f(textureLoad(gv_info, p, 0).y), 0.0);
        }
        case 28u: {
            // Bilateral sigma over 9 px (GlossySettings' largest).
            return vec4f(vec3f(textureLoad(gv_sigma, p, 0).a / 9.0), 0.0);
        }
        case 29u: {
            return vec4f(textureLoad(gv_denoised, p, 0).rgb, 1.0);
        }
        default: {
            return vec4f(0.0);
        }
    }
}
