//! `skin_bag play`: the bag's messages published as recorded bytes (untyped publishers,
//! `publish_raw`), each topic with the QoS its recorded publishers offered.
//!
//! - **Timed** (default): message i leaves at `start + (log_i - log_0) / rate`; `--loop` starts
//!   over; `--clock` publishes `/clock` with the bag time (before each message and every 10 ms
//!   between), the bag's own `/clock` messages are then not played.
//! - **Stepped** (`--step-on TOPIC`): the recorded timing is ignored; the played messages go out
//!   grouped by header stamp ([`super::step_groups`]), and after each group that the recording
//!   answered on TOPIC (a message with the same stamp) the player waits for the live answer
//!   before the next group. This is the lockstep of the simulation replayed: a node that runs
//!   once per complete input set (`task_controller -p trigger:=inputs`) sees exactly the
//!   recorded input sets, whatever the delivery timing.
//!
//! Before the first message, the player waits until every played topic has `--wait-subscribers`
//! matched subscribers in other processes (Fast DDS discovery takes up to seconds, and a volatile
//! publisher drops what it sends before that).
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Context as _, Result};
use futures::{FutureExt as _, Stream, StreamExt as _};
use r2r::rosgraph_msgs::msg::Clock;

use super::{header_stamp, read_raw, step_groups, RawBag};
use crate::nodes::topic_count;
use crate::shutdown;
use crate::topics::CLOCK;

/// Options of `skin_bag play`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlayOptions {
    /// Bag file to play (MCAP, CDR messages).
    #[arg(value_name = "IN.mcap")]
    pub bag: PathBuf,
    /// Play only these topics (default: every topic of the bag).
    #[arg(long, num_args = 1.., value_name = "TOPIC")]
    pub topics: Vec<String>,
    /// Time scale of the recorded timing (2: twice as fast).
    #[arg(long, default_value_t = 1.0, value_name = "R")]
    pub rate: f64,
    /// Start over at the end, until SIGINT/SIGTERM.
    #[arg(long = "loop")]
    pub repeat: bool,
    /// Publish /clock (rosgraph_msgs/Clock) with the bag's time, for nodes with use_sim_time.
    #[arg(long)]
    pub clock: bool,
    /// Before starting, wait until every played topic has this many subscribers in other
    /// processes (0: do not wait).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub wait_subscribers: usize,
    /// Per-topic count for the wait, overriding --wait-subscribers (e.g. `/skin/cells=2` when
    /// both the controller and the aggregator must be there).
    #[arg(long, num_args = 1.., value_name = "TOPIC=N", value_parser = topic_count)]
    pub wait_topic_subscribers: Vec<(String, usize)>,
    /// Longest wait for those subscribers [s]; after it the player starts anyway, naming the
    /// topics that lack them.
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    pub wait_timeout: f64,
    /// Stepped playback: after each header-stamp group the recording answered on TOPIC, wait
    /// for the live answer (TOPIC's messages are not played).
    #[arg(long, value_name = "TOPIC")]
    pub step_on: Option<String>,
    /// Stepped playback: longest wait for one answer [s] (an error after it).
    #[arg(long, default_value_t = 10.0, value_name = "S")]
    pub step_timeout: f64,
    /// Publish these topics transient local (latched) whatever the bag says (a bag written
    /// without offered QoS, e.g. by rosbags, plays volatile otherwise).
    #[arg(long, num_args = 1.., value_name = "TOPIC")]
    pub latched: Vec<String>,
    /// Keep the node alive this long after the last message [s], for reliable delivery to finish.
    #[arg(long, default_value_t = 0.5, value_name = "S")]
    pub linger: f64,
}

/// The live answers on the step topic: the newest stamp seen.
struct Answers {
    topic: String,
    definition: String,
    stream: Box<dyn Stream<Item = Vec<u8>> + Unpin>,
    newest: Option<i64>,
    count: u64,
}

impl Answers {
    fn take(&mut self) {
        while let Some(Some(data)) = self.stream.next().now_or_never() {
            self.count += 1;
            if let Some(s) = header_stamp(&self.definition, &data) {
                self.newest = Some(self.newest.map_or(s, |n| n.max(s)));
            }
        }
    }
}

