// The matte light (Mara et al.'s demodulated matte buffer), with the tests' fault injection.
fn signal_input(p: vec2i) -> vec3f {
    return matte_input(p);
}
