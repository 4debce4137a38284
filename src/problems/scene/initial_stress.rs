//! A body's initial stress: the Cauchy stress its points (or Gauss points) start in, held by
//! an elastic strain ([`crate::material::prestress`]). With loads that balance it from the
//! first step (a traction ramped by a table that starts at its full value) the body starts
//! in equilibrium: the surcharge beside a footing (reference/README.md item 77).

use crate::material::constitutive::ConstitutiveModel;
use crate::material::kinematics::PointState;
use crate::solver::error::InputError;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// The error of `key` (not the scene spec's: that module uses this one).
fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
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
}

impl StressComponents {
    /// The stress as a matrix.
    pub fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.xx, self.xy, self.xz, //
            self.xy, self.yy, self.yz, //
            self.xz, self.yz, self.zz,
        )
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
        for (name, v) in named {
            if !v.is_finite() {
                return Err(err(format!("{key}.{name}"), v, "must be finite"));
            }
            if dimension == 2 && matches!(name, "yz" | "xz") && v != 0.0 {
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

/// The state (of unit volume) holding the initial stress `stress` under `model`; `key` names
/// it in the error (a stress the model cannot hold elastically).
pub fn start_state(
    key: &str,
    stress: &StressComponents,
    model: &dyn ConstitutiveModel,
) -> Result<PointState, InputError> {
    crate::material::prestress::prestressed(model, &stress.matrix(), 1.0)
        .map_err(|e| err(key, format!("{stress:?}"), e.0))
}

/// Start every state of `states` in `start`, each keeping its volume.
pub fn start_in(states: &mut [PointState], start: &PointState) {
    for s in states.iter_mut() {
        *s = PointState {
            volume: s.volume,
            ..*start
        };
    }
}
