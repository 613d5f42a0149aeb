//! [`BagWriter`]: messages in, one MCAP file out.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use super::error::BagError;
use super::msgs::RosMessage;
use super::{cdr, defs};

/// The offered QoS of a latched publisher (reliable, transient local, depth 1) in rosbag2's YAML,
/// for [`BagWriter::add_topic`]: a player re-offers it, so late subscribers (RViz's robot model
/// on `/robot_description`) still get the message.
pub const TRANSIENT_LOCAL_QOS: &str =
    "- history: keep_last\n  depth: 1\n  reliability: reliable\n  durability: transient_local\n  \
deadline:\n    sec: 9223372036\n    nsec: 854775807\n  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n  \
liveliness: automatic\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n  \
avoid_ros_namespace_conventions: false\n";

/// A channel registered for a topic.
struct Channel {
    id: u16,
    type_name: String,
    sequence: u32,
    count: u64,
}

/// Writes a rosbag2 MCAP file: typed messages ([`BagWriter::write`]) or serialized ones of types
/// known only at run time ([`BagWriter::add_topic`] + [`BagWriter::write_raw`], what a recorder
/// needs). Schemas are registered once per type, channels once per topic. Call
/// [`BagWriter::finish`]: it writes the summary and index that readers seek by.
pub struct BagWriter {
    path: PathBuf,
    mcap: mcap::Writer<BufWriter<File>>,
    schemas: HashMap<String, u16>,
    channels: BTreeMap<String, Channel>,
}

impl BagWriter {
    /// Create (or truncate) the bag file at `path` (by convention `*.mcap`).
    pub fn create(path: impl AsRef<Path>) -> Result<Self, BagError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|source| BagError::Io { path: path.clone(), source })?;
        // Uncompressed chunks: every MCAP reader takes them, and the crate needs no C codecs.
        let mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("skin_bag ", env!("CARGO_PKG_VERSION")))
            .compression(None)
            .create(BufWriter::new(file))
            .map_err(|source| BagError::Mcap { path: path.clone(), source })?;
        Ok(Self { path, mcap, schemas: HashMap::new(), channels: BTreeMap::new() })
    }

    /// Write `msg` on `topic`, received and published at `t_ns` (ns; sim time or wall clock).
    /// The topic is registered on first use with its type's definition and no QoS (the player's
    /// defaults).
    pub fn write<M: RosMessage>(&mut self, topic: &str, t_ns: u64, msg: &M) -> Result<(), BagError> {
        let data = cdr::encode(msg).map_err(|message| BagError::Cdr {
            path: self.path.clone(),
            topic: topic.to_string(),
            message,
        })?;
        match self.channels.get(topic) {
            None => {
                let definition = defs::full_definition(M::TYPE_NAME).map_err(|missing| BagError::UnknownType {
                    path: self.path.clone(),
                    topic: topic.to_string(),
                    type_name: missing,
                })?;
                self.add_topic(topic, M::TYPE_NAME, &definition, "")?;
            }
            Some(c) if c.type_name != M::TYPE_NAME => {
                return Err(BagError::TopicType {
                    path: self.path.clone(),
                    topic: topic.to_string(),
                    registered: c.type_name.clone(),
                    requested: M::TYPE_NAME.to_string(),
                })
            }
            Some(_) => {}
        }
        self.write_raw(topic, t_ns, &data)
    }

    /// Registers `topic` (before its first message) with its type, the type's full definition
    /// as rosbag2 stores it, and the publishers' offered QoS (rosbag2's YAML text; empty: the
    /// player's defaults).
    pub fn add_topic(
        &mut self,
        topic: &str,
        type_name: &str,
        definition: &str,
        offered_qos: &str,
    ) -> Result<(), BagError> {
        let path = self.path.clone();
        let mcap_error = move |source| BagError::Mcap { path: path.clone(), source };
        let schema = match self.schemas.get(type_name) {
            Some(&id) => id,
            None => {
                let id = self.mcap.add_schema(type_name, "ros2msg", definition.as_bytes()).map_err(&mcap_error)?;
                self.schemas.insert(type_name.to_string(), id);
                id
            }
        };
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), offered_qos.to_string())]);
        let id = self.mcap.add_channel(schema, topic, "cdr", &metadata).map_err(&mcap_error)?;
        self.channels
            .insert(topic.to_string(), Channel { id, type_name: type_name.to_string(), sequence: 0, count: 0 });
        Ok(())
    }

    /// Writes one serialized message (CDR with its encapsulation header) of a registered topic.
    pub fn write_raw(&mut self, topic: &str, t_ns: u64, data: &[u8]) -> Result<(), BagError> {
        let Some(channel) = self.channels.get_mut(topic) else {
            return Err(BagError::Unregistered { path: self.path.clone(), topic: topic.to_string() });
        };
        channel.sequence = channel.sequence.wrapping_add(1);
        channel.count += 1;
        let header = mcap::records::MessageHeader {
            channel_id: channel.id,
            sequence: channel.sequence,
            log_time: t_ns,
            publish_time: t_ns,
        };
        self.mcap
            .write_to_known_channel(&header, data)
            .map_err(|source| BagError::Mcap { path: self.path.clone(), source })
    }

    /// Messages written per topic, in topic order.
    pub fn counts(&self) -> impl Iterator<Item = (&str, u64)> {
        self.channels.iter().map(|(t, c)| (t.as_str(), c.count))
    }

    /// Write the summary and close the file.
    pub fn finish(mut self) -> Result<(), BagError> {
        let path = self.path.clone();
        self.mcap.finish().map_err(|source| BagError::Mcap { path: path.clone(), source })?;
        self.mcap.into_inner().into_inner().map_err(|e| BagError::Io { path, source: e.into_error() })?;
        Ok(())
    }
}
