//! The task controller's heartbeat (`/controller/heartbeat`, `std_msgs/Header`): sent with every
//! period's commands. `skin_watchdog` zeroes the command topics when it stops; a second
//! controller on the same command topics hears it and refuses to command (one commander).
//!
//! `header.frame_id` identifies the sender: `<start ns> <pid>@<host> <topic>,<topic>,...` (its
//! start time on the system clock, its process, its command topics: `<topic>=<joints>` for an
//! arm's `Float64MultiArray`, `<topic>` for the base's `Twist`, `<topic>=twist_stamped` for a
//! base's `TwistStamped`); `header.stamp` is the controller's clock at the period.
use std::fmt;

/// The heartbeat topic.
pub const TOPIC: &str = "/controller/heartbeat";

/// What a command topic carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandType {
    /// An arm's joint velocities (`std_msgs/Float64MultiArray`) of this many joints.
    Arm(usize),
    /// The base's twist (`geometry_msgs/Twist`).
    Twist,
    /// The base's twist with a header (`geometry_msgs/TwistStamped`, frame `base_link`).
    TwistStamped,
}

/// The heartbeat's suffix of a [`CommandType::TwistStamped`] topic.
const STAMPED: &str = "twist_stamped";

impl CommandType {
    /// `topic` with this type, as a heartbeat names it.
    pub fn describe(self, topic: &str) -> String {
        match self {
            CommandType::Arm(n) => format!("{topic}={n}"),
            CommandType::Twist => topic.to_string(),
            CommandType::TwistStamped => format!("{topic}={STAMPED}"),
        }
    }
}

/// Who sends a heartbeat.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Commander {
    /// Start time, system clock \[ns since the epoch\].
    pub start_ns: u64,
    /// `<pid>@<host>`.
    pub process: String,
    /// The command topics it publishes ([`CommandType::describe`]).
    pub topics: Vec<String>,
}

impl Commander {
    /// This process, started now, commanding `topics`.
    pub fn this_process(topics: &[String]) -> Self {
        let start_ns = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
        Commander { start_ns, process: format!("{}@{}", std::process::id(), host.trim()), topics: topics.to_vec() }
    }

    /// Reads a heartbeat's `frame_id` (None: not a heartbeat of this format).
    pub fn parse(frame_id: &str) -> Option<Self> {
        let mut parts = frame_id.split(' ');
        let start_ns = parts.next()?.parse().ok()?;
        let process = parts.next()?.to_string();
        let topics = parts.next()?.split(',').filter(|t| !t.is_empty()).map(str::to_string).collect();
        parts.next().is_none().then_some(Commander { start_ns, process, topics })
    }

    /// The command topics with what they carry (None: a suffix this version does not know).
    pub fn topics(&self) -> impl Iterator<Item = (&str, Option<CommandType>)> + '_ {
        self.topics.iter().map(|t| match t.split_once('=') {
            Some((name, STAMPED)) => (name, Some(CommandType::TwistStamped)),
            Some((name, n)) => (name, n.parse().ok().map(CommandType::Arm)),
            None => (t.as_str(), Some(CommandType::Twist)),
        })
    }

    /// The command topics that `self` and `other` both publish.
    pub fn shared_topics<'a>(&'a self, other: &'a Commander) -> impl Iterator<Item = &'a str> + 'a {
        self.topics().map(|(t, _)| t).filter(move |t| other.topics().any(|(o, _)| o == *t))
    }

    /// Whether `self` must give way to `other`: both command a common topic and `other` came
    /// first (started earlier; at the same nanosecond, the smaller process name).
    pub fn yields_to(&self, other: &Commander) -> bool {
        let shared = self.shared_topics(other).next().is_some();
        let earlier = (other.start_ns, &other.process) < (self.start_ns, &self.process);
        shared && earlier
    }
}

/// The `frame_id` form (see the module doc).
impl fmt::Display for Commander {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", self.start_ns, self.process, self.topics.join(","))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_id_round_trip_and_who_gives_way() {
        let topics = |t: &[&str]| t.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let a = Commander { start_ns: 10, process: "1@h".into(), topics: topics(&["/l=6", "/base/cmd_vel"]) };
        assert_eq!(a.to_string(), "10 1@h /l=6,/base/cmd_vel");
        assert_eq!(
            a.topics().collect::<Vec<_>>(),
            [("/l", Some(CommandType::Arm(6))), ("/base/cmd_vel", Some(CommandType::Twist))]
        );
        let described = [CommandType::Arm(7), CommandType::Twist, CommandType::TwistStamped].map(|c| c.describe("/t"));
        assert_eq!(described, ["/t=7", "/t", "/t=twist_stamped"]);
        let s = Commander { topics: described.to_vec(), ..a.clone() };
        let kinds: Vec<_> = s.topics().map(|(_, k)| k).collect();
        assert_eq!(kinds, [Some(CommandType::Arm(7)), Some(CommandType::Twist), Some(CommandType::TwistStamped)]);
        let odd = Commander { topics: topics(&["/t=wrench"]), ..a.clone() };
        assert_eq!(odd.topics().collect::<Vec<_>>(), [("/t", None)], "an unknown type is not guessed");
        assert_eq!(Commander::parse(&a.to_string()), Some(a.clone()));
        for bad in ["", "x 1@h /l", "10 1@h", "10 1@h /l extra"] {
            assert_eq!(Commander::parse(bad), None, "{bad}");
        }
        let b = Commander { start_ns: 20, process: "2@h".into(), topics: topics(&["/base/cmd_vel"]) };
        assert!(b.yields_to(&a) && !a.yields_to(&b), "the later one gives way");
        let c = Commander { start_ns: 20, process: "3@h".into(), topics: topics(&["/other=6"]) };
        assert!(!c.yields_to(&a), "no common topic: no conflict");
        let e = Commander { start_ns: 20, process: "4@h".into(), topics: topics(&["/l=7"]) };
        assert!(e.yields_to(&a), "the same topic, whatever the joint count");
        assert_eq!(e.shared_topics(&a).collect::<Vec<_>>(), ["/l"]);
        let d = Commander { process: "0@h".into(), ..b.clone() };
        assert!(b.yields_to(&d) && !d.yields_to(&b), "same start: the smaller process name stays");
        assert!(!a.yields_to(&a), "its own heartbeat");
        let here = Commander::this_process(&topics(&["/l"]));
        assert!(here.start_ns > 0 && here.process.starts_with(&std::process::id().to_string()));
    }
}
