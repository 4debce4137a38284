//! The constitutive models by name: each [`ModelEntry`] gives a model's name, its parameters
//! (names, units, meaning) and the function that builds it from a [`Material`], the name and
//! parameters a study file's `[material]` table or a problem gives.
//!
//! The models igimp ships are [`BUILT_IN`] (one row each, the entry next to the model's
//! code); a program adds its own with [`register`] (`examples/hardening_von_mises.rs`).

use super::{ConstitutiveModel, MAX_INTERNAL};
use crate::solver::error::InputError;
use serde::de::Error as _;
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;
use std::sync::RwLock;

/// Most parameters a model may take (a [`Material`] holds them inline, so that problem specs
/// stay `Copy`).
pub const MAX_PARAMETERS: usize = 8;

/// One parameter of a model: its key in a `[material]` table, its unit and its meaning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parameter {
    pub name: &'static str,
    /// The unit in SI terms (`Pa`, `1` for a ratio); any consistent system works.
    pub unit: &'static str,
    pub meaning: &'static str,
}

/// Young's modulus, the first parameter of every built-in model but modified Cam-Clay (whose
/// bulk stiffness is pressure dependent).
pub const YOUNG_MODULUS: Parameter = Parameter {
    name: "young_modulus",
    unit: "Pa",
    meaning: "Young's modulus E, > 0",
};

/// Poisson's ratio, the second parameter of every built-in model but modified Cam-Clay.
pub const POISSON_RATIO: Parameter = Parameter {
    name: "poisson_ratio",
    unit: "1",
    meaning: "Poisson's ratio ν, in (−1, 0.5)",
};

/// A model the registry can build.
#[derive(Debug)]
pub struct ModelEntry {
    /// The `model` key of a `[material]` table, e.g. `von-mises`.
    pub name: &'static str,
    /// One line saying what the model is.
    pub summary: &'static str,
    /// Its parameters, all required, in the order [`Material::values`] holds them.
    pub parameters: &'static [Parameter],
    /// Check the parameter values (an error names `material.<key>`) and build the model.
    pub build: fn(&Material) -> Result<Box<dyn ConstitutiveModel>, InputError>,
}

/// The models igimp ships: Hencky elasticity, von Mises perfect plasticity, compressible
/// neo-Hookean elasticity, Drucker–Prager and Mohr–Coulomb plasticity and modified Cam-Clay.
pub static BUILT_IN: [&ModelEntry; 6] = [
    &super::LINEAR_ELASTIC,
    &super::VON_MISES,
    &super::NEO_HOOKEAN,
    &super::DRUCKER_PRAGER,
    &super::MOHR_COULOMB,
    &super::MODIFIED_CAM_CLAY,
];

/// Models added by the program ([`register`]), after the built-in ones.
static REGISTERED: RwLock<Vec<&'static ModelEntry>> = RwLock::new(Vec::new());

/// Every model: the built-in ones, then the registered ones in order.
pub fn models() -> Vec<&'static ModelEntry> {
    let registered = REGISTERED.read().unwrap_or_else(|e| e.into_inner());
    BUILT_IN
        .iter()
        .copied()
        .chain(registered.iter().copied())
        .collect()
}

/// The model named `name`, if any.
pub fn find(name: &str) -> Option<&'static ModelEntry> {
    models().into_iter().find(|e| e.name == name)
}

/// Add `entry` to the registry for the rest of the process, so that `[material]` tables and
/// [`Material::new`] can name it. Registering the same entry twice is a no-op; another entry
/// of a taken name, or one with more than [`MAX_PARAMETERS`] parameters or two of one name, is
/// an error.
pub fn register(entry: &'static ModelEntry) -> Result<(), InputError> {
    if entry.parameters.len() > MAX_PARAMETERS {
        return Err(InputError::new(
            "material.model",
            entry.name,
            format!(
                "takes {} parameters, at most {MAX_PARAMETERS}",
                entry.parameters.len()
            ),
        ));
    }
    for (i, p) in entry.parameters.iter().enumerate() {
        if p.name == "model" || entry.parameters[..i].iter().any(|q| q.name == p.name) {
            return Err(InputError::new(
                "material.model",
                entry.name,
                format!("declares the parameter `{}` twice (or as `model`)", p.name),
            ));
        }
    }
    let mut registered = REGISTERED.write().unwrap_or_else(|e| e.into_inner());
    match BUILT_IN
        .iter()
        .chain(registered.iter())
        .find(|e| e.name == entry.name)
    {
        Some(e) if std::ptr::eq(*e, entry) => Ok(()),
        Some(_) => Err(InputError::new(
            "material.model",
            entry.name,
            "is the name of another registered model",
        )),
        None => {
            registered.push(entry);
            Ok(())
        }
    }
}

