//! Newton's extrapolated start ([`crate::solver::newton::Predictor::Extrapolated`],
//! reference/README.md item 82): the last converged nodal increment, scaled by the ratio of
//! this increment's load to that one's, gathered onto this increment's equations.
//!
//! Why: a displacement-driven step started from a zero increment puts the whole jump of the
//! prescribed dofs (or of a bound footing's targets) on the first row of cells. Under steady
//! plastic flow that first iterate yields far beyond the solution and Newton crawls or fails
//! into cut-backs; the previous increment is already the shape of the flow.
//!
//! The ratio is taken per kind of load that drove the last increment: the prescribed dofs'
//! increments, the bound points' targets, and the increments of the point and nodal forces
//! (matched by dof or point index), each `s_k = Δ_new · Δ_last / |Δ_last|²`; the start's
//! scale is their mean. A kind that did not drive the last increment gives no ratio; with
//! none (the first increment, a strength reduction's steps) the start is zero.

use crate::discretise::dofs::DofMap;
use crate::discretise::point_penalty::PointPenalty;
use nalgebra::SVector;

/// What drives an increment: the step input's loads (`super::StepInput`'s fields).
#[derive(Clone, Copy)]
pub struct Drive<'a, const D: usize> {
    /// The prescribed dofs' increments (dof, Δu).
    pub prescribed: &'a [(usize, f64)],
    /// The bound points' penalties, with their targets.
    pub point_penalties: &'a [PointPenalty],
    /// The point forces at the increment's end.
    pub point_forces: &'a [SVector<f64, D>],
    /// The nodal forces at the increment's end (dof, force).
    pub nodal_forces: &'a [(usize, f64)],
}

/// The last converged increment and the loads that drove it.
#[derive(Debug, Default)]
pub struct ExtrapolatedStart<const D: usize> {
    /// Its nodal increment (dof = node·D + axis); empty before the first.
    increment: Vec<f64>,
    /// Its prescribed dofs' increments.
    prescribed: Vec<(usize, f64)>,
    /// Its bound points' targets (point, axis, target).
    targets: Vec<(usize, usize, f64)>,
    /// Its point forces' and nodal forces' increments (empty when the forces before it were
    /// not known: the first increment).
    point_force_increment: Vec<SVector<f64, D>>,
    nodal_force_increment: Vec<(usize, f64)>,
    /// The point and nodal forces of the converged state (where the next increment starts).
    point_forces: Vec<SVector<f64, D>>,
    nodal_forces: Vec<(usize, f64)>,
    /// The last attempt failed: its retries (the cut-backs) start from zero, as they would
    /// without the predictor, until an increment converges.
    failed: bool,
}

/// Accumulates Σ Δ_new·Δ_last and |Δ_last|² of one kind of load.
#[derive(Default)]
struct Ratio {
    cross: f64,
    last: f64,
}

impl Ratio {
    fn add(&mut self, new: f64, last: f64) {
        self.cross += new * last;
        self.last += last * last;
    }
    fn value(&self) -> Option<f64> {
        (self.last > 0.0).then(|| self.cross / self.last)
    }
}

