//! A typed `skin_core` parameter struct exposed as declared ROS parameters, generically.
//!
//! The struct is serialized (serde) to a tree and flattened to dotted names
//! (`fusion.weight_force`) with ROS parameter values. [`StructParams`] implements r2r's
//! [`RosParams`], so `Node::make_derived_parameter_handler` serves it through the standard
//! parameter services (list, get, set, set atomically, describe, get types):
//! - at registration, the node's parameter overrides (`--ros-args --params-file`, `-p`) are laid
//!   over the initial value (the core defaults file), then deserialized and validated; an unknown
//!   override is an error, so a typo in a parameter file does not pass silently;
//! - a set request replaces one leaf, unflattens, deserializes and calls the struct's validation;
//!   an invalid value is rejected with the key and the reason, and the struct stays unchanged;
//! - read-only entries (start-up settings such as file paths) are listed and readable, and a set
//!   request on them is rejected.
//!
//! Types: bool, integer, double (an integer is accepted for a double), string (enums in their
//! serde spelling), and arrays of those. Keys must not contain dots themselves.
use std::fmt;

use indexmap::IndexMap;
use r2r::{Parameter, ParameterValue, RosParams};
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::{Map, Number, Value};
use skin_core::param_file::declare::ParamSpec;

/// A parameter key with what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamError {
    /// Dotted key, e.g. `fusion.weight_force`.
    pub key: String,
    /// Why the key or its value is refused.
    pub reason: String,
}

impl ParamError {
    fn new(key: &str, reason: impl Into<String>) -> Self {
        ParamError { key: key.to_string(), reason: reason.into() }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.key.is_empty() {
            write!(f, "parameters: {}", self.reason)
        } else {
            write!(f, "parameter `{}`: {}", self.key, self.reason)
        }
    }
}

impl std::error::Error for ParamError {}

impl From<ParamError> for r2r::Error {
    fn from(e: ParamError) -> Self {
        // The variant r2r shows with a free-form message (the reason goes back to the caller of
        // set_parameters as is).
        r2r::Error::ParameterValueConv { name: e.key, msg: e.reason }
    }
}

/// Checks a whole struct; the error text should name the offending key.
pub type Validate<T> = fn(&T) -> Result<(), String>;

/// Parameter names that a node may receive without declaring them (rcl and r2r handle them).
const UNDECLARED_OK: [&str; 1] = ["use_sim_time"];

/// A typed parameter struct served as flat ROS parameters (see the module doc).
pub struct StructParams<T> {
    value: T,
    flat: IndexMap<String, ParameterValue>,
    validate: Validate<T>,
    /// Descriptions from declarations (`skin_core::param_file::declare`), by dotted key.
    declared: IndexMap<String, &'static str>,
    read_only: IndexMap<String, (ParameterValue, &'static str)>,
    /// Keys (or sections, ending in `.`) that only the start reads.
    start_only: Vec<String>,
}

impl<T: Serialize + DeserializeOwned> StructParams<T> {
    /// Serves `value` (validated with `validate`); [`Self::with_specs`] describes its keys.
    pub fn new(value: T, validate: Validate<T>) -> Result<Self, ParamError> {
        validate(&value).map_err(|reason| ParamError::new("", reason))?;
        Ok(StructParams {
            flat: flatten(&value)?,
            value,
            validate,
            declared: IndexMap::new(),
            read_only: IndexMap::new(),
            start_only: Vec::new(),
        })
    }

    /// Adds a read-only entry `name` (listed and readable; set requests are rejected).
    pub fn with_read_only(mut self, name: &str, value: ParameterValue, description: &'static str) -> Self {
        self.read_only.insert(name.to_string(), (value, description));
        self
    }

    /// Describes the keys of declared parameters (`ros2 param describe`: the description, unit,
    /// range, and whether the node applies a change while it runs); a key declared not `live`
    /// is read at start only.
    pub fn with_specs(mut self, specs: Vec<ParamSpec>) -> Self {
        self.start_only.extend(specs.iter().filter(|s| !s.live).map(|s| s.key.clone()));
        for s in specs {
            let unit = if s.unit.is_empty() { String::new() } else { format!(" [{}]", s.unit) };
            let when = if s.live && !self.is_start_only(&s.key) { "settable" } else { "start only" };
            // r2r takes `&'static str` descriptions: one string per parameter, made once per node
            let text = format!("{}{unit}, in {} ({when})", s.description, s.values);
            self.declared.insert(s.key, Box::leak(text.into_boxed_str()));
        }
        self
    }

