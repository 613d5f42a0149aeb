//! Parameter files: YAML read with errors that name the file and the line ([`yaml`]), layered
//! with `extends:` (a file overrides another key by key), and validated with errors that name the
//! file and the dotted key ([`InvalidParam`]). Every parameter file of the crate (skin model,
//! tasks, resolver, supervisor, controller setup, skin layout) loads through here.

use std::path::Path;

use serde::de::DeserializeOwned;
use thiserror::Error;

pub mod declare;
pub mod yaml;

use yaml::YamlError;

/// A parameter with an invalid value; `key` is its dotted path in the file.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("`{key}` = {value}: {reason}")]
pub struct InvalidParam {
    /// Dotted key, e.g. `proximity.decay_m`.
    pub key: String,
    /// The offending value.
    pub value: f64,
    /// Why it is invalid.
    pub reason: std::borrow::Cow<'static, str>,
}

impl InvalidParam {
    /// `Ok` when `value` is finite and strictly positive, else an error for `prefix` + `name`.
    pub fn positive_finite(prefix: &str, name: &str, value: f64) -> Result<(), InvalidParam> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(InvalidParam { key: format!("{prefix}{name}"), value, reason: "must be finite and > 0".into() })
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
            Err(InvalidParam { key: format!("{prefix}{name}"), value, reason: reason.into() })
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
    let p: T = serde_json::from_value(merged).map_err(|e| YamlError::Parse {
        file: file.clone(),
        line: None,
        column: None,
        message: e.to_string(),
    })?;
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
    let invalid = |message: String| YamlError::Parse {
        file: file.clone(),
        line: None,
        column: None,
        message: format!("{EXTENDS}: {message}"),
    };
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
