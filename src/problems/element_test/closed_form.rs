//! Closed forms of element tests: the limit or elastic state a path reaches, from the model's
//! parameters and the test's confinement. Each names the measure it predicts, the paths it
//! holds on and the parameters it reads; the study file names the form and its source.

use super::{ElementPath, ElementState, ElementTest};
use crate::material::constitutive::Material;
use crate::solver::error::InputError;
use serde::{Deserialize, Serialize};

/// A closed form of an element test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClosedForm {
    /// Mohr–Coulomb's limit in compression: σ_a = σ_c N_φ + 2c √N_φ, N_φ = (1 + sin φ)/(1 −
    /// sin φ), with σ_c the confining pressure (Mohr–Coulomb on the triaxial path;
    /// Drucker–Prager's plane-strain match on the biaxial path).
    MohrCoulombCompression,
    /// von Mises' limit: q = ρ_y (the yield stress on √(3 J₂)).
    VonMisesCompression,
    /// The elastic oedometer's lateral-to-axial stress ratio K₀ = ν/(1 − ν) (Hencky
    /// elasticity: exact at any strain, since ε_xx = ε_zz = 0).
    ElasticK0,
    /// Hencky elasticity in simple shear: τ_xy = 2G asinh(γ/2)/√(1 + γ²/4) (the logarithmic
    /// strain of F = I + γ e_x ⊗ e_y has principal values ±asinh(γ/2) at the angle with
    /// tan 2θ = 2/γ).
    HenckySimpleShear,
    /// Modified Cam-Clay, drained triaxial compression of a normally consolidated sample: the
    /// path q = 3(p − p₀) meets the critical state line q = M p at p = 3p₀/(3 − M).
    CamClayDrained,
    /// Modified Cam-Clay, undrained triaxial compression of a normally consolidated sample:
    /// p_f = p₀ 2^(−Λ), Λ = (λ̂ − κ̂)/λ̂ (constant volume: κ̂ ln(p_f/p₀) = −(λ̂ − κ̂) ln(2p_f/p₀)).
    CamClayUndrained,
    /// Modified Cam-Clay on the normal compression line: d ln p / dε_v = 1/λ̂.
    CamClayNormalCompression,
}

/// Modified Cam-Clay's parameters as the registry names them.
pub const CRITICAL_STATE_SLOPE: &str = "critical_state_slope";
pub const COMPRESSION_INDEX: &str = "compression_index";
pub const SWELLING_INDEX: &str = "swelling_index";

impl ClosedForm {
    pub const ALL: [ClosedForm; 7] = [
        ClosedForm::MohrCoulombCompression,
        ClosedForm::VonMisesCompression,
        ClosedForm::ElasticK0,
        ClosedForm::HenckySimpleShear,
        ClosedForm::CamClayDrained,
        ClosedForm::CamClayUndrained,
        ClosedForm::CamClayNormalCompression,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ClosedForm::MohrCoulombCompression => "mohr-coulomb-compression",
            ClosedForm::VonMisesCompression => "von-mises-compression",
            ClosedForm::ElasticK0 => "elastic-k0",
            ClosedForm::HenckySimpleShear => "hencky-simple-shear",
            ClosedForm::CamClayDrained => "cam-clay-drained",
            ClosedForm::CamClayUndrained => "cam-clay-undrained",
            ClosedForm::CamClayNormalCompression => "cam-clay-normal-compression",
        }
    }

    /// The measure ([`measures`]) the form predicts.
    pub fn measure(self) -> &'static str {
        match self {
            ClosedForm::MohrCoulombCompression => "axial_stress",
            ClosedForm::VonMisesCompression => "q",
            ClosedForm::ElasticK0 => "k0",
            ClosedForm::HenckySimpleShear => "shear_stress",
            ClosedForm::CamClayDrained | ClosedForm::CamClayUndrained => "p",
            ClosedForm::CamClayNormalCompression => "compression_slope",
        }
    }

    /// The paths on which the form holds.
    pub fn paths(self) -> &'static [ElementPath] {
        match self {
            ClosedForm::MohrCoulombCompression => {
                &[ElementPath::TriaxialDrained, ElementPath::PlaneStrainBiaxial]
            }
            ClosedForm::VonMisesCompression => &[
                ElementPath::TriaxialDrained,
                ElementPath::TriaxialUndrained,
                ElementPath::PlaneStrainBiaxial,
            ],
            ClosedForm::ElasticK0 => &[ElementPath::Oedometer],
            ClosedForm::HenckySimpleShear => &[ElementPath::SimpleShear],
            ClosedForm::CamClayDrained => &[ElementPath::TriaxialDrained],
            ClosedForm::CamClayUndrained => &[ElementPath::TriaxialUndrained],
            ClosedForm::CamClayNormalCompression => &[ElementPath::Isotropic],
        }
    }

    /// The form's value for `test` on `material`, whose state at the start of the path (after
    /// the confinement) is `start`. An error names the parameter the form needs
    /// (`material.<key>`) or the path it does not hold on (`path`).
    pub fn value(
        self,
        material: &Material,
        test: &ElementTest,
        start: &ElementState,
    ) -> Result<f64, InputError> {
        if !self.paths().contains(&test.path) {
            let allowed: Vec<&str> = self.paths().iter().map(|p| p.name()).collect();
            return Err(InputError::new(
                "path",
                test.path.name(),
                format!("closed form {} holds on {} only", self.name(), allowed.join(", ")),
            ));
        }
        let what = self.name();
        Ok(match self {
            ClosedForm::MohrCoulombCompression => {
                let c = material.require("cohesion", what)?;
                let phi = material.require("friction_angle", what)?.to_radians();
                let n = (1.0 + phi.sin()) / (1.0 - phi.sin());
                test.confining * n + 2.0 * c * n.sqrt()
            }
            ClosedForm::VonMisesCompression => material.require("yield_stress", what)?,
            ClosedForm::ElasticK0 => {
                let nu = material.require("poisson_ratio", what)?;
                nu / (1.0 - nu)
            }
            ClosedForm::HenckySimpleShear => {
                let e = material.require("young_modulus", what)?;
                let nu = material.require("poisson_ratio", what)?;
                let g = e / (2.0 * (1.0 + nu));
                let gamma = test.strain;
                2.0 * g * (0.5 * gamma).asinh() / (1.0 + 0.25 * gamma * gamma).sqrt()
            }
            ClosedForm::CamClayDrained => {
                let m = material.require(CRITICAL_STATE_SLOPE, what)?;
                3.0 * start.p() / (3.0 - m)
            }
            ClosedForm::CamClayUndrained => {
                let lambda = material.require(COMPRESSION_INDEX, what)?;
                let kappa = material.require(SWELLING_INDEX, what)?;
                start.p() * 2f64.powf(-(lambda - kappa) / lambda)
            }
            ClosedForm::CamClayNormalCompression => 1.0 / material.require(COMPRESSION_INDEX, what)?,
        })
    }
}

