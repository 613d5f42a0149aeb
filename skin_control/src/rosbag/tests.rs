use super::*;

fn cdr_stamp(sec: i32, nsec: u32, rest: &[u8]) -> Vec<u8> {
    let mut v = vec![0, 1, 0, 0];
    v.extend(sec.to_le_bytes());
    v.extend(nsec.to_le_bytes());
    v.extend(rest);
    v
}

const JOINT_STATE: &str = "# A joint state\nstd_msgs/Header header\nstring[] name\n";
const FLOAT64: &str = "float64 data\n";

#[test]
fn topic_specs_parse_with_and_without_type() {
    assert_eq!("/skin/cells".parse::<TopicSpec>(), Ok(TopicSpec { name: "/skin/cells".into(), type_name: None }));
    let t: TopicSpec = "/scan:sensor_msgs/LaserScan".parse().unwrap();
    assert_eq!(t.type_name.as_deref(), Some("sensor_msgs/msg/LaserScan"));
    let t: TopicSpec = "/scan:sensor_msgs/msg/LaserScan".parse().unwrap();
    assert_eq!(t.type_name.as_deref(), Some("sensor_msgs/msg/LaserScan"));
    assert!("scan".parse::<TopicSpec>().unwrap_err().contains("absolute"));
    assert!("/scan:LaserScan".parse::<TopicSpec>().unwrap_err().contains("pkg/msg/Type"));
}

#[test]
fn header_stamps_are_read_from_stamped_types_only() {
    let data = cdr_stamp(3, 250_000_000, &[1, 2, 3]);
    assert_eq!(header_stamp(JOINT_STATE, &data), Some(3_250_000_000));
    assert_eq!(header_stamp("builtin_interfaces/Time clock\n", &data), Some(3_250_000_000));
    assert_eq!(header_stamp(FLOAT64, &data), None);
    // A constant before the header is skipped.
    assert_eq!(header_stamp("uint8 MODE=1\nstd_msgs/Header header\n", &data), Some(3_250_000_000));
    assert_eq!(header_stamp(JOINT_STATE, &data[..10]), None, "too short");
    let full = skin_bag::full_definition("nav_msgs/msg/Odometry").unwrap();
    assert_eq!(header_stamp(&full, &data), Some(3_250_000_000));
}

#[test]
fn offered_qos_round_trips_through_the_stored_text() {
    let latched = qos_yaml(&[crate::qos::latched()]);
    assert!(latched.contains("durability: transient_local"), "{latched}");
    assert_eq!(OfferedQos::parse(&latched), OfferedQos { transient_local: true, best_effort: false });
    let mixed = qos_yaml(&[crate::qos::latched(), crate::qos::stream()]);
    assert_eq!(OfferedQos::parse(&mixed), OfferedQos { transient_local: false, best_effort: false });
    let be = qos_yaml(&[QosProfile::default().best_effort()]);
    assert!(OfferedQos::parse(&be).best_effort);
    assert_eq!(OfferedQos::parse(""), OfferedQos::default());
    // rosbag2 before Iron: numeric policies.
    assert!(OfferedQos::parse("- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n").transient_local);
}

#[test]
fn raw_bag_round_trips_bytes_types_and_qos() {
    let path = std::env::temp_dir().join(format!("skin_bag_unit_{}.mcap", std::process::id()));
    let mut w = RawBagWriter::create(&path).unwrap();
    w.add_topic("/joint_states", "sensor_msgs/msg/JointState", "").unwrap();
    w.add_topic("/base/cmd_vel", "geometry_msgs/msg/Twist", &qos_yaml(&[crate::qos::latched()])).unwrap();
    w.write("/joint_states", 20, &cdr_stamp(1, 0, &[9])).unwrap();
    w.write("/base/cmd_vel", 10, &[0, 1, 0, 0, 7]).unwrap();
    let err = w.write("/nope", 30, &[]).unwrap_err().to_string();
    assert!(err.contains("/nope"), "{err}");
    assert_eq!(w.counts().collect::<Vec<_>>(), [("/base/cmd_vel", 1), ("/joint_states", 1)]);
    w.finish().unwrap();
    let bag = read_raw(&path).unwrap();
    std::fs::remove_file(&path).ok();
    assert_eq!(
        bag.messages.iter().map(|m| (m.topic.as_str(), m.log_time_ns)).collect::<Vec<_>>(),
        [("/base/cmd_vel", 10), ("/joint_states", 20)]
    );
    assert_eq!(bag.messages[0].data, [0, 1, 0, 0, 7]);
    assert!(bag.topics["/base/cmd_vel"].qos.transient_local);
    assert!(!bag.topics["/joint_states"].qos.transient_local);
    assert_eq!(bag.topics["/joint_states"].type_name, "sensor_msgs/msg/JointState");
    assert_eq!(header_stamp(&bag.topics["/joint_states"].definition, &bag.messages[1].data), Some(1_000_000_000));
}