/// Plays the bag; prints what was published.
pub fn play(options: PlayOptions) -> Result<()> {
    if !(options.rate.is_finite() && options.rate > 0.0) {
        bail!("--rate {}: must be > 0", options.rate);
    }
    let bag = read_raw(&options.bag)?;
    let file = options.bag.display().to_string();
    let counted = options.wait_topic_subscribers.iter().map(|(t, _)| t);
    for t in options.topics.iter().chain(&options.latched).chain(&options.step_on).chain(counted) {
        if !bag.topics.contains_key(t) {
            bail!(
                "{file}: no topic {t} in the bag (it has {})",
                bag.topics.keys().cloned().collect::<Vec<_>>().join(", ")
            );
        }
    }
    let played_topic = |t: &str| {
        (options.topics.is_empty() || options.topics.iter().any(|p| p == t))
            && options.step_on.as_deref() != Some(t)
            && !(options.clock && t == CLOCK)
    };
    let played: Vec<usize> = (0..bag.messages.len()).filter(|&i| played_topic(&bag.messages[i].topic)).collect();
    if played.is_empty() {
        bail!("{file}: no message to play");
    }

    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, "skin_bag_play", "")?;
    let mut pubs = BTreeMap::new();
    for (name, topic) in bag.topics.iter().filter(|(n, _)| played_topic(n)) {
        let mut qos = topic.qos;
        qos.transient_local |= options.latched.contains(name);
        let p = node.create_publisher_untyped(name, &topic.type_name, qos.profile()).with_context(|| {
            format!("{file}: {name}: cannot publish type {} (is it one r2r was built with?)", topic.type_name)
        })?;
        pubs.insert(name.clone(), p);
    }
    let clock = if options.clock { Some(node.create_publisher::<Clock>(CLOCK, crate::qos::stream())?) } else { None };
    let mut answers = match &options.step_on {
        Some(t) => {
            let topic = &bag.topics[t];
            let stream = node
                .subscribe_raw(t, &topic.type_name, topic.qos.profile().volatile())
                .with_context(|| format!("{t}: cannot subscribe with type {}", topic.type_name))?;
            Some(Answers {
                topic: t.clone(),
                definition: topic.definition.clone(),
                stream: Box::new(stream),
                newest: None,
                count: 0,
            })
        }
        None => None,
    };

    wait_for_subscribers(&pubs, &options)?;
    let send = |i: usize| -> Result<()> {
        let m = &bag.messages[i];
        pubs[&m.topic].publish_raw(&m.data).with_context(|| format!("{}: publishing", m.topic))
    };
    let mut sent = 0u64;
    match answers.as_mut() {
        Some(answers) => {
            let groups = step_groups(&bag, &played, &answers.topic);
            let steps = groups.iter().filter(|g| g.answered).count();
            println!(
                "skin_bag: playing {} messages of {file} in {} stamp groups, {steps} answered on {}",
                played.len(),
                groups.len(),
                answers.topic
            );
            for g in &groups {
                for &i in &g.messages {
                    publish_clock(clock.as_ref(), &bag, i)?;
                    send(i)?;
                    sent += 1;
                }
                if g.answered {
                    wait_answer(&mut node, answers, g.stamp, options.step_timeout)?;
                }
                if shutdown::requested() {
                    break;
                }
            }
        }
        None => loop {
            println!("skin_bag: playing {} messages of {file} at rate {}", played.len(), options.rate);
            let start = Instant::now();
            let t0 = bag.messages[played[0]].log_time_ns;
            for &i in &played {
                let due = Duration::from_nanos(((bag.messages[i].log_time_ns - t0) as f64 / options.rate) as u64);
                while start.elapsed() < due && !shutdown::requested() {
                    if let Some(c) = &clock {
                        let t = t0 + (start.elapsed().as_nanos() as f64 * options.rate) as u64;
                        c.publish(&clock_msg(t)).context(CLOCK)?;
                    }
                    node.spin_once((due - start.elapsed().min(due)).min(Duration::from_millis(10)));
                }
                if shutdown::requested() {
                    break;
                }
                publish_clock(clock.as_ref(), &bag, i)?;
                send(i)?;
                sent += 1;
            }
            if !options.repeat || shutdown::requested() {
                break;
            }
        },
    }
    let linger = Instant::now() + Duration::from_secs_f64(options.linger.max(0.0));
    while Instant::now() < linger && !shutdown::requested() {
        node.spin_once(Duration::from_millis(10));
    }
    let answered = answers.as_ref().map(|a| format!(", {} answers on {}", a.count, a.topic)).unwrap_or_default();
    println!("skin_bag: published {sent} messages{answered}");
    Ok(())
}

fn clock_msg(t_ns: u64) -> Clock {
    Clock {
        clock: r2r::builtin_interfaces::msg::Time {
            sec: (t_ns / 1_000_000_000) as i32,
            nanosec: (t_ns % 1_000_000_000) as u32,
        },
    }
}

fn publish_clock(clock: Option<&r2r::Publisher<Clock>>, bag: &RawBag, i: usize) -> Result<()> {
    match clock {
        Some(c) => c.publish(&clock_msg(bag.messages[i].log_time_ns)).context(CLOCK),
        None => Ok(()),
    }
}

/// Waits until every publisher has its number of inter-process subscribers
/// (`--wait-topic-subscribers`, else `--wait-subscribers`), or the timeout (then warns naming
/// the topics without them).
fn wait_for_subscribers(pubs: &BTreeMap<String, r2r::PublisherUntyped>, options: &PlayOptions) -> Result<()> {
    let wanted: Vec<(String, usize)> = pubs
        .keys()
        .map(|name| {
            let n = options
                .wait_topic_subscribers
                .iter()
                .find(|(t, _)| t == name)
                .map_or(options.wait_subscribers, |(_, n)| *n);
            (name.clone(), n)
        })
        .collect();
    let count = |topic: &str| pubs.get(topic).map(|p| p.get_inter_process_subscription_count());
    let lacking = crate::nodes::wait_for_subscribers(&wanted, count, Duration::from_secs_f64(options.wait_timeout))?;
    if !lacking.is_empty() && !shutdown::requested() {
        eprintln!(
            "skin_bag: after {} s, too few subscribers on {}: starting anyway",
            options.wait_timeout,
            lacking.join(", ")
        );
    }
    Ok(())
}

/// Spins until a live answer with a stamp >= `stamp` has arrived.
fn wait_answer(node: &mut r2r::Node, answers: &mut Answers, stamp: i64, timeout_s: f64) -> Result<()> {
    let deadline = Instant::now() + Duration::from_secs_f64(timeout_s);
    loop {
        answers.take();
        if answers.newest.is_some_and(|n| n >= stamp) || shutdown::requested() {
            return Ok(());
        }
        if Instant::now() > deadline {
            bail!(
                "{}: no answer with stamp {:.6} s within {timeout_s} s (newest: {})",
                answers.topic,
                stamp as f64 * 1e-9,
                answers.newest.map_or("none".into(), |n| format!("{:.6} s", n as f64 * 1e-9))
            );
        }
        node.spin_once(Duration::from_millis(10));
    }
}
