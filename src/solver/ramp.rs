//! How a load grows with the load factor λ ∈ [0, 1] of the load stepping: in proportion
//! (the paper's ramp), or by a table of (λ, factor) rows, linear between them.

use crate::solver::error::InputError;
use serde::{Deserialize, Serialize};

/// A load's factor as a function of the load factor λ (the fraction of the load steps done).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ramp {
    /// factor = λ.
    #[default]
    Linear,
    /// (λ, factor) rows from λ = 0 to λ = 1, λ strictly increasing; linear between rows.
    Table(Vec<[f64; 2]>),
}

impl Ramp {
    /// Is it the linear ramp (factor = load fraction)?
    pub fn is_linear(&self) -> bool {
        *self == Ramp::Linear
    }

    /// The factor at load factor `t` (clamped to [0, 1]).
    pub fn factor(&self, t: f64) -> f64 {
        let t = t.clamp(0.0, 1.0);
        match self {
            Ramp::Linear => t,
            Ramp::Table(rows) => {
                let k = rows.partition_point(|r| r[0] < t).clamp(1, rows.len() - 1);
                let ([t0, f0], [t1, f1]) = (rows[k - 1], rows[k]);
                f0 + (f1 - f0) * (t - t0) / (t1 - t0)
            }
        }
    }

    /// The factor of a dead load following this ramp at `load_factor`: a table's value, or
    /// with the linear ramp `load_factor` itself, unclamped (a dynamic analysis passes its
    /// time function's value, which may leave [0, 1]).
    pub fn applied(&self, load_factor: f64) -> f64 {
        match self {
            Ramp::Linear => load_factor,
            table => table.factor(load_factor),
        }
    }

    /// A table has at least two rows, starts at λ = 0, ends at λ = 1, increases strictly in
    /// λ and has finite factors; `field` names it in the error.
    pub fn validate(&self, field: &str) -> Result<(), InputError> {
        let Ramp::Table(rows) = self else {
            return Ok(());
        };
        if rows.len() < 2 {
            return Err(InputError::new(
                field,
                format!("{rows:?}"),
                "must have at least two [load fraction, factor] rows",
            ));
        }
        for (i, r) in rows.iter().enumerate() {
            if !r[0].is_finite() || !r[1].is_finite() {
                return Err(InputError::new(
                    format!("{field}[{i}]"),
                    format!("{r:?}"),
                    "must be finite",
                ));
            }
            if i > 0 && r[0] <= rows[i - 1][0] {
                return Err(InputError::new(
                    format!("{field}[{i}][0]"),
                    r[0],
                    format!("must be greater than the row before's {}", rows[i - 1][0]),
                ));
            }
        }
        let (first, last) = (rows[0][0], rows[rows.len() - 1][0]);
        if first != 0.0 || last != 1.0 {
            return Err(InputError::new(
                field,
                format!("load fractions {first} .. {last}"),
                "must start at load fraction 0 and end at 1",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_interpolates_between_its_rows() {
        let r = Ramp::Table(vec![[0.0, 0.0], [0.5, 1.0], [1.0, -1.0]]);
        r.validate("ramp").unwrap();
        assert_eq!(r.factor(0.25), 0.5);
        assert_eq!(r.factor(0.75), 0.0);
        assert_eq!(r.factor(1.0), -1.0);
        assert_eq!(r.factor(0.0), 0.0);
        assert_eq!(Ramp::Linear.factor(0.3), 0.3);
        assert!(Ramp::Table(vec![[0.0, 0.0], [0.5, 1.0]]).validate("r").is_err());
        assert!(Ramp::Table(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
            .validate("r")
            .is_err());
        assert!(Ramp::Table(vec![[0.0, 0.0]]).validate("r").is_err());
    }
}
