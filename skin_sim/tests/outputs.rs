//! A run's figure and bag: `figure.png` is a picture of the run, `run.mcap` carries its topics
//! (every cycle's joint states and commands, the arrangement switches) and reads back.

use skin_bag::msgs::{Arrangement, Float64MultiArray, JointState, MarkerArray, StringMsg, TfMessage};
use skin_bag::read_bag;
use skin_sim::outputs::artifacts::{FigurePng, KeyFrames, RunBag};
use skin_sim::outputs::report::{write_all, RunOutput};
use skin_sim::run::runner::RunTarget;
use skin_sim::run::scenario;
use skin_sim::scene::RunOverrides;

#[test]
fn figure_and_bag_of_a_run() {
    for name in ["intentional_contact", "force_tracking_interaction"] {
        let target = RunTarget::from(scenario::find(name).unwrap());
        let report = target.run(&RunOverrides { duration_s: Some(0.5), ..RunOverrides::default() }, |_| {}).unwrap();
        let dir = std::env::temp_dir().join(format!("skin_sim_outputs_{name}_{}", std::process::id()));
        let files = write_all(&report, &dir, &[&FigurePng, &RunBag]).unwrap();
        assert_eq!(files, [dir.join("figure.png"), dir.join("run.mcap")]);
        let png = std::fs::read(&files[0]).unwrap();
        assert_eq!(&png[1..4], b"PNG", "{name}: a PNG");

        let messages = read_bag(&files[1]).unwrap();
        let r = &report.record;
        let count = |topic: &str| messages.iter().filter(|m| m.topic == topic).count();
        assert_eq!(count("/joint_states"), r.cycles.len(), "{name}");
        assert_eq!(count("/controller/state"), r.cycles.len());
        assert_eq!(count("/supervisor/arrangement"), 1 + r.switches.len());
        let last = messages.iter().rev().find(|m| m.topic == "/joint_states").unwrap().decode::<JointState>().unwrap();
        assert_eq!(last.position, r.cycles.last().unwrap().q, "{name}: positions bit for bit");
        assert_eq!(last.name, r.joint_names);
        let commands: usize = messages
            .iter()
            .filter(|m| m.topic.ends_with("/forward_velocity_controller/commands"))
            .map(|m| m.decode::<Float64MultiArray>().unwrap().data.len())
            .sum();
        assert_eq!(commands, r.cycles.len() * r.arm_joints.len(), "{name}: every arm joint every cycle");
        let first =
            messages.iter().find(|m| m.topic == "/supervisor/arrangement").unwrap().decode::<Arrangement>().unwrap();
        assert_eq!(first.mode, r.cycles[0].mode.as_u8());
        // the view: the robot's description once, per view frame /tf, the markers when they change
        let description =
            messages.iter().find(|m| m.topic == "/robot_description").unwrap().decode::<StringMsg>().unwrap();
        assert!(description.data.contains("<robot"), "{name}");
        assert_eq!(count("/robot_description"), 1);
        assert_eq!(count("/tf"), r.view.frames.len(), "{name}");
        let tf = messages.iter().find(|m| m.topic == "/tf").unwrap().decode::<TfMessage>().unwrap();
        assert_eq!(tf.transforms.len(), r.view.links.len());
        let changed = r.view.frames.iter().filter(|f| !f.markers.is_empty()).count();
        assert_eq!(count("/skin/markers"), changed, "{name}");
        let markers = messages.iter().find(|m| m.topic == "/skin/markers").unwrap().decode::<MarkerArray>().unwrap();
        assert_eq!(markers.markers[0].action, 3, "{name}: the first update clears the display");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn key_frames_are_rendered_or_the_reason_is_written() {
    // intentional_contact's first 10 s: the start, the switch to intentional contact (8.8 s), the
    // end. Rendered through EGL where it works (the bootstrap installs Mesa's); where it does not
    // the note says why and the states are still there.
    let target = RunTarget::from(scenario::find("intentional_contact").unwrap());
    let report = target.run(&RunOverrides { duration_s: Some(10.0), ..RunOverrides::default() }, |_| {}).unwrap();
    let labels: Vec<&str> = report.record.key_frames().map(|k| k.label.as_str()).collect();
    assert_eq!(labels, ["start", "avoidance -> intentional_contact", "end"]);
    let dir = std::env::temp_dir().join(format!("skin_sim_keyframes_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = KeyFrames { video: false }.write(&report, &dir).unwrap();
    let view: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("keyframes.json")).unwrap()).unwrap();
    let frames = view["frames"].as_array().unwrap();
    // 10 fps over 10 s and the switch
    assert_eq!(frames.len(), 102, "frames at the view rate, the switch, the end");
    assert_eq!(frames.iter().filter(|f| f["label"] != "").count(), 3);
    assert!(std::fs::read_to_string(dir.join("scene.xml")).unwrap().contains("<mujoco"));
    let pngs: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with("keyframe_"))
        .collect();
    if file == dir.join("keyframes.json") {
        assert_eq!(pngs.len(), 3, "one picture per key frame");
        for p in &pngs {
            let png = std::fs::read(p.path()).unwrap();
            assert_eq!(&png[1..4], b"PNG");
        }
    } else {
        let note = std::fs::read_to_string(&file).unwrap();
        assert!(note.starts_with("key frames not rendered") && note.len() > 60, "{note}");
        assert!(pngs.is_empty());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
