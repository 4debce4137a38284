//! The cases of a dynamics study: each sweep's plan for a tier, its case specs and ids.

use super::*;

/// One case to solve.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicCase {
    pub id: String,
    pub method: Method,
    pub spec: CaseSpec,
}

/// The problem input of one case. Serialised untagged, so that a bar case's key (a hash of
/// its spec) is what it was before the kind had a second problem.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
// A study holds tens of cases: the cantilever's size (its spec and its reference's) costs
// nothing, and boxing it would lose Copy.
#[allow(clippy::large_enum_variant)]
pub enum CaseSpec {
    Bar(BarSpec),
    Manufactured(DynamicManufacturedSpec),
    Cantilever(CantileverCase),
    /// A bar measured against a reference analysis instead of the small-amplitude closed form.
    BarAgainst(BarCase),
}

/// A vibrating bar case and the analysis it is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BarCase {
    pub spec: BarSpec,
    pub reference: BarReferenceRun,
}

/// The reference analysis of a bar case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BarReferenceRun {
    pub method: Method,
    pub spec: BarSpec,
}

/// A dynamic cantilever case and the analysis it is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CantileverCase {
    pub spec: DynamicCantileverSpec,
    pub reference: ReferenceRun,
}

/// The reference analysis of a cantilever case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReferenceRun {
    pub method: Method,
    pub spec: DynamicCantileverSpec,
}

/// Elements through the depth of a cantilever spec (h = depth / elements).
pub(super) fn through_depth(s: &DynamicCantileverSpec) -> usize {
    (s.beam.depth / s.beam.element_size).round() as usize
}

impl CaseSpec {
    pub fn validate(&self) -> Result<(), crate::solver::error::InputError> {
        match self {
            CaseSpec::Bar(b) => b.validate(),
            CaseSpec::Manufactured(m) => m.validate(),
            CaseSpec::Cantilever(c) => c.spec.validate().and_then(|_| c.reference.spec.validate()),
            CaseSpec::BarAgainst(c) => c.spec.validate().and_then(|_| c.reference.spec.validate()),
        }
    }

    /// Points (or Gauss points) × time steps: the planner's cost.
    pub fn cost(&self) -> f64 {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => {
                (b.elements * b.points_per_cell * b.time_steps()) as f64
            }
            CaseSpec::Manufactured(m) => {
                ((m.cells * m.points_per_cell).pow(m.dimension as u32) * m.time_steps()) as f64
            }
            CaseSpec::Cantilever(c) => {
                let b = &c.spec.beam;
                let cells = (b.length / b.element_size) * (b.depth / b.element_size);
                cells * (b.points_per_cell * b.points_per_cell * c.spec.time_steps()) as f64
            }
        }
    }

    /// What names the case in its sweep: its field (manufactured), mass matrix, elements
    /// (cells per side), points per cell and time steps per period.
    pub fn levels(&self) -> CaseLevels {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => CaseLevels {
                field: None,
                mass: b.mass,
                elements: b.elements,
                points_per_cell: b.points_per_cell,
                steps_per_period: b.steps_per_period,
            },
            CaseSpec::Manufactured(m) => CaseLevels {
                field: Some(m.field),
                mass: m.mass,
                elements: m.cells,
                points_per_cell: m.points_per_cell,
                steps_per_period: m.steps_per_period,
            },
            CaseSpec::Cantilever(c) => CaseLevels {
                field: None,
                mass: c.spec.mass,
                elements: through_depth(&c.spec),
                points_per_cell: c.spec.beam.points_per_cell,
                steps_per_period: c.spec.steps_per_period,
            },
        }
    }

    /// The period of the motion: the bar's 4L/c, the manufactured forcing's 2/c, the
    /// cantilever's time unit T₁ (the Euler–Bernoulli first mode).
    pub fn period(&self) -> f64 {
        match self {
            CaseSpec::Bar(b) | CaseSpec::BarAgainst(BarCase { spec: b, .. }) => b.period(),
            CaseSpec::Manufactured(m) => m.period(),
            CaseSpec::Cantilever(c) => c.spec.period(),
        }
    }
}

/// The sweep's lists after the tier's overrides.
pub(super) struct SweepPlan {
    pub(super) methods: Vec<Method>,
    pub(super) elements: Vec<i64>,
    pub(super) steps_per_period: Vec<i64>,
    pub(super) reference: Option<SweepReference>,
}

/// The discretisation of one case ([`CaseSpec::levels`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaseLevels {
    pub field: Option<Field>,
    pub mass: MassMatrix,
    pub elements: usize,
    pub points_per_cell: usize,
    pub steps_per_period: usize,
}

