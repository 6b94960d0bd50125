//! A glTF/GLB scene with its side files (an archive: see `hush_engine::fuzz`), loaded and
//! prepared for the GPU.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = hush_engine::fuzz::scene(data);
});
