//! `skin_bag`: record topics of a running graph into a rosbag2 MCAP file and play one back, with
//! the messages kept as serialized CDR bytes end to end (r2r's raw subscriptions and untyped
//! publishers): no field is decoded, so any message type r2r was built with passes unchanged.
//!
//! The file format is `skin_bag`'s (profile `ros2`, one `ros2msg` schema per type with the
//! complete definition of [`skin_bag::full_definition`], one `cdr` channel per topic), read
//! by rosbags, `ros2 bag` and Foxglove, and written by `skin_bag::BagWriter` itself:
//! [`RawBagWriter`] only adds the definitions of types skin_bag does not embed (from the ament
//! index) and stores each topic's offered QoS (`offered_qos_profiles`, as rosbag2 does) so that
//! playback offers the same durability (a latched `/goal` stays latched).
//!
//! - [`record`]: `skin_bag record`;
//! - [`play`]: `skin_bag play`;
//! - this module: what neither needs ROS for (topic specs, the writer and reader, header stamps,
//!   QoS metadata, the step schedule), unit tested.
use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context as _, Result};
use r2r::qos::{DurabilityPolicy, HistoryPolicy, ReliabilityPolicy};
use r2r::QosProfile;
use skin_bag::BagWriter;

pub mod play;
pub mod record;

/// A topic to record: its name and, if given on the command line, its type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicSpec {
    /// Topic name, e.g. `/skin/cells`.
    pub name: String,
    /// Message type `pkg/msg/Type` (None: taken from the ROS graph).
    pub type_name: Option<String>,
}

impl std::str::FromStr for TopicSpec {
    type Err = String;

    /// `/topic` or `/topic:pkg/msg/Type` (`pkg/Type` is accepted and completed).
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, type_name) = match s.split_once(':') {
            Some((n, t)) => (n, Some(t)),
            None => (s, None),
        };
        if !name.starts_with('/') || name.len() < 2 {
            return Err(format!("`{s}`: a topic must be an absolute name (`/skin/cells`)"));
        }
        let type_name = match type_name {
            None => None,
            Some(t) => Some(normalize_type(t).ok_or_else(|| format!("`{s}`: type `{t}` is not `pkg/msg/Type`"))?),
        };
        Ok(TopicSpec { name: name.to_string(), type_name })
    }
}

/// `pkg/msg/Type` from `pkg/msg/Type` or `pkg/Type`; None if it is neither.
pub fn normalize_type(t: &str) -> Option<String> {
    let parts: Vec<&str> = t.split('/').collect();
    let ok = |p: &&str| !p.is_empty() && p.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    match parts.as_slice() {
        [pkg, "msg", ty] if ok(pkg) && ok(ty) => Some(t.to_string()),
        [pkg, ty] if ok(pkg) && ok(ty) => Some(format!("{pkg}/msg/{ty}")),
        _ => None,
    }
}

/// The header stamp \[ns\] of a serialized message whose type starts with a `std_msgs/Header`
/// (or a `builtin_interfaces/Time`), given the type's definition text (`ros2msg`, as stored in
/// a bag's schema); None for other types or bytes too short. The stamp is the first field:
/// `int32 sec`, `uint32 nanosec` right after the 4-byte CDR encapsulation header.
pub fn header_stamp(definition: &str, data: &[u8]) -> Option<i64> {
    if !starts_with_stamp(definition) {
        return None;
    }
    let little = match data.get(..2)? {
        [0, 1] => true,
        [0, 0] => false,
        _ => return None,
    };
    let word = |b: &[u8]| -> [u8; 4] { [b[0], b[1], b[2], b[3]] };
    let (sec, nsec) = (word(data.get(4..8)?), word(data.get(8..12)?));
    let (sec, nsec) = if little {
        (i32::from_le_bytes(sec), u32::from_le_bytes(nsec))
    } else {
        (i32::from_be_bytes(sec), u32::from_be_bytes(nsec))
    };
    Some(sec as i64 * 1_000_000_000 + nsec as i64)
}