#[test]
fn definitions_outside_skin_bag_come_from_the_ament_index() {
    let dir = std::env::temp_dir().join(format!("skin_bag_ament_{}", std::process::id()));
    let msg = dir.join("share/demo_msgs/msg");
    std::fs::create_dir_all(&msg).unwrap();
    std::fs::write(msg.join("Outer.msg"), "Inner a # comment\nInner[] b\nstd_msgs/Empty e\nint32 X=1\n").unwrap();
    std::fs::write(msg.join("Inner.msg"), "float64 v\n").unwrap();
    let std = dir.join("share/std_msgs/msg");
    std::fs::create_dir_all(&std).unwrap();
    std::fs::write(std.join("Empty.msg"), "").unwrap();
    let text = ament_definition("demo_msgs/Outer", dir.to_str().unwrap(), &mut Default::default());
    let missing = ament_definition("demo_msgs/Missing", dir.to_str().unwrap(), &mut Default::default());
    std::fs::remove_dir_all(&dir).ok();
    let sep = "=".repeat(80);
    assert_eq!(
        text.unwrap(),
        format!("Inner a # comment\nInner[] b\nstd_msgs/Empty e\nint32 X=1\n\n{sep}\nMSG: demo_msgs/Inner\nfloat64 v\n\n{sep}\nMSG: std_msgs/Empty\n")
    );
    assert!(missing.unwrap_err().contains("share/demo_msgs/msg/Missing.msg"));
}

#[test]
fn unknown_types_are_named_with_the_topic() {
    let path = std::env::temp_dir().join(format!("skin_bag_unknown_{}.mcap", std::process::id()));
    let mut w = RawBagWriter::create(&path).unwrap();
    let err = w.add_topic("/x", "foo_msgs/msg/Bar", "").unwrap_err().to_string();
    std::fs::remove_file(&path).ok();
    assert!(err.contains("/x") && err.contains("foo_msgs/Bar"), "{err}");
}

fn msg(topic: &str, t: u64, stamp: Option<i32>) -> RawMessage {
    RawMessage {
        topic: topic.into(),
        log_time_ns: t,
        data: stamp.map_or(vec![0, 1, 0, 0, 0, 0, 0, 0], |s| cdr_stamp(s, 0, &[])),
    }
}

#[test]
fn step_groups_follow_stamps_not_arrival() {
    let mut bag = RawBag::default();
    for (t, def) in [("/a", JOINT_STATE), ("/b", JOINT_STATE), ("/f", FLOAT64), ("/state", JOINT_STATE)] {
        bag.topics.insert(
            t.into(),
            BagTopic { type_name: "x/msg/Y".into(), definition: def.into(), qos: OfferedQos::default() },
        );
    }
    // Recorded arrival: /a(1) before /b(0) (two readers, no order between topics).
    bag.messages = vec![
        msg("/f", 0, None),
        msg("/a", 1, Some(0)),
        msg("/a", 2, Some(1)),
        msg("/b", 3, Some(0)),
        msg("/state", 4, Some(0)),
        msg("/b", 5, Some(1)),
        msg("/f", 6, None),
        msg("/a", 7, Some(2)),
        msg("/b", 8, Some(2)),
    ];
    let played: Vec<usize> = (0..bag.messages.len()).filter(|&i| bag.messages[i].topic != "/state").collect();
    let g = step_groups(&bag, &played, "/state");
    let s = 1_000_000_000;
    assert_eq!(
        g,
        [
            StepGroup { stamp: i64::MIN, messages: vec![0], answered: false },
            StepGroup { stamp: 0, messages: vec![1, 3], answered: true },
            // The unstamped /f(6) follows /b(1), the stamped message before it.
            StepGroup { stamp: s, messages: vec![2, 5, 6], answered: false },
            StepGroup { stamp: 2 * s, messages: vec![7, 8], answered: false },
        ]
    );
}