/// The names of every model, comma-separated (for error messages).
fn known() -> String {
    models().iter().map(|e| e.name).collect::<Vec<_>>().join(", ")
}

/// A material: a model of the registry and a value for each of its parameters. `Copy`, so
/// that a problem's spec holds one by value; [`Material::build`] checks the values and makes
/// the model.
#[derive(Clone, Copy)]
pub struct Material {
    entry: &'static ModelEntry,
    values: [f64; MAX_PARAMETERS],
}

impl Material {
    /// The model named `model` with `parameters` (key, value), each of the model's parameters
    /// given once and no other: an error names the key as `material.<key>` (`material.model`
    /// for an unknown model, listing the known ones). The values are checked by
    /// [`Material::build`].
    pub fn new(model: &str, parameters: &[(&str, f64)]) -> Result<Self, InputError> {
        let entry = find(model).ok_or_else(|| {
            InputError::new(
                "material.model",
                format!("{model:?}"),
                format!("must name a known model: {}", known()),
            )
        })?;
        Self::of(entry, parameters)
    }

    /// [`Material::new`] for the model `entry` (which need not be registered).
    pub fn of(entry: &'static ModelEntry, parameters: &[(&str, f64)]) -> Result<Self, InputError> {
        let schema = entry.parameters;
        if schema.len() > MAX_PARAMETERS {
            return Err(InputError::new(
                "material.model",
                entry.name,
                format!("takes {} parameters, at most {MAX_PARAMETERS}", schema.len()),
            ));
        }
        let names = || schema.iter().map(|p| p.name).collect::<Vec<_>>().join(", ");
        let mut values = [f64::NAN; MAX_PARAMETERS];
        let mut given = [false; MAX_PARAMETERS];
        for &(key, value) in parameters {
            let Some(i) = schema.iter().position(|p| p.name == key) else {
                return Err(InputError::new(
                    format!("material.{key}"),
                    value,
                    format!(
                        "is not a parameter of the model {} (its parameters: {})",
                        entry.name,
                        names()
                    ),
                ));
            };
            if given[i] {
                return Err(InputError::new(
                    format!("material.{key}"),
                    value,
                    "is given twice",
                ));
            }
            given[i] = true;
            values[i] = value;
        }
        if let Some(i) = (0..schema.len()).find(|&i| !given[i]) {
            let p = &schema[i];
            return Err(InputError::new(
                format!("material.{}", p.name),
                "(missing)",
                format!(
                    "the model {} needs it: {} ({}); its parameters: {}",
                    entry.name,
                    p.meaning,
                    p.unit,
                    names()
                ),
            ));
        }
        Ok(Self { entry, values })
    }

    /// Hencky elasticity ([`super::LinearElastic`]) with E and ν.
    pub fn linear_elastic(young_modulus: f64, poisson_ratio: f64) -> Self {
        Self::from_values(&super::LINEAR_ELASTIC, &[young_modulus, poisson_ratio])
    }

    /// Von Mises perfect plasticity ([`super::VonMises`]) with E, ν and the yield stress ρ_y.
    pub fn von_mises(young_modulus: f64, poisson_ratio: f64, yield_stress: f64) -> Self {
        Self::from_values(&super::VON_MISES, &[young_modulus, poisson_ratio, yield_stress])
    }

    /// The material of `entry` with its parameters' values in declaration order.
    fn from_values(entry: &'static ModelEntry, given: &[f64]) -> Self {
        debug_assert_eq!(given.len(), entry.parameters.len());
        let mut values = [f64::NAN; MAX_PARAMETERS];
        values[..given.len()].copy_from_slice(given);
        Self { entry, values }
    }

