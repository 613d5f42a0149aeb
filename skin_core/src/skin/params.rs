//! Skin model parameters (`config/skin_model.yaml`): cell characteristics, fusion and repulsion,
//! loaded and validated with errors naming the file and the key.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::aggregate::FusionParams;
use super::characteristic::{ForceCharacteristic, ProximityCharacteristic};
use super::repulsion::RepulsionParams;
use crate::declare_params;
use crate::param_file::{load_validated, parse_validated, InvalidParam, ParamsError};

declare_params! {
    /// All skin model parameters (one YAML file, sections as the fields).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct SkinParams {
        /// Proximity characteristic (distance <-> signal).
        pub proximity: ProximityCharacteristic => nested,
        /// Force characteristic (force <-> signal).
        pub force: ForceCharacteristic => nested,
        /// Fusion of force and proximity into the cells' virtual force (interactive-force-control paper eq. (6)).
        pub fusion: FusionParams => nested,
        /// Repulsion from proximity (intentional-contact paper eq. (3), interactive-force-control paper eq. (16)).
        pub repulsion: RepulsionParams => nested,
    }
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
                reason: "must not exceed proximity.range_m (the cells measure no farther)".into(),
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
    use crate::param_file::yaml::YamlError;
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
        write(
            "c.yaml",
            &format!("extends: {}\narm: {{sync_gain_per_s: -1.0}}\n", config.join("resolver.yaml").display()),
        );
        let e = ResolverParams::load(&dir.join("c.yaml")).unwrap_err().to_string();
        assert!(e.contains("c.yaml") && e.contains("arm.sync_gain_per_s"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn invalid_value_names_file_and_key() {
        let text = std::fs::read_to_string(shipped()).unwrap();
        let bad = text.replace("decay_m: 0.03", "decay_m: -0.03");
        assert_ne!(bad, text, "test expects `decay_m: 0.03` in the shipped file");
        let e = SkinParams::from_yaml_str(&bad, "bad.yaml").unwrap_err().to_string();
        assert!(e.contains("bad.yaml") && e.contains("proximity.decay_m"), "{e}");
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
