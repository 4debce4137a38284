//! The closed forms a scene's measure can be compared with: the smooth platen on a Hencky
//! block (reference/README.md item 65) and the confined column of a Hencky or neo-Hookean
//! material under its own weight (item 67).

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

/// An elastic law under uniaxial strain F = diag(1, …, λ) along the column's axis: the first
/// Piola stress P(λ) and the stored energy W(λ) per unit reference volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UniaxialLaw {
    /// Hencky: P = M ln λ / λ, W = M/2 ln²λ, M = λ_L + 2μ.
    Hencky { lambda: f64, mu: f64 },
    /// Compressible neo-Hookean (Kratos' law): P = λ_L ln λ / λ + μ (λ − 1/λ),
    /// W = μ/2 (λ² − 1) − μ ln λ + λ_L/2 ln²λ.
    NeoHookean { lambda: f64, mu: f64 },
}

impl UniaxialLaw {
    pub fn piola(self, s: f64) -> f64 {
        match self {
            UniaxialLaw::Hencky { lambda, mu } => (lambda + 2.0 * mu) * s.ln() / s,
            UniaxialLaw::NeoHookean { lambda, mu } => lambda * s.ln() / s + mu * (s - 1.0 / s),
        }
    }

    pub fn energy(self, s: f64) -> f64 {
        let l = s.ln();
        match self {
            UniaxialLaw::Hencky { lambda, mu } => 0.5 * (lambda + 2.0 * mu) * l * l,
            UniaxialLaw::NeoHookean { lambda, mu } => {
                0.5 * mu * (s * s - 1.0) - mu * l + 0.5 * lambda * l * l
            }
        }
    }

    /// The stretch λ ≤ 1 at which P(λ) = `p` ≤ 0: P is increasing in y = ln λ for y < 1 (dP/dy
    /// = M (1 − y) e^−y for Hencky, λ_L (1 − y) e^−y + 2μ cosh y for neo-Hookean), so the root
    /// is unique; bracketed by doubling, then bisection to the last bit. `None` beyond the
    /// law's largest compressive stress (Hencky's P is bounded below by −M e at λ = 1/e).
    pub fn stretch(self, p: f64) -> Option<f64> {
        if p >= 0.0 {
            return (p == 0.0).then_some(1.0);
        }
        let f = |y: f64| self.piola(y.exp()) - p;
        let mut lo = -1.0;
        while f(lo) > 0.0 {
            lo *= 2.0;
            if lo < -700.0 {
                return None;
            }
        }
        // Hencky's P has its minimum at y = −1 (λ = 1/e): past it the root is not the branch
        // of the loaded column.
        if matches!(self, UniaxialLaw::Hencky { .. }) && f(-1.0) > 0.0 {
            return None;
        }
        let (mut a, mut b) = (
            if matches!(self, UniaxialLaw::Hencky { .. }) {
                -1.0
            } else {
                lo
            },
            0.0,
        );
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if f(m) > 0.0 {
                b = m;
            } else {
                a = m;
            }
        }
        Some((0.5 * (a + b)).exp())
    }
}

/// A laterally confined elastic column under its own weight (reference/README.md item 67):
/// uniaxial strain along the gravity's axis, P(λ(Z)) = −ρ₀ g (L − Z) from equilibrium with a
/// free top, and u(Z) = [G(λ(Z)) − G(λ(0))] / (ρ₀ g), G(λ) = (λ − 1) P(λ) − W(λ) (integrating
/// ∫₀^Z (λ − 1) dZ' by parts, dZ = P'(λ) dλ / (ρ₀ g)).
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    pub law: UniaxialLaw,
    pub axis: usize,
    /// The body's base and height along the axis.
    pub base: f64,
    pub height: f64,
    /// ρ₀ g at full load.
    pub unit_weight: f64,
    pub ramp: Ramp,
}

impl Column {
    /// The displacement along the axis at `at` (its coordinate along the axis) and load factor
    /// `t`; NaN past the law's largest compressive stress.
    pub fn displacement(&self, at: &[f64], t: f64) -> f64 {
        let w = self.unit_weight * self.ramp.factor(t);
        if w == 0.0 {
            return 0.0;
        }
        let z = (at[self.axis] - self.base).clamp(0.0, self.height);
        let g = |z: f64| -> Option<f64> {
            let s = self.law.stretch(-w * (self.height - z))?;
            Some((s - 1.0) * self.law.piola(s) - self.law.energy(s))
        };
        match (g(z), g(0.0)) {
            (Some(a), Some(b)) => (a - b) / w,
            _ => f64::NAN,
        }
    }
}

impl Scene {
    /// The column of a closed form: a box body under one gravity load along an axis, of a
    /// Hencky or neo-Hookean material.
    pub fn column(&self, key: &str) -> Result<Column, InputError> {
        let (axis, g) = super::spec::column_axis(self).ok_or_else(|| {
            err(
                format!("{key}.closed_form"),
                "column-displacement",
                "needs one box body under one gravity load along an axis (the column)",
            )
        })?;
        let body = &self.bodies[0];
        let material = &self.materials[&body.material];
        let (e, nu) = self.hencky_parameters(key)?;
        let (lambda, mu) = crate::material::constitutive::lame(e, nu);
        let law = match material.model() {
            "linear-elastic" => UniaxialLaw::Hencky { lambda, mu },
            "neo-hookean" => UniaxialLaw::NeoHookean { lambda, mu },
            other => {
                return Err(err(
                    format!("{key}.closed_form"),
                    other,
                    "holds for the linear-elastic (Hencky) and neo-hookean models only",
                ))
            }
        };
        let bb = body.bounding_box();
        let ramp = self
            .loads
            .iter()
            .find(|l| l.kind == LoadKind::Gravity)
            .map_or(Ramp::Linear, |l| l.ramp.clone());
        Ok(Column {
            law,
            axis,
            base: bb.min[axis],
            height: bb.max[axis] - bb.min[axis],
            unit_weight: body.density * g,
            ramp,
        })
    }
}
