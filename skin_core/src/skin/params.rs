//! Skin model parameters (`config/skin_model.yaml`): cell characteristics, fusion and repulsion,
//! loaded and validated with errors naming the file and the key.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::aggregate::FusionParams;
use super::characteristic::{ForceCharacteristic, ProximityCharacteristic};
use super::repulsion::RepulsionParams;
use super::yaml::{self, YamlError};

/// A parameter with an invalid value; `key` is its dotted path in the file.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("`{key}` = {value}: {reason}")]
pub struct InvalidParam {
    /// Dotted key, e.g. `proximity.decay_m`.
    pub key: String,
    /// The offending value.
    pub value: f64,
    /// Why it is invalid.
    pub reason: &'static str,
}

impl InvalidParam {
    /// `Ok` when `value` is finite and strictly positive, else an error for `prefix` + `name`.
    pub fn positive_finite(prefix: &str, name: &str, value: f64) -> Result<(), InvalidParam> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(InvalidParam {
                key: format!("{prefix}{name}"),
                value,
                reason: "must be finite and > 0",
            })
        }
    }

    /// `Ok` when `value` is finite and in `[lo, hi]`, else an error for `prefix` + `name`.
    pub fn in_range(
        prefix: &str,
        name: &str,
        value: f64,
        lo: f64,
        hi: f64,
        reason: &'static str,
    ) -> Result<(), InvalidParam> {
        if value.is_finite() && (lo..=hi).contains(&value) {
            Ok(())
        } else {
            Err(InvalidParam {
                key: format!("{prefix}{name}"),
                value,
                reason,
            })
        }
    }
}

/// Errors loading a parameter file (skin model, resolver, tasks).
#[derive(Debug, Error)]
pub enum ParamsError {
    /// Unreadable or unparsable file.
    #[error(transparent)]
    Yaml(#[from] YamlError),
    /// A value out of its valid range.
    #[error("{file}: {param}")]
    Invalid {
        /// The file.
        file: String,
        /// The parameter and why it is invalid.
        param: InvalidParam,
    },
}

/// Parses YAML `text` as `T` and checks it with `validate`; `source` names the file in errors.
pub fn parse_validated<T: DeserializeOwned>(
    text: &str,
    source: &str,
    validate: impl FnOnce(&T) -> Result<(), InvalidParam>,
) -> Result<T, ParamsError> {
    let p: T = yaml::parse_str(text, source)?;
    validate(&p).map_err(|param| ParamsError::Invalid { file: source.to_string(), param })?;
    Ok(p)
}

/// Reads the file at `path`, then [`parse_validated`]. A file with an `extends` key (another
/// parameter file, relative to this one; not `base` as in the controller setups: the resolver
/// has a `base` section) holds only its differences from that file: its
/// sections are merged into the base's key by key, at every depth (e.g. `arm: {sync_gain_per_s:
/// 1.0}` over `config/resolver.yaml` changes that one value).
pub fn load_validated<T: DeserializeOwned>(
    path: &Path,
    validate: impl FnOnce(&T) -> Result<(), InvalidParam>,
) -> Result<T, ParamsError> {
    let (text, file) = yaml::read_text(path)?;
    let layer: serde_json::Value = yaml::parse_str(&text, &file)?;
    if layer.get(EXTENDS).is_none() {
        // parsed from the text, so that errors keep their line and column
        return parse_validated(&text, &file, validate);
    }
    let merged = read_layers(path, 0)?;
    let p: T = serde_json::from_value(merged).map_err(|e| YamlError::Parse { file: file.clone(), line: None, column: None, message: e.to_string() })?;
    validate(&p).map_err(|param| ParamsError::Invalid { file, param })?;
    Ok(p)
}

/// The key naming the file a parameter file derives from.
const EXTENDS: &str = "extends";

/// How many files a parameter file may derive through (a cycle ends here with an error).
const MAX_EXTENDS_DEPTH: usize = 8;

/// The file at `path` merged over the files it extends, `depth` files below the one first named.
fn read_layers(path: &Path, depth: usize) -> Result<serde_json::Value, YamlError> {
    let (text, file) = yaml::read_text(path)?;
    let mut layer: serde_json::Map<String, serde_json::Value> = yaml::parse_str(&text, &file)?;
    let Some(base) = layer.remove(EXTENDS) else {
        return Ok(serde_json::Value::Object(layer));
    };
    let invalid = |message: String| YamlError::Parse { file: file.clone(), line: None, column: None, message: format!("{EXTENDS}: {message}") };
    let base = base.as_str().ok_or_else(|| invalid("must be a file name".into()))?;
    if depth >= MAX_EXTENDS_DEPTH {
        return Err(invalid(format!("more than {MAX_EXTENDS_DEPTH} files deep (a cycle?)")));
    }
    let mut merged = read_layers(&path.parent().unwrap_or(Path::new(".")).join(base), depth + 1)?;
    merge(&mut merged, serde_json::Value::Object(layer));
    Ok(merged)
}

/// Merges `layer` into `base`: maps key by key (recursively), any other value replaces.
fn merge(base: &mut serde_json::Value, layer: serde_json::Value) {
    match (base, layer) {
        (serde_json::Value::Object(b), serde_json::Value::Object(l)) => {
            for (key, value) in l {
                match b.get_mut(&key) {
                    Some(slot) => merge(slot, value),
                    None => {
                        b.insert(key, value);
                    }
                }
            }
        }
        (slot, value) => *slot = value,
    }
}

/// All skin model parameters (one YAML file, sections as the fields).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkinParams {
    /// Proximity characteristic (distance <-> signal).
    pub proximity: ProximityCharacteristic,
    /// Force characteristic (force <-> signal).
    pub force: ForceCharacteristic,
    /// Fusion of force and proximity into the cells' virtual force (paper 003 eq. (6)).
    pub fusion: FusionParams,
    /// Repulsion from proximity (paper 000 eq. (3), paper 003 eq. (16)).
    pub repulsion: RepulsionParams,
}

