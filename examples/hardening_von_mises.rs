//! A constitutive model defined outside the crate, through the public contract
//! ([`ConstitutiveModel`], its [`InternalVariable`], a registry [`ModelEntry`]): von Mises
//! plasticity with linear isotropic hardening, registered by name and run on the §5.1
//! elasto-plastic column.
//!
//! **Model.** Hencky elasticity (eq 14) and the yield function f = ρ − (ρ_y + H α) on
//! ρ = √(3 J2) of the Kirchhoff stress, α the equivalent plastic strain (the model's internal
//! variable `equivalent_plastic_strain`). Backward Euler with associated flow is a radial
//! return on the trial log strain: with s_t = dev τ_t, ρ_t = √(3/2)|s_t| > ρ_y + H α_n,
//! Δγ = (ρ_t − ρ_y − H α_n)/(3G + H), α = α_n + Δγ, s = r s_t with r = (ρ_y + H α)/ρ_t
//! (= 1 − 3GΔγ/ρ_t) and ε^e = ε_t − Δγ (3/2) s_t/ρ_t. Consistent tangent (de Souza Neto et
//! al. 2008, eq 7.120, regrouped): D = K 1⊗1 + 2G r (I_dev − n⊗n) + 2GH/(3G + H) n⊗n,
//! n = s_t/|s_t| (`tests/verification/examples.rs` checks it against central differences).
//! Written so, at H = 0 the update and the tangent are the built-in von Mises' operation for
//! operation (H α and the last term are exact zeros), and the column reproduces it bit for
//! bit.
//!
//! **Closed form of the column** ([`HardeningColumn`]). In uniaxial strain (F = diag(F, 1, 1),
//! y = ln F ≤ 0) the plastic strain is p diag(1, −½, −½) with α = −p, and the yield condition
//! 2μ(3p/2 − y) = ρ_y + H α gives p = (ρ_y + 2μ y)/(3μ + H) below the yield strain
//! −ρ_y/(2μ), so τ_zz = M y − 2μ p (M = λ + 2μ; at H = 0 this is K y − ⅔ρ_y, the perfectly
//! plastic column of `igimp::problems::column::AnalyticalColumn`). Equilibrium fixes the
//! Cauchy stress σ_zz(Z) = −ρ0 g (L0 − Z) whatever the material, so F(Z) is the root of
//! τ_zz(ln F)/F = σ_zz(Z) (τ_zz e^{−y} increases with y: one root) and u(Z) = ∫₀^Z (F − 1).
//! Hardening stiffens the yielded zone (dτ_zz/dy = M − 4μ²/(3μ + H) > K), so the base F
//! moves towards 1 and the top settles less than in the perfectly plastic column.
//!
//! `cargo run --release --example hardening_von_mises` prints the column with H = 0 against
//! the built-in von Mises, and with H > 0 against both closed forms;
//! `tests/verification/examples.rs` runs the same functions and checks them.

use igimp::material::constitutive::registry::{self, Parameter, POISSON_RATIO, YOUNG_MODULUS};
use igimp::material::constitutive::{
    lame, ConstitutiveModel, InternalVariable, InternalVariables, LinearElastic, Material, MaterialError,
    MaterialResponse, MaterialState, ModelEntry,
};
use igimp::material::tensor::{identity_outer, identity_sym, outer, Tensor4};
use igimp::problems::column::{solve_column, ColumnOutcome, ColumnSpec, Method};
use igimp::solver::error::InputError;
use nalgebra::Matrix3;

/// The model's one internal variable.
pub const EQUIVALENT_PLASTIC_STRAIN: InternalVariable = InternalVariable {
    name: "equivalent_plastic_strain",
    initial: 0.0,
    meaning: "accumulated equivalent plastic strain α, the argument of the hardening law",
};

/// Von Mises plasticity with linear isotropic hardening ρ_y + H α (module docs).
#[derive(Debug, Clone, Copy)]
pub struct HardeningVonMises {
    pub young_modulus: f64,
    pub yield_stress: f64,
    /// H ≥ 0; 0 is perfect plasticity.
    pub hardening_modulus: f64,
    bulk: f64,
    shear: f64,
    d_elastic: Tensor4,
}

impl HardeningVonMises {
    /// E > 0, −1 < ν < 0.5, ρ_y > 0 and H ≥ 0, all finite; errors name `material.<key>`.
    pub fn try_new(
        young_modulus: f64,
        poisson_ratio: f64,
        yield_stress: f64,
        hardening_modulus: f64,
    ) -> Result<Self, InputError> {
        let elastic = LinearElastic::try_new(young_modulus, poisson_ratio)?;
        if !(yield_stress.is_finite() && yield_stress > 0.0) {
            return Err(InputError::new(
                "material.yield_stress",
                yield_stress,
                "must be finite and > 0",
            ));
        }
        if !(hardening_modulus.is_finite() && hardening_modulus >= 0.0) {
            return Err(InputError::new(
                "material.hardening_modulus",
                hardening_modulus,
                "must be finite and >= 0",
            ));
        }
        let (lambda, mu) = lame(young_modulus, poisson_ratio);
        Ok(Self {
            young_modulus,
            yield_stress,
            hardening_modulus,
            bulk: lambda + 2.0 * mu / 3.0,
            shear: mu,
            d_elastic: *elastic.stiffness(),
        })
    }

