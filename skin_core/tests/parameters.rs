//! Parameters declared once: every declared range is enforced by the loader, and the generated
//! reference page is current.

use std::path::PathBuf;

use serde_json::Value;
use skin_core::param_file::declare::{Declared, Values};
use skin_core::tasks::params::TaskParams;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The leaf at dotted `key` (its first element for an array).
fn leaf<'a>(v: &'a mut Value, key: &str) -> Option<&'a mut Value> {
    let leaf = key.split('.').try_fold(v, |v, k| v.get_mut(k))?;
    if leaf.is_array() {
        return leaf.get_mut(0);
    }
    Some(leaf)
}

#[test]
fn every_declared_range_is_enforced_with_the_key_and_the_range() {
    let shipped = TaskParams::load(&root().join("config/tasks.yaml")).unwrap();
    let specs = TaskParams::all_specs();
    assert!(specs.len() > 30, "{} specs", specs.len());
    let mut checked = 0;
    for spec in &specs {
        let Values::Range(range) = spec.values else { continue };
        let mut v = serde_json::to_value(&shipped).unwrap();
        let Some(x) = leaf(&mut v, &spec.key) else { continue }; // an unset optional section
                                                                 // above the maximum; an integer parameter stays an integer
        *x = if x.is_u64() { Value::from(range.max as u64 + 1) } else { Value::from(range.max * 2.0 + 1.0) };
        let p: TaskParams = serde_json::from_value(v).unwrap();
        let e = p.validate().expect_err(&spec.key);
        assert!(e.key.starts_with(&spec.key), "{} refused as {}", spec.key, e.key);
        assert!(e.reason.contains(&range.to_string()), "{}: {}", spec.key, e.reason);
        checked += 1;
    }
    assert!(checked > 30);
}

#[test]
fn a_file_error_names_the_file_the_key_and_the_range() {
    let text = std::fs::read_to_string(root().join("config/tasks.yaml")).unwrap().replace("sectors: 8", "sectors: 400");
    let e = TaskParams::from_yaml_str(&text, "my_tasks.yaml").unwrap_err().to_string();
    assert!(e.contains("my_tasks.yaml") && e.contains("base_avoidance.sectors") && e.contains("[1, 360]"), "{e}");
}

#[test]
fn docs_parameters_md_is_generated_from_the_declarations() {
    let expected = skin_core::params_doc::document(&root()).unwrap();
    let committed = std::fs::read_to_string(root().join("docs/parameters.md")).unwrap_or_default();
    assert!(
        committed == expected,
        "docs/parameters.md is out of date: cargo run -p skin_core --bin skin_params_doc -- --out docs/parameters.md"
    );
}
