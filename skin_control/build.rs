//! Link fixes for ROS 2 from PyPI wheels, so the binaries run without sourcing anything.
fn main() {
    // librcl.so from the wheels needs CPython symbols (its Python typesupport dependencies do not
    // link libpython): without this, binaries die with "undefined symbol: PyExc_RuntimeError".
    println!("cargo:rustc-link-arg=-Wl,--push-state,--no-as-needed,-lpython3.11,--pop-state");
    // The wheels' own RPATHs are wrong once installed into a venv: embed ours (DT_RPATH, which,
    // unlike RUNPATH, also applies to the libraries' own dependencies). scripts/bootstrap writes it.
    println!("cargo:rerun-if-env-changed=SKIN_RPATH");
    if let Ok(rpath) = std::env::var("SKIN_RPATH") {
        if !rpath.is_empty() {
            println!("cargo:rustc-link-arg=-Wl,--disable-new-dtags,-rpath,{rpath}");
        }
    }
}
