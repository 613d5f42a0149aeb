use super::msgs::*;
use super::*;

fn header(ns: u64, frame: &str) -> Header {
    Header { stamp: Time::from_nanos(ns), frame_id: frame.to_string() }
}

#[test]
fn clock_bytes_are_the_cdr_header_then_two_le_words() {
    let msg = Clock { clock: Time { sec: 1, nanosec: 2 } };
    assert_eq!(cdr::encode(&msg).unwrap(), [0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
}

#[test]
fn float64_after_a_byte_is_aligned_to_8_from_the_payload_start() {
    // stamp (8) + string length (4) + "a\0" (2) + mode (1) = 15: one padding byte before blend.
    let msg = ControllerState { header: header(0, "a"), mode: 7, blend: 0.5, ..Default::default() };
    let bytes = cdr::encode(&msg).unwrap();
    let payload = &bytes[4..];
    assert_eq!(&payload[8..14], &[2, 0, 0, 0, b'a', 0]);
    assert_eq!(payload[14], 7);
    assert_eq!(&payload[16..24], &0.5f64.to_le_bytes());
}

#[test]
fn every_topic_type_round_trips_through_a_file() {
    let dir = std::env::temp_dir().join(format!("skin_bag_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("roundtrip.mcap");

    let odom = Odometry {
        header: header(5, "odom"),
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose { position: Point { x: 1.0, y: 2.0, z: 0.0 }, orientation: Quaternion::default() },
            covariance: std::array::from_fn(|i| i as f64),
        },
        twist: TwistWithCovariance::default(),
    };
    let cells = SkinCellArray {
        header: header(5, ""),
        cell_id: vec![3, 1042],
        force: vec![0.25, 0.5, 0.75, 0.0, 0.0, 0.0],
        proximity: vec![0.125, 1.0],
        acceleration: vec![0.0, 0.0, 9.81, 0.0, 0.1, 9.8],
        temperature: vec![31.5, 30.0],
    };
    let state = ControllerState {
        header: header(5, ""),
        mode: 1,
        tasks: vec![TaskState { name: "goal".into(), priority: 1, error_norm: 0.2, torque_norm: 3.0 }],
        ..Default::default()
    };
    let mut bag = BagWriter::create(&path).unwrap();
    bag.write("/base/odom", 5, &odom).unwrap();
    bag.write("/skin/cells", 5, &cells).unwrap();
    bag.write("/controller/state", 4, &state).unwrap();
    bag.write("/controller/state", 6, &state).unwrap();
    bag.finish().unwrap();

    let msgs = read_bag(&path).unwrap();
    let topics: Vec<(&str, u64)> = msgs.iter().map(|m| (m.topic.as_str(), m.log_time_ns)).collect();
    assert_eq!(topics, [("/controller/state", 4), ("/base/odom", 5), ("/skin/cells", 5), ("/controller/state", 6)]);
    assert_eq!(msgs[0].decode::<ControllerState>().unwrap(), state);
    assert_eq!(msgs[1].decode::<Odometry>().unwrap(), odom);
    assert_eq!(msgs[2].decode::<SkinCellArray>().unwrap(), cells);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_topic_keeps_its_type_and_errors_name_file_and_topic() {
    let dir = std::env::temp_dir().join(format!("skin_bag_type_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("types.mcap");
    let mut bag = BagWriter::create(&path).unwrap();
    bag.write("/clock", 0, &Clock::default()).unwrap();
    let err = bag.write("/clock", 1, &Twist::default()).unwrap_err().to_string();
    assert!(err.contains("types.mcap") && err.contains("/clock"), "{err}");
    bag.finish().unwrap();

    let msgs = read_bag(&path).unwrap();
    let err = msgs[0].decode::<Twist>().unwrap_err().to_string();
    assert!(err.contains("rosgraph_msgs/msg/Clock") && err.contains("types.mcap"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_file_is_named() {
    let err = read_bag("/nonexistent/dir/x.mcap").unwrap_err().to_string();
    assert!(err.starts_with("/nonexistent/dir/x.mcap:"), "{err}");
}

#[test]
fn tf_markers_and_a_latched_description_round_trip() {
    let dir = std::env::temp_dir().join(format!("skin_sim_bag_viz_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("viz.mcap");
    let tf = TfMessage {
        transforms: vec![TransformStamped {
            header: header(7, "odom"),
            child_frame_id: "base".into(),
            transform: Transform {
                translation: Vector3 { x: 1.0, y: -2.0, z: 0.5 },
                rotation: Quaternion { x: 0.0, y: 0.0, z: 0.6, w: 0.8 },
            },
        }],
    };
    let cells = Marker {
        header: header(7, "link3"),
        ns: "skin_cells".into(),
        id: 2,
        type_: Marker::SPHERE_LIST,
        points: vec![Point { x: 0.1, y: 0.0, z: 0.0 }],
        colors: vec![ColorRgba { r: 1.0, g: 0.5, b: 0.5, a: 1.0 }],
        ..Default::default()
    };
    let markers = MarkerArray { markers: vec![Marker { action: Marker::DELETEALL, ..Default::default() }, cells] };
    let description = StringMsg { data: "<robot name=\"r\"/>".into() };
    let mut bag = BagWriter::create(&path).unwrap();
    let definition = full_definition(StringMsg::TYPE_NAME).unwrap();
    bag.add_topic("/robot_description", StringMsg::TYPE_NAME, &definition, TRANSIENT_LOCAL_QOS).unwrap();
    bag.write("/robot_description", 0, &description).unwrap();
    bag.write("/tf", 7, &tf).unwrap();
    bag.write("/skin/markers", 7, &markers).unwrap();
    bag.finish().unwrap();

    let msgs = read_bag(&path).unwrap();
    assert_eq!(msgs[0].decode::<StringMsg>().unwrap(), description);
    assert_eq!(msgs[1].decode::<TfMessage>().unwrap(), tf);
    assert_eq!(msgs[2].decode::<MarkerArray>().unwrap(), markers);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn marker_definition_carries_every_nested_type() {
    let full = full_definition(MarkerArray::TYPE_NAME).unwrap();
    for dep in [
        "visualization_msgs/Marker",
        "visualization_msgs/UVCoordinate",
        "visualization_msgs/MeshFile",
        "sensor_msgs/CompressedImage",
        "std_msgs/ColorRGBA",
        "builtin_interfaces/Duration",
        "geometry_msgs/Pose",
    ] {
        assert!(full.contains(&format!("MSG: {dep}\n")), "{dep} missing");
    }
    let tf = full_definition(TfMessage::TYPE_NAME).unwrap();
    assert!(tf.starts_with("geometry_msgs/TransformStamped[] transforms\n"));
    assert!(tf.contains("MSG: geometry_msgs/Transform\n"));
}