/// The methods a bar case can use: every material point family and the line elements.
pub const BAR_METHODS: [Method; Method::FAMILIES + 2] = Method::listed(Some(1), &[]);

/// The methods of a plane manufactured case: every material point family, Q4 and Q8.
pub const MANUFACTURED_METHODS: [Method; Method::FAMILIES + 2] = manufactured_dynamic::METHODS;
/// The methods of a 3D manufactured case: every material point family, Hex8 and Hex20.
pub const MANUFACTURED_METHODS_3D: [Method; Method::FAMILIES + 2] =
    crate::problems::manufactured3d::METHODS_3D;
/// The methods of a dynamic cantilever case: every material point family and Q8.
pub const CANTILEVER_METHODS: [Method; Method::FAMILIES + 1] = crate::problems::cantilever_dynamic::METHODS;

/// Most elements of one case (1D: cheap; a bound against typos).
pub(super) const MAX_ELEMENTS: i64 = 65_536;
/// Most time steps per period.
pub(super) const MAX_STEPS_PER_PERIOD: i64 = 65_536;

impl DynamicSweep {
    pub(super) fn plan(&self, tier: Tier) -> Option<SweepPlan> {
        if !crate::study::vocabulary::TieredSweep::runs_in(self, tier) {
            return None;
        }
        let q = (tier == Tier::Quick).then_some(&self.quick);
        Some(SweepPlan {
            methods: q
                .and_then(|q| q.methods.clone())
                .unwrap_or_else(|| self.methods.clone()),
            elements: q
                .and_then(|q| q.elements.clone())
                .unwrap_or_else(|| self.elements.clone()),
            steps_per_period: q
                .and_then(|q| q.steps_per_period.clone())
                .unwrap_or_else(|| self.steps_per_period.clone()),
            reference: q.and_then(|q| q.reference).or(self.reference),
        })
    }

    /// What the sweep varies (the full tier's lists decide; validation keeps the quick
    /// tier's the same).
    pub fn refinement(&self) -> Refinement {
        if self.elements.len() > 1 {
            Refinement::Space
        } else {
            Refinement::Time
        }
    }
}

impl DynamicStudy {
    pub fn sweep(&self, id: &str) -> Option<&DynamicSweep> {
        self.sweeps.iter().find(|s| s.id == id)
    }

