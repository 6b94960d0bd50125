// Debug views of the matte chain's intermediates (when the denoiser has run).
var dv_temporal: texture_2d<f32>;
var dv_reason: texture_2d<u32>;
var dv_radius: texture_2d<f32>;
var dv_firefly: texture_2d<f32>;
var dv_denoised: texture_2d<f32>;

// x: colour; w: 1 when it is light (exposed and tone-mapped like the image).
fn denoise_view(view: u32, p: vec2i) -> vec4f {
    switch view {
        case 16u: {
            return vec4f(textureLoad(dv_temporal, p, 0).rgb, 1.0);
        }
        case 17u: {
            return vec4f(vec3f(textureLoad(dv_temporal, p, 0).a), 0.0);
        }
        case 18u: {
            // Red: disoccluded; yellow: low confidence; blue: history clamped.
            let r = textureLoad(dv_reason, p, 0).x & 255u;
            var c = vec3f(0.0);
            if (r & 1u) != 0u {
                c = vec3f(1.0, 0.0, 0.0);
            } else if (r & 2u) != 0u {
                c = vec3f(1.0, 1.0, 0.0);
            }
            if (r & 4u) != 0u {
                c += vec3f(0.0, 0.3, 1.0);
            }
            return vec4f(c, 0.0);
        }
        case 19u: {
            // Radius over R (the disocclusion radius at full strength is white).
            let r = textureLoad(dv_radius, p, 0).r;
            return vec4f(vec3f(r / max(f32(frame.size.x) * 0.05, 1.0)), 0.0);
        }
        case 20u: {
            return vec4f(textureLoad(dv_firefly, p, 0).rgb, 1.0);
        }
        case 21u: {
            return vec4f(textureLoad(dv_denoised, p, 0).rgb, 1.0);
        }
        default: {
            return glossy_chain_view(view, p);
        }
    }
}
