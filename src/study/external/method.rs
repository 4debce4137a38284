//! A study's method: one of igimp's ([`Method`]) or another code's through its adapter,
//! written `ext:<adapter>` (the adapter's default basis) or `ext:<adapter>@<method>` (the
//! basis the adapter is asked to use, named as igimp names it).

use crate::basis::method::Method;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// An external code's method: its adapter's name and the basis asked of it.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ExternalMethod {
    /// The adapter's folder name under the adapters folder (`[a-z0-9-]+`).
    pub adapter: String,
    /// The basis the adapter is asked to use (`None`: its manifest's first).
    pub basis: Option<Method>,
}

/// A method of a study: igimp's own, solved in process, or an external code's.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum StudyMethod {
    Own(Method),
    External(ExternalMethod),
}

impl From<Method> for StudyMethod {
    fn from(m: Method) -> Self {
        StudyMethod::Own(m)
    }
}

impl StudyMethod {
    /// The name in study files and `results.json`.
    pub fn name(&self) -> String {
        match self {
            StudyMethod::Own(m) => m.name().to_string(),
            StudyMethod::External(e) => match e.basis {
                None => format!("ext:{}", e.adapter),
                Some(b) => format!("ext:{}@{}", e.adapter, b.name()),
            },
        }
    }

    /// The name as part of a case id (a file name): `ext-<adapter>[-<method>]`.
    pub fn slug(&self) -> String {
        self.name().replace([':', '@'], "-")
    }

    /// Parse a study file's method name.
    pub fn parse(name: &str) -> Result<Self, String> {
        let Some(rest) = name.strip_prefix("ext:") else {
            return Method::from_name(name).map(StudyMethod::Own).ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown method {name:?}: expected one of {}, or ext:<adapter>[@<method>]",
                    names.join(", ")
                )
            });
        };
        let (adapter, basis) = match rest.split_once('@') {
            Some((a, b)) => (a, Some(b)),
            None => (rest, None),
        };
        if adapter.is_empty()
            || !adapter
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
        {
            return Err(format!(
                "external method {name:?}: the adapter's name must be lower-case letters, digits and '-' (ext:<adapter>[@<method>])"
            ));
        }
        let basis = match basis {
            None => None,
            Some(b) => Some(
                Method::from_name(b)
                    .ok_or_else(|| format!("external method {name:?}: {b:?} is not a method igimp names"))?,
            ),
        };
        Ok(StudyMethod::External(ExternalMethod {
            adapter: adapter.to_string(),
            basis,
        }))
    }

    /// igimp's method, if it is one.
    pub fn own(&self) -> Option<Method> {
        match self {
            StudyMethod::Own(m) => Some(*m),
            StudyMethod::External(_) => None,
        }
    }

    /// True for igimp's finite element comparators.
    pub fn is_fem(&self) -> bool {
        self.own().is_some_and(Method::is_fem)
    }

    /// The human name: igimp's method's, or the study's name of an external one.
    pub fn label(&self) -> String {
        match self {
            StudyMethod::Own(m) => m.label().to_string(),
            StudyMethod::External(_) => self.name(),
        }
    }

    pub fn is_external(&self) -> bool {
        matches!(self, StudyMethod::External(_))
    }

    /// True for the methods whose points per cell matter: the material point methods, and
    /// an external code (it solves the case's material points).
    pub fn uses_material_points(&self) -> bool {
        match self {
            StudyMethod::Own(m) => m.uses_material_points(),
            StudyMethod::External(_) => true,
        }
    }
}

impl std::fmt::Display for StudyMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl Serialize for StudyMethod {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.name())
    }
}

impl<'de> Deserialize<'de> for StudyMethod {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        StudyMethod::parse(&name).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_refused() {
        for n in ["mpm", "fem-q8", "ext:kratos-mpm", "ext:igimp@igimp"] {
            assert_eq!(StudyMethod::parse(n).unwrap().name(), n);
        }
        assert_eq!(
            StudyMethod::parse("ext:igimp@mpm").unwrap().slug(),
            "ext-igimp-mpm"
        );
        for bad in ["ext:", "ext:Kratos", "ext:a b", "ext:igimp@nope", "mpn"] {
            assert!(StudyMethod::parse(bad).is_err(), "{bad}");
        }
    }
}