/// Whether the first field of a message definition is a `std_msgs/Header` or a
/// `builtin_interfaces/Time` (constants and comments skipped).
fn starts_with_stamp(definition: &str) -> bool {
    let first = definition
        .lines()
        .filter_map(|l| l.split('#').next())
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.contains('='));
    let ty = first.and_then(|l| l.split_whitespace().next()).unwrap_or_default();
    matches!(ty, "std_msgs/Header" | "builtin_interfaces/Time")
}

/// The `offered_qos_profiles` text rosbag2 (Jazzy) stores per channel: a YAML list of the
/// publishers' profiles (deadline, lifespan and lease are written as "infinite", as rosbag2 does
/// for the defaults).
pub fn qos_yaml(profiles: &[QosProfile]) -> String {
    const INFINITE: &str = "\n    sec: 9223372036\n    nsec: 854775807";
    let mut out = String::new();
    for p in profiles {
        let history = match p.history {
            HistoryPolicy::KeepAll => "keep_all",
            HistoryPolicy::KeepLast => "keep_last",
            _ => "system_default",
        };
        let reliability = match p.reliability {
            ReliabilityPolicy::Reliable => "reliable",
            ReliabilityPolicy::BestEffort => "best_effort",
            _ => "system_default",
        };
        let durability = match p.durability {
            DurabilityPolicy::TransientLocal => "transient_local",
            DurabilityPolicy::Volatile => "volatile",
            _ => "system_default",
        };
        out.push_str(&format!(
            "- history: {history}\n  depth: {}\n  reliability: {reliability}\n  durability: {durability}\n  deadline:{INFINITE}\n  lifespan:{INFINITE}\n  liveliness: automatic\n  liveliness_lease_duration:{INFINITE}\n  avoid_ros_namespace_conventions: false\n",
            p.depth
        ));
    }
    out
}

/// What a player offers for a topic recorded with `offered_qos_profiles` (empty: not recorded):
/// transient local if every recorded publisher offered it, best effort if any offered that.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OfferedQos {
    /// Late joiners get the last message (a latched topic).
    pub transient_local: bool,
    /// Some publisher was best effort.
    pub best_effort: bool,
}

impl OfferedQos {
    /// From the stored `offered_qos_profiles` text (rosbag2's YAML, string or numeric policies).
    pub fn parse(yaml: &str) -> Self {
        let values = |key: &str| -> Vec<String> {
            yaml.lines()
                .filter_map(|l| l.trim_start_matches([' ', '-']).strip_prefix(key))
                .filter_map(|rest| rest.strip_prefix(':'))
                .map(|v| v.trim().to_string())
                .collect()
        };
        let durability = values("durability");
        let reliability = values("reliability");
        OfferedQos {
            // rosbag2 before Iron wrote the rmw enum values: transient local = 1, best effort = 2.
            transient_local: !durability.is_empty() && durability.iter().all(|v| v == "transient_local" || v == "1"),
            best_effort: reliability.iter().any(|v| v == "best_effort" || v == "2"),
        }
    }

    /// The profile to publish with.
    pub fn profile(&self) -> QosProfile {
        let p = if self.transient_local { crate::qos::latched() } else { QosProfile::default().keep_last(100) };
        if self.best_effort {
            p.best_effort()
        } else {
            p.reliable()
        }
    }
}

/// The complete `ros2msg` definition of `type_name` (`pkg/msg/Type`), as rosbag2 stores it:
/// `skin_bag::full_definition` for the graph's types, else composed the same way from the
/// `.msg` files of the ament index (`<prefix>/share/<pkg>/msg/<Type>.msg` for each prefix of
/// `AMENT_PREFIX_PATH`), as rosbag2 finds them.
pub fn full_definition(type_name: &str) -> Result<String, String> {
    skin_bag::full_definition(type_name).or_else(|_| {
        let prefixes = std::env::var("AMENT_PREFIX_PATH").unwrap_or_default();
        let mut seen = std::collections::BTreeSet::new();
        ament_definition(&type_name.replacen("/msg/", "/", 1), &prefixes, &mut seen)
    })
}

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "string", "wstring",
];

