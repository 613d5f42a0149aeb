//! Link settings for the binaries of the ROS 2 packages (`skin_control`, `skin_sim_ros`), called
//! from their build scripts so that both link the same way:
//! - ROS 2 from PyPI wheels: `librcl.so` pulls in Python typesupport libraries that use CPython
//!   symbols without linking libpython, so binaries die at start with "undefined symbol:
//!   PyExc_RuntimeError" unless they link it. Detected, not assumed: an ament prefix that is a
//!   Python venv (`pyvenv.cfg`) holding `lib/librcl.so` is a wheel install, and its
//!   `lib/python3.X` names the library. A stock `/opt/ros/jazzy` needs nothing.
//!   `SKIN_LINK_PYTHON=python3.12` forces a library, `SKIN_LINK_PYTHON=none` turns it off.
//! - `SKIN_RPATH` (written by scripts/bootstrap) is embedded as DT_RPATH, which unlike RUNPATH
//!   also applies to the libraries' own dependencies: the wheels' RPATHs are wrong once installed.
#![warn(missing_docs)]

use std::env;
use std::path::Path;

/// Prints the cargo instructions for a ROS 2 package's binaries, tests and examples.
pub fn emit() {
    for var in ["SKIN_LINK_PYTHON", "SKIN_RPATH", "AMENT_PREFIX_PATH"] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    let prefixes = env::var("AMENT_PREFIX_PATH").unwrap_or_default();
    let python = match env::var("SKIN_LINK_PYTHON") {
        Ok(v) if v == "none" || v.is_empty() => None,
        Ok(v) => Some(v),
        Err(_) => prefixes.split(':').find_map(|p| wheel_python(Path::new(p))),
    };
    if let Some(lib) = python {
        println!("cargo:rustc-link-arg=-Wl,--push-state,--no-as-needed,-l{lib},--pop-state");
    }
    if let Ok(rpath) = env::var("SKIN_RPATH") {
        if !rpath.is_empty() {
            println!("cargo:rustc-link-arg=-Wl,--disable-new-dtags,-rpath,{rpath}");
        }
    }
}

/// `python3.X` when `prefix` is a venv of ROS 2 wheels (see the crate docs), else None.
fn wheel_python(prefix: &Path) -> Option<String> {
    if !prefix.join("pyvenv.cfg").is_file() || !prefix.join("lib/librcl.so").exists() {
        return None;
    }
    std::fs::read_dir(prefix.join("lib"))
        .ok()?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .find(|name| name.starts_with("python3.") && !name.contains(".so"))
}
