//! Speed of the solver core: one load step of the W = 400,000 column (2 points per element)
//! at 256 and 512 elements, and the per-point kinematics + constitutive + tangent kernel.
//! `cargo bench --bench solver`

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use igimp::basis::Basis;
use igimp::constitutive::LinearElastic;
use igimp::kinematics::{evaluate_point, PointState};
use igimp::newton::LoadStepping;
use igimp::problems::column::ColumnSpec;
use nalgebra::SMatrix;
use std::hint::black_box;

fn load_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("column_load_step");
    for elements in [256usize, 512] {
        let spec = ColumnSpec {
            elements,
            weight: 400_000.0,
            ..ColumnSpec::default()
        };
        // The 10th of 20 steps: points have moved off the element edges.
        group.bench_function(format!("igimp_{elements}_elements"), |b| {
            b.iter_batched(
                || {
                    let mut s = spec.mpm_solver(Basis::Gimp).unwrap();
                    for _ in 0..9 {
                        s.step().unwrap();
                    }
                    s
                },
                |mut s| black_box(s.step().unwrap()),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

fn point_kernel(c: &mut Criterion) {
    let model = LinearElastic::try_new(1e6, 0.3).unwrap();
    let state = PointState::undeformed(0.1);
    let g1 = SMatrix::<f64, 1, 1>::new(-0.05);
    let g2 = SMatrix::<f64, 2, 2>::new(-0.05, 0.02, 0.01, 0.03);
    c.bench_function("point_kernel_1d_with_tangent", |b| {
        b.iter(|| {
            black_box(
                evaluate_point::<1>(&model, &state, black_box(&g1))
                    .unwrap()
                    .spatial_tangent(&model, &state),
            )
        })
    });
    c.bench_function("point_kernel_2d_with_tangent", |b| {
        b.iter(|| {
            black_box(
                evaluate_point::<2>(&model, &state, black_box(&g2))
                    .unwrap()
                    .spatial_tangent(&model, &state),
            )
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = load_step, point_kernel
}
criterion_main!(benches);
