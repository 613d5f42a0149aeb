//! `skin_touch`: what the skin and the model make of one virtual touch, for tuning and debugging.
//!
//! A spherical fingertip approaches (or presses on) the skin of a link at a chosen cell; the
//! command derives every cell's proximity and force signals through the skin characteristics,
//! then reports what the controllers will see: the patch wrenches of interactive-force-control paper eq. (6)-(8) and
//! the joint torques of intentional-contact paper eq. (3)-(4) (proximity repulsion), eq. (6) (contact) and
//! interactive-force-control paper eq. (13)-(14) (patch wrenches).
//!
//! ```text
//! skin_touch --urdf urdf/tomm.urdf --layout config/skin/tomm.yaml --params config/skin_model.yaml \
//!            --link right_forearm_link --distance 0.03
//! skin_touch ... --link right_forearm_link --force 5
//! ```
use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Parser;
use nalgebra::{DVector, Point3, Vector3};
use serde_json::json;
use skin_core::model::{update_kinematics, ModelData, RobotModel};
use skin_core::skin::aggregate::{aggregate_patches, PatchWrench};
use skin_core::skin::cell_forces::{cell_contact_forces, cell_repulsion_forces};
use skin_core::skin::layout::{ResolvedLayout, SkinLayout};
use skin_core::skin::params::SkinParams;
use skin_core::skin::signals::CellReading;
use skin_core::skin::torques::{patch_wrenches_to_torques, point_forces_to_torques};

#[derive(Parser)]
#[command(
    about = "Touch the skin with a virtual fingertip and print the patch wrenches and joint torques it causes",
    long_about = None
)]
struct Args {
    /// Robot URDF.
    #[arg(long, value_name = "FILE")]
    urdf: PathBuf,
    /// Skin layout (config/skin/<robot>.yaml).
    #[arg(long, value_name = "FILE")]
    layout: PathBuf,
    /// Skin model parameters (config/skin_model.yaml).
    #[arg(long, value_name = "FILE")]
    params: PathBuf,
    /// Link to touch; the touch is centred on the first cell of the link unless --cell is given.
    #[arg(long, value_name = "NAME", required_unless_present = "cell")]
    link: Option<String>,
    /// Cell id to centre the touch on.
    #[arg(long, value_name = "ID")]
    cell: Option<u32>,
    /// Gap between the fingertip and the cell along the cell normal [m] (0: touching).
    #[arg(long, default_value_t = 0.0, value_name = "M")]
    distance: f64,
    /// Total force the fingertip presses with when touching [N].
    #[arg(long, default_value_t = 0.0, value_name = "N")]
    force: f64,
    /// Fingertip radius [m].
    #[arg(long, default_value_t = 0.01, value_name = "M")]
    radius: f64,
    /// Joint positions in model order (default: all zero).
    #[arg(long, value_name = "V1,V2,...", allow_hyphen_values = true, value_delimiter = ',')]
    q: Option<Vec<f64>>,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
}

fn main() {
    if let Err(e) = run(Args::parse()) {
        eprintln!("skin_touch: {e:#}");
        std::process::exit(2);
    }
}

/// The fingertip: a sphere in world coordinates pressing with `force` when it touches.
struct Fingertip {
    centre: Vector3<f64>,
    radius: f64,
    force: f64,
}

