//! Latency of the ROS graph (make bench): a probe publishes the task controller's inputs for
//! TOMM at 250 Hz, a 718-cell `/skin/cells` last (it completes the input set of a period), and
//! times from that publish to the right arm's command (`Float64MultiArray`) that the cycle sends.
//! One period at a time, so every command belongs to the period just sent. Start the controller
//! first: `task_controller --setup config/controller/tomm.yaml --ros-args -p trigger:=inputs -p
//! supervisor:=internal`. Prints `{"ros_latency_p50_us": .., "ros_latency_p99_us": ..}`.
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use clap::Parser;
use futures::{FutureExt, StreamExt};
use r2r::builtin_interfaces::msg::Time;
use r2r::nav_msgs::msg::Odometry;
use r2r::sensor_msgs::msg::{JointState, LaserScan};
use r2r::skin_msgs::msg::SkinCellArray;
use r2r::std_msgs::msg::Float64MultiArray;
use r2r::NativeMsg;
use skin_control::qos;
use skin_core::controller::ControllerConfig;

#[derive(Parser)]
#[command(about = "Times /skin/cells -> arm command through a running task_controller (trigger:=inputs)")]
struct Args {
    /// Controller setup (the robot's joints and skin layout).
    #[arg(long, default_value = "config/controller/tomm.yaml")]
    setup: std::path::PathBuf,
    /// Periods to time.
    #[arg(long, default_value_t = 2000)]
    periods: usize,
    /// Publishing rate of the input sets [Hz].
    #[arg(long, default_value_t = 250.0)]
    rate_hz: f64,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() -> Result<()> {
    let args = Args::parse();
    let config = ControllerConfig::load(&args.setup).with_context(|| args.setup.display().to_string())?;
    let model = &config.model;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, "ros_latency", "")?;
    let joints_pub = node.create_publisher::<JointState>("/joint_states", qos::stream())?;
    let odom_pub = node.create_publisher::<Odometry>("/base/odom", qos::stream())?;
    let scan_pub = node.create_publisher::<LaserScan>("/scan", qos::stream())?;
    let cells_pub = node.create_publisher::<SkinCellArray>("/skin/cells", qos::stream())?;
    let mut commands =
        node.subscribe::<Float64MultiArray>("/right_arm/forward_velocity_controller/commands", qos::stream())?;

    // the robot at its posture, at rest; a dozen cells see something (the avoidance level is
    // filled), every cell is in the message (the whole conversion and aggregation path)
    let arm: Vec<usize> = (0..model.nv()).filter(|&j| !model.joint_names()[j].starts_with("base_")).collect();
    let mut joints = JointState {
        name: arm.iter().map(|&j| model.joint_names()[j].clone()).collect(),
        position: arm.iter().map(|&j| config.setup.posture[j]).collect(),
        velocity: vec![0.0; arm.len()],
        ..Default::default()
    };
    let mut odom = Odometry::default();
    odom.pose.pose.orientation.w = 1.0;
    let mut scan = LaserScan {
        header: r2r::std_msgs::msg::Header { frame_id: "laser".into(), ..Default::default() },
        angle_min: -std::f32::consts::PI,
        angle_max: std::f32::consts::PI,
        angle_increment: std::f32::consts::TAU / 360.0,
        range_min: 0.05,
        range_max: 8.0,
        ranges: vec![8.5; 360],
        ..Default::default()
    };
    let n = config.layout.num_cells();
    let cells = SkinCellArray {
        cell_id: config.layout.cells().iter().map(|c| c.id).collect(),
        force: vec![0.0; 3 * n],
        proximity: (0..n).map(|i| if i % 60 == 0 { 0.6 } else { 0.0 }).collect(),
        // every signal a real cell sends: the acceleration (gravity) and the temperature too
        acceleration: (0..n).flat_map(|_| [0.0, 0.0, 9.81]).collect(),
        temperature: vec![30.0; n],
        ..Default::default()
    };

    // The skin driver keeps its message in the middleware's (C) form and updates it in place
    // each period, as a C++ driver would: r2r's `publish` of the Rust message would first copy
    // it into a new C message (an allocation per array).
    let mut cells = NativeMsg::<SkinCellArray>::from(&cells);

    // wait until the controller listens to every input
    let start = Instant::now();
    while [joints_pub.get_inter_process_subscription_count()?, cells_pub.get_inter_process_subscription_count()?]
        .contains(&0)
    {
        node.spin_once(Duration::from_millis(20));
        if start.elapsed() > Duration::from_secs(30) {
            bail!("no task_controller subscribed to /joint_states and /skin/cells within 30 s");
        }
    }
    let mut clock = r2r::Clock::create(r2r::ClockType::RosTime)?;
    let period = Duration::from_secs_f64(1.0 / args.rate_hz);
    let mut latencies = Vec::with_capacity(args.periods);
    let warmup = 50;
    let mut next = Instant::now();
    for k in 0..args.periods + warmup {
        let stamp: Time = r2r::Clock::to_builtin_time(&clock.get_now()?);
        joints.header.stamp = stamp.clone();
        odom.header.stamp = stamp.clone();
        scan.header.stamp = stamp.clone();
        (cells.header.stamp.sec, cells.header.stamp.nanosec) = (stamp.sec, stamp.nanosec);
        joints_pub.publish(&joints)?;
        odom_pub.publish(&odom)?;
        scan_pub.publish(&scan)?;
        let sent = Instant::now();
        cells_pub.publish_native(&mut cells)?;
        loop {
            // rcl_wait returns as soon as the command arrives: a longer timeout only spares the
            // controller the probe's polling (both share the machine's cores)
            node.spin_once(Duration::from_millis(50));
            if commands.next().now_or_never().flatten().is_some() {
                break;
            }
            if sent.elapsed() > Duration::from_secs(5) {
                bail!("no arm command within 5 s of period {k}: is task_controller running with trigger:=inputs?");
            }
        }
        if k >= warmup {
            latencies.push(sent.elapsed().as_secs_f64() * 1e6);
        }
        next += period;
        if let Some(wait) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    }
    latencies.sort_by(f64::total_cmp);
    println!(
        "{{\"ros_latency_p50_us\": {:.1}, \"ros_latency_p99_us\": {:.1}}}",
        percentile(&latencies, 0.5),
        percentile(&latencies, 0.99)
    );
    Ok(())
}
