//! `skin_watchdog`: zero commands when the task controller stops. A small process of its own
//! (r2r, std_msgs, geometry_msgs and the decision in `crate::watchdog`; no model, no
//! controller code), started beside the controller; see docs/reliability.md.
use std::time::{Duration, Instant};

use crate::heartbeat::CommandType;
use crate::nodes::{local, ros_now};
use crate::tf::BASE_FRAME;
use crate::topics::{CMD_VEL, WATCHDOG};
use crate::watchdog::{Verdict, Watchdog};
use crate::{heartbeat, nodes, qos, shutdown};
use anyhow::{Context as _, Result};
use clap::Parser;
use futures::{FutureExt as _, StreamExt as _};
use r2r::geometry_msgs::msg::{Twist, TwistStamped};
use r2r::std_msgs::msg::{Float64MultiArray, Header};

/// Watches /controller/heartbeat (sent by task_controller with every period's commands). When it
/// has been silent for longer than --timeout-s (the controller crashed, was killed, hangs, or its
/// link is down), publishes zero velocities on every command topic, repeats them every
/// --hold-period-s until heartbeats return, and announces the trip on /controller/watchdog (the
/// controller then continues from zero). Until the first heartbeat the topics are held at zero.
///
/// It cannot cover its own death nor a lost link between itself and the robot drivers: the robot
/// side must add its own command timeouts (UR protective stop / external control timeout, the base
/// driver's cmd_vel timeout).
#[derive(Parser)]
#[command(
    version,
    after_help = "Examples:\n  skin_watchdog                      # TOMM: both UR5 arms and the base\n  skin_watchdog --arm /arm/forward_velocity_controller/commands=7 --no-base --timeout-s 0.1"
)]
struct Args {
    /// An arm's command topic (std_msgs/Float64MultiArray) and its joint count; repeat per arm
    /// [default: left_arm/forward_velocity_controller/commands=6 right_arm/forward_velocity_controller/commands=6,
    /// relative: under the node's namespace].
    #[arg(long = "arm", value_name = "TOPIC=N", value_parser = arm_topic)]
    arms: Vec<(String, usize)>,
    /// The base's twist topic (geometry_msgs/Twist; relative: under the node's namespace).
    #[arg(long, value_name = "TOPIC", default_value = local(CMD_VEL))]
    base: String,
    /// The base's topic carries geometry_msgs/TwistStamped (task_controller's
    /// base_command_stamped; the zeros in frame base_link, stamped with the node's clock).
    #[arg(long)]
    base_stamped: bool,
    /// No base topic (a fixed arm).
    #[arg(long)]
    no_base: bool,
    /// Also zero the command topics that heartbeats name (`<topic>=<joints>`, the base's twist
    /// topic), from the first heartbeat that names them on: a simulation of any robot. The
    /// topics given above are zeroed from the start (a robot: publishers long discovered when
    /// they are needed).
    #[arg(long)]
    learn_topics: bool,
    /// Heartbeat silence that trips [s] (default: 1.5 periods of the controller's 125 Hz, so the
    /// zeros leave within 2 periods of the last command).
    #[arg(long, value_name = "S", default_value_t = 0.012, value_parser = seconds)]
    timeout_s: f64,
    /// Period of the repeated zeros while tripped [s].
    #[arg(long, value_name = "S", default_value_t = 0.008, value_parser = seconds)]
    hold_period_s: f64,
}

/// A base's command publisher, of the type the base takes.
enum BasePublisher {
    Twist(r2r::Publisher<Twist>),
    Stamped(r2r::Publisher<TwistStamped>),
}

/// The command topics and their zero messages.
#[derive(Default)]
struct Outputs {
    arms: Vec<(String, r2r::Publisher<Float64MultiArray>, Float64MultiArray)>,
    bases: Vec<(String, BasePublisher)>,
}

impl Outputs {
    /// A command topic of type `kind`.
    fn add(&mut self, node: &mut r2r::Node, topic: &str, kind: CommandType) -> r2r::Result<()> {
        let name = topic.to_string();
        match kind {
            CommandType::Arm(n) => {
                let msg = Float64MultiArray { data: vec![0.0; n], ..Default::default() };
                self.arms.push((name, node.create_publisher(topic, qos::stream())?, msg));
            }
            CommandType::Twist => {
                self.bases.push((name, BasePublisher::Twist(node.create_publisher(topic, qos::stream())?)))
            }
            CommandType::TwistStamped => {
                self.bases.push((name, BasePublisher::Stamped(node.create_publisher(topic, qos::stream())?)))
            }
        }
        Ok(())
    }

    fn topics(&self) -> Vec<String> {
        self.arms.iter().map(|a| a.0.clone()).chain(self.bases.iter().map(|b| b.0.clone())).collect()
    }

