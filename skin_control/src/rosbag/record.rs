//! `skin_bag record`: raw subscriptions to the given topics, every message written as received
//! (log time: wall clock at reception) until SIGINT/SIGTERM; then the messages already delivered
//! to the process are drained and written and the file is finished (summary and index).
use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use anyhow::{bail, Context as _, Result};
use futures::{FutureExt as _, Stream, StreamExt as _};
use r2r::qos::{DurabilityPolicy, ReliabilityPolicy};
use r2r::QosProfile;

use super::{normalize_type, qos_yaml, RawBagWriter, TopicSpec};
use crate::shutdown;

/// Options of `skin_bag record`.
#[derive(Debug, Clone, clap::Args)]
pub struct RecordOptions {
    /// Output bag file (MCAP; created or truncated).
    #[arg(value_name = "OUT.mcap")]
    pub out: PathBuf,
    /// Topics to record: `/topic` (type from the ROS graph, waiting for a publisher) or
    /// `/topic:pkg/msg/Type` (subscribed at once, before any publisher exists).
    #[arg(long, num_args = 1.., required = true, value_name = "TOPIC[:TYPE]")]
    pub topics: Vec<TopicSpec>,
    /// How long to wait for the publishers of topics given without a type [s].
    #[arg(long, default_value_t = 30.0, value_name = "SECONDS")]
    pub wait_timeout: f64,
    /// Subscribe to these topics transient local: the last message a latched publisher sent
    /// before the recorder joined is recorded too (such a subscription matches only transient
    /// local publishers). Topics given without a type get this by themselves when all their
    /// publishers offer it.
    #[arg(long, num_args = 1.., value_name = "TOPIC")]
    pub latched: Vec<String>,
    /// Stop by itself after this much wall time [s] (default: at SIGINT/SIGTERM only).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
}

/// Subscription depth: the DDS reader keeps this many samples while the loop writes.
const DEPTH: usize = 1000;

/// A topic being recorded; registered in the bag at its first message, with the QoS its
/// publishers offer then (they exist: one has sent).
struct Recorded {
    name: String,
    type_name: String,
    registered: bool,
    stream: Box<dyn Stream<Item = Vec<u8>> + Unpin>,
}

/// Records until SIGINT/SIGTERM (or `--duration`); prints the per-topic counts.
pub fn record(options: RecordOptions) -> Result<()> {
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, "skin_bag_record", "")?;
    let types = resolve_types(&mut node, &options)?;
    let mut bag = RawBagWriter::create(&options.out)?;
    let mut topics = Vec::new();
    for (name, type_name) in &types {
        let mut qos = subscription_qos(&offered(&node, name)?);
        if options.latched.contains(name) {
            qos = qos.transient_local();
        }
        let stream = node.subscribe_raw(name, type_name, qos).with_context(|| {
            format!("{name}: cannot subscribe with type {type_name} (is it one r2r was built with?)")
        })?;
        topics.push(Recorded {
            name: name.clone(),
            type_name: type_name.clone(),
            registered: false,
            stream: Box::new(stream),
        });
    }
    let list: Vec<String> = types.iter().map(|(n, t)| format!("{n} ({t})")).collect();
    println!("skin_bag: recording {} topics to {}: {}", types.len(), options.out.display(), list.join(", "));
    let start = Instant::now();
    let end = options.duration.map(Duration::from_secs_f64);
    while !shutdown::requested() && end.is_none_or(|d| start.elapsed() < d) {
        node.spin_once(Duration::from_millis(5));
        drain(&node, &mut topics, &mut bag)?;
    }
    // What DDS has delivered to the process but not yet been taken: until a pass brings nothing.
    loop {
        node.spin_once(Duration::ZERO);
        if drain(&node, &mut topics, &mut bag)? == 0 {
            break;
        }
    }
    let counts: Vec<String> = bag.counts().map(|(t, n)| format!("{t} {n}")).collect();
    let total: u64 = bag.counts().map(|(_, n)| n).sum();
    bag.finish()?;
    println!("skin_bag: recorded {total} messages to {}: {}", options.out.display(), counts.join(", "));
    Ok(())
}

/// Writes every message waiting in the subscriptions' queues; returns how many.
fn drain(node: &r2r::Node, topics: &mut [Recorded], bag: &mut RawBagWriter) -> Result<usize> {
    let mut n = 0;
    for t in topics.iter_mut() {
        while let Some(Some(data)) = t.stream.next().now_or_never() {
            if !std::mem::replace(&mut t.registered, true) {
                bag.add_topic(&t.name, &t.type_name, &qos_yaml(&offered(node, &t.name)?))?;
            }
            let now = SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
            bag.write(&t.name, now.as_nanos() as u64, &data)?;
            n += 1;
        }
    }
    Ok(n)
}

/// The QoS profiles the publishers of `topic` offer.
fn offered(node: &r2r::Node, topic: &str) -> Result<Vec<QosProfile>> {
    Ok(node
        .get_publishers_info_by_topic(topic, false)
        .with_context(|| format!("{topic}: publisher information"))?
        .into_iter()
        .map(|info| info.qos_profile)
        .collect())
}

/// Each requested topic with its type: as given, else from the graph (waiting for a publisher
/// up to `--wait-timeout`; a topic with several types is an error).
fn resolve_types(node: &mut r2r::Node, options: &RecordOptions) -> Result<Vec<(String, String)>> {
    let deadline = Instant::now() + Duration::from_secs_f64(options.wait_timeout);
    loop {
        let graph = node.get_topic_names_and_types().context("reading the ROS graph")?;
        let mut out = Vec::new();
        let mut missing = Vec::new();
        for spec in &options.topics {
            if let Some(t) = &spec.type_name {
                out.push((spec.name.clone(), t.clone()));
                continue;
            }
            match graph.get(&spec.name).map(Vec::as_slice) {
                Some([t]) => {
                    let t = normalize_type(t).with_context(|| format!("{}: type `{t}` from the graph", spec.name))?;
                    out.push((spec.name.clone(), t));
                }
                Some(many) if many.len() > 1 => {
                    bail!(
                        "{}: published with several types ({}): give one as {}:pkg/msg/Type",
                        spec.name,
                        many.join(", "),
                        spec.name
                    )
                }
                _ => missing.push(spec.name.as_str()),
            }
        }
        if missing.is_empty() {
            return Ok(out);
        }
        if Instant::now() > deadline || shutdown::requested() {
            bail!(
                "no publisher of {} after {} s: start the publishers first or give the types (`{}:pkg/msg/Type`)",
                missing.join(", "),
                options.wait_timeout,
                missing[0]
            );
        }
        node.spin_once(Duration::from_millis(50));
    }
}

/// The subscription QoS that matches every publisher seen: reliable unless one is best effort,
/// transient local if all offer it (so a latched message sent before we joined is recorded),
/// else volatile. A deep keep-last history: nothing is dropped while the loop writes.
fn subscription_qos(offered: &[QosProfile]) -> QosProfile {
    let best_effort = offered.iter().any(|p| p.reliability == ReliabilityPolicy::BestEffort);
    let latched = !offered.is_empty() && offered.iter().all(|p| p.durability == DurabilityPolicy::TransientLocal);
    let q = QosProfile::default().keep_last(DEPTH);
    let q = if best_effort { q.best_effort() } else { q.reliable() };
    if latched {
        q.transient_local()
    } else {
        q.volatile()
    }
}
