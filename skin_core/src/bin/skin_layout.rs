//! `skin_layout`: generates a skin layout YAML by tiling cells over the collision geometry of
//! chosen URDF links (one patch per link): hexagonal grids on primitives, a Poisson-disk set on
//! meshes (STL, OBJ, DAE; or on their fitted boxes with `--meshes box`).
//!
//! ```text
//! skin_layout --urdf urdf/planar7.urdf --links link1,link2:0 --pitch 0.025 --out config/skin/planar7.yaml
//! ```
//!
//! `--links` takes `link` (all its collision elements) or `link:i+j` (elements i, j in document
//! order); `--faces link=+z,-z` restricts the box faces tiled on a link (default: all six);
//! `--spheres` also tiles spheres, `--caps` the end caps of cylinders and capsules;
//! `--patch-frame link|primitive` places the patch frames. It prints each patch's cells and the
//! share of its link's surface within one pitch of a cell that faces it
//! (`skin_core::skin::coverage`).
//! `package://` mesh URIs are searched in `--package-path` directories, then `ROS_PACKAGE_PATH`,
//! then `AMENT_PREFIX_PATH` (`skin_core::mesh::package`).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::{Parser, ValueEnum};
use nalgebra::Vector3;
use skin_core::mesh::{load_uri, MeshMode, PackagePath};
use skin_core::model::{RobotModel, Shape};
use skin_core::skin::coverage::coverage;
use skin_core::skin::generate::{generate_layout, GeneratorSpec, LinkSelection, PatchFrame};
use skin_core::skin::tiling::Face;

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FrameArg {
    Link,
    Primitive,
}

/// Tile skin cells over URDF collision primitives and write a skin layout YAML.
#[derive(Parser, Debug)]
#[command(name = "skin_layout", version)]
struct Args {
    /// URDF file.
    #[arg(long)]
    urdf: PathBuf,
    /// Comma-separated links to cover: `link` or `link:i+j` (collision element indices).
    #[arg(long, value_delimiter = ',', required_unless_present = "mesh_bounds")]
    links: Vec<String>,
    /// Cell centre distance in metres.
    #[arg(long, default_value_t = 0.025)]
    pitch: f64,
    /// Box faces to tile on a link, e.g. `left_palm=+z` or `base=+x,-x` (repeatable).
    #[arg(long)]
    faces: Vec<String>,
    /// Tile sphere primitives too.
    #[arg(long)]
    spheres: bool,
    /// Tile the end caps of cylinders (disks) and capsules (hemispheres) too.
    #[arg(long)]
    caps: bool,
    /// Patch frame placement.
    #[arg(long, value_enum, default_value_t = FrameArg::Primitive)]
    patch_frame: FrameArg,
    /// Mesh collision elements: cells on the mesh surface (`mesh`) or on its fitted box (`box`).
    #[arg(long, default_value = "mesh")]
    meshes: MeshMode,
    /// Directory searched for `package://` mesh URIs before ROS_PACKAGE_PATH and
    /// AMENT_PREFIX_PATH: one that contains package directories, or a package itself (repeatable).
    #[arg(long)]
    package_path: Vec<PathBuf>,
    /// Output YAML file.
    #[arg(long, required_unless_present = "mesh_bounds")]
    out: Option<PathBuf>,
    /// Instead of a layout: print every mesh collision element of the URDF as read (JSON: link,
    /// collision index, triangle count, bounding box in the element's frame, scale applied).
    #[arg(long)]
    mesh_bounds: bool,
}

/// The `--mesh-bounds` listing.
fn mesh_bounds(model: &RobotModel, urdf: &std::path::Path, path: &PackagePath) -> Result<String> {
    let mut rows = Vec::new();
    for f in 0..model.nframes() {
        for (i, c) in model.link_collisions(f).iter().enumerate() {
            let Shape::Mesh { filename, scale } = &c.shape else { continue };
            let link = &model.frame_names()[f];
            let m = load_uri(filename, scale, urdf, path).with_context(|| format!("link `{link}`"))?;
            let lo = m.vertices.iter().fold(Vector3::repeat(f64::MAX), |a, v| a.inf(v));
            let hi = m.vertices.iter().fold(Vector3::repeat(f64::MIN), |a, v| a.sup(v));
            rows.push(serde_json::json!({
                "link": link, "collision": i, "file": filename, "triangles": m.triangles.len(),
                "min": [lo.x, lo.y, lo.z], "max": [hi.x, hi.y, hi.z],
            }));
        }
    }
    Ok(serde_json::to_string(&rows)?)
}

fn quote(arg: &str) -> String {
    if !arg.is_empty() && arg.chars().all(|c| c.is_ascii_alphanumeric() || "-_./:=,+".contains(c)) {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    let model = RobotModel::from_urdf_file(&args.urdf).with_context(|| format!("loading {}", args.urdf.display()))?;
    let package_path = PackagePath::from_env(&args.package_path);
    if args.mesh_bounds {
        println!("{}", mesh_bounds(&model, &args.urdf, &package_path)?);
        return Ok(());
    }
    let out = args.out.clone().expect("required without --mesh-bounds");
    let links = args
        .links
        .iter()
        .map(|s| s.parse::<LinkSelection>().map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()?;
    let mut faces = Vec::new();
    for f in &args.faces {
        let Some((link, list)) = f.split_once('=') else {
            bail!("--faces `{f}`: expected `link=+z,-x`");
        };
        let list = list.split(',').map(str::parse::<Face>).collect::<Result<Vec<_>, _>>();
        faces.push((link.to_string(), list.map_err(anyhow::Error::msg)?));
    }
    let spec = GeneratorSpec {
        links,
        pitch_m: args.pitch,
        faces,
        spheres: args.spheres,
        caps: args.caps,
        patch_frame: match args.patch_frame {
            FrameArg::Link => PatchFrame::Link,
            FrameArg::Primitive => PatchFrame::Primitive,
        },
        meshes: args.meshes,
        package_path,
        skip_empty: false,
    };
    let layout = generate_layout(&model, &spec)?;
    // Sanity: the output must load and resolve like any other layout.
    let resolved = layout.resolve(&model).context("generated layout does not resolve")?;

    let command: Vec<String> =
        std::iter::once("skin_layout".to_string()).chain(std::env::args().skip(1).map(|a| quote(&a))).collect();
    let mut header = String::from("Skin layout generated by skin_layout (skin_core); regenerate instead of editing:\n");
    header += &format!("  {}\n", command.join(" "));
    header += &format!(
        "{} patches, {} cells, pitch {} m. Cell position and outward normal in the patch frame.",
        layout.patches.len(),
        layout.cells.len(),
        args.pitch
    );
    let text = layout.to_yaml(&header);
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(&out, text).with_context(|| format!("writing {}", out.display()))?;
    let covered = coverage(&model, &resolved, args.pitch);
    for p in &layout.patches {
        let n = layout.cells.iter().filter(|c| c.patch == p.id).count();
        let share = match covered.iter().find(|c| c.link == p.link).and_then(|c| c.covered()) {
            Some(share) => format!("{:>5.1} % of its surface covered", 100.0 * share),
            None => "coverage not measured (meshes are not sampled)".into(),
        };
        eprintln!("patch {:>3} {:<28} {:>4} cells, {share}", p.id, p.link, n);
    }
    eprintln!("{}: {} patches, {} cells", out.display(), layout.patches.len(), layout.cells.len());
    Ok(())
}