    /// The bar's spec of one case.
    pub fn bar_spec(
        b: &BarSection,
        material: Material,
        newton: &NewtonSection,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> BarSpec {
        BarSpec {
            length: b.length,
            material,
            density: b.density,
            velocity: b.velocity,
            elements: elements as usize,
            points_per_cell: ppc as usize,
            steps_per_period: steps as usize,
            periods: b.periods,
            beta: b.beta,
            gamma: b.gamma,
            mass,
            newton: newton.settings(),
            rho_infinity: b.rho_infinity,
        }
    }

    /// The dynamic cantilever of one case: `elements` through the depth, `ppc` points per
    /// cell along each axis, `steps` per T₁.
    pub fn cantilever_spec(
        c: &CantileverSection,
        material: Material,
        newton: &NewtonSection,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> DynamicCantileverSpec {
        let beam = CantileverSpec {
            length: c.length,
            depth: c.depth,
            material,
            load: c.load,
            element_size: c.depth / elements as f64,
            points_per_cell: ppc as usize,
            grid_below: c.grid_below,
            grid_margin: c.grid_margin,
            newton: newton.settings(),
            ..CantileverSpec::default()
        };
        DynamicCantileverSpec {
            beam,
            density: c.density,
            periods: c.periods,
            steps_per_period: steps as usize,
            beta: c.beta,
            gamma: c.gamma,
            mass,
            rho_infinity: c.rho_infinity,
        }
    }

    /// The spec of one case of `sweep` by `method` (`None`: the file gives no problem section,
    /// a manufactured sweep has no field or a cantilever sweep no reference; validation
    /// reports each).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn case_spec_of(
        &self,
        sweep: &DynamicSweep,
        method: Method,
        reference: Option<&SweepReference>,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> Option<CaseSpec> {
        let m = self.material.material();
        if let Some(c) = &self.cantilever {
            let r = reference?;
            let spec = Self::cantilever_spec(c, m, &self.newton, mass, elements, ppc, steps);
            return Some(CaseSpec::Cantilever(CantileverCase {
                spec,
                reference: ReferenceRun {
                    method: r.method.unwrap_or(method),
                    spec: Self::cantilever_spec(
                        c,
                        m,
                        &self.newton,
                        mass,
                        r.elements,
                        ppc,
                        r.steps_per_period,
                    ),
                },
            }));
        }
        let spec = self.case_spec(sweep, mass, elements, ppc, steps)?;
        Some(match (spec, reference, &self.bar) {
            (CaseSpec::Bar(spec), Some(r), Some(b)) => CaseSpec::BarAgainst(BarCase {
                spec,
                reference: BarReferenceRun {
                    method: r.method.unwrap_or(method),
                    spec: Self::bar_spec(b, m, &self.newton, mass, r.elements, ppc, r.steps_per_period),
                },
            }),
            (spec, _, _) => spec,
        })
    }

    /// The spec of one case of `sweep` (`None`: the file gives neither problem section, or a
    /// manufactured sweep without its field; validation reports both). Not for the cantilever,
    /// whose cases also depend on their method and reference.
    pub fn case_spec(
        &self,
        sweep: &DynamicSweep,
        mass: MassMatrix,
        elements: i64,
        ppc: i64,
        steps: i64,
    ) -> Option<CaseSpec> {
        if let Some(b) = &self.bar {
            return Some(CaseSpec::Bar(Self::bar_spec(
                b,
                self.material.material(),
                &self.newton,
                mass,
                elements,
                ppc,
                steps,
            )));
        }
        let m = self.manufactured.as_ref()?;
        let field = sweep.field?;
        Some(CaseSpec::Manufactured(DynamicManufacturedSpec {
            field,
            amplitude: match field {
                Field::AxisAligned => m.amplitude.axis_aligned,
                Field::Vortex => m.amplitude.vortex,
            },
            material: self.material.material(),
            density: m.density,
            cells: elements as usize,
            points_per_cell: ppc as usize,
            steps_per_period: steps as usize,
            periods: m.periods,
            beta: m.beta,
            gamma: m.gamma,
            mass,
            newton: self.newton.settings(),
            domain_update: Default::default(),
            dimension: m.dimension,
            rho_infinity: m.rho_infinity,
        }))
    }

    /// `<method>[-<field>]-<mass>-e<elements>-p<ppc>-n<steps per period>`.
    pub fn case_id(method: Method, spec: &CaseSpec) -> String {
        let CaseLevels {
            field,
            mass,
            elements,
            points_per_cell: ppc,
            steps_per_period: steps,
        } = spec.levels();
        let mass = match mass {
            MassMatrix::Consistent => "cm",
            MassMatrix::Lumped => "lm",
        };
        let field = field.map_or(String::new(), |f| format!("-{}", f.name()));
        // A cantilever case names its reference: one discretisation may be measured against
        // two (a space and a time sweep).
        let reference = match spec {
            CaseSpec::Cantilever(c) => format!(
                "-vs-{}-e{}-n{}",
                c.reference.method.name(),
                through_depth(&c.reference.spec),
                c.reference.spec.steps_per_period
            ),
            CaseSpec::BarAgainst(c) => format!(
                "-vs-{}-e{}-n{}",
                c.reference.method.name(),
                c.reference.spec.elements,
                c.reference.spec.steps_per_period
            ),
            _ => String::new(),
        };
        format!(
            "{}{field}-{mass}-e{elements}-p{ppc}-n{steps}{reference}",
            method.name()
        )
    }

    /// The methods a case of this study may use.
    pub fn methods(&self) -> &'static [Method] {
        if self.cantilever.is_some() {
            return &CANTILEVER_METHODS;
        }
        match &self.manufactured {
            None => &BAR_METHODS,
            Some(m) if m.dimension == 3 => &MANUFACTURED_METHODS_3D,
            Some(_) => &MANUFACTURED_METHODS,
        }
    }

    pub(super) fn sweep_cases(&self, s: &DynamicSweep, plan: &SweepPlan) -> Vec<DynamicCase> {
        let mut out = vec![];
        for &method in &plan.methods {
            for &mass in &s.mass {
                for &ppc in &s.points_per_cell {
                    for &e in &plan.elements {
                        for &n in &plan.steps_per_period {
                            let Some(spec) =
                                self.case_spec_of(s, method, plan.reference.as_ref(), mass, e, ppc, n)
                            else {
                                continue;
                            };
                            out.push(DynamicCase {
                                id: Self::case_id(method, &spec),
                                method,
                                spec,
                            });
                        }
                    }
                }
            }
        }
        out
    }

    pub fn cases(&self, tier: Tier) -> (Vec<DynamicCase>, SweepIndex) {
        distinct_cases(
            self.sweeps
                .iter()
                .filter_map(|s| Some((s.id.clone(), self.sweep_cases(s, &s.plan(tier)?)))),
            |c| c.id.as_str(),
        )
    }
}