impl SkinParams {
    /// Checks every section; the error's key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        self.proximity.validate("proximity.")?;
        self.force.validate("force.")?;
        self.fusion.validate("fusion.")?;
        self.repulsion.validate("repulsion.")?;
        if self.repulsion.range_m > self.proximity.range_m {
            return Err(InvalidParam {
                key: "repulsion.range_m".into(),
                value: self.repulsion.range_m,
                reason: "must not exceed proximity.range_m (the cells measure no farther)",
            });
        }
        Ok(())
    }

    /// Parses and validates YAML text; `source` names the file in errors.
    pub fn from_yaml_str(text: &str, source: &str) -> Result<Self, ParamsError> {
        parse_validated(text, source, Self::validate)
    }

    /// Reads, parses and validates the file at `path`.
    pub fn load(path: &Path) -> Result<Self, ParamsError> {
        load_validated(path, Self::validate)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn shipped() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/skin_model.yaml")
    }

    #[test]
    fn shipped_params_load() {
        let p = SkinParams::load(&shipped()).expect("shipped skin_model.yaml");
        assert!(p.repulsion.range_m <= p.proximity.range_m);
    }

    #[test]
    fn a_file_extends_another_key_by_key() {
        use crate::resolver::ResolverParams;
        let config = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config");
        let base = ResolverParams::load(&config.join("resolver.yaml")).unwrap();
        let phases = ResolverParams::load(&config.join("resolver_phases.yaml")).unwrap();
        assert_ne!(phases.arm.sync_gain_per_s, base.arm.sync_gain_per_s);
        let mut expected = base.clone();
        expected.arm.sync_gain_per_s = phases.arm.sync_gain_per_s;
        assert_eq!(phases, expected);

        let dir = std::env::temp_dir().join(format!("skin_params_extends_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
        write("a.yaml", "extends: b.yaml\n");
        write("b.yaml", "extends: a.yaml\n");
        let e = ResolverParams::load(&dir.join("a.yaml")).unwrap_err().to_string();
        assert!(e.contains("a.yaml") && e.contains("extends") && e.contains("cycle"), "{e}");
        write("c.yaml", &format!("extends: {}\narm: {{sync_gain_per_s: -1.0}}\n", config.join("resolver.yaml").display()));
        let e = ResolverParams::load(&dir.join("c.yaml")).unwrap_err().to_string();
        assert!(e.contains("c.yaml") && e.contains("arm.sync_gain_per_s"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn invalid_value_names_file_and_key() {
        let text = std::fs::read_to_string(shipped()).unwrap();
        let bad = text.replace("decay_m: 0.03", "decay_m: -0.03");
        assert_ne!(
            bad, text,
            "test expects `decay_m: 0.03` in the shipped file"
        );
        let e = SkinParams::from_yaml_str(&bad, "bad.yaml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bad.yaml") && e.contains("proximity.decay_m"),
            "{e}"
        );
    }

    #[test]
    fn parse_error_names_file_and_line() {
        let text = "proximity:\n  range_m: 0.1\n  decay_m: 0.02\n  bogus: 3\n";
        let e = SkinParams::from_yaml_str(text, "x.yaml").unwrap_err();
        match &e {
            ParamsError::Yaml(YamlError::Parse { file, line, .. }) => {
                assert_eq!(file, "x.yaml");
                assert!(line.is_some(), "{e}");
            }
            other => panic!("unexpected {other}"),
        }
        assert!(e.to_string().starts_with("x.yaml:"), "{e}");
    }
}