/// `pkg/Type`'s text, then each dependency not yet in `seen` (sorted, depth first) after a line
/// of 80 `=` and `MSG: pkg/Type`.
fn ament_definition(
    type_name: &str,
    prefixes: &str,
    seen: &mut std::collections::BTreeSet<String>,
) -> Result<String, String> {
    let (package, ty) = type_name.split_once('/').ok_or_else(|| format!("`{type_name}` is not pkg/Type"))?;
    let text = std::env::split_paths(prefixes)
        .map(|p| p.join("share").join(package).join("msg").join(format!("{ty}.msg")))
        .find_map(|f| std::fs::read_to_string(f).ok())
        .ok_or_else(|| format!("{type_name}: no share/{package}/msg/{ty}.msg under AMENT_PREFIX_PATH ({prefixes})"))?;
    let deps: std::collections::BTreeSet<String> = text
        .lines()
        .filter_map(|l| l.split('#').next()?.split_whitespace().next())
        .map(|t| t.split(['[', '<']).next().unwrap_or(t))
        .filter(|t| !PRIMITIVES.contains(t))
        .map(|t| if t.contains('/') { t.to_string() } else { format!("{package}/{t}") })
        .collect();
    let mut out = text.clone();
    for dep in deps {
        if seen.insert(dep.clone()) {
            out.push_str(&format!("\n{}\nMSG: {dep}\n", "=".repeat(80)));
            out.push_str(&ament_definition(&dep, prefixes, seen)?);
        }
    }
    Ok(out)
}

/// [`skin_bag::BagWriter`] for serialized messages of types known only at run time: the
/// definitions come from skin_bag's embedded ones or the ament index ([`full_definition`]).
pub struct RawBagWriter(BagWriter);

impl RawBagWriter {
    /// Creates (or truncates) the bag file at `path`.
    pub fn create(path: &Path) -> Result<Self> {
        Ok(Self(BagWriter::create(path)?))
    }

    /// Registers `topic` with its type and the offered QoS text (before its first message).
    pub fn add_topic(&mut self, topic: &str, type_name: &str, offered_qos: &str) -> Result<()> {
        let definition = full_definition(type_name)
            .map_err(|e| anyhow::anyhow!("topic {topic}: no message definition for type {type_name}: {e}"))?;
        Ok(self.0.add_topic(topic, type_name, &definition, offered_qos)?)
    }

    /// Writes one serialized message (CDR with its encapsulation header) of a registered topic.
    pub fn write(&mut self, topic: &str, t_ns: u64, data: &[u8]) -> Result<()> {
        Ok(self.0.write_raw(topic, t_ns, data)?)
    }

    /// Messages written per topic.
    pub fn counts(&self) -> impl Iterator<Item = (&str, u64)> {
        self.0.counts()
    }

    /// Writes the summary and closes the file.
    pub fn finish(self) -> Result<()> {
        Ok(self.0.finish()?)
    }
}

/// A topic of a bag: its type, definition and offered QoS.
#[derive(Debug, Clone)]
pub struct BagTopic {
    /// Message type as stored (`pkg/msg/Type`).
    pub type_name: String,
    /// The schema's definition text.
    pub definition: String,
    /// What the recorded publishers offered.
    pub qos: OfferedQos,
}

/// One serialized message of a bag.
#[derive(Debug, Clone)]
pub struct RawMessage {
    /// Topic.
    pub topic: String,
    /// Log time \[ns\].
    pub log_time_ns: u64,
    /// CDR bytes with the encapsulation header.
    pub data: Vec<u8>,
}

