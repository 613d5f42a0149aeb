//! Parameters declared once. [`declare_params!`](crate::declare_params) writes a parameter
//! struct with, beside each field, its unit, its valid range and whether it may change while the
//! controller runs; the field's doc comment is its description. From that one declaration come:
//! the range checks of the YAML loaders (errors name the file and the dotted key, and say the
//! range), the ROS parameter descriptions and checks of the nodes (`ros2 param set` is refused
//! with the range in the reason), and the tables of `docs/parameters.md` (`skin_params_doc`).

use std::fmt;

use super::InvalidParam;

/// The valid values of a number: finite, from `min` to `max`, each bound included unless open.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower bound.
    pub min: f64,
    /// Whether `min` itself is excluded.
    pub min_open: bool,
    /// Upper bound.
    pub max: f64,
    /// Whether `max` itself is excluded.
    pub max_open: bool,
}

impl Range {
    /// `(0, max]`.
    pub const fn positive(max: f64) -> Self {
        Range { min: 0.0, min_open: true, max, max_open: false }
    }

    /// `[min, max]`.
    pub const fn closed(min: f64, max: f64) -> Self {
        Range { min, min_open: false, max, max_open: false }
    }

    /// `[min, max)`.
    pub const fn below(min: f64, max: f64) -> Self {
        Range { min, min_open: false, max, max_open: true }
    }

    /// Whether `x` is finite and in the range.
    pub fn contains(&self, x: f64) -> bool {
        let above_min = if self.min_open { x > self.min } else { x >= self.min };
        let below_max = if self.max_open { x < self.max } else { x <= self.max };
        x.is_finite() && above_min && below_max
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let open = if self.min_open { "(" } else { "[" };
        let close = if self.max_open { ")" } else { "]" };
        write!(f, "{open}{}, {}{close}", self.min, self.max)
    }
}

/// The values a parameter may take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Values {
    /// A number, or numbers, in a range.
    Range(Range),
    /// One of these names (an enumeration; serde checks it).
    Choices(&'static str),
    /// Free text of this form (names, topics; the loader checks what it must).
    Text(&'static str),
}

impl fmt::Display for Values {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Values::Range(r) => r.fmt(f),
            Values::Choices(c) | Values::Text(c) => f.write_str(c),
        }
    }
}

/// What one declared parameter is.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Dotted key in the file (`hand_force.lambda_kg`).
    pub key: String,
    /// Unit (`""` for none).
    pub unit: &'static str,
    /// Its valid values (of every number in it).
    pub values: Values,
    /// Its doc comment.
    pub description: String,
    /// Whether it may change while the controller runs (`ros2 param set`); otherwise it is read
    /// at start only.
    pub live: bool,
}

/// A struct written with [`declare_params!`](crate::declare_params).
pub trait Declared {
    /// Every parameter's spec, keys under `prefix` (`"hand_force."`).
    fn specs(prefix: &str, out: &mut Vec<ParamSpec>);

    /// Checks every number against its declared range; the error names the dotted key.
    fn check(&self, prefix: &str) -> Result<(), InvalidParam>;

    /// [`Declared::specs`] from the top.
    fn all_specs() -> Vec<ParamSpec> {
        let mut out = Vec::new();
        Self::specs("", &mut out);
        out
    }
}

impl<T: Declared> Declared for Option<T> {
    fn specs(prefix: &str, out: &mut Vec<ParamSpec>) {
        T::specs(prefix, out)
    }

    fn check(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.as_ref().map_or(Ok(()), |v| v.check(prefix))
    }
}

/// A map of declared structs by name (per-joint overrides): keys `<prefix><name>.<field>`.
impl<T: Declared> Declared for std::collections::BTreeMap<String, T> {
    fn specs(prefix: &str, out: &mut Vec<ParamSpec>) {
        T::specs(&format!("{prefix}<name>."), out)
    }

    fn check(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.iter().try_for_each(|(name, v)| v.check(&format!("{prefix}{name}.")))
    }
}

/// The numbers in a parameter's value (one, or one per element).
pub trait Numbers {
    /// Calls `f` with each number and its element index (`None` for a scalar).
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam>;
}

impl Numbers for f64 {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        f(None, *self)
    }
}

impl Numbers for Option<f64> {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        self.map_or(Ok(()), |x| f(None, x))
    }
}

impl Numbers for usize {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        f(None, *self as f64)
    }
}

impl Numbers for [f64] {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        self.iter().enumerate().try_for_each(|(i, &x)| f(Some(i), x))
    }
}

impl<const N: usize> Numbers for [f64; N] {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        self.as_slice().each(f)
    }
}

impl Numbers for Vec<f64> {
    fn each(&self, f: &mut dyn FnMut(Option<usize>, f64) -> Result<(), InvalidParam>) -> Result<(), InvalidParam> {
        self.as_slice().each(f)
    }
}

/// Checks every number of `value` (parameter `key`) against `range`.
pub fn check_numbers(key: &str, value: &dyn Numbers, range: Range, unit: &str) -> Result<(), InvalidParam> {
    value.each(&mut |index, x| {
        if range.contains(x) {
            return Ok(());
        }
        let key = index.map_or_else(|| key.to_string(), |i| format!("{key}[{i}]"));
        let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
        Err(InvalidParam { key, value: x, reason: format!("must be in {range}{unit}").into() })
    })
}

