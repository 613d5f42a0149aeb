//! `skin_model`: evaluates the robot model of a URDF at one or many states and prints JSON
//! (mass matrix, bias and gravity torques, optionally a point Jacobian and its J̇q̇). Used to
//! inspect models and by the reference tests against pinocchio and MuJoCo.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{anyhow, bail, Context, Result};
use clap::Parser;
use nalgebra::{DMatrix, DVector, Matrix6xX, Vector3, Vector6};
use serde::Deserialize;
use serde_json::{json, Value};
use skin_core::model::{
    bias_forces, crba, gravity, point_jacobian, point_jacobian_dot_qdot, update_kinematics, MimicMode, ModelData,
    RobotModel, UrdfOptions,
};

/// Evaluate kinematics and dynamics of a URDF robot model and print one JSON document.
///
/// Output keys: "joints" (names in model order), "mass_matrix" (n rows of n), "bias"
/// (C(q,q̇)q̇ + g(q)), "gravity" (g(q)); with --link also "jacobian" (6 rows of n, world axes,
/// linear rows first, for the point given in the link frame) and "jacobian_dot_qdot" (6, the
/// classical acceleration of that point and the angular acceleration for q̈ = 0).
/// Gravity is 9.81 m/s² along world -z. What loading repaired or accepted with reservations
/// (inertias) is printed to stderr as warnings naming the link; docs/dynamics.md ("Loading any
/// URDF") has the rules.
#[derive(Parser, Debug)]
#[command(name = "skin_model", version, about, long_about)]
struct Args {
    /// URDF file (plain URDF, no xacro).
    #[arg(long, value_name = "FILE")]
    urdf: PathBuf,
    /// Mimic joints: `independent` (each its own joint and coordinate, the <mimic> element
    /// ignored: pinocchio's default) or `follow` (q = multiplier * q_leader + offset, no
    /// coordinate of its own: pinocchio's mimic=True).
    #[arg(long, value_enum, default_value_t = Mimic::Independent)]
    mimic: Mimic,
    /// Joint positions, comma separated, in model order (see "joints" in the output).
    #[arg(long, value_name = "V1,V2,...", allow_hyphen_values = true, required_unless_present_any = ["batch", "joints"])]
    q: Option<String>,
    /// Joint velocities, comma separated (default: zeros).
    #[arg(long, value_name = "V1,V2,...", allow_hyphen_values = true)]
    qd: Option<String>,
    /// Link (frame) whose point Jacobian is printed.
    #[arg(long, value_name = "NAME")]
    link: Option<String>,
    /// Point in the link frame in metres (default 0,0,0); requires --link.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, requires = "link")]
    point: Option<String>,
    /// Batch mode: JSON list of states `{"q": [..], "qd": [..], "link": "name", "point": [x,y,z]}`
    /// ("qd", "link", "point" optional); prints a JSON list of result objects.
    #[arg(long, value_name = "STATES.json", conflicts_with_all = ["q", "qd", "link", "point"])]
    batch: Option<PathBuf>,
    /// Print the names of the generalized coordinates (the order of q) as a JSON list and exit.
    #[arg(long, conflicts_with_all = ["q", "qd", "link", "point", "batch"])]
    joints: bool,
}

/// `--mimic` values (see [`MimicMode`]).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Mimic {
    Independent,
    Follow,
}

/// One state of batch mode.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct State {
    q: Vec<f64>,
    #[serde(default)]
    qd: Option<Vec<f64>>,
    #[serde(default)]
    link: Option<String>,
    #[serde(default)]
    point: Option<[f64; 3]>,
}

fn parse_list(what: &str, s: &str) -> Result<Vec<f64>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            let v: f64 = t.parse().map_err(|_| anyhow!("--{what}: `{t}` is not a number"))?;
            if !v.is_finite() {
                bail!("--{what}: `{t}` is not a finite number");
            }
            Ok(v)
        })
        .collect()
}

fn check_len(model: &RobotModel, what: &str, v: &[f64]) -> Result<()> {
    if v.len() != model.nv() {
        bail!(
            "{what} has {} values but the model has {} joints: {}",
            v.len(),
            model.nv(),
            model.joint_names().join(", ")
        );
    }
    Ok(())
}