    /// (s_t, ρ_t, the trial yield function) at the trial strain and the committed α.
    fn trial(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> (Matrix3<f64>, f64, f64) {
        let s_trial = deviator(eps_trial) * (2.0 * self.shear);
        let rho_trial = 1.5f64.sqrt() * s_trial.norm();
        let alpha = committed.internal.get(0);
        let f = rho_trial - (self.yield_stress + self.hardening_modulus * alpha);
        (s_trial, rho_trial, f)
    }
}

fn deviator(m: &Matrix3<f64>) -> Matrix3<f64> {
    m - Matrix3::identity() * (m.trace() / 3.0)
}

impl ConstitutiveModel for HardeningVonMises {
    fn update(
        &self,
        eps_trial: &Matrix3<f64>,
        committed: &MaterialState,
    ) -> Result<MaterialResponse, MaterialError> {
        let (g, alpha) = (self.shear, committed.internal.get(0));
        let (s_trial, rho_trial, f) = self.trial(eps_trial, committed);
        let p = Matrix3::identity() * (self.bulk * eps_trial.trace());
        if f <= 0.0 {
            return Ok(MaterialResponse {
                tau: s_trial + p,
                eps_e: *eps_trial,
                internal: InternalVariables::from_slice(&[alpha]),
            });
        }
        let h = self.hardening_modulus;
        let dgamma = f / (3.0 * g + h);
        let ratio = (self.yield_stress + h * (alpha + dgamma)) / rho_trial;
        let s = s_trial * ratio;
        let eps_e = eps_trial - s_trial * (1.5 * dgamma / rho_trial);
        if !eps_e.iter().all(|v| v.is_finite()) {
            return Err(MaterialError(
                "hardening return map produced a non-finite strain".into(),
            ));
        }
        Ok(MaterialResponse {
            tau: s + p,
            eps_e,
            internal: InternalVariables::from_slice(&[alpha + dgamma]),
        })
    }

    fn tangent(&self, eps_trial: &Matrix3<f64>, committed: &MaterialState) -> Tensor4 {
        let (g, h, alpha) = (self.shear, self.hardening_modulus, committed.internal.get(0));
        let (s_trial, rho_trial, f) = self.trial(eps_trial, committed);
        if f <= 0.0 {
            return self.d_elastic;
        }
        let dgamma = f / (3.0 * g + h);
        let ratio = (self.yield_stress + h * (alpha + dgamma)) / rho_trial;
        let n = s_trial / s_trial.norm();
        let i_dev = identity_sym() - identity_outer() * (1.0 / 3.0);
        identity_outer() * self.bulk
            + (i_dev - outer(&n, &n)) * (2.0 * g * ratio)
            + outer(&n, &n) * (2.0 * g * h / (3.0 * g + h))
    }

    fn young_modulus(&self) -> f64 {
        self.young_modulus
    }

    fn internal_variables(&self) -> &'static [InternalVariable] {
        &[EQUIVALENT_PLASTIC_STRAIN]
    }
}

/// The model's registry row: `model = "von-mises-hardening"` with E, ν, ρ_y and H.
pub static HARDENING: ModelEntry = ModelEntry {
    name: "von-mises-hardening",
    summary: "von Mises plasticity with linear isotropic hardening (examples/hardening_von_mises.rs)",
    parameters: &[
        YOUNG_MODULUS,
        POISSON_RATIO,
        Parameter {
            name: "yield_stress",
            unit: "Pa",
            meaning: "initial yield stress ρ_y on ρ = √(3 J2), > 0",
        },
        Parameter {
            name: "hardening_modulus",
            unit: "Pa",
            meaning: "H, the slope of the yield stress against the equivalent plastic strain, >= 0",
        },
    ],
    build: |m| {
        Ok(Box::new(HardeningVonMises::try_new(
            m.value("young_modulus"),
            m.value("poisson_ratio"),
            m.value("yield_stress"),
            m.value("hardening_modulus"),
        )?))
    },
};

/// The paper's plastic column (E = 1e6, ν = 0, ρ_y = 3e4) at W = 400,000, its yielded zone
/// most of the column: `elements` elements of 2 points by iGIMP.
pub const E: f64 = 1.0e6;
pub const YIELD: f64 = 3.0e4;
pub const WEIGHT: f64 = 400_000.0;

/// The hardening material with H = `h`, by its registered name (registered here if it is not).
pub fn hardening(h: f64) -> Material {
    registry::register(&HARDENING).expect("a new name");
    Material::new(
        "von-mises-hardening",
        &[
            ("young_modulus", E),
            ("poisson_ratio", 0.0),
            ("yield_stress", YIELD),
            ("hardening_modulus", h),
        ],
    )
    .expect("every parameter given")
}