/// A whole bag: its topics and every message in log-time order (file order on ties).
#[derive(Debug, Clone, Default)]
pub struct RawBag {
    /// Topics by name.
    pub topics: BTreeMap<String, BagTopic>,
    /// The messages.
    pub messages: Vec<RawMessage>,
}

/// Reads an MCAP bag (uncompressed chunks, as rosbags and `skin_bag` write them).
pub fn read_raw(path: &Path) -> Result<RawBag> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read the bag", path.display()))?;
    let stream = mcap::MessageStream::new(&bytes).with_context(|| format!("{}: not an MCAP file", path.display()))?;
    let mut bag = RawBag::default();
    for message in stream {
        let message = message.with_context(|| format!("{}: MCAP", path.display()))?;
        let channel = &message.channel;
        if channel.message_encoding != "cdr" {
            bail!(
                "{}: topic {}: message encoding {:?}, expected \"cdr\"",
                path.display(),
                channel.topic,
                channel.message_encoding
            );
        }
        if !bag.topics.contains_key(&channel.topic) {
            let schema = channel.schema.as_ref();
            let type_name = schema.map(|s| s.name.clone()).unwrap_or_default();
            let type_name = normalize_type(&type_name).with_context(|| {
                format!(
                    "{}: topic {}: schema name `{type_name}` is not a ROS 2 message type",
                    path.display(),
                    channel.topic
                )
            })?;
            bag.topics.insert(
                channel.topic.clone(),
                BagTopic {
                    type_name,
                    definition: schema.map(|s| String::from_utf8_lossy(&s.data).into_owned()).unwrap_or_default(),
                    qos: OfferedQos::parse(
                        channel.metadata.get("offered_qos_profiles").map(String::as_str).unwrap_or(""),
                    ),
                },
            );
        }
        bag.messages.push(RawMessage {
            topic: channel.topic.clone(),
            log_time_ns: message.log_time,
            data: message.data.into_owned(),
        });
    }
    bag.messages.sort_by_key(|m| m.log_time_ns);
    Ok(bag)
}

/// Step mode of the player: the played messages as groups of one header stamp each, in stamp
/// order, with whether the recording answered the group on the step topic.
///
/// A message without a stamp belongs to the group of the stamped message before it in log
/// order (the first groups' own stamp: `i64::MIN`). Within a group, log order is kept. A group
/// is answered when the bag holds a message on `step_topic` with the group's stamp: the player
/// then waits for the live answer before the next group.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StepGroup {
    /// The group's header stamp \[ns\].
    pub stamp: i64,
    /// Indices into the bag's messages, in publishing order.
    pub messages: Vec<usize>,
    /// The recording has an answer with this stamp on the step topic.
    pub answered: bool,
}

/// The [`StepGroup`]s of `bag` for the messages `played` (indices, log order) and `step_topic`.
pub fn step_groups(bag: &RawBag, played: &[usize], step_topic: &str) -> Vec<StepGroup> {
    let stamp_of = |m: &RawMessage| bag.topics.get(&m.topic).and_then(|t| header_stamp(&t.definition, &m.data));
    let answers: std::collections::BTreeSet<i64> =
        bag.messages.iter().filter(|m| m.topic == step_topic).filter_map(stamp_of).collect();
    let mut current = i64::MIN;
    let mut keyed: Vec<(i64, usize)> = played
        .iter()
        .map(|&i| {
            if let Some(s) = stamp_of(&bag.messages[i]) {
                current = s;
            }
            (current, i)
        })
        .collect();
    keyed.sort_by_key(|&(s, _)| s); // stable: log order within a stamp
    let mut groups: Vec<StepGroup> = Vec::new();
    for (stamp, i) in keyed {
        match groups.last_mut() {
            Some(g) if g.stamp == stamp => g.messages.push(i),
            _ => groups.push(StepGroup { stamp, messages: vec![i], answered: answers.contains(&stamp) }),
        }
    }
    groups
}

#[cfg(test)]
mod tests;
