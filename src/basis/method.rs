//! The names of the solution methods every problem and study uses, in two levels: a material
//! point method with its basis family ([`Basis`]), or a finite element comparator with its
//! element ([`Element`]). No solver code: problems dispatch on the level and hand the family
//! or element to their solver; study files, `results.json` and the reports name methods by
//! [`Method::name`] (kebab-case, as serialised, unchanged from the flat enum it replaced).

use crate::basis::Basis;
use crate::solver::error::InputError;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A finite element comparator's element (updated Lagrangian, the same constitutive code).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Element {
    /// Two-noded line elements (2 Gauss points by default).
    Line2,
    /// Three-noded line elements (3 Gauss points by default).
    Line3,
    /// 4-node quadrilaterals, 2×2 Gauss points (Figure 17 reference).
    Q4,
    /// 8-node quadrilaterals, 3×3 Gauss points (Figure 21).
    Q8,
    /// 8-node hexahedra, 2×2×2 Gauss points (3D).
    Hex8,
    /// 20-node serendipity hexahedra, 3×3×3 Gauss points (3D).
    Hex20,
}

impl Element {
    /// Every element, in declaration order.
    pub const ALL: [Element; 6] = [
        Element::Line2,
        Element::Line3,
        Element::Q4,
        Element::Q8,
        Element::Hex8,
        Element::Hex20,
    ];

    /// The space dimension the element discretises.
    pub const fn dimension(self) -> usize {
        match self {
            Element::Line2 | Element::Line3 => 1,
            Element::Q4 | Element::Q8 => 2,
            Element::Hex8 | Element::Hex20 => 3,
        }
    }
}

/// A discretisation method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Method {
    /// An implicit material point method with the given basis family.
    MaterialPoint(Basis),
    /// Updated-Lagrangian FEM with the given element.
    Fem(Element),
}

impl Method {
    /// Standard implicit MPM.
    pub const MPM: Method = Method::MaterialPoint(Basis::Mpm);
    /// Implicit GIMP (the paper's method).
    pub const IGIMP: Method = Method::MaterialPoint(Basis::Gimp);
    /// CPDI2.
    pub const CPDI: Method = Method::MaterialPoint(Basis::Cpdi);
    /// Quadratic B-spline MPM.
    pub const BSPLINE2: Method = Method::MaterialPoint(Basis::Bspline2);
    /// Cubic B-spline MPM.
    pub const BSPLINE3: Method = Method::MaterialPoint(Basis::Bspline3);
    /// Total-Lagrangian MPM.
    pub const TLMPM: Method = Method::MaterialPoint(Basis::Tlmpm);
    /// Linear (two-noded) line FEM.
    pub const FEM_LINEAR: Method = Method::Fem(Element::Line2);
    /// Quadratic (three-noded) line FEM.
    pub const FEM_QUADRATIC: Method = Method::Fem(Element::Line3);
    /// Q4 quadrilateral FEM.
    pub const FEM_Q4: Method = Method::Fem(Element::Q4);
    /// Q8 quadrilateral FEM.
    pub const FEM_Q8: Method = Method::Fem(Element::Q8);
    /// Hex8 hexahedral FEM.
    pub const FEM_HEX8: Method = Method::Fem(Element::Hex8);
    /// Hex20 serendipity hexahedral FEM.
    pub const FEM_HEX20: Method = Method::Fem(Element::Hex20);

    /// How many material point families there are ([`Basis::ALL`]): problem method lists are
    /// sized by it, so that a new family joins them without an edit.
    pub const FAMILIES: usize = Basis::ALL.len();

    /// Every method: the material point families, then the elements.
    pub const ALL: [Method; Basis::ALL.len() + Element::ALL.len()] = Method::listed(None, &[]);

    /// The material point methods, one per basis family.
    pub const MATERIAL_POINT: [Method; Basis::ALL.len()] = {
        let mut out = [Method::MPM; Basis::ALL.len()];
        let mut i = 0;
        while i < out.len() {
            out[i] = Method::MaterialPoint(Basis::ALL[i]);
            i += 1;
        }
        out
    };