/// The measures of a test's final state (compression positive): p, q, the axial and lateral
/// stresses, K₀ = τ_xx/τ_yy, the shear stress τ_xy, the driven strain and the volumetric log
/// strain; with two path steps or more, the compression slope d ln p / dε_v of the last step.
pub fn measures(states: &[ElementState]) -> Vec<(&'static str, f64)> {
    let Some(last) = states.last() else {
        return vec![];
    };
    let mut out = vec![
        ("p", last.p()),
        ("q", last.q()),
        ("axial_stress", -last.tau[(1, 1)]),
        ("lateral_stress", -last.tau[(0, 0)]),
        ("shear_stress", last.tau[(0, 1)]),
        ("strain", last.strain),
        ("volumetric_strain", last.volumetric_strain()),
    ];
    if last.tau[(1, 1)] != 0.0 {
        out.push(("k0", last.tau[(0, 0)] / last.tau[(1, 1)]));
    }
    let path: Vec<&ElementState> = states.iter().filter(|s| !s.confining).collect();
    if let [.., a, b] = path.as_slice() {
        let dv = b.volumetric_strain() - a.volumetric_strain();
        if dv != 0.0 && a.p() > 0.0 && b.p() > 0.0 {
            out.push(("compression_slope", (b.p() / a.p()).ln() / dv));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::constitutive::LinearElastic;
    use crate::problems::element_test::run;

    fn test(path: ElementPath, strain: f64) -> ElementTest {
        ElementTest {
            path,
            confining: 0.0,
            confining_steps: 1,
            strain,
            steps: 10,
            tolerance: 1e-12,
            max_iterations: 20,
        }
    }

    /// Hencky simple shear and the oedometer reproduce their closed forms to round-off: the
    /// driver's kinematics (ΔF, b^e, the logarithm) are those of the solvers.
    #[test]
    fn hencky_paths_match_their_closed_forms() {
        let m = Material::linear_elastic(1e5, 0.3);
        let model = LinearElastic::try_new(1e5, 0.3).unwrap();
        for (path, form, strain) in [
            (ElementPath::SimpleShear, ClosedForm::HenckySimpleShear, 1.5),
            (ElementPath::Oedometer, ClosedForm::ElasticK0, 0.2),
        ] {
            let t = test(path, strain);
            let out = run(&model, &t);
            assert!(out.failure.is_none(), "{:?}", out.failure);
            let exact = form.value(&m, &t, &out.states[0]).unwrap();
            let got = measures(&out.states)
                .into_iter()
                .find(|(k, _)| *k == form.measure())
                .unwrap()
                .1;
            assert!(
                (got - exact).abs() <= 1e-12 * exact.abs(),
                "{path:?}: {got} against {exact}"
            );
        }
        let wrong =
            ClosedForm::ElasticK0.value(&m, &test(ElementPath::SimpleShear, 1.0), &Default::default());
        assert_eq!(wrong.unwrap_err().field, "path");
    }
}
