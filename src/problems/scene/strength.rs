//! A scene's strength reduction: the soil's strength divided by a factor F that follows a
//! ramp over the load steps ([`crate::material::strength_reduction`]), and the factor of
//! safety read where the body collapses (reference/README.md item 79).

use super::spec::Scene;
use crate::material::strength_reduction::StrengthReduction;
use crate::solver::error::{InputError, SolveError};

const KEY: &str = "strength_reduction.ramp";

impl Scene {
    /// The strength reduction of the scene's material, if it has one; an error names the
    /// ramp's key.
    pub fn strength_reduction(&self) -> Result<Option<StrengthReduction>, InputError> {
        let Some(s) = &self.strength_reduction else {
            return Ok(None);
        };
        let material = self.materials[&self.bodies[0].material];
        StrengthReduction::new(KEY, material, s.ramp.clone()).map(Some)
    }

    /// Did the run that stopped at `failure` collapse under the strength reduction: did it
    /// fail while F was above its value at the start? A failure at the starting F (while
    /// gravity comes on) is a failure, not a factor of safety.
    pub fn collapsed(&self, failure: Option<&SolveError>) -> bool {
        match (&self.strength_reduction, failure) {
            (Some(s), Some(f)) => s.ramp.factor(f.load_factor) > s.ramp.factor(0.0),
            _ => false,
        }
    }

    /// The factor of safety of a run that ended at `failure` after `load_steps` steps: F at
    /// its last committed state if it collapsed ([`Self::collapsed`]); with `limit` (a
    /// displacement limit and the displacement after each converged step), F where the
    /// displacement first moved the limit from its value when F began to rise, linear
    /// between steps, if that comes first. NaN if the body stood at every F.
    pub fn factor_of_safety(
        &self,
        failure: Option<&SolveError>,
        limit: Option<(f64, &[f64])>,
        load_steps: usize,
    ) -> f64 {
        let Some(s) = &self.strength_reduction else {
            return f64::NAN;
        };
        let f = |step: usize| s.ramp.factor(step as f64 / load_steps.max(1) as f64);
        let at_collapse = match failure {
            Some(e) if self.collapsed(failure) => s.ramp.factor(e.reached),
            _ => f64::NAN,
        };
        let Some((limit, moved)) = limit else {
            return at_collapse;
        };
        // The steps at the starting F come first; the limit is measured from the last one's
        // displacement (the body under its weight at full strength).
        let start = (1..=moved.len()).take_while(|&k| f(k) <= f(0)).count();
        let base = if start == 0 { 0.0 } else { moved[start - 1] };
        let mut before = 0.0;
        for k in start + 1..=moved.len() {
            let d = (moved[k - 1] - base).abs();
            if d >= limit {
                // Every converged step precedes the collapse: a limit reached at one is first.
                let t = if d > before {
                    (limit - before) / (d - before)
                } else {
                    1.0
                };
                return f(k - 1) + t * (f(k) - f(k - 1));
            }
            before = d;
        }
        at_collapse
    }
}
