//! Arbitrary text as URDF into the robot model parser. Checked: no panic; a model that loads is
//! consistent (one name, limit and axis per joint, `lower <= upper`, unit axes, finite
//! non-negative body masses) and its kinematics and dynamics run without panicking.

use nalgebra::{DMatrix, DVector};
use skin_core::model::{crba, gravity, update_kinematics, ModelData, RobotModel};

use crate::fixtures::text;

fn check_model(m: &RobotModel) {
    let nv = m.nv();
    assert_eq!((m.joint_names().len(), m.joint_limits().len()), (nv, nv));
    assert_eq!(m.frame_names().len(), m.nframes());
    for j in 0..nv {
        let l = &m.joint_limits()[j];
        assert!(l.lower <= l.upper, "joint {}: {l:?}", m.joint_names()[j]);
        assert!((m.joint_axis(j).norm() - 1.0).abs() < 1e-9, "joint {}: axis", m.joint_names()[j]);
        // massless bodies are allowed when their descendants make M positive definite
        let mass = m.body_mass(j);
        assert!(mass.is_finite() && mass >= 0.0, "joint {}: body mass {mass}", m.joint_names()[j]);
        assert_eq!(m.joint_index(&m.joint_names()[j]), Some(j));
    }
    let mut data = ModelData::new(m);
    let zero = vec![0.0; nv];
    update_kinematics(m, &mut data, &zero, &zero).expect("finite q and qd of the model's size");
    let mut mass_matrix = DMatrix::zeros(nv, nv);
    crba(m, &mut data, &mut mass_matrix).expect("sizes from the model");
    let mut tau = DVector::zeros(nv);
    gravity(m, &mut data, &mut tau).expect("sizes from the model");
}

/// The property check of the `urdf` target.
pub fn check(data: &[u8]) {
    if let Ok(m) = RobotModel::from_urdf_str(&text(data), "fuzz.urdf") {
        check_model(&m);
    }
}