fn run(a: Args) -> Result<()> {
    if !(a.distance.is_finite() && a.distance >= 0.0) {
        bail!("--distance must be a finite value >= 0 m, got {}", a.distance);
    }
    if !(a.force.is_finite() && a.force >= 0.0) {
        bail!("--force must be a finite value >= 0 N, got {}", a.force);
    }
    if a.force > 0.0 && a.distance > 0.0 {
        bail!("a fingertip presses only when it touches: give --distance 0 with --force");
    }
    if !(a.radius.is_finite() && a.radius > 0.0) {
        bail!("--radius must be a finite value > 0 m, got {}", a.radius);
    }
    let model = RobotModel::from_urdf_file(&a.urdf)?;
    let layout = SkinLayout::load(&a.layout)?.resolve(&model)?;
    let params = SkinParams::load(&a.params)?;
    let n = model.nv();
    let q = a.q.clone().unwrap_or_else(|| vec![0.0; n]);
    let mut data = ModelData::new(&model);
    update_kinematics(&model, &mut data, &q, &vec![0.0; n])?;

    let target = target_cell(&a, &model, &layout)?;
    let cell = &layout.cells()[target];
    let pose = data.frame_pose(cell.frame);
    let normal = pose.rotation * cell.normal_link;
    let tip = Fingertip {
        centre: (pose * Point3::from(cell.position_link)).coords + normal * (a.distance + a.radius),
        radius: a.radius,
        force: a.force,
    };
    let readings = touch_readings(&layout, &data, &tip, &params);

    let mut wrenches = Vec::new();
    aggregate_patches(&layout, &readings, &params.fusion, &mut wrenches)?;
    let frame_pose = |f: usize| data.frame_pose(f);
    let (mut repulsion, mut contact) = (Vec::new(), Vec::new());
    cell_repulsion_forces(&layout, &readings, &params.proximity, &params.repulsion, frame_pose, &mut repulsion)?;
    cell_contact_forces(&layout, &readings, &params.force, &params.fusion, frame_pose, &mut contact)?;
    let (mut tau_d, mut tau_c, mut tau_skin) = (DVector::zeros(n), DVector::zeros(n), DVector::zeros(n));
    point_forces_to_torques(&model, &data, &repulsion, &mut tau_d);
    point_forces_to_torques(&model, &data, &contact, &mut tau_c);
    patch_wrenches_to_torques(&model, &data, &layout, &wrenches, |_| true, &mut tau_skin);

    let touched: Vec<usize> =
        (0..readings.len()).filter(|&i| readings[i].proximity > 0.0 || readings[i].force[0] > 0.0).collect();
    if a.json {
        let patches: Vec<_> = active_patches(&wrenches)
            .map(|(j, w)| {
                json!({"patch": layout.patches()[j].id, "link": layout.patches()[j].link,
                       "force": w.force.as_slice(), "moment": w.moment.as_slice(),
                       "centroid": w.centroid.as_slice(), "active_cells": w.active_cells})
            })
            .collect();
        let out = json!({
            "cell": cell.id, "touched_cells": touched.len(), "patches": patches,
            "joints": model.joint_names(),
            "tau_repulsion": tau_d.as_slice(), "tau_contact": tau_c.as_slice(),
            "tau_patches": tau_skin.as_slice(),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "fingertip r = {:.3} m, {:.3} m off cell {} of {} ({}), pressing {:.2} N: {} cells sense it",
        a.radius,
        a.distance,
        cell.id,
        layout.patches()[cell.patch].link,
        layout.source(),
        a.force,
        touched.len()
    );
    println!("\npatch wrenches (patch frame, fused signal units, interactive-force-control paper eq. 6-8):");
    println!("  {:>5} {:<24} {:>6} {:>26} {:>26}", "patch", "link", "active", "force", "moment");
    for (j, w) in active_patches(&wrenches) {
        println!(
            "  {:>5} {:<24} {:>6} {:>26} {:>26}",
            layout.patches()[j].id,
            layout.patches()[j].link,
            w.active_cells,
            fmt3(&w.force),
            fmt3(&w.moment)
        );
    }
    println!("\njoint torques [N m or N]:");
    println!("  {:<28} {:>14} {:>14} {:>14}", "joint", "repulsion(e4)", "contact(e6)", "patches(e14)");
    for (j, name) in model.joint_names().iter().enumerate() {
        if tau_d[j] != 0.0 || tau_c[j] != 0.0 || tau_skin[j] != 0.0 {
            println!("  {:<28} {:>14.4} {:>14.4} {:>14.4}", name, tau_d[j], tau_c[j], tau_skin[j]);
        }
    }
    Ok(())
}

/// The cell the touch is centred on: --cell, or the first cell on --link.
fn target_cell(a: &Args, model: &RobotModel, layout: &ResolvedLayout) -> Result<usize> {
    if let Some(id) = a.cell {
        return layout.cell_index(id).ok_or_else(|| anyhow!("no cell with id {id} in {}", layout.source()));
    }
    let link = a.link.as_deref().unwrap_or_default();
    let frame = model
        .frame_index(link)
        .ok_or_else(|| anyhow!("no link '{link}' in {}; links: {}", model.source(), model.frame_names().join(", ")))?;
    layout
        .cells()
        .iter()
        .position(|c| c.frame == frame)
        .with_context(|| format!("link '{link}' carries no skin cell in {}", layout.source()))
}

/// Every cell's readings under the fingertip: proximity from the gap along the cell normal to the
/// sphere (the cell's optical sensor looks along its normal); a pressing fingertip's force is
/// shared among the cells under it, weighted by how close each is to the fingertip.
fn touch_readings(layout: &ResolvedLayout, data: &ModelData, tip: &Fingertip, p: &SkinParams) -> Vec<CellReading> {
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    let mut depth = vec![0.0; layout.num_cells()];
    for (i, c) in layout.cells().iter().enumerate() {
        let pose = data.frame_pose(c.frame);
        let pos = (pose * Point3::from(c.position_link)).coords;
        let n = pose.rotation * c.normal_link;
        let rel = tip.centre - pos;
        let along = rel.dot(&n);
        let lateral = (rel - n * along).norm();
        if along <= 0.0 || lateral >= tip.radius {
            continue; // the sphere is behind the cell or off its line of sight
        }
        let half_chord = (tip.radius * tip.radius - lateral * lateral).sqrt();
        let gap = (along - half_chord).max(0.0);
        readings[i].proximity = p.proximity.signal(gap);
        depth[i] = (tip.radius - gap).max(0.0); // how far the (soft) fingertip reaches past this cell's gap
    }
    if tip.force > 0.0 {
        let total: f64 = depth.iter().sum();
        for (r, d) in readings.iter_mut().zip(&depth) {
            if *d > 0.0 && total > 0.0 {
                r.force = [p.force.signal(tip.force * d / total); 3];
            }
        }
    }
    readings
}

fn active_patches(w: &[PatchWrench]) -> impl Iterator<Item = (usize, &PatchWrench)> {
    w.iter().enumerate().filter(|(_, w)| w.active_cells > 0)
}

fn fmt3(v: &Vector3<f64>) -> String {
    format!("[{:7.3} {:7.3} {:7.3}]", v[0], v[1], v[2])
}
