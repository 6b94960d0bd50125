// The denoiser has not run: its views are black.
fn denoise_view(view: u32, p: vec2i) -> vec4f {
    return vec4f(0.0);
}
