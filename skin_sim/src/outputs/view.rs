//! What a viewer sees of a run: at the scene's view rate (and at the start, the first switches
//! and the end) the MuJoCo state, the robot's link poses and the skin's marker updates, as the
//! aggregator publishes them on `/skin/markers` ([`skin_core::skin::markers`]). The recording
//! (`run.mcap`: `/tf`, `/skin/markers`) and the rendered frames and video are made from these
//! frames, so the picture and RViz agree.

use nalgebra::Isometry3;
use skin_core::controller::ControllerConfig;
use skin_core::model::{update_kinematics, ModelData, RobotModel};
use skin_core::skin::aggregate::{aggregate_patches, FusionParams, PatchWrench};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::markers::SkinMarkers;
use skin_core::supervisor::Mode;

use crate::scene::spec::{GoalSpec, ViewSpec};
use crate::scene::Scene;
use crate::world::KeyFrame;
use crate::world::World;

/// Most key frames (labelled frames) one run keeps: the start, the first switches, the end.
pub const MAX_KEY_FRAMES: usize = 8;

/// The TF frame the robot's tree hangs from: the world of the simulation, which is the
/// odometry frame of the base (RViz's fixed frame in `config/skin.rviz`).
pub const ODOM_FRAME: &str = "odom";

/// A run's view: the frames and what is needed to show them.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct View {
    /// Camera and frame rate, from the scene's `view:`.
    pub spec: ViewSpec,
    /// The URDF of the robot (`/robot_description`).
    #[serde(skip)]
    pub robot_description: String,
    /// The links in the TF tree (URDF names): every link but the base's virtual x and y links.
    pub links: Vec<String>,
    /// Per link, its parent in the TF tree (index into `links`; None: [`ODOM_FRAME`]).
    pub parents: Vec<Option<usize>>,
    /// The scene's goals (drawn from their start on).
    pub goals: Vec<GoalSpec>,
    /// Every skin cell (drawn idle unless a marker shows it active).
    pub cells: Vec<CellSite>,
    /// The frames in time order.
    pub frames: Vec<KeyFrame>,
}

/// Where a skin cell sits: its link and its position in the link frame \[m\] (as a marker point).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CellSite {
    /// The link (a TF frame).
    pub link: String,
    /// Position in the link frame \[m\].
    pub position: [f64; 3],
}

/// Captures a run's [`View`], called once per control cycle.
pub struct ViewRecorder {
    model: RobotModel,
    data: ModelData,
    frames: Vec<usize>,
    layout: ResolvedLayout,
    fusion: FusionParams,
    markers: SkinMarkers,
    wrenches: Vec<PatchWrench>,
    period_s: f64,
    next_s: f64,
    labelled: usize,
    view: View,
}

/// A world pose as `[x, y, z, qx, qy, qz, qw]`.
pub fn pose_array(p: &Isometry3<f64>) -> [f64; 7] {
    let (t, q) = (p.translation.vector, p.rotation.coords);
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w]
}

/// The links of `model` in the TF tree and each one's parent (None: [`ODOM_FRAME`]). The
/// base's planar joints become one transform `odom -> base_link`: the links they move before
/// the yaw joint (`base_x_link`, `base_y_link`) are left out.
pub fn tf_tree(model: &RobotModel) -> (Vec<usize>, Vec<Option<usize>>) {
    let virtual_links: Vec<usize> =
        model.planar_base().into_iter().flat_map(|[x, y, _]| [x, y]).map(|j| model.joint_child_frame(j)).collect();
    let frames: Vec<usize> = (0..model.nframes()).filter(|f| !virtual_links.contains(f)).collect();
    let index = |f: usize| frames.iter().position(|&g| g == f);
    let parents = frames
        .iter()
        .map(|&f| {
            let mut joint = model.frame_parent_joint(f);
            // a link fixed to a moving body hangs from that body's own link, which hangs from the
            // nearest kept link of the joint's ancestors
            if let Some(j) = joint.filter(|&j| model.joint_child_frame(j) != f) {
                if let Some(k) = index(model.joint_child_frame(j)) {
                    return Some(k);
                }
            }
            while let Some(j) = joint {
                joint = model.joint_parent(j);
                if let Some(k) = joint.and_then(|p| index(model.joint_child_frame(p))) {
                    return Some(k);
                }
            }
            None
        })
        .collect();
    (frames, parents)
}