    /// The model's name.
    pub fn model(&self) -> &'static str {
        self.entry.name
    }

    /// The model's registry entry.
    pub fn entry(&self) -> &'static ModelEntry {
        self.entry
    }

    /// The parameters' values in the order the model declares them.
    pub fn values(&self) -> &[f64] {
        &self.values[..self.entry.parameters.len()]
    }

    /// (key, value) of every parameter, in declaration order.
    pub fn parameters(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.entry
            .parameters
            .iter()
            .map(|p| p.name)
            .zip(self.values().iter().copied())
    }

    /// The value of parameter `name`, if the model has it.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.parameters().find(|(k, _)| *k == name).map(|(_, v)| v)
    }

    /// The value of parameter `name`, which the model declares (for its builder).
    ///
    /// # Panics
    /// If the model has no such parameter: its entry and its builder disagree.
    pub fn value(&self, name: &str) -> f64 {
        self.get(name)
            .unwrap_or_else(|| panic!("the model {} declares no parameter `{name}`", self.entry.name))
    }

    /// The value of parameter `name`, which `what` needs (e.g. a closed form's elastic
    /// constants): an error names `material.<name>` if the model has no such parameter.
    pub fn require(&self, name: &str, what: &str) -> Result<f64, InputError> {
        self.get(name).ok_or_else(|| {
            InputError::new(
                format!("material.{name}"),
                "(missing)",
                format!(
                    "{what} needs it, and the model {} has no such parameter",
                    self.entry.name
                ),
            )
        })
    }

    /// The material must be of the model `entry`, which `what` needs (a closed form derived
    /// for it): an error names `material.model`.
    pub fn require_model(&self, entry: &ModelEntry, what: &str) -> Result<(), InputError> {
        if self.entry.name == entry.name {
            Ok(())
        } else {
            Err(InputError::new(
                "material.model",
                format!("{:?}", self.entry.name),
                format!("must be {:?}: {what}", entry.name),
            ))
        }
    }

    /// Set parameter `name` (which the model has) to `value`.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), InputError> {
        match self.entry.parameters.iter().position(|p| p.name == name) {
            Some(i) => {
                self.values[i] = value;
                Ok(())
            }
            None => Err(InputError::new(
                format!("material.{name}"),
                value,
                format!("is not a parameter of the model {}", self.entry.name),
            )),
        }
    }

    /// Check the parameter values and build the model: an error names `material.<key>`.
    pub fn build(&self) -> Result<Box<dyn ConstitutiveModel>, InputError> {
        let model = (self.entry.build)(self)?;
        let declared = model.internal_variables().len();
        if declared > MAX_INTERNAL {
            return Err(InputError::new(
                "material.model",
                self.entry.name,
                format!("declares {declared} internal variables, at most {MAX_INTERNAL}"),
            ));
        }
        Ok(model)
    }
}

impl PartialEq for Material {
    fn eq(&self, other: &Self) -> bool {
        self.entry.name == other.entry.name && self.values() == other.values()
    }
}

impl std::fmt::Debug for Material {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("Material");
        s.field("model", &self.entry.name);
        for (k, v) in self.parameters() {
            s.field(k, &v);
        }
        s.finish()
    }
}

/// As a `[material]` table: `model`, then each parameter in declaration order.
impl Serialize for Material {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(1 + self.entry.parameters.len()))?;
        map.serialize_entry("model", self.entry.name)?;
        for (k, v) in self.parameters() {
            map.serialize_entry(k, &v)?;
        }
        map.end()
    }
}

/// From a `[material]` table, its model looked up in the registry.
impl<'de> Deserialize<'de> for Material {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Table {
            model: String,
            #[serde(flatten)]
            parameters: BTreeMap<String, f64>,
        }
        let t = Table::deserialize(d)?;
        let given: Vec<(&str, f64)> = t.parameters.iter().map(|(k, &v)| (k.as_str(), v)).collect();
        Material::new(&t.model, &given).map_err(D::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_material_names_its_model_and_keys() {
        let m = Material::new(
            "von-mises",
            &[
                ("poisson_ratio", 0.3),
                ("yield_stress", 2e4),
                ("young_modulus", 1e6),
            ],
        )
        .unwrap();
        assert_eq!(m, Material::von_mises(1e6, 0.3, 2e4));
        assert_eq!(m.get("yield_stress"), Some(2e4));
        let e = Material::new("von-mieses", &[]).unwrap_err();
        assert_eq!(e.field, "material.model");
        assert!(e.allowed.contains("linear-elastic, von-mises"), "{e}");
        let e = Material::new("von-mises", &[("young_modulus", 1e6), ("poisson_ratio", 0.3)]).unwrap_err();
        assert_eq!(e.field, "material.yield_stress");
        let e = Material::new(
            "linear-elastic",
            &[("young_modulus", 1.0), ("poisson_ratio", 0.3), ("yield", 1.0)],
        )
        .unwrap_err();
        assert_eq!(e.field, "material.yield");
        assert!(e.allowed.contains("young_modulus, poisson_ratio"), "{e}");
        let e = Material::von_mises(1e6, 0.3, -1.0).build().err().unwrap();
        assert_eq!(e.field, "material.yield_stress");
    }

    #[test]
    fn a_material_reads_back_what_it_writes() {
        let m = Material::von_mises(1e6, 0.0, 3e4);
        let json = serde_json::to_string(&m).unwrap();
        assert_eq!(
            json,
            r#"{"model":"von-mises","young_modulus":1000000.0,"poisson_ratio":0.0,"yield_stress":30000.0}"#
        );
        assert_eq!(serde_json::from_str::<Material>(&json).unwrap(), m);
        assert!(serde_json::from_str::<Material>(r#"{"model":"x"}"#).is_err());
    }
}