    /// Marks a section (`skin.`) that only this node's start reads, whatever its declarations
    /// say of other nodes. Start-only keys take overrides at start; set requests are rejected.
    pub fn with_start_only_section(mut self, section: &str) -> Self {
        self.start_only.push(section.to_string());
        self
    }

    fn is_start_only(&self, key: &str) -> bool {
        self.start_only.iter().any(|k| key == k || (k.ends_with('.') && key.starts_with(k.as_str())))
    }

    /// The current, valid struct.
    pub fn value(&self) -> &T {
        &self.value
    }

    /// The current values by dotted key.
    pub fn flat(&self) -> &IndexMap<String, ParameterValue> {
        &self.flat
    }

    /// The struct with `key` set to `value`, validated; `self` is unchanged.
    pub fn with_value(&self, key: &str, value: &ParameterValue) -> Result<T, ParamError> {
        if self.read_only.contains_key(key) {
            return Err(ParamError::new(key, "read-only: read at start, restart the node to change it"));
        }
        if self.is_start_only(key) {
            return Err(ParamError::new(key, "read-only: read at start, restart the node to change it"));
        }
        let current = self.flat.get(key).ok_or_else(|| ParamError::new(key, "no such parameter"))?;
        let mut flat = self.flat.clone();
        flat.insert(key.to_string(), coerce(key, current, value)?);
        let candidate: T = unflatten(&flat).map_err(|reason| ParamError::new(key, reason))?;
        (self.validate)(&candidate).map_err(|reason| ParamError::new(key, reason))?;
        Ok(candidate)
    }

    /// Sets `key` to `value` (see [`Self::with_value`]).
    pub fn set(&mut self, key: &str, value: &ParameterValue) -> Result<(), ParamError> {
        let value = self.with_value(key, value)?;
        self.flat = flatten(&value)?;
        self.value = value;
        Ok(())
    }

    fn description(&self, key: &str) -> &'static str {
        self.declared.get(key).copied().unwrap_or("")
    }

    /// Lays the node's parameter overrides (name -> value, as r2r reads them from `--ros-args`)
    /// over the current value, all at once, then validates; an unknown name is an error.
    pub fn apply_overrides(&mut self, overrides: &IndexMap<String, Parameter>) -> Result<(), ParamError> {
        let mut flat = self.flat.clone();
        for (key, p) in overrides {
            if let Some(current) = flat.get_mut(key) {
                *current = coerce(key, current, &p.value)?;
            } else if !self.read_only.contains_key(key) && !UNDECLARED_OK.contains(&key.as_str()) {
                return Err(ParamError::new(key, "unknown parameter (a typo in the parameter file?)"));
            }
        }
        let value: T = unflatten(&flat).map_err(|reason| ParamError::new("", reason))?;
        (self.validate)(&value).map_err(|reason| ParamError::new("", reason))?;
        self.flat = flatten(&value)?;
        self.value = value;
        Ok(())
    }

    /// [`Self::apply_overrides`], then declares every key in `params` with its description.
    fn register(&mut self, params: &mut IndexMap<String, Parameter>) -> Result<(), ParamError> {
        self.apply_overrides(params)?;
        for (key, v) in &self.flat {
            let description = self.description(key);
            params.insert(key.clone(), Parameter { value: v.clone(), description });
        }
        for (key, (v, description)) in &self.read_only {
            params.insert(key.clone(), Parameter { value: v.clone(), description });
        }
        Ok(())
    }
}

impl<T: Serialize + DeserializeOwned> RosParams for StructParams<T> {
    fn register_parameters(
        &mut self,
        prefix: &str,
        _param: Option<Parameter>,
        params: &mut IndexMap<String, Parameter>,
    ) -> r2r::Result<()> {
        if !prefix.is_empty() {
            return Err(ParamError::new(prefix, "StructParams serves the node's top level only").into());
        }
        Ok(self.register(params)?)
    }

    fn get_parameter(&mut self, name: &str) -> r2r::Result<ParameterValue> {
        self.flat
            .get(name)
            .or_else(|| self.read_only.get(name).map(|(v, _)| v))
            .cloned()
            .ok_or_else(|| ParamError::new(name, "no such parameter").into())
    }

