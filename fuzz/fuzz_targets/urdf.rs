//! libFuzzer target: [`skin_fuzz::urdf::check`] on every input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| skin_fuzz::urdf::check(data));