/// The column of `material` by iGIMP on `elements` elements (W = [`WEIGHT`]).
pub fn column(material: Material, elements: usize) -> ColumnOutcome {
    let spec = ColumnSpec {
        material,
        weight: WEIGHT,
        elements,
        ..ColumnSpec::default()
    };
    let out = solve_column(&spec, Method::IGIMP).expect("a valid column");
    assert!(out.failure.is_none(), "{}: {:?}", material.model(), out.failure);
    out
}

/// The largest difference between two columns' point values (σ_zz, σ_xx, F_zz relative to
/// their scales W, W, 1) and top displacements (relative).
pub fn largest_difference(a: &ColumnOutcome, b: &ColumnOutcome) -> f64 {
    let points = a.points.iter().zip(&b.points).map(|(p, q)| {
        let s = ((p.sigma_zz - q.sigma_zz).abs() + (p.sigma_xx - q.sigma_xx).abs()) / WEIGHT;
        s.max((p.f_zz - q.f_zz).abs())
    });
    let top = (a.top_displacement - b.top_displacement).abs() / b.top_displacement.abs();
    points.fold(top, f64::max)
}

/// The column of the hardening material in closed form (module docs).
#[derive(Debug, Clone, Copy)]
pub struct HardeningColumn {
    pub lambda: f64,
    pub mu: f64,
    pub yield_stress: f64,
    pub hardening_modulus: f64,
    /// ρ0 g.
    pub unit_weight: f64,
    pub length: f64,
}

impl HardeningColumn {
    /// The column of [`WEIGHT`] (L0 = 50, ν = 0) with H = `h`.
    pub fn of(h: f64) -> Self {
        let length = ColumnSpec::default().length;
        let (lambda, mu) = lame(E, 0.0);
        Self {
            lambda,
            mu,
            yield_stress: YIELD,
            hardening_modulus: h,
            unit_weight: WEIGHT / length,
            length,
        }
    }

    /// τ_zz at the vertical log strain y ≤ 0.
    pub fn kirchhoff(&self, y: f64) -> f64 {
        let m = self.lambda + 2.0 * self.mu;
        let p = ((self.yield_stress + 2.0 * self.mu * y) / (3.0 * self.mu + self.hardening_modulus)).min(0.0);
        m * y - 2.0 * self.mu * p
    }

    /// F at initial height Z: the root of τ_zz(ln F)/F = σ_zz(Z), by bisection in y.
    pub fn deformation_gradient(&self, z0: f64) -> f64 {
        let sigma = -self.unit_weight * (self.length - z0);
        let g = |y: f64| self.kirchhoff(y) * (-y).exp() - sigma;
        let (mut lo, mut hi) = (-1.0, 0.0);
        while g(lo) > 0.0 {
            lo *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (0.5 * (lo + hi)).exp()
    }

    /// Initial height of first yield: where the Kirchhoff stress reaches the elastic limit.
    pub fn yield_height(&self) -> f64 {
        let y = -self.yield_stress / (2.0 * self.mu);
        let sigma = self.kirchhoff(y) * (-y).exp();
        (self.length + sigma / self.unit_weight).max(0.0)
    }

    /// u(Z) = ∫₀^Z (F − 1) dZ' by composite Simpson on each smooth piece (below and above the
    /// yield height).
    pub fn displacement(&self, z0: f64) -> f64 {
        let simpson = |a: f64, b: f64| {
            let n = 4000;
            let h = (b - a) / n as f64;
            (0..=n)
                .map(|i| {
                    let w = if i == 0 || i == n {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * (self.deformation_gradient(a + h * i as f64) - 1.0)
                })
                .sum::<f64>()
                * h
                / 3.0
        };
        let zy = self.yield_height().min(z0);
        simpson(0.0, zy) + simpson(zy, z0)
    }
}

#[allow(dead_code)]
fn main() {
    let elements = 64;
    let built_in = column(Material::von_mises(E, 0.0, YIELD), elements);
    let h0 = column(hardening(0.0), elements);
    println!(
        "H = 0 against the built-in von Mises ({elements} elements, W = {WEIGHT}): largest difference {:.1e}",
        largest_difference(&h0, &built_in)
    );
    for h in [0.0, 0.1 * E, 0.5 * E] {
        let exact = HardeningColumn::of(h);
        let o = column(hardening(h), elements);
        let (f0, u) = (exact.deformation_gradient(0.0), exact.displacement(exact.length));
        println!(
            "H = {h:e}: base F {:.6} (closed form {f0:.6}, error {:.2e}), top u {:.5} (closed form {u:.5}), yield height {:.3}",
            o.base_f,
            (o.base_f - f0).abs() / f0,
            o.top_displacement,
            exact.yield_height()
        );
    }
}
