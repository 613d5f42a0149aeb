//! Where a URDF's mesh files are: `package://<pkg>/<path>` URIs resolved over a search path
//! (as ROS does), `file://` URIs and plain paths relative to the URDF's directory.
//!
//! The search path, in order: the directories given explicitly (`--package-path`), then every
//! entry of `ROS_PACKAGE_PATH` (ROS 1 style: `<dir>/<pkg>/<path>`, and `<dir>` itself when it is
//! the package, i.e. its name is `<pkg>`), then every prefix of `AMENT_PREFIX_PATH` (ROS 2 style:
//! `<prefix>/share/<pkg>/<path>`). The first existing file wins.

use std::path::{Path, PathBuf};

use super::error::MeshError;

/// The directories `package://` URIs are searched in (see the module documentation).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PackagePath {
    /// Directories that contain packages (`<dir>/<pkg>`), or are one.
    pub package_dirs: Vec<PathBuf>,
    /// Install prefixes (`<prefix>/share/<pkg>`).
    pub prefixes: Vec<PathBuf>,
}

fn split_env(name: &str) -> Vec<PathBuf> {
    std::env::var_os(name)
        .map(|v| std::env::split_paths(&v).filter(|p| !p.as_os_str().is_empty()).collect())
        .unwrap_or_default()
}

impl PackagePath {
    /// `explicit` directories first, then `ROS_PACKAGE_PATH`, then `AMENT_PREFIX_PATH`.
    pub fn from_env(explicit: &[PathBuf]) -> Self {
        let mut package_dirs = explicit.to_vec();
        package_dirs.extend(split_env("ROS_PACKAGE_PATH"));
        PackagePath { package_dirs, prefixes: split_env("AMENT_PREFIX_PATH") }
    }

    /// Every place `package://pkg/rest` may be, in search order.
    fn candidates(&self, pkg: &str, rest: &str) -> Vec<PathBuf> {
        let mut out = Vec::new();
        for d in &self.package_dirs {
            out.push(d.join(pkg).join(rest));
            if d.file_name().is_some_and(|n| n == pkg) {
                out.push(d.join(rest));
            }
        }
        for p in &self.prefixes {
            out.push(p.join("share").join(pkg).join(rest));
        }
        out
    }

    /// The file of a mesh `uri` of the URDF at `urdf` (`package://`, `file://`, or a path
    /// relative to the URDF's directory). Errors name the URI and the places searched.
    pub fn resolve(&self, uri: &str, urdf: &Path) -> Result<PathBuf, MeshError> {
        if let Some(rest) = uri.strip_prefix("package://") {
            let (pkg, path) = rest.split_once('/').unwrap_or((rest, ""));
            let candidates = self.candidates(pkg, path);
            return candidates.iter().find(|p| p.is_file()).cloned().ok_or_else(|| MeshError::NotFound {
                uri: uri.to_string(),
                searched: if candidates.is_empty() {
                    "no package directories (give --package-path, or set ROS_PACKAGE_PATH or AMENT_PREFIX_PATH)".into()
                } else {
                    candidates.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
                },
            });
        }
        let path = PathBuf::from(uri.strip_prefix("file://").unwrap_or(uri));
        let path = if path.is_absolute() { path } else { urdf.parent().unwrap_or(Path::new(".")).join(path) };
        if path.is_file() {
            Ok(path)
        } else {
            Err(MeshError::NotFound { uri: uri.to_string(), searched: path.display().to_string() })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolves_in_order_and_names_the_uri() {
        let dir = std::env::temp_dir().join(format!("skin_pkg_{}", std::process::id()));
        let file = dir.join("share/my_robot/meshes/a.stl");
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, b"x").unwrap();
        let urdf = dir.join("robot.urdf");
        let ament = PackagePath { package_dirs: vec![], prefixes: vec![dir.clone()] };
        assert_eq!(ament.resolve("package://my_robot/meshes/a.stl", &urdf).unwrap(), file);
        let ros1 = PackagePath { package_dirs: vec![dir.join("share")], prefixes: vec![] };
        assert_eq!(ros1.resolve("package://my_robot/meshes/a.stl", &urdf).unwrap(), file);
        let itself = PackagePath { package_dirs: vec![dir.join("share/my_robot")], prefixes: vec![] };
        assert_eq!(itself.resolve("package://my_robot/meshes/a.stl", &urdf).unwrap(), file);
        assert_eq!(ament.resolve("share/my_robot/meshes/a.stl", &urdf).unwrap(), file);
        let e = ament.resolve("package://other/x.stl", &urdf).unwrap_err().to_string();
        assert!(e.contains("package://other/x.stl") && e.contains("share/other/x.stl"), "{e}");
        let e = PackagePath::default().resolve("package://other/x.stl", &urdf).unwrap_err().to_string();
        assert!(e.contains("--package-path"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
