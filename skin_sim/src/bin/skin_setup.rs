//! `skin_setup`: the files to run a new robot from its URDF: a skin layout on the links it
//! names, a controller setup, and a scene reaching a goal past a movable obstacle
//! (`skin_sim::new_robot`; walk-through in docs/new-robot.md).
//!
//! ```text
//! skin_setup --urdf panda.urdf --end-effector panda_hand --package-path <dir> --out out/panda
//! skin_sim run out/panda/panda_scene.yaml --controller out/panda/panda_controller.yaml
//! ```

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Parser;
use skin_core::mesh::MeshMode;
use skin_core::model::BASE_JOINTS;
use skin_sim::new_robot::base::with_planar_base;
use skin_sim::new_robot::{pose, write_files, Choices};

/// Write a skin layout, a controller setup and a reach-past-an-obstacle scene for a URDF.
#[derive(Parser, Debug)]
#[command(name = "skin_setup", version)]
struct Args {
    /// The robot's URDF.
    #[arg(long)]
    urdf: PathBuf,
    /// The link that reaches the goal.
    #[arg(long)]
    end_effector: String,
    /// The joints that move, comma-separated [default: every joint from the root to the end effector].
    #[arg(long, value_delimiter = ',')]
    arm_joints: Vec<String>,
    /// Keep the mobile base moving: the URDF's base_x_joint, base_y_joint, base_yaw_joint, or,
    /// when it has none, those joints added in front of its root link (written as
    /// `<out>/<name>_mobile.urdf`); without it the base is frozen.
    #[arg(long)]
    mobile_base: bool,
    /// Links to cover with skin, comma-separated [default: the links the arm joints carry that
    /// have collision geometry].
    #[arg(long, value_delimiter = ',')]
    skin_links: Vec<String>,
    /// Cell pitch [m].
    #[arg(long, default_value_t = 0.04)]
    pitch: f64,
    /// Mesh collision geometry as meshes (`mesh`: cells on the surface, convex hulls in MuJoCo)
    /// or as their fitted boxes (`box`).
    #[arg(long, default_value = "mesh")]
    meshes: MeshMode,
    /// Directory searched for `package://` mesh URIs before ROS_PACKAGE_PATH and
    /// AMENT_PREFIX_PATH (repeatable).
    #[arg(long)]
    package_path: Vec<PathBuf>,
    /// Start position of a joint, `name=value` (repeatable or comma-separated): arm joints keep
    /// it, other joints are frozen there [default: found for arm joints, 0 within the limits
    /// for the others].
    #[arg(long, value_delimiter = ',')]
    initial: Vec<String>,
    /// Scene duration [s].
    #[arg(long, default_value_t = 30.0)]
    duration: f64,
    /// File name prefix [default: the URDF's file stem].
    #[arg(long)]
    name: Option<String>,
    /// Output directory [default: out/<name>].
    #[arg(long)]
    out: Option<PathBuf>,
}

fn run(args: Args) -> Result<()> {
    let started = Instant::now();
    let name = args
        .name
        .clone()
        .unwrap_or_else(|| args.urdf.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or("robot".into()));
    let mut initial = BTreeMap::new();
    for kv in &args.initial {
        let Some((k, v)) = kv.split_once('=') else { bail!("--initial `{kv}`: expected `joint=value`") };
        let v: f64 = v.trim().parse().with_context(|| format!("--initial `{kv}`: not a number"))?;
        initial.insert(k.trim().to_string(), v);
    }
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("out").join(&name));
    let mut urdf = args.urdf.clone();
    if args.mobile_base {
        let text = std::fs::read_to_string(&urdf).with_context(|| format!("reading {}", urdf.display()))?;
        if !BASE_JOINTS.iter().all(|b| text.contains(&format!("\"{b}\""))) {
            let mobile = with_planar_base(&text, &urdf).map_err(anyhow::Error::msg)?;
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            urdf = dir.join(format!("{name}_mobile.urdf"));
            std::fs::write(&urdf, mobile).with_context(|| format!("writing {}", urdf.display()))?;
        }
    }
    let choices = Choices {
        urdf: urdf.clone(),
        name: name.clone(),
        end_effector: args.end_effector.clone(),
        arm_joints: args.arm_joints.clone(),
        skin_links: args.skin_links.clone(),
        mobile_base: args.mobile_base,
        pitch_m: args.pitch,
        meshes: args.meshes,
        package_path: args.package_path.clone(),
        initial,
        config_dir: skin_sim::scene::config_dir(),
        duration_s: args.duration,
    };
    let robot = choices.robot()?;
    let resolved = robot.layout.resolve(&robot.model).context("generated layout does not resolve")?;
    let skin_s = started.elapsed().as_secs_f64();
    let fixed: Vec<usize> = choices.initial.keys().filter_map(|k| robot.model.joint_index(k)).collect();
    let placement = pose::place(&robot, &resolved, &fixed).map_err(|reason| {
        skin_sim::new_robot::SetupChoiceError::Placement { urdf: urdf.display().to_string(), reason }
    })?;
    let command =
        std::iter::once("skin_setup".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let files = write_files(&choices, &robot, &placement, &dir, &command)?;
    for w in robot.model.warnings() {
        eprintln!("warning: {w}");
    }
    for p in &robot.layout.patches {
        let n = robot.layout.cells.iter().filter(|c| c.patch == p.id).count();
        eprintln!("patch {:>3} {:<28} {:>4} cells", p.id, p.link, n);
    }
    println!(
        "{name}: {} cells on {} links (loaded and tiled in {skin_s:.2} s), {} arm joints, goal {:.3} m from the start; \
         setup written in {:.2} s",
        robot.layout.cells.len(),
        robot.layout.patches.len(),
        robot.arm.len(),
        (placement.goal - placement.start).norm(),
        started.elapsed().as_secs_f64()
    );
    println!("  skin_sim run {} --controller {}", files.scene.display(), files.controller.display());
    Ok(())
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("skin_setup: {e:#}");
            ExitCode::from(2)
        }
    }
}
