//! Where the nodes find their data files (URDF, layouts, parameter files).
use std::path::{Path, PathBuf};

/// The package name, as in `package.xml` (its share directory holds installed data files).
pub const PACKAGE: &str = "skin_control";

/// Directories a relative path is tried against, in order: the working directory, each
/// `<prefix>/share/skin_control` of `AMENT_PREFIX_PATH` (an installed package), and the
/// repository this binary was built from.
pub fn search_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![PathBuf::from(".")];
    if let Some(prefixes) = std::env::var_os("AMENT_PREFIX_PATH") {
        dirs.extend(std::env::split_paths(&prefixes).map(|p| p.join("share").join(PACKAGE)));
    }
    // The crate sits one level below the repository root.
    dirs.extend(Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf));
    dirs
}

/// The existing file that `path` names: itself when absolute, else the first hit in `dirs`.
/// The error lists every place tried.
pub fn resolve_in(path: &str, dirs: &[PathBuf]) -> Result<PathBuf, String> {
    let p = Path::new(path);
    let candidates: Vec<PathBuf> =
        if p.is_absolute() { vec![p.to_path_buf()] } else { dirs.iter().map(|d| d.join(p)).collect() };
    candidates.iter().find(|c| c.is_file()).cloned().ok_or_else(|| {
        let tried: Vec<String> = candidates.iter().map(|c| c.display().to_string()).collect();
        format!("`{path}` not found (tried {})", tried.join(", "))
    })
}

/// [`resolve_in`] the [`search_dirs`].
pub fn resolve(path: &str) -> Result<PathBuf, String> {
    resolve_in(path, &search_dirs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_fall_back_to_the_repository() {
        let p = resolve("config/skin_model.yaml").unwrap();
        assert!(p.is_file());
        let e = resolve_in("nope.yaml", &[PathBuf::from("/a"), PathBuf::from("/b")]).unwrap_err();
        assert_eq!(e, "`nope.yaml` not found (tried /a/nope.yaml, /b/nope.yaml)");
        let e = resolve_in("/abs/nope.yaml", &[PathBuf::from("/a")]).unwrap_err();
        assert_eq!(e, "`/abs/nope.yaml` not found (tried /abs/nope.yaml)");
    }
}