impl<const D: usize> ExtrapolatedStart<D> {
    /// The scale of the last increment that this one's loads call for, if any kind of load
    /// drove the last one.
    fn scale(&self, input: Drive<'_, D>) -> Option<f64> {
        let mut ratios = [
            Ratio::default(),
            Ratio::default(),
            Ratio::default(),
            Ratio::default(),
        ];
        if same_keys(
            input.prescribed.iter().map(|p| p.0),
            self.prescribed.iter().map(|p| p.0),
        ) {
            for (new, last) in input.prescribed.iter().zip(&self.prescribed) {
                ratios[0].add(new.1, last.1);
            }
        }
        let bound = input.point_penalties;
        if same_keys(
            bound.iter().map(|p| (p.point, p.axis)),
            self.targets.iter().map(|t| (t.0, t.1)),
        ) {
            for (new, last) in bound.iter().zip(&self.targets) {
                ratios[1].add(new.target, last.2);
            }
        }
        if input.point_forces.len() == self.point_forces.len()
            && self.point_force_increment.len() == self.point_forces.len()
        {
            for ((now, before), last) in input
                .point_forces
                .iter()
                .zip(&self.point_forces)
                .zip(&self.point_force_increment)
            {
                for a in 0..D {
                    ratios[2].add(now[a] - before[a], last[a]);
                }
            }
        }
        let nodal = input.nodal_forces;
        if same_keys(nodal.iter().map(|f| f.0), self.nodal_forces.iter().map(|f| f.0))
            && same_keys(
                self.nodal_forces.iter().map(|f| f.0),
                self.nodal_force_increment.iter().map(|f| f.0),
            )
        {
            for ((now, before), last) in nodal
                .iter()
                .zip(&self.nodal_forces)
                .zip(&self.nodal_force_increment)
            {
                ratios[3].add(now.1 - before.1, last.1);
            }
        }
        let (sum, count) = ratios
            .iter()
            .filter_map(Ratio::value)
            .fold((0.0, 0), |(s, n), r| (s + r, n + 1));
        (count > 0).then(|| sum / count as f64).filter(|s| s.is_finite())
    }

    /// Fill `u` (this increment's equations) with the extrapolated start; false (and `u`
    /// untouched) when there is none.
    pub fn fill(&self, input: Drive<'_, D>, dofs: &DofMap, u: &mut [f64]) -> bool {
        if self.failed || self.increment.len() != dofs.num_dofs() {
            return false;
        }
        let scale = self.scale(input);
        #[cfg(feature = "seeded-bugs")]
        let scale = match scale {
            Some(_) if crate::seeded::active(crate::seeded::Bug::ExtrapolatedStartUnscaled) => Some(1.0),
            s => s,
        };
        match scale {
            Some(s) if s != 0.0 => {
                dofs.gather(&self.increment, u);
                u.iter_mut().for_each(|v| *v *= s);
                true
            }
            _ => false,
        }
    }

    /// Note a failed attempt: the next starts from zero.
    pub fn failed(&mut self) {
        self.failed = true;
    }

    /// Remember the converged increment `du_nodal` of `input`'s loads.
    pub fn record(&mut self, input: Drive<'_, D>, du_nodal: &[f64]) {
        self.failed = false;
        self.increment.clear();
        self.increment.extend_from_slice(du_nodal);
        self.prescribed.clear();
        self.prescribed.extend_from_slice(input.prescribed);
        self.targets.clear();
        self.targets
            .extend(input.point_penalties.iter().map(|p| (p.point, p.axis, p.target)));
        self.point_force_increment.clear();
        if self.point_forces.len() == input.point_forces.len() {
            self.point_force_increment.extend(
                input
                    .point_forces
                    .iter()
                    .zip(&self.point_forces)
                    .map(|(a, b)| a - b),
            );
        }
        self.nodal_force_increment.clear();
        if same_keys(
            input.nodal_forces.iter().map(|f| f.0),
            self.nodal_forces.iter().map(|f| f.0),
        ) {
            self.nodal_force_increment.extend(
                input
                    .nodal_forces
                    .iter()
                    .zip(&self.nodal_forces)
                    .map(|(a, b)| (a.0, a.1 - b.1)),
            );
        }
        self.point_forces.clear();
        self.point_forces.extend_from_slice(input.point_forces);
        self.nodal_forces.clear();
        self.nodal_forces.extend_from_slice(input.nodal_forces);
    }
}

/// Whether two sequences of keys are equal (same length, same keys in the same order).
fn same_keys<K: PartialEq>(a: impl ExactSizeIterator<Item = K>, b: impl ExactSizeIterator<Item = K>) -> bool {
    a.len() == b.len() && a.zip(b).all(|(x, y)| x == y)
}