    fn set_parameter(&mut self, name: &str, value: &ParameterValue) -> r2r::Result<()> {
        Ok(self.set(name, value)?)
    }

    fn check_parameter(&self, name: &str, value: &ParameterValue) -> r2r::Result<()> {
        self.with_value(name, value).map(|_| ()).map_err(Into::into)
    }
}

/// `value` as a parameter of the type of `current` (an integer may set a double).
fn coerce(key: &str, current: &ParameterValue, value: &ParameterValue) -> Result<ParameterValue, ParamError> {
    use ParameterValue as P;
    match (current, value) {
        (P::Double(_), P::Integer(i)) => Ok(P::Double(*i as f64)),
        (P::DoubleArray(_), P::IntegerArray(a)) => Ok(P::DoubleArray(a.iter().map(|&i| i as f64).collect())),
        (P::NotSet, v) => Ok(v.clone()),
        (c, v) if std::mem::discriminant(c) == std::mem::discriminant(v) => Ok(v.clone()),
        (c, v) => Err(ParamError::new(key, format!("expected type {}, got {}", c.type_name(), v.type_name()))),
    }
}

/// The leaves of `value`'s serde tree by dotted key, sorted by key.
pub fn flatten<T: Serialize>(value: &T) -> Result<IndexMap<String, ParameterValue>, ParamError> {
    let tree = serde_json::to_value(value).map_err(|e| ParamError::new("", e.to_string()))?;
    let mut out = IndexMap::new();
    flatten_into("", &tree, &mut out)?;
    Ok(out)
}

fn flatten_into(key: &str, v: &Value, out: &mut IndexMap<String, ParameterValue>) -> Result<(), ParamError> {
    if let Value::Object(map) = v {
        for (name, child) in map {
            let child_key = if key.is_empty() { name.clone() } else { format!("{key}.{name}") };
            flatten_into(&child_key, child, out)?;
        }
    } else {
        out.insert(key.to_string(), leaf(key, v)?);
    }
    Ok(())
}

fn leaf(key: &str, v: &Value) -> Result<ParameterValue, ParamError> {
    use ParameterValue as P;
    let all = |pred: fn(&Value) -> bool, a: &[Value]| !a.is_empty() && a.iter().all(pred);
    Ok(match v {
        Value::Null => P::NotSet,
        Value::Bool(b) => P::Bool(*b),
        Value::Number(n) => number(key, n)?,
        Value::String(s) => P::String(s.clone()),
        Value::Array(a) if all(Value::is_boolean, a) => P::BoolArray(a.iter().filter_map(Value::as_bool).collect()),
        Value::Array(a) if all(Value::is_i64, a) => P::IntegerArray(a.iter().filter_map(Value::as_i64).collect()),
        Value::Array(a) if all(Value::is_number, a) => P::DoubleArray(a.iter().filter_map(Value::as_f64).collect()),
        Value::Array(a) if all(Value::is_string, a) => {
            P::StringArray(a.iter().filter_map(|s| s.as_str().map(str::to_string)).collect())
        }
        Value::Array(_) | Value::Object(_) => {
            return Err(ParamError::new(key, "not a ROS parameter type (empty, mixed or nested array)"))
        }
    })
}

fn number(key: &str, n: &Number) -> Result<ParameterValue, ParamError> {
    if let Some(i) = n.as_i64() {
        Ok(ParameterValue::Integer(i))
    } else if n.is_f64() {
        Ok(ParameterValue::Double(n.as_f64().unwrap_or(f64::NAN)))
    } else {
        Err(ParamError::new(key, "integer beyond the range of a ROS integer parameter"))
    }
}

/// Rebuilds `T` from dotted keys (the inverse of [`flatten`]); the error is serde's reason.
pub fn unflatten<T: DeserializeOwned>(flat: &IndexMap<String, ParameterValue>) -> Result<T, String> {
    let mut root = Map::new();
    for (key, v) in flat {
        let mut node = &mut root;
        let mut parts = key.split('.').peekable();
        while let Some(part) = parts.next() {
            if parts.peek().is_none() {
                node.insert(part.to_string(), to_json(key, v)?);
            } else {
                let child = node.entry(part.to_string()).or_insert_with(|| Value::Object(Map::new()));
                node = child.as_object_mut().ok_or_else(|| format!("`{key}`: `{part}` is a value and a section"))?;
            }
        }
    }
    serde_json::from_value(Value::Object(root)).map_err(|e| e.to_string())
}

