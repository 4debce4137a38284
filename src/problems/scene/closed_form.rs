//! The closed forms a scene's measure can be compared with: the smooth platen on a Hencky
//! block (reference/README.md item 65).

use super::spec::{Components, LoadKind, Reference, Scene};
use crate::solver::error::InputError;
use crate::solver::ramp::Ramp;

fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
}

impl Scene {
    /// The platen of a closed form: its body, the axis and value of its single displacement
    /// component, and the material's (E, ν).
    pub fn platen(&self, key: &str, r: &Reference) -> Result<Platen, InputError> {
        let body_name = r
            .body
            .as_ref()
            .ok_or_else(|| err(format!("{key}.body"), "missing", "a closed form needs its body"))?;
        let body = self.bodies.iter().find(|b| &b.name == body_name).ok_or_else(|| {
            err(
                format!("{key}.body"),
                format!("{body_name:?}"),
                "must name a body",
            )
        })?;
        let load_name = r.load.as_ref().ok_or_else(|| {
            err(
                format!("{key}.load"),
                "missing",
                "a closed form needs its displacement load",
            )
        })?;
        let load = self
            .loads
            .iter()
            .find(|l| l.kind == LoadKind::Displacement && l.name.as_ref() == Some(load_name))
            .ok_or_else(|| {
                err(
                    format!("{key}.load"),
                    format!("{load_name:?}"),
                    "must name a displacement load",
                )
            })?;
        let given = load
            .displacement
            .as_ref()
            .map(Components::given)
            .unwrap_or_default();
        let [(axis, delta)] = given[..] else {
            return Err(err(
                format!("{key}.load"),
                format!("{load_name:?}"),
                "must move one component (a smooth platen)",
            ));
        };
        if body.bounds.is_none() {
            return Err(err(
                format!("{key}.body"),
                format!("{body_name:?}"),
                "must be a box body (the closed form is a block's)",
            ));
        }
        let bounds = body.bounding_box();
        let material = &self.materials[&body.material];
        if material.model() != "linear-elastic" {
            return Err(err(
                format!("{key}.closed_form"),
                material.model(),
                "holds for the linear-elastic (Hencky) model only",
            ));
        }
        let (young, poisson) = self.hencky_parameters(key)?;
        let height = bounds.max[axis] - bounds.min[axis];
        Ok(Platen {
            dimension: self.dimension,
            axis,
            delta,
            ramp: load.ramp.clone(),
            height,
            min: bounds.min.clone(),
            area: (0..self.dimension)
                .filter(|&a| a != axis)
                .map(|a| bounds.max[a] - bounds.min[a])
                .product(),
            young,
            poisson,
        })
    }
}

/// A smooth platen on a Hencky block (reference/README.md item 65): the closed forms.
#[derive(Debug, Clone, PartialEq)]
pub struct Platen {
    pub dimension: usize,
    pub axis: usize,
    /// The platen's displacement at full load.
    pub delta: f64,
    pub ramp: Ramp,
    pub height: f64,
    pub min: Vec<f64>,
    /// The initial area (2D: width) under the platen.
    pub area: f64,
    pub young: f64,
    pub poisson: f64,
}

impl Platen {
    /// (λ along the platen's axis, λ across it, τ along it) at load factor `t`.
    fn stretches(&self, t: f64) -> (f64, f64, f64) {
        let lambda = 1.0 + self.delta * self.ramp.factor(t) / self.height;
        let eps = lambda.ln();
        let (e, nu) = (self.young, self.poisson);
        let (lateral, tau) = if self.dimension == 2 {
            (-nu / (1.0 - nu) * eps, e / (1.0 - nu * nu) * eps)
        } else {
            (-nu * eps, e * eps)
        };
        (lambda, lateral.exp(), tau)
    }

    /// The force on the platen's nodes along its axis at load factor `t` (the reaction: the
    /// force they exert on the body): τ A₀ / λ.
    pub fn force(&self, t: f64) -> f64 {
        let (lambda, _, tau) = self.stretches(t);
        tau * self.area / lambda
    }

    /// Component `axis` of the displacement at `at` at load factor `t`: (λ_i − 1)(at_i − min_i).
    pub fn displacement(&self, at: &[f64], axis: usize, t: f64) -> f64 {
        let (lambda, lateral, _) = self.stretches(t);
        let l = if axis == self.axis { lambda } else { lateral };
        (l - 1.0) * (at[axis] - self.min[axis])
    }
}
