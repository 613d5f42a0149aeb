//! The nodes' ROS wiring (topics, timers, services, parameters), one module per executable, each
//! beside its work without ROS (docs/ros.md). The nodes that `skin_stack` composes in one process
//! (one r2r node each, one executor) have a `start` function that creates the node's entities
//! and spawns its tasks on a single-threaded `LocalPool`; the caller spins the node and runs the
//! pool, then calls the handle's `stop` (final messages, summary) when SIGINT/SIGTERM arrives.
//! The standalone ones ([`skin_aggregator`], [`skin_watchdog`]) have a `main`.
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context as _, Result};

use crate::paths;

pub mod priority_supervisor;
pub mod skin_aggregator;
pub mod skin_watchdog;
pub mod task_controller;

/// The name a node creates its entity with: `topic` relative (without the leading `/`), so that
/// the node's namespace and remapping rules apply. Global names ([`crate::topics::CLOCK`],
/// [`crate::topics::TF`]) are passed as they are.
pub fn local(topic: &str) -> &str {
    topic.strip_prefix('/').unwrap_or(topic)
}

/// `name` as it resolves in `node`'s namespace (for logs; remapping rules are not applied).
pub fn resolved(node: &r2r::Node, name: &str) -> String {
    if name.starts_with('/') {
        return name.to_string();
    }
    let ns = node.namespace().unwrap_or_default();
    format!("{}/{name}", ns.trim_end_matches('/'))
}

/// `TOPIC=N` of `--wait-topic-subscribers`.
pub fn topic_count(s: &str) -> Result<(String, usize), String> {
    let (topic, n) = s.split_once('=').ok_or_else(|| format!("`{s}`: expected TOPIC=N"))?;
    let n = n.parse().map_err(|e| format!("`{s}`: count `{n}`: {e}"))?;
    Ok((topic.to_string(), n))
}

/// A start-up setting: the command-line option, else the ROS parameter `key`, else `default`.
pub fn file_setting(node: &r2r::Node, option: Option<String>, key: &str, default: &str) -> Result<String> {
    let param: Option<String> = node.get_parameter(key).with_context(|| format!("ROS parameter `{key}`"))?;
    Ok(option.or(param).unwrap_or_else(|| default.to_string()))
}

/// [`paths::resolve`] with the setting's name in the error.
pub fn resolve(setting: &str, what: &str) -> Result<PathBuf> {
    paths::resolve(setting).map_err(|e| anyhow::anyhow!("{what}: {e}"))
}

/// The node's ROS clock now, in seconds (sim time when `use_sim_time` is set).
pub fn ros_now(node: &r2r::Node) -> f64 {
    let clock = node.get_ros_clock();
    let mut clock = clock.lock().unwrap();
    clock.get_now().map(|d| d.as_secs_f64()).unwrap_or(0.0)
}

/// Logs the first occurrence of each of `N` kinds of problem once (the counts go into the
/// shutdown summary).
#[derive(Debug, Clone, Copy)]
pub struct OnceLog<const N: usize>([bool; N]);

impl<const N: usize> Default for OnceLog<N> {
    fn default() -> Self {
        OnceLog([false; N])
    }
}

impl<const N: usize> OnceLog<N> {
    /// True the first time `kind` is seen.
    pub fn first(&mut self, kind: usize) -> bool {
        !std::mem::replace(&mut self.0[kind.min(N - 1)], true)
    }
}

/// A binary's exit code (skin_sim's convention): 0, 1 when an outcome check failed
/// (`Some(false)`), 2 when the run failed (the error is printed).
pub fn exit_code(binary: &str, run: Result<Option<bool>>) -> std::process::ExitCode {
    if let Err(e) = &run {
        eprintln!("{binary}: {e:#}");
    }
    std::process::ExitCode::from(code(&run))
}

/// `run`, the result of a binary whose work is done: its teardown from here on is bounded, ending
/// with the code [`exit_code`] gives `run` ([`crate::shutdown::bound_teardown`]).
pub fn bounded(run: Result<Option<bool>>) -> Result<Option<bool>> {
    crate::shutdown::bound_teardown(code(&run).into());
    run
}

/// The number [`exit_code`] gives `run`.
fn code(run: &Result<Option<bool>>) -> u8 {
    match run {
        Ok(Some(false)) => 1,
        Ok(_) => 0,
        Err(_) => 2,
    }
}

/// The arguments before `--ros-args` (what clap parses; rcl parses the rest).
pub fn cli_args() -> impl Iterator<Item = String> {
    std::env::args().take_while(|a| a != "--ros-args")
}

/// `--wait-topic-subscribers` of a node whose outputs a recording must hold from the first
/// message on.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SubscriberWait {
    /// Before taking any input, wait (at most 30 s) until TOPIC (an output of this node) has N
    /// matched subscribers in other processes, then print `ready` on stdout; e.g.
    /// `/skin/patches=1` when a recorder must get the first message (a volatile publisher drops
    /// what it sends before discovery has matched a subscriber).
    #[arg(long, num_args = 1.., value_name = "TOPIC=N", value_parser = topic_count)]
    pub wait_topic_subscribers: Vec<(String, usize)>,
}

