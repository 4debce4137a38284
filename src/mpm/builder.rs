//! A material point solver from its parts, one named part at a time
//! ([`MpmSolver::builder`]): what [`MpmSolver::try_new`] takes positionally.

use super::{Loads, MpmSettings, MpmSolver};
use crate::basis::{Basis, DomainUpdate};
use crate::material::constitutive::ConstitutiveModel;
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::solver::error::InputError;
use nalgebra::SVector;

/// The parts of a material point solver; [`Self::build`] validates them all at once.
pub struct MpmBuilder<const D: usize> {
    grid: Grid<D>,
    points: MaterialPoints<D>,
    model: Option<Box<dyn ConstitutiveModel>>,
    fixed: Vec<(usize, usize)>,
    loads: Loads<D>,
    settings: MpmSettings,
}

impl<const D: usize> MpmSolver<D> {
    /// Start a solver of `points` on `grid`: no supports, no loads, the default settings
    /// ([`MpmSettings::default`]: iGIMP, 20 load steps); a material is required.
    pub fn builder(grid: Grid<D>, points: MaterialPoints<D>) -> MpmBuilder<D> {
        MpmBuilder {
            grid,
            points,
            model: None,
            fixed: vec![],
            loads: Loads {
                gravity: SVector::zeros(),
                point_loads: vec![],
            },
            settings: MpmSettings::default(),
        }
    }
}

impl<const D: usize> MpmBuilder<D> {
    /// The constitutive model of every point.
    pub fn material(mut self, model: impl ConstitutiveModel + 'static) -> Self {
        self.model = Some(Box::new(model));
        self
    }

    /// The constitutive model, already boxed.
    pub fn boxed_material(mut self, model: Box<dyn ConstitutiveModel>) -> Self {
        self.model = Some(model);
        self
    }

    /// Fix grid node `node` along `axis` (a homogeneous Dirichlet condition).
    pub fn fix(mut self, node: usize, axis: usize) -> Self {
        self.fixed.push((node, axis));
        self
    }

    /// Fix every (node, axis) of `dofs`.
    pub fn fix_all(mut self, dofs: impl IntoIterator<Item = (usize, usize)>) -> Self {
        self.fixed.extend(dofs);
        self
    }

    /// Gravitational acceleration at the end of the analysis (body force per unit mass).
    pub fn gravity(mut self, g: SVector<f64, D>) -> Self {
        self.loads.gravity = g;
        self
    }

    /// A force carried by material point `point` at the end of the analysis.
    pub fn point_load(mut self, point: usize, force: SVector<f64, D>) -> Self {
        self.loads.point_loads.push((point, force));
        self
    }

    /// The basis family.
    pub fn basis(mut self, basis: Basis) -> Self {
        self.settings.basis = basis;
        self
    }

    /// How the point domains follow the deformation (GIMP).
    pub fn domain_update(mut self, update: DomainUpdate) -> Self {
        self.settings.domain_update = update;
        self
    }

    /// The number of equal load increments.
    pub fn load_steps(mut self, n: usize) -> Self {
        self.settings.load_steps = n;
        self
    }

    /// All settings at once (replaces the basis, domain update and load steps set before).
    pub fn settings(mut self, settings: MpmSettings) -> Self {
        self.settings = settings;
        self
    }

    /// The solver, or the first invalid part: a missing material, a fixed dof off the grid,
    /// a point outside it, invalid settings ([`MpmSolver::try_new`]).
    pub fn build(self) -> Result<MpmSolver<D>, InputError> {
        let model = self.model.ok_or_else(|| {
            InputError::new(
                "material",
                "none",
                "a constitutive model is required (MpmBuilder::material)",
            )
        })?;
        MpmSolver::try_new(
            self.grid,
            self.points,
            model,
            self.fixed,
            self.loads,
            self.settings,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::constitutive::LinearElastic;
    use crate::solver::load_stepping::LoadStepping;

    fn parts() -> (Grid<1>, MaterialPoints<1>) {
        let grid = Grid::try_new([0.0], [1.0], [4]).unwrap();
        let points = MaterialPoints::fill_box(&grid, [0.0], [4.0], [2], 1.0).unwrap();
        (grid, points)
    }

    /// The builder is `try_new` with named parts: the same column, solved, to the bit; and a
    /// missing material or a support off the grid is an error naming the part.
    #[test]
    fn the_builder_builds_what_try_new_builds_and_names_missing_parts() {
        let (grid, points) = parts();
        let g = SVector::<f64, 1>::new(-0.01);
        let mut built = MpmSolver::builder(grid.clone(), points.clone())
            .material(LinearElastic::try_new(1.0, 0.0).unwrap())
            .fix(0, 0)
            .gravity(g)
            .load_steps(2)
            .build()
            .unwrap();
        let settings = MpmSettings {
            load_steps: 2,
            ..MpmSettings::default()
        };
        let loads = Loads {
            gravity: g,
            point_loads: vec![],
        };
        let model = Box::new(LinearElastic::try_new(1.0, 0.0).unwrap());
        let mut direct =
            MpmSolver::try_new(grid.clone(), points.clone(), model, vec![(0, 0)], loads, settings).unwrap();
        built.run().unwrap();
        direct.run().unwrap();
        assert_eq!(built.points.position, direct.points.position);
        assert!(
            built.points.position[7][0] < 3.75,
            "the column settles under gravity"
        );

        let missing = MpmSolver::builder(grid.clone(), points.clone())
            .build()
            .err()
            .unwrap();
        assert_eq!(missing.field, "material");
        let off_grid = MpmSolver::builder(grid, points)
            .material(LinearElastic::try_new(1.0, 0.0).unwrap())
            .fix(5, 0)
            .build()
            .err()
            .unwrap();
        assert_eq!(off_grid.field, "fixed dof");
    }
}
