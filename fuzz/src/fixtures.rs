//! What the checks share: the shipped TOMM controller configuration, loaded once.

use std::path::Path;
use std::sync::OnceLock;

use nalgebra::Isometry3;
use skin_core::controller::ControllerConfig;
use skin_core::model::{update_kinematics, ModelData};

/// The TOMM setup (`config/controller/tomm.yaml`) with everything it names, and the link frame
/// poses of its model at the setup's posture.
pub struct Tomm {
    /// The loaded configuration.
    pub config: ControllerConfig,
    /// World pose of every model frame at `config.setup.posture`.
    pub frame_poses: Vec<Isometry3<f64>>,
}

/// The shared [`Tomm`] fixture (loaded on first use; a load failure is a broken checkout).
pub fn tomm() -> &'static Tomm {
    static TOMM: OnceLock<Tomm> = OnceLock::new();
    TOMM.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/controller/tomm.yaml");
        let config = ControllerConfig::load(&path).unwrap_or_else(|e| panic!("fixture {}: {e}", path.display()));
        let model = &config.model;
        let mut data = ModelData::new(model);
        let qd = vec![0.0; model.nv()];
        update_kinematics(model, &mut data, &config.setup.posture, &qd).expect("posture of the shipped setup");
        let frame_poses = (0..model.nframes()).map(|f| *data.frame_pose(f)).collect();
        Tomm { config, frame_poses }
    })
}

/// The fuzz input as text: invalid UTF-8 is replaced, so every input reaches the parsers.
pub fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}