impl ViewRecorder {
    /// The recorder of a run of `scene` with the controller `config`: the skin markers from its
    /// layout and fusion parameters (the aggregator's).
    pub fn new(scene: &Scene, config: &ControllerConfig) -> Self {
        let model = config.model.clone();
        let (frames, parents) = tf_tree(&model);
        let spec = scene.spec.view;
        ViewRecorder {
            data: ModelData::new(&model),
            markers: SkinMarkers::new(&config.layout),
            layout: config.layout.clone(),
            fusion: config.skin.fusion,
            wrenches: Vec::new(),
            period_s: 1.0 / spec.fps,
            next_s: 0.0,
            labelled: 0,
            view: View {
                spec,
                robot_description: scene.robot_description.clone(),
                links: frames.iter().map(|&f| model.frame_names()[f].clone()).collect(),
                parents,
                goals: scene.spec.goals.clone(),
                cells: config
                    .layout
                    .patches()
                    .iter()
                    .flat_map(|p| {
                        config.layout.cells()[p.cells.clone()]
                            .iter()
                            .map(|c| CellSite { link: p.link.clone(), position: c.position_link.into() })
                    })
                    .collect(),
                frames: Vec::new(),
            },
            frames,
            model,
        }
    }

    /// Called every control cycle with the world as the controller saw it, its arrangement and
    /// the event of the cycle (`start`, a switch); takes a frame when one is due or there is an
    /// event (labelled while key frames are left: the start, the first switches).
    pub fn cycle(&mut self, world: &World, mode: Mode, event: Option<String>) {
        let due = world.time() >= self.next_s - 1e-9;
        if !due && event.is_none() {
            return;
        }
        // one key frame is kept for the end
        let label = event.filter(|_| self.labelled + 1 < MAX_KEY_FRAMES);
        self.capture(world, mode, label.unwrap_or_default());
        if due {
            self.next_s +=
                self.period_s * ((world.time() - self.next_s) / self.period_s).floor().max(0.0) + self.period_s;
        }
    }

    /// The view, with a last frame `end` of `world` in `mode`.
    pub fn finish(mut self, world: &World, mode: Mode) -> View {
        self.capture(world, mode, "end".into());
        self.view
    }

    fn capture(&mut self, world: &World, mode: Mode, label: String) {
        self.labelled += usize::from(!label.is_empty());
        let q = world.q();
        update_kinematics(&self.model, &mut self.data, q, &vec![0.0; q.len()])
            .expect("the world's joints are the model's");
        let readings = world.skin_readings();
        let mut markers = Vec::new();
        if readings.len() == self.layout.num_cells() {
            aggregate_patches(&self.layout, readings, &self.fusion, &mut self.wrenches).expect("lengths checked");
            self.markers.update(&self.layout, readings, &self.fusion, &self.wrenches, &mut markers);
        }
        let mut frame = world.key_frame(label);
        frame.mode = mode.name().to_string();
        frame.poses = self.frames.iter().map(|&f| pose_array(self.data.frame_pose(f))).collect();
        frame.markers = markers;
        self.view.frames.push(frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base_links_collapse_into_odom_to_base_link() {
        let model = RobotModel::from_urdf_file(&crate::scene::config_dir().join("../urdf/tomm.urdf")).unwrap();
        let (frames, parents) = tf_tree(&model);
        let name = |k: usize| model.frame_names()[frames[k]].as_str();
        let parent = |link: &str| {
            let k = (0..frames.len()).find(|&k| name(k) == link).unwrap_or_else(|| panic!("{link} not in the tree"));
            parents[k].map_or(ODOM_FRAME, name)
        };
        assert_eq!(parent("base_link"), ODOM_FRAME);
        assert!(!(0..frames.len()).any(|k| name(k) == "base_x_link" || name(k) == "base_y_link"));
        // every link reaches odom
        for k in 0..frames.len() {
            let (mut at, mut hops) = (Some(k), 0);
            while let Some(p) = at {
                at = parents[p];
                hops += 1;
                assert!(hops <= frames.len(), "{} is in a cycle", name(k));
            }
        }
        let planar = RobotModel::from_urdf_file(&crate::scene::config_dir().join("../urdf/planar7.urdf")).unwrap();
        let (frames, parents) = tf_tree(&planar);
        let name = |k: usize| planar.frame_names()[frames[k]].as_str();
        let of = |link: &str| parents[(0..frames.len()).find(|&k| name(k) == link).unwrap()].map_or(ODOM_FRAME, name);
        // the model keeps no parent of a root joint's link: it hangs from odom
        assert_eq!((of("link2"), of("link1"), of("ee")), ("link1", ODOM_FRAME, "link7"));
    }
}