struct Evaluator<'a> {
    model: &'a RobotModel,
    data: ModelData,
    m: DMatrix<f64>,
    bias: DVector<f64>,
    g: DVector<f64>,
    j: Matrix6xX<f64>,
}

impl<'a> Evaluator<'a> {
    fn new(model: &'a RobotModel) -> Self {
        let n = model.nv();
        Self {
            model,
            data: ModelData::new(model),
            m: DMatrix::zeros(n, n),
            bias: DVector::zeros(n),
            g: DVector::zeros(n),
            j: Matrix6xX::zeros(n),
        }
    }

    fn eval(&mut self, q: &[f64], qd: Option<&[f64]>, link: Option<&str>, point: [f64; 3]) -> Result<Value> {
        let model = self.model;
        check_len(model, "q", q)?;
        let zeros = vec![0.0; model.nv()];
        let qd = qd.unwrap_or(&zeros);
        check_len(model, "qd", qd)?;
        let frame = match link {
            None => None,
            Some(name) => Some(model.frame_index(name).ok_or_else(|| {
                anyhow!("unknown link `{name}` in {}; known links: {}", model.source(), model.frame_names().join(", "))
            })?),
        };
        update_kinematics(model, &mut self.data, q, qd)?;
        crba(model, &mut self.data, &mut self.m)?;
        bias_forces(model, &mut self.data, &mut self.bias)?;
        gravity(model, &mut self.data, &mut self.g)?;
        let n = model.nv();
        let rows = |m: &DMatrix<f64>| -> Vec<Vec<f64>> { (0..n).map(|r| m.row(r).iter().copied().collect()).collect() };
        let mut out = json!({
            "joints": model.joint_names(),
            "mass_matrix": rows(&self.m),
            "bias": self.bias.as_slice(),
            "gravity": self.g.as_slice(),
        });
        if let Some(f) = frame {
            let p = Vector3::from(point);
            point_jacobian(model, &self.data, f, &p, &mut self.j)?;
            let mut jdqd = Vector6::zeros();
            point_jacobian_dot_qdot(model, &self.data, f, &p, &mut jdqd)?;
            let jrows: Vec<Vec<f64>> = (0..6).map(|r| self.j.row(r).iter().copied().collect()).collect();
            out["jacobian"] = json!(jrows);
            out["jacobian_dot_qdot"] = json!(jdqd.as_slice());
        }
        Ok(out)
    }
}

fn run(args: Args) -> Result<Value> {
    let mimic = match args.mimic {
        Mimic::Independent => MimicMode::Independent,
        Mimic::Follow => MimicMode::Follow,
    };
    let model = RobotModel::from_urdf_file_with(&args.urdf, &UrdfOptions { mimic })?;
    for w in model.warnings() {
        eprintln!("skin_model: warning: {}: {w}", model.source());
    }
    if args.joints {
        return Ok(json!(model.joint_names()));
    }
    let mut ev = Evaluator::new(&model);
    if let Some(batch) = &args.batch {
        let text = std::fs::read_to_string(batch).with_context(|| format!("cannot read {}", batch.display()))?;
        let states: Vec<State> = serde_json::from_str(&text)
            .with_context(|| format!("{}: expected a JSON list of states", batch.display()))?;
        let mut results = Vec::with_capacity(states.len());
        for (i, s) in states.iter().enumerate() {
            let r = ev
                .eval(&s.q, s.qd.as_deref(), s.link.as_deref(), s.point.unwrap_or([0.0; 3]))
                .with_context(|| format!("{}: state {i}", batch.display()))?;
            results.push(r);
        }
        return Ok(Value::Array(results));
    }
    let q = parse_list("q", args.q.as_deref().unwrap_or_default())?;
    let qd = args.qd.as_deref().map(|s| parse_list("qd", s)).transpose()?;
    let point = match &args.point {
        None => [0.0; 3],
        Some(s) => {
            let p = parse_list("point", s)?;
            <[f64; 3]>::try_from(p.as_slice()).map_err(|_| anyhow!("--point needs 3 values x,y,z, got {}", p.len()))?
        }
    };
    ev.eval(&q, qd.as_deref(), args.link.as_deref(), point)
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(args) {
        Ok(v) => {
            println!("{v}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("skin_model: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
