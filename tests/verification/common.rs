//! Helpers shared by the integration tests.
#![allow(dead_code)]

use igimp::basis::Basis;
use igimp::discretise::ghost::GhostSettings;
use igimp::material::constitutive::ConstitutiveModel;
use igimp::material::kinematics::{left_cauchy_green_from_strain, log_strain, PointState};
use igimp::mpm::{DomainUpdate, Loads, MpmSettings};
use igimp::solver::newton::NewtonSettings;
use nalgebra::{Matrix3, SVector};

/// The settings of the single-state checks (tangents, patches): `basis` with eq (39)'s domain
/// update, one load step, `ghost`, and the defaults otherwise.
pub fn single_step_settings(basis: Basis, ghost: GhostSettings) -> MpmSettings {
    MpmSettings {
        basis,
        domain_update: DomainUpdate::Stretch,
        newton: NewtonSettings::default(),
        load_steps: 1,
        weak_node_tolerance: 0.0,
        weak_node_treatment: Default::default(),
        volume_update: Default::default(),
        linear_solver: Default::default(),
        ghost,
        dynamics: None,
        f_bar: false,
    }
}

/// No gravity and no point loads.
pub fn no_loads<const D: usize>() -> Loads<D> {
    Loads {
        gravity: SVector::<f64, D>::zeros(),
        point_loads: vec![],
    }
}

/// Commit every state at the homogeneous deformation F (`f`), as if a previous step had
/// converged there elastically: F, V = det F V₀ (V₀ the volume paired with the state),
/// ε^e = ½ ln(F Fᵀ), b^e = exp(2 ε^e) and τ of `elastic`.
pub fn commit_stretched<'a>(
    states: impl IntoIterator<Item = (&'a mut PointState, f64)>,
    f: &Matrix3<f64>,
    elastic: &dyn ConstitutiveModel,
) {
    let eps = log_strain(&(f * f.transpose())).unwrap();
    for (s, volume0) in states {
        s.f = *f;
        s.volume = volume0 * f.determinant();
        s.material.eps_e = eps;
        s.material.b_e = left_cauchy_green_from_strain(&eps);
        s.tau = elastic.update(&eps, &s.material).unwrap().tau;
    }
}

/// Seeded SplitMix64: reproducible pseudo-random numbers without a dependency.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// The assembled tangent of `sys` against central differences of its residual at a random
/// increment of scale `u0_scale` (step 1e-7): (max |K − K_fd| / max |K|, max |K − Kᵀ| /
/// max |K|) and the trial von Mises stresses of its points at that increment, from which the
/// FEM tangent tests place a yield stress (`fem2d`, `fem3d`).
pub fn fd_tangent_errors<const D: usize>(
    sys: &mut igimp::discretise::assembly::LoadStepSystem<'_, D>,
    u0_scale: f64,
    seed: u64,
) -> (f64, f64, Vec<f64>) {
    use igimp::solver::newton::NonlinearSystem;
    let n = sys.num_unknowns();
    let mut rng = Rng::new(seed);
    let u0: Vec<f64> = (0..n).map(|_| rng.uniform(-u0_scale, u0_scale)).collect();
    let mut r = vec![0.0; n];
    sys.evaluate(&u0, &mut r).unwrap();
    let rho: Vec<f64> = sys
        .trials
        .iter()
        .map(|t| {
            let tau = t.as_ref().unwrap().response.tau;
            let s = tau - nalgebra::Matrix3::identity() * (tau.trace() / 3.0);
            (1.5 * s.norm_squared()).sqrt()
        })
        .collect();
    sys.assemble_tangent();
    let k: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| sys.matrix.get(i, j)).collect())
        .collect();
    let h = 1e-7;
    let (mut rp, mut rm) = (vec![0.0; n], vec![0.0; n]);
    let (mut err, mut kmax, mut asym) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..n {
        let mut u = u0.clone();
        u[j] += h;
        sys.evaluate(&u, &mut rp).unwrap();
        u[j] -= 2.0 * h;
        sys.evaluate(&u, &mut rm).unwrap();
        for i in 0..n {
            err = err.max(((rp[i] - rm[i]) / (2.0 * h) - k[i][j]).abs());
            kmax = kmax.max(k[i][j].abs());
            asym = asym.max((k[i][j] - k[j][i]).abs());
        }
    }
    (err / kmax, asym / kmax, rho)
}

/// The largest |D_fd − D| of `m`'s update by central differences at `eps` (h = 1e-8,
/// symmetric perturbations), over max(|D|, `floor`): a floor such as E where D vanishes (the
/// apex of perfect plasticity, where the stress is fixed), 0 otherwise.
pub fn material_tangent_error(
    m: &dyn ConstitutiveModel,
    eps: &Matrix3<f64>,
    s: &igimp::material::constitutive::MaterialState,
    floor: f64,
) -> f64 {
    let d_alg = m.tangent(eps, s);
    let h = 1e-8;
    let mut worst: f64 = 0.0;
    for k in 0..3 {
        for l in 0..3 {
            let mut d = Matrix3::zeros();
            d[(k, l)] += 0.5;
            d[(l, k)] += 0.5;
            let fd = (m.update(&(eps + d * h), s).unwrap().tau - m.update(&(eps - d * h), s).unwrap().tau)
                / (2.0 * h);
            let exact = igimp::material::tensor::contract(&d_alg, &d);
            worst = worst.max((fd - exact).amax() / d_alg.amax().max(floor));
        }
    }
    worst
}
