//! [`BagWriter`]: messages in, one MCAP file out.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use super::{cdr, defs, BagError, RosMessage};

/// A channel registered for a topic.
struct Channel {
    id: u16,
    type_name: &'static str,
    sequence: u32,
}

/// Writes a rosbag2 MCAP file. Schemas are registered once per type and channels once per
/// topic, on first use. Call [`BagWriter::finish`]: it writes the summary and index that readers
/// seek by.
pub struct BagWriter {
    path: PathBuf,
    mcap: mcap::Writer<BufWriter<File>>,
    schemas: HashMap<&'static str, u16>,
    channels: HashMap<String, Channel>,
}

impl BagWriter {
    /// Create (or truncate) the bag file at `path` (by convention `*.mcap`).
    pub fn create(path: impl AsRef<Path>) -> Result<Self, BagError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|source| BagError::Io {
            path: path.clone(),
            source,
        })?;
        // Uncompressed chunks: every MCAP reader takes them, and the crate needs no C codecs.
        let mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("skin_sim ", env!("CARGO_PKG_VERSION")))
            .compression(None)
            .create(BufWriter::new(file))
            .map_err(|source| BagError::Mcap {
                path: path.clone(),
                source,
            })?;
        Ok(Self {
            path,
            mcap,
            schemas: HashMap::new(),
            channels: HashMap::new(),
        })
    }

    /// Write `msg` on `topic`, received and published at `t_ns` (ns; sim time or wall clock).
    pub fn write<M: RosMessage>(
        &mut self,
        topic: &str,
        t_ns: u64,
        msg: &M,
    ) -> Result<(), BagError> {
        let data = cdr::encode(msg).map_err(|message| BagError::Cdr {
            path: self.path.clone(),
            topic: topic.to_string(),
            message,
        })?;
        let channel = self.channel(topic, M::TYPE_NAME)?;
        channel.sequence = channel.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: channel.id,
            sequence: channel.sequence,
            log_time: t_ns,
            publish_time: t_ns,
        };
        self.mcap
            .write_to_known_channel(&header, &data)
            .map_err(|source| BagError::Mcap {
                path: self.path.clone(),
                source,
            })
    }

    /// Write the summary and close the file.
    pub fn finish(mut self) -> Result<(), BagError> {
        let path = self.path.clone();
        self.mcap.finish().map_err(|source| BagError::Mcap {
            path: path.clone(),
            source,
        })?;
        self.mcap
            .into_inner()
            .into_inner()
            .map_err(|e| BagError::Io {
                path,
                source: e.into_error(),
            })?;
        Ok(())
    }

    /// The channel of `topic`, registered (with its type's schema) on first use.
    fn channel(&mut self, topic: &str, type_name: &'static str) -> Result<&mut Channel, BagError> {
        if !self.channels.contains_key(topic) {
            let schema = self.schema(topic, type_name)?;
            // rosbag2 records the publishers' QoS here; empty = the player's defaults.
            let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), String::new())]);
            let id = self
                .mcap
                .add_channel(schema, topic, "cdr", &metadata)
                .map_err(|source| BagError::Mcap {
                    path: self.path.clone(),
                    source,
                })?;
            self.channels.insert(
                topic.to_string(),
                Channel {
                    id,
                    type_name,
                    sequence: 0,
                },
            );
        }
        let channel = self.channels.get_mut(topic).expect("registered above");
        if channel.type_name != type_name {
            return Err(BagError::TopicType {
                path: self.path.clone(),
                topic: topic.to_string(),
                registered: channel.type_name.to_string(),
                requested: type_name.to_string(),
            });
        }
        Ok(channel)
    }

    fn schema(&mut self, topic: &str, type_name: &'static str) -> Result<u16, BagError> {
        if let Some(&id) = self.schemas.get(type_name) {
            return Ok(id);
        }
        let text = defs::full_definition(type_name).map_err(|missing| BagError::UnknownType {
            path: self.path.clone(),
            topic: topic.to_string(),
            type_name: missing,
        })?;
        let id = self
            .mcap
            .add_schema(type_name, "ros2msg", text.as_bytes())
            .map_err(|source| BagError::Mcap {
                path: self.path.clone(),
                source,
            })?;
        self.schemas.insert(type_name, id);
        Ok(id)
    }
}
