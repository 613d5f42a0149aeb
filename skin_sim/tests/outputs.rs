//! A run's figure and bag: `figure.png` is a picture of the run, `run.mcap` carries its topics
//! (every cycle's joint states and commands, the arrangement switches) and reads back.

use skin_sim::bag::msgs::{Arrangement, Float64MultiArray, JointState};
use skin_sim::bag::read_bag;
use skin_sim::outputs::{FigurePng, RunBag};
use skin_sim::report::write_all;
use skin_sim::runner::RunTarget;
use skin_sim::scenario;
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
        let first = messages.iter().find(|m| m.topic == "/supervisor/arrangement").unwrap().decode::<Arrangement>().unwrap();
        assert_eq!(first.mode, r.cycles[0].mode.as_u8());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
