//! `skin_aggregator`: skin cells in, patch wrenches and RViz markers out (interactive-force-control paper eq. 6-8).
//! The node's wiring only; the work is in `crate::aggregator`. See docs/ros.md.
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::aggregator::Aggregator;
use crate::convert::{patch_frame_id, IssueKind};
use crate::nodes::{self, file_setting, resolve};
use crate::ros_params::StructParams;
use crate::tf::{FrameTransform, TfPublisher};
use crate::timing::Timing;
use crate::topics::{CELLS as CELLS_TOPIC, MARKERS as MARKERS_TOPIC, PATCHES as PATCHES_TOPIC};
use crate::{markers, qos, shutdown};
use anyhow::{Context as _, Result};
use clap::Parser;
use futures::{executor::LocalPool, task::LocalSpawnExt, StreamExt};
use r2r::skin_msgs::msg::PatchWrenchArray;
use r2r::visualization_msgs::msg::MarkerArray;
use r2r::{ParameterValue, RosParams};
use skin_core::model::RobotModel;
use skin_core::param_file::declare::Declared;
use skin_core::skin::layout::{ResolvedLayout, SkinLayout};
use skin_core::skin::params::SkinParams;

const NODE: &str = "skin_aggregator";

/// Aggregates skin cells (/skin/cells, skin_msgs/SkinCellArray) into patch wrenches
/// (/skin/patches, skin_msgs/PatchWrenchArray) and RViz markers (/skin/markers).
///
/// Files are given by these options, else by the ROS parameters urdf_file, layout_file,
/// skin_model_file (`--ros-args -p urdf_file:=... ` or `--params-file config/ros/skin_aggregator.yaml`),
/// else the defaults below. Relative paths are tried against the working directory, the installed
/// package's share directory, then the source repository. The skin model file gives the initial
/// values of the settable parameters (fusion.weight_force, ...), which the node's ROS parameters
/// override.
#[derive(Parser)]
#[command(
    version,
    after_help = "ROS arguments go after --ros-args, e.g.\n  skin_aggregator --ros-args --params-file config/ros/skin_aggregator.yaml -p fusion.weight_force:=0.8"
)]
struct Args {
    /// Robot URDF [default: urdf/tomm.urdf].
    #[arg(long, value_name = "FILE")]
    urdf: Option<String>,
    /// Skin layout [default: config/skin/tomm.yaml].
    #[arg(long, value_name = "FILE")]
    layout: Option<String>,
    /// Skin model parameter file (initial parameter values) [default: config/skin_model.yaml].
    #[arg(long, value_name = "FILE")]
    skin_model: Option<String>,
    #[command(flatten)]
    wait: nodes::SubscriberWait,
}

struct Setup {
    layout: ResolvedLayout,
    params: StructParams<SkinParams>,
}

fn setup(node: &r2r::Node, args: Args) -> Result<Setup> {
    let urdf = file_setting(node, args.urdf, "urdf_file", "urdf/tomm.urdf")?;
    let layout_file = file_setting(node, args.layout, "layout_file", "config/skin/tomm.yaml")?;
    let skin_model = file_setting(node, args.skin_model, "skin_model_file", "config/skin_model.yaml")?;
    let model = RobotModel::from_urdf_file(&resolve(&urdf, "urdf_file")?)?;
    let layout = SkinLayout::load(&resolve(&layout_file, "layout_file")?)?.resolve(&model)?;
    let defaults = SkinParams::load(&resolve(&skin_model, "skin_model_file")?)?;
    let mut params = StructParams::new(defaults, |p| p.validate().map_err(|e| e.to_string()))?
        .with_specs(SkinParams::all_specs())
        .with_read_only("urdf_file", ParameterValue::String(urdf), "Robot URDF (read at start)")
        .with_read_only("layout_file", ParameterValue::String(layout_file), "Skin layout (read at start)")
        .with_read_only(
            "skin_model_file",
            ParameterValue::String(skin_model),
            "Skin model file: initial values of the other parameters (read at start)",
        );
    // Here rather than inside r2r's registration: this error says where the value came from.
    params
        .apply_overrides(&node.params.lock().unwrap())
        .context("ROS parameter overrides (--ros-args -p / --params-file)")?;
    Ok(Setup { layout, params })
}

