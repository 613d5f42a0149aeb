//! libFuzzer target: [`skin_fuzz::cell_input::check`] on every input.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| skin_fuzz::cell_input::check(data));
