//! A body's initial stress: the Cauchy stress its points (or Gauss points) start in, held by
//! an elastic strain ([`crate::material::prestress`]). With loads that balance it from the
//! first step (a traction ramped by a table that starts at its full value) the body starts
//! in equilibrium: the surcharge beside a footing (reference/README.md item 77). A stress that
//! grows with depth below a surface (`per_depth`) starts a body under its own weight, gravity
//! at full value from the first step: the geostatic state σ_v = −γ d, σ_h = K₀ σ_v
//! (reference/README.md item 80).

use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::PointState;
use crate::solver::error::InputError;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// The error of `key` (not the scene spec's: that module uses this one).
fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
}

/// The stress's growth per unit depth below `surface`, a coordinate along the last axis
/// (`y` in 2D, `z` in 3D); absent components do not grow.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthGradient {
    pub surface: f64,
    #[serde(default)]
    pub xx: f64,
    #[serde(default)]
    pub yy: f64,
    #[serde(default)]
    pub zz: f64,
    #[serde(default)]
    pub xy: f64,
    #[serde(default)]
    pub yz: f64,
    #[serde(default)]
    pub xz: f64,
}

/// Components of a symmetric stress (tension positive); absent ones are zero.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StressComponents {
    #[serde(default)]
    pub xx: f64,
    #[serde(default)]
    pub yy: f64,
    #[serde(default)]
    pub zz: f64,
    #[serde(default)]
    pub xy: f64,
    #[serde(default)]
    pub yz: f64,
    #[serde(default)]
    pub xz: f64,
    /// The stress grows below a surface: σ(X) = σ + d · per_depth at depth d = surface − X
    /// along the last axis (d ≥ 0: above the surface σ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_depth: Option<DepthGradient>,
}

/// A symmetric matrix of six components.
fn symmetric([xx, yy, zz, xy, yz, xz]: [f64; 6]) -> Matrix3<f64> {
    Matrix3::new(
        xx, xy, xz, //
        xy, yy, yz, //
        xz, yz, zz,
    )
}

impl StressComponents {
    /// The stress at the surface (everywhere without `per_depth`) as a matrix.
    pub fn matrix(&self) -> Matrix3<f64> {
        symmetric([self.xx, self.yy, self.zz, self.xy, self.yz, self.xz])
    }

    /// The stress at a point whose coordinate along the last axis is `last`.
    pub fn at(&self, last: f64) -> Matrix3<f64> {
        match &self.per_depth {
            None => self.matrix(),
            Some(g) => {
                let d = (g.surface - last).max(0.0);
                self.matrix() + d * symmetric([g.xx, g.yy, g.zz, g.xy, g.yz, g.xz])
            }
        }
    }

    /// Finite components, and in plane strain (`dimension` 2) no out-of-plane shear.
    pub fn check(&self, key: &str, dimension: usize) -> Result<(), InputError> {
        let named = [
            ("xx", self.xx),
            ("yy", self.yy),
            ("zz", self.zz),
            ("xy", self.xy),
            ("yz", self.yz),
            ("xz", self.xz),
        ];
        let gradient = self.per_depth.map(|g| {
            [
                ("per_depth.surface", g.surface),
                ("per_depth.xx", g.xx),
                ("per_depth.yy", g.yy),
                ("per_depth.zz", g.zz),
                ("per_depth.xy", g.xy),
                ("per_depth.yz", g.yz),
                ("per_depth.xz", g.xz),
            ]
        });
        for (name, v) in named.into_iter().chain(gradient.into_iter().flatten()) {
            if !v.is_finite() {
                return Err(err(format!("{key}.{name}"), v, "must be finite"));
            }
            if dimension == 2 && (name.ends_with("yz") || name.ends_with("xz")) && v != 0.0 {
                return Err(err(
                    format!("{key}.{name}"),
                    v,
                    "must be 0 in plane strain (no out-of-plane shear)",
                ));
            }
        }
        Ok(())
    }
}

/// Start each state of `states` in `stress` at its point, `last[i]` the point's initial
/// coordinate along the last axis, each keeping its volume; `key` names the stress in the
/// error. Points at one depth share one solve of [`crate::material::prestress::prestressed`].
pub fn start_in(
    key: &str,
    stress: &StressComponents,
    model: &dyn ConstitutiveModel,
    states: &mut [PointState],
    last: &[f64],
) -> Result<(), InputError> {
    debug_assert_eq!(states.len(), last.len());
    let mut held: Option<(f64, PointState)> = None;
    for (s, &x) in states.iter_mut().zip(last) {
        // Uniform stresses solve once; graded ones once per depth (a row of points).
        let depth = stress.per_depth.map_or(0.0, |g| (g.surface - x).max(0.0));
        let start = match held {
            Some((d, start)) if d == depth => start,
            _ => {
                let start =
                    crate::material::prestress::prestressed(model, &stress.at(x), 1.0).map_err(|e| {
                        let given = match stress.per_depth {
                            None => format!("{stress:?}"),
                            Some(_) => format!("{:?} at depth {depth}", stress.at(x)),
                        };
                        err(key, given, e.0)
                    })?;
                held = Some((depth, start));
                start
            }
        };
        *s = PointState {
            volume: s.volume,
            ..start
        };
    }
    Ok(())
}