/// Runs `skin_aggregator` until SIGINT/SIGTERM: its command line parsed here, then its topics wired to
/// [`crate::aggregator`].
pub fn main() -> Result<()> {
    // clap sees the arguments before --ros-args; rcl parses the rest.
    let args = Args::parse_from(std::env::args().take_while(|a| a != "--ros-args"));
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, NODE, "")?;
    let logger = node.logger().to_string();
    let args_wait = args.wait.clone();
    let Setup { layout, params } = setup(&node, args)?;
    let params = Arc::new(Mutex::new(params));
    let served: Arc<Mutex<dyn RosParams + Send>> = params.clone();
    let (param_services, mut param_changes) =
        node.make_derived_parameter_handler(served).context("declaring the parameters")?;
    // Read from the serialized bytes (convert::cdr_cells: no C message per message).
    let mut cells =
        node.subscribe_raw(nodes::local(CELLS_TOPIC), crate::topics::CELLS_TYPE, qos::sensor_input(1000))?;
    let patches_pub = node.create_publisher::<PatchWrenchArray>(nodes::local(PATCHES_TOPIC), qos::stream())?;
    let markers_pub = node.create_publisher::<MarkerArray>(nodes::local(MARKERS_TOPIC), qos::stream())?;
    // The patch frames {p_j} that /skin/patches is expressed in, fixed in their links.
    let _patch_frames = match TfPublisher::new(&mut node)? {
        Ok(tf) => {
            let frames: Vec<FrameTransform> = layout
                .patches()
                .iter()
                .map(|p| FrameTransform {
                    parent: p.link.clone(),
                    child: patch_frame_id(p.id),
                    pose: p.link_from_patch,
                })
                .collect();
            tf.send_static(&frames, &r2r::builtin_interfaces::msg::Time::default())
                .context(crate::topics::TF_STATIC)?;
            Some(tf)
        }
        Err(why) => {
            r2r::log_warn!(&logger, "{why} (the patch frames skin_patch_<id> of {PATCHES_TOPIC})");
            None
        }
    };
    r2r::log_info!(
        &logger,
        "{} -> {}, {}: layout {} ({} patches, {} cells)",
        CELLS_TOPIC,
        PATCHES_TOPIC,
        MARKERS_TOPIC,
        layout.source(),
        layout.patches().len(),
        layout.num_cells()
    );

    args_wait.wait(NODE, &[PATCHES_TOPIC.into(), MARKERS_TOPIC.into()], |topic| match topic {
        PATCHES_TOPIC => Some(patches_pub.get_inter_process_subscription_count()),
        MARKERS_TOPIC => Some(markers_pub.get_inter_process_subscription_count()),
        _ => None,
    })?;

    let mut pool = LocalPool::new();
    let spawner = pool.spawner();
    spawner.spawn_local(param_services)?;
    let log = logger.clone();
    spawner.spawn_local(async move {
        while let Some((name, value)) = param_changes.next().await {
            r2r::log_info!(&log, "parameter {name} set to {value:?}");
        }
    })?;
    let aggregator = Arc::new(Mutex::new(Aggregator::new(layout)));
    // Per message: the aggregation (cells in, both messages built) and the whole cycle (with
    // publishing).
    let timing = Arc::new(Mutex::new((Timing::default(), Timing::default())));
    let (agg, time, log) = (aggregator.clone(), timing.clone(), logger.clone());
    let markers_out = markers_pub.clone();
    spawner.spawn_local(async move {
        let mut logged = [false; IssueKind::ALL.len()];
        let mut logged_refusal = false;
        let mut publish_failed = false;
        while let Some(msg) = cells.next().await {
            let start = Instant::now();
            let fusion = params.lock().unwrap().value().fusion;
            let mut agg = agg.lock().unwrap();
            let read = agg.process(&msg, &fusion, |issue| {
                // Each kind once, with an example; the counts go into the shutdown summary.
                if !std::mem::replace(&mut logged[issue.kind as usize], true) {
                    r2r::log_warn!(&log, "{CELLS_TOPIC}: {issue} (further ones are counted, totals at shutdown)");
                }
            });
            let (patches, markers) = match read {
                Ok(out) => out,
                Err(e) => {
                    if !std::mem::replace(&mut logged_refusal, true) {
                        r2r::log_warn!(&log, "{CELLS_TOPIC}: {e} (further refusals are counted, total at shutdown)");
                    }
                    continue;
                }
            };
            let built = start.elapsed();
            let sent = patches_pub.publish(patches).map_err(|e| format!("{PATCHES_TOPIC}: {e}")).and_then(|_| {
                if markers.markers.is_empty() {
                    Ok(())
                } else {
                    markers_out.publish(markers).map_err(|e| format!("{MARKERS_TOPIC}: {e}"))
                }
            });
            if let Err(e) = sent {
                if !std::mem::replace(&mut publish_failed, true) {
                    r2r::log_error!(&log, "publishing failed: {e}");
                }
            }
            let mut time = time.lock().unwrap();
            time.0.add(built);
            time.1.add(start.elapsed());
        }
    })?;

    while !shutdown::requested() {
        node.spin_once(Duration::from_millis(20));
        pool.run_until_stalled();
    }
    // Leave RViz clean: the markers would otherwise stay on screen.
    let clear = MarkerArray { markers: vec![markers::delete_all()] };
    if let Err(e) = markers_pub.publish(&clear) {
        r2r::log_warn!(&logger, "{MARKERS_TOPIC}: clearing the markers failed: {e}");
    }
    let (issues, refused) = {
        let agg = aggregator.lock().unwrap();
        (*agg.issues(), agg.refused())
    };
    let (aggregation, cycle) = &*timing.lock().unwrap();
    r2r::log_info!(
        &logger,
        "stopping after {} messages: aggregation {aggregation}, with publishing {cycle}; bad input: {issues}; messages refused: {refused}",
        cycle.count
    );
    shutdown::bound_teardown(0);
    Ok(())
}