    /// A problem's methods, derived from the one declaration of each family ([`Basis::ALL`])
    /// and element ([`Element::ALL`]): every material point family, then the elements of
    /// `dimension` (every element if `None`), less `excluded`, in declaration order. `N` is
    /// their count; a wrong one is a compile-time error.
    pub const fn listed<const N: usize>(dimension: Option<usize>, excluded: &[Method]) -> [Method; N] {
        let mut out = [Method::MPM; N];
        let mut k = 0;
        let mut i = 0;
        while i < Basis::ALL.len() + Element::ALL.len() {
            let m = if i < Basis::ALL.len() {
                Method::MaterialPoint(Basis::ALL[i])
            } else {
                Method::Fem(Element::ALL[i - Basis::ALL.len()])
            };
            let of_dimension = match (m, dimension) {
                (Method::Fem(e), Some(d)) => e.dimension() == d,
                _ => true,
            };
            let mut kept = of_dimension;
            let mut j = 0;
            while j < excluded.len() {
                if m.same_as(excluded[j]) {
                    kept = false;
                }
                j += 1;
            }
            if kept {
                assert!(k < N, "more methods than N");
                out[k] = m;
                k += 1;
            }
            i += 1;
        }
        assert!(k == N, "fewer methods than N");
        out
    }

    /// `==` in a const context.
    const fn same_as(self, other: Method) -> bool {
        match (self, other) {
            (Method::MaterialPoint(a), Method::MaterialPoint(b)) => a as u8 == b as u8,
            (Method::Fem(a), Method::Fem(b)) => a as u8 == b as u8,
            _ => false,
        }
    }

    /// The name in study files and `results.json`.
    pub fn name(self) -> &'static str {
        match self {
            Method::MaterialPoint(b) => b.method_name(),
            Method::Fem(Element::Line2) => "fem-linear",
            Method::Fem(Element::Line3) => "fem-quadratic",
            Method::Fem(Element::Q4) => "fem-q4",
            Method::Fem(Element::Q8) => "fem-q8",
            Method::Fem(Element::Hex8) => "fem-hex8",
            Method::Fem(Element::Hex20) => "fem-hex20",
        }
    }

    /// The method named `name` in a study file.
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The human name, as in the paper.
    pub fn label(self) -> &'static str {
        match self {
            Method::MaterialPoint(b) => b.label(),
            Method::Fem(Element::Line2) => "linear FEM",
            Method::Fem(Element::Line3) => "quadratic FEM",
            Method::Fem(Element::Q4) => "Q4 FEM",
            Method::Fem(Element::Q8) => "Q8 FEM",
            Method::Fem(Element::Hex8) => "Hex8 FEM",
            Method::Fem(Element::Hex20) => "Hex20 FEM",
        }
    }

    /// True for the finite element comparators.
    pub fn is_fem(self) -> bool {
        matches!(self, Method::Fem(_))
    }

    /// True for the methods whose points per cell matter (the material point methods).
    pub fn uses_material_points(self) -> bool {
        matches!(self, Method::MaterialPoint(_))
    }

    /// The basis family of a material point method.
    pub fn basis(self) -> Option<Basis> {
        match self {
            Method::MaterialPoint(b) => Some(b),
            Method::Fem(_) => None,
        }
    }

    /// True if the method's answer depends on the domain update rule (§3.3; GIMP only).
    pub fn uses_domain_update(self) -> bool {
        self.basis().is_some_and(Basis::uses_domain_update)
    }

    /// `Ok` if `self` is one of `supported` (a problem's methods), else [`Self::unsupported`].
    pub fn expect_one_of(self, problem: &str, supported: &[Method]) -> Result<(), InputError> {
        if supported.contains(&self) {
            Ok(())
        } else {
            Err(self.unsupported(problem, supported))
        }
    }

    /// The error of a method `problem` has no solution for: it names the field `method` and
    /// the methods the problem has.
    pub fn unsupported(self, problem: &str, supported: &[Method]) -> InputError {
        let names: Vec<&str> = supported.iter().map(|m| m.name()).collect();
        InputError::new(
            "method",
            self.name(),
            format!("the {problem} is solved by {}", names.join(", ")),
        )
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Method {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Method {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Method::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            serde::de::Error::custom(format!(
                "unknown variant `{name}`, expected one of {}",
                names
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
    }
}
