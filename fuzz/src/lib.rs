//! The properties that the fuzz targets (`fuzz_targets/`, one line each) check, as plain
//! functions of the raw fuzz input: each panics when a property fails, which libFuzzer reports as
//! a finding (docs/fuzzing.md). The shipped files are the seeds: libFuzzer runs them first.

pub mod cell_input;
pub mod config_yaml;
pub mod fixtures;
pub mod urdf;