/// A doc comment's lines as one sentence.
pub fn description(lines: &[&str]) -> String {
    lines.iter().map(|l| l.trim()).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ")
}

/// Writes a parameter struct and its [`Declared`] impl. Each field is followed by `=>` and
/// `{ unit: "N/m", range: Range::positive(1e4), live: false }` (a number or numbers),
/// `{ choices: "mean | max", live: true }` (an enumeration; `"true | false"` for a flag),
/// `{ text: "topic names", live: false }` (free text), or `nested` (a struct of its own,
/// itself declared; `Option` of one too). Doc comments describe the parameter; `#[serde(...)]`
/// attributes go after them.
#[macro_export]
macro_rules! declare_params {
    (
        $(#[$smeta:meta])*
        pub struct $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $(#[serde($($serde:tt)*)])*
                pub $field:ident : $ty:ty => $spec:tt
            ),* $(,)?
        }
    ) => {
        $(#[$smeta])*
        pub struct $name {
            $(
                $(#[doc = $doc])*
                $(#[serde($($serde)*)])*
                pub $field: $ty,
            )*
        }

        impl $crate::param_file::declare::Declared for $name {
            fn specs(prefix: &str, out: &mut Vec<$crate::param_file::declare::ParamSpec>) {
                $( $crate::declare_params!(@spec prefix, out, $field, $ty, [$($doc),*], $spec); )*
            }

            fn check(&self, prefix: &str) -> Result<(), $crate::param_file::InvalidParam> {
                let _ = prefix; // a struct of text fields checks nothing
                $( $crate::declare_params!(@check self, prefix, $field, $spec); )*
                Ok(())
            }
        }
    };
    (@spec $prefix:ident, $out:ident, $field:ident, $ty:ty, [$($doc:literal),*], nested) => {
        <$ty as $crate::param_file::declare::Declared>::specs(&format!("{}{}.", $prefix, stringify!($field)), $out)
    };
    (@spec $prefix:ident, $out:ident, $field:ident, $ty:ty, [$($doc:literal),*],
        { unit: $unit:literal, range: $range:expr, live: $live:expr }) => {
        $crate::declare_params!(@push $prefix, $out, $field, $unit, Range($range), [$($doc),*], $live)
    };
    (@spec $prefix:ident, $out:ident, $field:ident, $ty:ty, [$($doc:literal),*],
        { choices: $choices:literal, live: $live:expr }) => {
        $crate::declare_params!(@push $prefix, $out, $field, "", Choices($choices), [$($doc),*], $live)
    };
    (@spec $prefix:ident, $out:ident, $field:ident, $ty:ty, [$($doc:literal),*],
        { text: $text:literal, live: $live:expr }) => {
        $crate::declare_params!(@push $prefix, $out, $field, "", Text($text), [$($doc),*], $live)
    };
    (@push $prefix:ident, $out:ident, $field:ident, $unit:literal, $kind:ident($values:expr), [$($doc:literal),*], $live:expr) => {
        $out.push($crate::param_file::declare::ParamSpec {
            key: format!("{}{}", $prefix, stringify!($field)),
            unit: $unit,
            values: $crate::param_file::declare::Values::$kind($values),
            description: $crate::param_file::declare::description(&[$($doc),*]),
            live: $live,
        })
    };
    (@check $self:ident, $prefix:ident, $field:ident, { choices: $choices:literal, live: $live:expr }) => {};
    (@check $self:ident, $prefix:ident, $field:ident, { text: $text:literal, live: $live:expr }) => {};
    (@check $self:ident, $prefix:ident, $field:ident, nested) => {
        $crate::param_file::declare::Declared::check(&$self.$field, &format!("{}{}.", $prefix, stringify!($field)))?
    };
    (@check $self:ident, $prefix:ident, $field:ident, { unit: $unit:literal, range: $range:expr, live: $live:expr }) => {
        $crate::param_file::declare::check_numbers(
            &format!("{}{}", $prefix, stringify!($field)),
            &$self.$field,
            $range,
            $unit,
        )?
    };
}

/// A Markdown table of `specs`, each with its value in `values` (a shipped file, serialized):
/// key, value, unit, range, whether it changes at run time, description.
pub fn markdown_table(specs: &[ParamSpec], values: &serde_json::Value) -> String {
    let mut out =
        String::from("| Key | Shipped value | Unit | Range | Run time | Description |\n|---|---|---|---|---|---|\n");
    for s in specs {
        let value = s.key.split('.').try_fold(values, |v, k| v.get(k)).filter(|v| !v.is_null());
        let value = value.map_or_else(|| "none".to_string(), |v| format!("`{v}`"));
        let live = if s.live { "settable" } else { "start only" };
        let desc = s.description.replace('|', "\\|");
        let values = s.values.to_string().replace('|', "\\|");
        out += &format!("| `{}` | {value} | {} | {values} | {live} | {desc} |\n", s.key, s.unit);
    }
    out
}