    /// Zeros on every topic; a stamped twist carries `now_s` (the node's clock) and frame
    /// base_link.
    fn zeros(&self, now_s: f64) -> r2r::Result<()> {
        for (_, p, m) in &self.arms {
            p.publish(m)?;
        }
        for (_, base) in &self.bases {
            match base {
                BasePublisher::Twist(p) => p.publish(&Twist::default())?,
                BasePublisher::Stamped(p) => {
                    let stamp = crate::convert::robot::time_msg(now_s);
                    let header = Header { stamp, frame_id: BASE_FRAME.into() };
                    p.publish(&TwistStamped { header, twist: Twist::default() })?
                }
            }
        }
        Ok(())
    }
}

fn arm_topic(s: &str) -> Result<(String, usize), String> {
    let (topic, n) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected TOPIC=N"))?;
    match n.parse() {
        Ok(n) if n > 0 && !topic.is_empty() => Ok((topic.to_string(), n)),
        _ => Err(format!("`{s}`: expected TOPIC=N with N > 0 joints")),
    }
}

fn seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("`{s}`: {e}"))?;
    if (0.001..=10.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v}: must be in [0.001, 10] s"))
    }
}

/// Runs `skin_watchdog` until SIGINT/SIGTERM: its command line parsed here, then its topics wired to
/// [`crate::watchdog`].
pub fn main() -> Result<()> {
    let mut args = Args::parse_from(nodes::cli_args());
    if args.arms.is_empty() && !args.learn_topics {
        args.arms = ["left", "right"].map(|s| (format!("{s}_arm/forward_velocity_controller/commands"), 6)).to_vec();
    }
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, "skin_watchdog", "")?;
    let logger = node.logger().to_string();
    let mut out = Outputs::default();
    for (t, n) in &args.arms {
        out.add(&mut node, t, CommandType::Arm(*n))?;
    }
    if !args.no_base && !args.learn_topics {
        let kind = if args.base_stamped { CommandType::TwistStamped } else { CommandType::Twist };
        out.add(&mut node, &args.base, kind)?;
    }
    let trips = node.create_publisher::<Header>(local(WATCHDOG), qos::stream())?;
    let mut beats = node.subscribe::<Header>(local(heartbeat::TOPIC), qos::stream())?;
    let learn = if args.learn_topics { " and the topics the heartbeats name" } else { "" };
    r2r::log_info!(
        &logger,
        "watching {} (timeout {} s); zeros on {}{learn}",
        heartbeat::TOPIC,
        args.timeout_s,
        out.topics().join(", ")
    );
    let mut dog = Watchdog::new(
        Duration::from_secs_f64(args.timeout_s),
        Duration::from_secs_f64(args.hold_period_s),
        Instant::now(),
    );
    let mut last_sender = String::from("none yet");
    // topics of a type this version does not know, warned about once
    let mut unknown: Vec<String> = Vec::new();
    let mut failed = false;
    while !shutdown::requested() {
        let now = Instant::now();
        node.spin_once(dog.next_check(now).saturating_duration_since(now).min(Duration::from_millis(50)));
        while let Some(Some(beat)) = beats.next().now_or_never() {
            if dog.beat(Instant::now()) {
                r2r::log_info!(&logger, "heartbeat from {}: zeros stop", beat.frame_id);
            }
            if let Some(sender) = heartbeat::Commander::parse(&beat.frame_id).filter(|_| args.learn_topics) {
                for (topic, kind) in sender.topics() {
                    if out.topics().iter().any(|t| t == topic) {
                        continue;
                    }
                    match kind {
                        Some(kind) => {
                            out.add(&mut node, topic, kind)?;
                            r2r::log_info!(&logger, "zeros on {topic} too (named by the heartbeat, {kind:?})");
                        }
                        None if !unknown.iter().any(|t| t == topic) => {
                            r2r::log_warn!(&logger, "heartbeat names {topic} of an unknown type: not zeroed");
                            unknown.push(topic.to_string());
                        }
                        None => {}
                    }
                }
            }
            last_sender = beat.frame_id;
        }
        let verdict = dog.check(Instant::now());
        if verdict == Verdict::Quiet {
            continue;
        }
        let mut sent = out.zeros(ros_now(&node));
        if verdict == Verdict::Trip {
            let why = format!(
                "no heartbeat for {} s from {last_sender}: zero commands on {}",
                args.timeout_s,
                out.topics().join(", ")
            );
            r2r::log_error!(&logger, "{why}");
            let stamp = crate::convert::robot::time_msg(
                std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH)?.as_secs_f64(),
            );
            sent = sent.and(trips.publish(&Header { stamp, frame_id: why }));
        }
        if let Err(e) = sent {
            if !std::mem::replace(&mut failed, true) {
                r2r::log_error!(&logger, "publishing zeros failed: {e}");
            }
        }
    }
    r2r::log_info!(&logger, "stopping after {} trips", dog.trips());
    shutdown::bound_teardown(0);
    Ok(())
}
