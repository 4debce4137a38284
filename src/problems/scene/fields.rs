//! A solve's state as the case protocol carries it (`studies/PROTOCOL.md`): every material
//! point's position, Cauchy stress, deformation gradient and volume after a load step, and
//! the reaction of each region; and a scene's measures read back from them, so that a case
//! solved by another code is measured by the same code as one solved here.

use super::discrete::{DiscreteScene, Reactions};
use super::solve::{gather, read_measures, MeasureValue, PointSink, Probe};
use super::spec::Scene;
use crate::material::kinematics::{log_strain, spectral_map, sym_eigen, PointState};
use crate::mpm::particles::MaterialPoints;
use crate::solver::error::InputError;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// Every point's state after one load step. Tensors are 3 × 3, row-major (in plane strain
/// F_zz = 1 and σ_zz is the out-of-plane stress).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointFields {
    /// Current position x.
    pub position: Vec<Vec<f64>>,
    /// Cauchy stress σ.
    pub cauchy: Vec<Vec<f64>>,
    /// Deformation gradient F; or, from a code that does not give F,
    /// `left_cauchy_green` (every measure needs only b and σ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deformation_gradient: Option<Vec<Vec<f64>>>,
    /// Left Cauchy–Green tensor b = F Fᵀ, when F is not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_cauchy_green: Option<Vec<Vec<f64>>>,
    /// Current volume.
    pub volume: Vec<f64>,
    /// Half the side of the current domain along each axis (codes that track domains).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_length: Option<Vec<Vec<f64>>>,
}

fn row_major(m: &Matrix3<f64>) -> Vec<f64> {
    (0..9).map(|k| m[(k / 3, k % 3)]).collect()
}

fn matrix(v: &[f64]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| v[3 * i + j])
}

impl PointFields {
    /// The committed state of `points`.
    pub fn of_points<const D: usize>(points: &MaterialPoints<D>) -> Self {
        let v = |x: &nalgebra::SVector<f64, D>| x.iter().copied().collect::<Vec<f64>>();
        PointFields {
            position: points.position.iter().map(v).collect(),
            cauchy: points.state.iter().map(|s| row_major(&s.cauchy())).collect(),
            deformation_gradient: Some(points.state.iter().map(|s| row_major(&s.f)).collect()),
            left_cauchy_green: None,
            volume: points.state.iter().map(|s| s.volume).collect(),
            half_length: Some(points.half_length.iter().map(v).collect()),
        }
    }

    /// Sizes that agree with `count` points in dimension `d`, and finite values; an error
    /// names the key under `key`.
    pub fn validate(&self, key: &str, count: usize, d: usize) -> Result<(), InputError> {
        let rows = |name: &str, rows: &[Vec<f64>], width: usize| -> Result<(), InputError> {
            if rows.len() != count {
                return Err(InputError::new(
                    format!("{key}.{name}"),
                    format!("{} entries", rows.len()),
                    format!("must have one per point of the case ({count})"),
                ));
            }
            for (p, r) in rows.iter().enumerate() {
                if r.len() != width {
                    return Err(InputError::new(
                        format!("{key}.{name}[{p}]"),
                        format!("{} values", r.len()),
                        format!("must have {width}"),
                    ));
                }
                if let Some(i) = r.iter().position(|v| !v.is_finite()) {
                    return Err(InputError::new(
                        format!("{key}.{name}[{p}][{i}]"),
                        r[i],
                        "must be finite",
                    ));
                }
            }
            Ok(())
        };
        rows("position", &self.position, d)?;
        rows("cauchy", &self.cauchy, 9)?;
        match (&self.deformation_gradient, &self.left_cauchy_green) {
            (Some(f), None) => {
                rows("deformation_gradient", f, 9)?;
                for (p, f) in f.iter().enumerate() {
                    let j = matrix(f).determinant();
                    if j <= 0.0 {
                        return Err(InputError::new(
                            format!("{key}.deformation_gradient[{p}]"),
                            format!("det F = {j}"),
                            "must have det F > 0",
                        ));
                    }
                }
            }
            (None, Some(b)) => {
                rows("left_cauchy_green", b, 9)?;
                for (p, b) in b.iter().enumerate() {
                    let m = matrix(b);
                    let (l, _) = sym_eigen(&(0.5 * (m + m.transpose())));
                    if (m - m.transpose()).amax() > 1e-9 * m.amax() || l.iter().any(|&x| x <= 0.0) {
                        return Err(InputError::new(
                            format!("{key}.left_cauchy_green[{p}]"),
                            format!("{b:?}"),
                            "must be symmetric positive definite",
                        ));
                    }
                }
            }
            _ => {
                return Err(InputError::new(
                    key,
                    "deformation_gradient and left_cauchy_green",
                    "must give exactly one of the two",
                ))
            }
        }
        if let Some(h) = &self.half_length {
            rows("half_length", h, d)?;
        }
        let volume: Vec<Vec<f64>> = self.volume.iter().map(|&v| vec![v]).collect();
        rows("volume", &volume, 1)?;
        if let Some(p) = self.volume.iter().position(|&v| v <= 0.0) {
            return Err(InputError::new(
                format!("{key}.volume[{p}]"),
                self.volume[p],
                "must be > 0",
            ));
        }
        Ok(())
    }

