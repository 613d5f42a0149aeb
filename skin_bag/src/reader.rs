//! [`read_bag`]: every message of an MCAP bag in log-time order, decoded on demand.

use std::path::Path;
use std::sync::Arc;

use super::cdr;
use super::error::BagError;
use super::msgs::RosMessage;

/// One message of a bag, still CDR encoded.
#[derive(Debug, Clone)]
pub struct BagMessage {
    /// The bag file it came from (for errors).
    pub path: Arc<Path>,
    /// Topic.
    pub topic: String,
    /// Type name of its schema, e.g. `sensor_msgs/msg/JointState`.
    pub type_name: String,
    /// Log time \[ns\].
    pub log_time_ns: u64,
    /// CDR bytes, encapsulation header included.
    pub data: Vec<u8>,
}

impl BagMessage {
    /// Decode as `M`; fails when the schema is another type or the bytes do not fit.
    pub fn decode<M: RosMessage>(&self) -> Result<M, BagError> {
        if self.type_name != M::TYPE_NAME {
            return Err(BagError::TopicType {
                path: self.path.to_path_buf(),
                topic: self.topic.clone(),
                registered: self.type_name.clone(),
                requested: M::TYPE_NAME.to_string(),
            });
        }
        cdr::decode(&self.data).map_err(|message| BagError::Cdr {
            path: self.path.to_path_buf(),
            topic: self.topic.clone(),
            message,
        })
    }
}

/// Every message of the MCAP file at `path`, sorted by log time (stable: file order on ties).
/// Chunks must be uncompressed, as rosbags and this crate write them.
pub fn read_bag(path: impl AsRef<Path>) -> Result<Vec<BagMessage>, BagError> {
    let path = path.as_ref().to_path_buf();
    let bytes = std::fs::read(&path).map_err(|source| BagError::Io { path: path.clone(), source })?;
    let stream = mcap::MessageStream::new(&bytes).map_err(|source| BagError::Mcap { path: path.clone(), source })?;
    let shared: Arc<Path> = Arc::from(path.as_path());
    let mut out = Vec::new();
    for message in stream {
        let message = message.map_err(|source| BagError::Mcap { path: path.clone(), source })?;
        let channel = &message.channel;
        if channel.message_encoding != "cdr" {
            return Err(BagError::Encoding {
                path,
                topic: channel.topic.clone(),
                encoding: channel.message_encoding.clone(),
            });
        }
        out.push(BagMessage {
            path: shared.clone(),
            topic: channel.topic.clone(),
            type_name: channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default(),
            log_time_ns: message.log_time,
            data: message.data.into_owned(),
        });
    }
    out.sort_by_key(|m| m.log_time_ns);
    Ok(out)
}
