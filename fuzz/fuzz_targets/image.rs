//! A texture (PNG, JPEG) or environment map (EXR) decoded as a scene's images are.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = hush_engine::fuzz::image(data);
});