    /// Point `p`'s state as igimp holds it: F (the left stretch √b where only b is given),
    /// volume, τ = J σ and the logarithmic strain ½ ln b as the elastic one (exact for
    /// elastic models, which the energy measure needs).
    fn state(&self, p: usize) -> PointState {
        let (f, b) = match (&self.deformation_gradient, &self.left_cauchy_green) {
            (Some(f), _) => {
                let f = matrix(&f[p]);
                (f, f * f.transpose())
            }
            (None, Some(b)) => {
                let b = matrix(&b[p]);
                let (l, q) = sym_eigen(&b);
                (spectral_map(&l, &q, |x| x.max(0.0).sqrt()), b)
            }
            (None, None) => (Matrix3::identity(), Matrix3::identity()),
        };
        let mut s = PointState::undeformed(self.volume[p]);
        s.tau = matrix(&self.cauchy[p]) * f.determinant();
        s.material.eps_e = log_strain(&b).unwrap_or_else(Matrix3::zeros);
        s.f = f;
        s
    }
}

/// The measures of `scene` (resolved as `discrete`) from the fields and reactions after each
/// converged step, as [`super::solve`] reads them from a solver: the points are `discrete`'s,
/// in order. A measure the fields cannot give (a domain edge without domains) is NaN.
pub fn measures_of_fields(
    scene: &Scene,
    discrete: &DiscreteScene,
    steps: &[(PointFields, Reactions)],
) -> Vec<MeasureValue> {
    let named = discrete.named_dofs();
    let x0 = &discrete.points.position;
    let read = |fields: &PointFields, reactions: &Reactions| {
        let displacement = |at: &[f64], axis: usize, edge: bool| {
            let dist = |p: usize| -> f64 { x0[p].iter().zip(at).map(|(a, b)| (a - b) * (a - b)).sum() };
            let Some(p) = (0..x0.len()).min_by(|&a, &b| dist(a).total_cmp(&dist(b))) else {
                return f64::NAN;
            };
            let grow = match (&fields.half_length, edge) {
                (_, false) => 0.0,
                (Some(h), true) => {
                    (h[p][axis] - discrete.points.half_length[p][axis]) * (at[axis] - x0[p][axis]).signum()
                }
                (None, true) => f64::NAN,
            };
            fields.position[p][axis] - x0[p][axis] + grow
        };
        // A region's reaction along `axis`, once per region: the probe is asked per dof.
        let reaction_of = |name: &str, axis: usize| reactions.get(name).and_then(|r| r.get(axis).copied());
        let points = |f: PointSink<'_>| {
            for p in 0..x0.len() {
                f(
                    &x0[p],
                    &fields.position[p],
                    discrete.points.volume[p],
                    &fields.state(p),
                );
            }
        };
        read_measures(
            scene,
            &named,
            &Probe {
                displacement: &displacement,
                reaction: &|_, _| f64::NAN,
                region_reaction: Some(&reaction_of),
                points: &points,
            },
        )
    };
    let history: Vec<Vec<_>> = steps.iter().map(|(f, r)| read(f, r)).collect();
    let unloaded = || {
        let fields = PointFields {
            position: x0.clone(),
            cauchy: vec![row_major(&Matrix3::zeros()); x0.len()],
            deformation_gradient: Some(vec![row_major(&Matrix3::identity()); x0.len()]),
            left_cauchy_green: None,
            volume: discrete.points.volume.clone(),
            half_length: Some(discrete.points.half_length.clone()),
        };
        let zero = named
            .iter()
            .map(|n| (n.0.clone(), vec![0.0; discrete.dimension]))
            .collect();
        read(&fields, &zero)
    };
    gather(scene, &history, unloaded)
}