fn to_json(key: &str, v: &ParameterValue) -> Result<Value, String> {
    use ParameterValue as P;
    let double =
        |x: f64| Number::from_f64(x).map(Value::Number).ok_or_else(|| format!("`{key}` = {x}: not a finite number"));
    Ok(match v {
        P::NotSet => Value::Null,
        P::Bool(b) => Value::Bool(*b),
        P::Integer(i) => Value::from(*i),
        P::Double(x) => double(*x)?,
        P::String(s) => Value::String(s.clone()),
        P::BoolArray(a) => Value::from(a.clone()),
        P::ByteArray(a) => Value::from(a.clone()),
        P::IntegerArray(a) => Value::from(a.clone()),
        P::DoubleArray(a) => Value::Array(a.iter().map(|&x| double(x)).collect::<Result<_, _>>()?),
        P::StringArray(a) => Value::from(a.clone()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;
    use skin_core::param_file::declare::Declared;
    use skin_core::skin::params::SkinParams;
    use std::path::Path;

    fn skin_params() -> SkinParams {
        SkinParams::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/skin_model.yaml")).unwrap()
    }

    fn served() -> StructParams<SkinParams> {
        StructParams::new(skin_params(), |p| p.validate().map_err(|e| e.to_string()))
            .unwrap()
            .with_specs(SkinParams::all_specs())
            .with_read_only("layout_file", ParameterValue::String("l.yaml".into()), "layout")
    }

    #[test]
    fn skin_params_flatten_to_dotted_leaves_and_back() {
        let p = skin_params();
        let flat = flatten(&p).unwrap();
        assert_eq!(flat["fusion.weight_force"], ParameterValue::Double(0.5));
        assert_eq!(flat["fusion.force_reduction"], ParameterValue::String("mean".into()));
        assert_eq!(unflatten::<SkinParams>(&flat).unwrap(), p);
    }

    #[test]
    fn set_applies_valid_values_and_rejects_invalid_ones_with_the_reason() {
        let mut s = served();
        s.set("fusion.weight_force", &ParameterValue::Double(0.25)).unwrap();
        assert_eq!(s.value().fusion.weight_force, 0.25);
        s.set("fusion.weight_force", &ParameterValue::Integer(1)).unwrap();
        assert_eq!(s.value().fusion.weight_force, 1.0);
        let e = s.set("fusion.weight_force", &ParameterValue::Double(1.5)).unwrap_err();
        assert_eq!(e.key, "fusion.weight_force");
        assert!(e.reason.contains("fusion.weight_force") && e.reason.contains("[0, 1]"), "{e}");
        assert_eq!(s.value().fusion.weight_force, 1.0, "unchanged after a rejection");
        let e = s.set("fusion.force_reduction", &ParameterValue::String("median".into())).unwrap_err();
        assert!(e.reason.contains("unknown variant `median`"), "{e}");
        s.set("fusion.force_reduction", &ParameterValue::String("max".into())).unwrap();
        let e = s.set("fusion.weight_force", &ParameterValue::String("x".into())).unwrap_err();
        assert_eq!(e.reason, "expected type double, got string");
        // A cross-field rule of SkinParams::validate names the other key.
        let e = s.set("proximity.range_m", &ParameterValue::Double(0.05)).unwrap_err();
        assert!(e.reason.contains("repulsion.range_m"), "{e}");
        let e = s.set("layout_file", &ParameterValue::String("x".into())).unwrap_err();
        assert!(e.reason.starts_with("read-only"), "{e}");
        let e = s.set("fusion.bogus", &ParameterValue::Double(0.0)).unwrap_err();
        assert_eq!(e.to_string(), "parameter `fusion.bogus`: no such parameter");
        let e = s.set("fusion.weight_force", &ParameterValue::Double(f64::NAN)).unwrap_err();
        assert!(e.reason.contains("not a finite number"), "{e}");
    }

    #[test]
    fn register_overlays_overrides_declares_everything_and_rejects_unknown_keys() {
        let mut s = served();
        let mut params = IndexMap::new();
        params.insert("fusion.weight_force".to_string(), Parameter::new(ParameterValue::Double(0.75)));
        params.insert("use_sim_time".to_string(), Parameter::new(ParameterValue::Bool(false)));
        s.register_parameters("", None, &mut params).unwrap();
        assert_eq!(s.value().fusion.weight_force, 0.75);
        assert_eq!(params["fusion.weight_force"].value, ParameterValue::Double(0.75));
        let described = params["fusion.weight_force"].description;
        assert!(described.contains("in [0, 1] (settable)"), "{described}");
        assert_eq!(params["layout_file"].value, ParameterValue::String("l.yaml".into()));
        assert_eq!(params.len(), s.flat().len() + 2);
        assert_eq!(s.get_parameter("layout_file").unwrap(), ParameterValue::String("l.yaml".into()));
        assert!(s.check_parameter("fusion.weight_force", &ParameterValue::Double(2.0)).is_err());

        let mut s = served();
        let mut params = IndexMap::new();
        params.insert("fusion.weight_forc".to_string(), Parameter::new(ParameterValue::Double(0.75)));
        let e = s.register_parameters("", None, &mut params).unwrap_err().to_string();
        assert!(e.contains("fusion.weight_forc") && e.contains("unknown parameter"), "{e}");

        let mut s = served();
        let mut params = IndexMap::new();
        params.insert("fusion.activity_threshold".to_string(), Parameter::new(ParameterValue::Double(1.0)));
        let e = s.register_parameters("", None, &mut params).unwrap_err().to_string();
        assert!(e.contains("fusion.activity_threshold"), "{e}");
    }

    #[test]
    fn start_only_keys_take_overrides_but_refuse_sets() {
        // a section this node reads at start, and a key declared not live
        let fixed = ParamSpec {
            key: "fusion.weight_force".into(),
            unit: "",
            values: skin_core::param_file::declare::Values::Choices("any"),
            description: "w".into(),
            live: false,
        };
        let mut s = served().with_start_only_section("proximity.").with_specs(vec![fixed]);
        let mut o = IndexMap::new();
        o.insert("proximity.range_m".to_string(), Parameter::new(ParameterValue::Double(0.2)));
        s.apply_overrides(&o).unwrap();
        assert_eq!(s.value().proximity.range_m, 0.2);
        for key in ["proximity.range_m", "fusion.weight_force"] {
            let e = s.set(key, &ParameterValue::Double(0.3)).unwrap_err();
            assert!(e.reason.starts_with("read-only"), "{e}");
        }
        s.set("fusion.activity_threshold", &ParameterValue::Double(0.1)).unwrap();
    }

    #[test]
    fn arrays_options_and_integers() {
        #[derive(Serialize, Deserialize, Debug, PartialEq)]
        struct Inner {
            gains: [f64; 2],
            ids: Vec<u32>,
            names: Vec<String>,
            limit: Option<f64>,
        }
        #[derive(Serialize, Deserialize, Debug, PartialEq)]
        struct Outer {
            count: u32,
            inner: Inner,
        }
        let v = Outer {
            count: 3,
            inner: Inner { gains: [1.0, 2.5], ids: vec![4, 5], names: vec!["a".into()], limit: None },
        };
        let mut s = StructParams::new(v, |_| Ok(())).unwrap();
        assert_eq!(s.flat()["count"], ParameterValue::Integer(3));
        assert_eq!(s.flat()["inner.ids"], ParameterValue::IntegerArray(vec![4, 5]));
        // serde_json writes 1.0 as a float: the array stays a double array.
        assert_eq!(s.flat()["inner.gains"], ParameterValue::DoubleArray(vec![1.0, 2.5]));
        assert_eq!(s.flat()["inner.limit"], ParameterValue::NotSet);
        s.set("inner.gains", &ParameterValue::IntegerArray(vec![3, 4])).unwrap();
        assert_eq!(s.value().inner.gains, [3.0, 4.0]);
        s.set("inner.limit", &ParameterValue::Double(0.5)).unwrap();
        assert_eq!(s.value().inner.limit, Some(0.5));
        let e = s.set("count", &ParameterValue::Integer(-1)).unwrap_err();
        assert!(e.reason.contains("-1"), "{e}");
        let e = s.set("count", &ParameterValue::Double(1.0)).unwrap_err();
        assert_eq!(e.reason, "expected type integer, got double");
    }
}
