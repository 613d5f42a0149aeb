//! The `skin_model` binary: JSON shape of single and batch evaluation, bad-argument handling.

use std::process::{Command, Output};

use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_skin_model");
const TOMM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/tomm.urdf");
const PLANAR7: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../urdf/planar7.urdf");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run skin_model")
}

fn matrix_shape(v: &Value) -> (usize, usize) {
    let rows = v.as_array().unwrap();
    let cols = rows[0].as_array().unwrap().len();
    assert!(rows
        .iter()
        .all(|r| r.as_array().unwrap().len() == cols && r.as_array().unwrap().iter().all(Value::is_f64)));
    (rows.len(), cols)
}

#[test]
fn single_state_json_shape() {
    let q = "0.1,-0.2,0.3,0.4,-1.2,1.1,0.5,0.6,0.7,-0.4,-1.0,-1.3,0.2,0.3,0.1";
    let out = run(&["--urdf", TOMM, "--q", q, "--link", "left_hand", "--point", "0,0,0.01"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["joints"].as_array().unwrap().len(), 15);
    assert_eq!(v["joints"][3], "left_shoulder_pan_joint");
    assert_eq!(matrix_shape(&v["mass_matrix"]), (15, 15));
    assert_eq!(matrix_shape(&v["jacobian"]), (6, 15));
    assert_eq!(v["bias"].as_array().unwrap().len(), 15);
    assert_eq!(v["gravity"].as_array().unwrap().len(), 15);
    assert_eq!(v["jacobian_dot_qdot"].as_array().unwrap().len(), 6);
    // qd defaults to zero: bias equals gravity, J̇q̇ is zero
    assert_eq!(v["bias"], v["gravity"]);
    assert!(v["jacobian_dot_qdot"].as_array().unwrap().iter().all(|x| x.as_f64() == Some(0.0)));
    // the right arm does not move the left hand
    assert!((9..15).all(|c| (0..6).all(|r| v["jacobian"][r][c].as_f64() == Some(0.0))));
}

#[test]
fn without_link_no_jacobian() {
    let out = run(&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,0", "--qd", "1,-1,1,-1,1,-1,1"]);
    assert!(out.status.success());
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.get("jacobian").is_none());
    assert_eq!(matrix_shape(&v["mass_matrix"]), (7, 7));
    // planar arm: gravity torques are exactly zero
    assert!(v["gravity"].as_array().unwrap().iter().all(|x| x.as_f64() == Some(0.0)));
}

#[test]
fn batch_mode_returns_one_result_per_state() {
    let dir = std::env::temp_dir().join(format!("skin_model_batch_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("states.json");
    std::fs::write(
        &file,
        r#"[{"q":[0,0.1,0.2,0.3,0.4,0.5,0.6]},
            {"q":[0,0,0,0,0,0,0],"qd":[1,1,1,1,1,1,1],"link":"ee","point":[0.1,0,0]}]"#,
    )
    .unwrap();
    let out = run(&["--urdf", PLANAR7, "--batch", file.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let list = v.as_array().unwrap();
    assert_eq!(list.len(), 2);
    assert!(list[0].get("jacobian").is_none());
    assert_eq!(matrix_shape(&list[1]["jacobian"]), (6, 7));
    // stretched arm turning as a whole at 1 rad/s: tip point at 1.85 m, centripetal -1.85 m/s² along x
    let a = list[1]["jacobian_dot_qdot"].as_array().unwrap();
    let ax = a[0].as_f64().unwrap();
    assert!(ax < 0.0 && ax.is_finite());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_arguments_fail_with_a_clear_message() {
    let cases: [(&[&str], &str); 6] = [
        (&["--urdf", PLANAR7, "--q", "0,0,0"], "q has 3 values but the model has 7 joints"),
        (&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,0", "--link", "nope"], "unknown link `nope`"),
        (&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,abc"], "`abc` is not a number"),
        (&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,NaN"], "not a finite number"),
        (&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,0", "--qd", "1,2"], "qd has 2 values"),
        (&["--urdf", "missing_robot.urdf", "--q", "0"], "missing_robot.urdf"),
    ];
    for (args, expected) in cases {
        let out = run(args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{args:?}: `{stderr}` lacks `{expected}`");
        assert!(out.stdout.is_empty());
    }
    // unknown links list the known ones and name the URDF
    let out = run(&["--urdf", PLANAR7, "--q", "0,0,0,0,0,0,0", "--link", "nope"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("planar7.urdf") && stderr.contains("link7") && stderr.contains("ee"), "{stderr}");
    // missing --q is a usage error from the argument parser
    assert!(!run(&["--urdf", PLANAR7]).status.success());
}
