//! A load step's record counts the work its cutbacks did: the failed increments and the
//! Newton iterations of every increment before the recorded one (reference/README.md item
//! 76: a footing's record showed 82 iterations where about 2,500 had been made).

use igimp::solver::load_stepping::{LinearRecord, StepReport, SubStep};
use igimp::solver::newton::NewtonReport;
use igimp::study::results::step_records;

fn newton(residuals: &[f64]) -> NewtonReport {
    NewtonReport {
        residuals: residuals.to_vec(),
        accepted_floor: None,
    }
}

fn attempt(load_factor: f64, converged: bool, residuals: &[f64]) -> SubStep {
    SubStep {
        load_factor,
        converged,
        failure: (!converged).then(|| "diverged".to_string()),
        residuals: residuals.to_vec(),
    }
}

#[test]
fn a_step_records_its_cutbacks_and_their_iterations() {
    let last = [1.0, 1e-2, 1e-5, 1e-10];
    let cut = StepReport {
        step: 1,
        load_factor: 0.5,
        newton: newton(&last),
        weak_nodes: 0,
        linear: LinearRecord::default(),
        substeps: vec![
            attempt(0.5, false, &[1.0, 3.0, 9.0, 27.0, 81.0]),
            attempt(0.25, false, &[1.0, 2.0, 4.0]),
            attempt(0.125, true, &[1.0, 1e-3, 1e-9]),
            attempt(0.25, true, &[1.0, 1e-3, 1e-7, 1e-11]),
            attempt(0.5, true, &last),
        ],
    };
    let plain = StepReport {
        step: 2,
        substeps: vec![],
        ..cut.clone()
    };
    let records = step_records(&[cut, plain]);
    assert_eq!(records[0].cutbacks, 2);
    // 4 + 2 failed, 2 + 3 converged before the recorded increment's own 3.
    assert_eq!(records[0].earlier_iterations, 11);
    assert_eq!(records[0].residuals, last);
    assert_eq!((records[1].cutbacks, records[1].earlier_iterations), (0, 0));
    let text = serde_json::to_string(&records[1]).unwrap();
    assert!(
        !text.contains("cutbacks") && !text.contains("earlier_iterations"),
        "{text}"
    );
}
