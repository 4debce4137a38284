//! A study file's material: a `[material]` table naming a model of the registry
//! ([`crate::material::constitutive::registry`]) with its parameters,
//!
//! ```toml
//! [material]
//! model = "von-mises"
//! young_modulus = 1.0e6    # Pa
//! poisson_ratio = 0.3
//! yield_stress = 2.0e4     # Pa
//! ```
//!
//! and, where a study solves several materials, `[materials.<name>]` tables of the same form
//! that a sweep names (`material = "<name>"`; the compaction's plastic sweeps). Every error
//! names the file's key (`material.yield_stress`, `materials.von-mises.model`) and, through
//! [`super::locate`], its line: an unknown model lists the known ones, a missing or unknown
//! parameter lists the model's.

use super::vocabulary::Checker;
use super::StudyError;
use crate::material::constitutive::Material;
use crate::solver::error::InputError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A `[material]` table as the file writes it: the model's name and its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialTable {
    /// The model's name in the registry, e.g. `linear-elastic` or `von-mises`.
    pub model: String,
    /// Every other key: the model's parameters.
    #[serde(flatten)]
    pub parameters: BTreeMap<String, f64>,
}

impl MaterialTable {
    /// The table of `material`.
    pub fn of(material: &Material) -> Self {
        Self {
            model: material.model().to_string(),
            parameters: material.parameters().map(|(k, v)| (k.to_string(), v)).collect(),
        }
    }

    /// The material of this table at key `path` (`material`, `materials.<name>`), its model
    /// built once to check the values: an error names the key under `path`.
    pub fn resolve(&self, path: &str) -> Result<Material, InputError> {
        let given: Vec<(&str, f64)> = self.parameters.iter().map(|(k, &v)| (k.as_str(), v)).collect();
        let keyed = |mut e: InputError| {
            if let Some(rest) = e.field.strip_prefix("material") {
                e.field = format!("{path}{rest}");
            }
            e
        };
        let material = Material::new(&self.model, &given).map_err(keyed)?;
        material.build().map_err(keyed)?;
        Ok(material)
    }

    /// The material of a table its study checked when it was read ([`Checker::material`]).
    ///
    /// # Panics
    /// If the table does not resolve (a study kind reads no file without checking it).
    pub fn material(&self) -> Material {
        self.resolve("material")
            .unwrap_or_else(|e| panic!("a study's material is checked when it is read: {e}"))
    }

    /// The value of parameter `key` as written, if any.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.parameters.get(key).copied()
    }

    /// The value of parameter `key` as written, NaN if absent (for reports).
    pub fn parameter(&self, key: &str) -> f64 {
        self.get(key).unwrap_or(f64::NAN)
    }
}

impl Checker<'_> {
    /// The material of the table at key `path`, checked: an error names the file's key.
    pub fn material(&self, path: &str, table: &MaterialTable) -> Result<Material, StudyError> {
        table
            .resolve(path)
            .map_err(|e| self.err(e.field, e.value, e.allowed))
    }

    /// The value of `material`'s parameter `name`, which `what` needs: an error names the key
    /// under `path`.
    pub fn material_parameter(
        &self,
        path: &str,
        material: &Material,
        name: &str,
        what: &str,
    ) -> Result<f64, StudyError> {
        material.require(name, what).map_err(|e| {
            let key = format!("{path}{}", e.field.strip_prefix("material").unwrap_or(&e.field));
            self.err(key, e.value, e.allowed)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_key_under_the_tables_path() {
        let table: MaterialTable =
            toml::from_str("model = \"von-mises\"\nyoung_modulus = 1.0e6\npoisson_ratio = 0.3\n").unwrap();
        let e = table.resolve("materials.plastic").unwrap_err();
        assert_eq!(e.field, "materials.plastic.yield_stress");
        let table: MaterialTable = toml::from_str("model = \"elastic\"\n").unwrap();
        let e = table.resolve("material").unwrap_err();
        assert_eq!(e.field, "material.model");
        assert!(e.allowed.contains("linear-elastic, von-mises"), "{e}");
        let m = Material::von_mises(1e6, 0.3, 2e4);
        assert_eq!(MaterialTable::of(&m).resolve("material").unwrap(), m);
    }
}