impl SubscriberWait {
    /// Waits as asked (nothing when nothing was asked); `count` gives an output topic's matched
    /// subscribers (`None`: not an output of the node, named in the error with `outputs`).
    pub fn wait(
        &self,
        node: &str,
        outputs: &[String],
        count: impl Fn(&str) -> Option<r2r::Result<usize>>,
    ) -> Result<()> {
        if self.wait_topic_subscribers.is_empty() {
            return Ok(());
        }
        let lacking = wait_for_subscribers(&self.wait_topic_subscribers, count, Duration::from_secs(30))
            .map_err(|e| anyhow::anyhow!("--wait-topic-subscribers: {e} (outputs: {})", outputs.join(", ")))?;
        if lacking.is_empty() {
            println!("{node}: ready (subscribers matched)");
        } else {
            println!("{node}: after 30 s too few subscribers on {}: starting anyway", lacking.join(", "));
        }
        use std::io::Write as _;
        std::io::stdout().flush().context("stdout")
    }
}

/// The topics of `wanted` (`TOPIC`, N) with fewer than N matched subscribers in other processes,
/// as `TOPIC (n of N)`; `count` gives a topic's count (`None`: not a topic of the caller, an
/// error).
pub fn lacking_subscribers(
    wanted: &[(String, usize)],
    count: impl Fn(&str) -> Option<r2r::Result<usize>>,
) -> Result<Vec<String>> {
    let mut lacking = Vec::new();
    for (topic, n_wanted) in wanted {
        let n = count(topic)
            .ok_or_else(|| anyhow::anyhow!("`{topic}` is not published here"))?
            .with_context(|| format!("{topic}: subscription count"))?;
        if n < *n_wanted {
            lacking.push(format!("{topic} ({n} of {n_wanted})"));
        }
    }
    Ok(lacking)
}

/// [`lacking_subscribers`] polled every 10 ms until none lack or `timeout` has passed (or a
/// stop was requested); returns the ones still lacking. Matching is DDS's work: the node need
/// not spin (and does not take inputs meanwhile).
pub fn wait_for_subscribers(
    wanted: &[(String, usize)],
    count: impl Fn(&str) -> Option<r2r::Result<usize>>,
    timeout: Duration,
) -> Result<Vec<String>> {
    let deadline = std::time::Instant::now() + timeout;
    loop {
        let lacking = lacking_subscribers(wanted, &count)?;
        if lacking.is_empty() || std::time::Instant::now() > deadline || crate::shutdown::requested() {
            return Ok(lacking);
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// What a node's poll in [`spin_nodes`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    /// Nothing sent: the next round may wait for traffic.
    Idle,
    /// Something was published: a node of this process may have a message already.
    Busy,
    /// Stop spinning.
    Done,
}

/// [`spin_nodes`] with one node.
pub fn spin(node: &mut r2r::Node, pool: &mut futures::executor::LocalPool, mut poll: impl FnMut() -> Pass) {
    spin_nodes(&mut [(node, &mut poll)], pool);
}

/// After a stop request, takes what was delivered to `node` or is still on its way (a subscriber
/// can be hundreds of samples behind a lockstep run that goes several times faster than real
/// time): spins until `taken` (a count of samples handled) has not changed for 100 ms, for at
/// most `limit`.
pub fn drain(
    node: &mut r2r::Node,
    pool: &mut futures::executor::LocalPool,
    mut taken: impl FnMut() -> u64,
    limit: Duration,
) {
    let start = std::time::Instant::now();
    let (mut last, mut last_change) = (taken(), start);
    while last_change.elapsed() < Duration::from_millis(100) && start.elapsed() < limit {
        node.spin_once(Duration::from_millis(10));
        pool.run_until_stalled();
        let now = taken();
        if now != last {
            (last, last_change) = (now, std::time::Instant::now());
        }
    }
}

/// Spins each node, runs `pool` (its tasks take what the node took) and calls the node's poll,
/// node after node, until SIGINT/SIGTERM or a poll says [`Pass::Done`]. One node waits in its
/// wait set (woken by its own traffic). Several nodes (r2r has no shared wait set) are polled:
/// after a round in which nothing was published the first node waits at most 100 us, the
/// others are only checked. A node's poll runs right after its own messages are in, so a
/// lockstep period (the simulator's state to the controller, its commands back) takes one round
/// of spins, not one round per hop: each `spin_once` builds and tears down an rcl wait set.
pub fn spin_nodes(nodes: &mut [(&mut r2r::Node, &mut dyn FnMut() -> Pass)], pool: &mut futures::executor::LocalPool) {
    let wait = if nodes.len() > 1 { Duration::from_micros(100) } else { Duration::from_millis(5) };
    let mut busy = false;
    while !crate::shutdown::requested() {
        let may_wait = !std::mem::replace(&mut busy, false);
        for (k, (node, poll)) in nodes.iter_mut().enumerate() {
            node.spin_once(if k == 0 && may_wait { wait } else { Duration::ZERO });
            pool.run_until_stalled();
            match poll() {
                Pass::Done => return,
                Pass::Busy => busy = true,
                Pass::Idle => {}
            }
        }
    }
}
