//! Every example runs, as `cargo run --release --example <name>` would, and prints what its
//! doc says (`cargo test` builds the examples beside the test binaries; `custom_basis` is also
//! compiled into this binary and checked by `families`).

use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/examples/<name>`, beside this test binary's `deps/`.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile = exe.parent().and_then(|d| d.parent()).unwrap();
    profile.join("examples").join(name)
}

/// Run example `name` with `args`: it exits 0 and its output contains every one of `says`.
fn runs(name: &str, args: &[&str], says: &[&str]) {
    let path = example(name);
    assert!(
        path.exists(),
        "{} not built: the whole `cargo test` builds the examples (or `cargo build --release --examples`)",
        path.display()
    );
    let out = Command::new(&path)
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{name} {args:?} failed:\n{text}");
    for s in says {
        assert!(text.contains(s), "{name} {args:?} does not say {s:?}:\n{text}");
    }
}

#[test]
fn the_column_example_converges_at_every_size() {
    runs("column", &[], &["elements 256", "failure None"]);
}

#[test]
fn the_cantilever_example_reaches_the_last_step() {
    runs("cantilever", &[], &["final step 50", "failure: None"]);
}

#[test]
fn the_compaction_example_prints_every_steps_residuals() {
    runs("compaction", &[], &["step 20:"]);
}

#[test]
fn the_stabilisation_probe_runs_both_problems_and_explains_its_usage() {
    runs("stabilisation", &["compaction", "1", "2", "ghost:0.1"], &[]);
    runs("stabilisation", &["cantilever", "ghost:0.01"], &[]);
    let out = Command::new(example("stabilisation")).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("usage: stabilisation"));
}

/// `examples/hardening_von_mises.rs`: a model defined outside the crate (linear isotropic
/// hardening von Mises, with its own internal variable), registered by name and run on the
/// plastic column.
mod hardening {
    use crate::common::Rng;
    use crate::hardening_von_mises::{
        column, hardening, largest_difference, HardeningColumn, HardeningVonMises, E,
        EQUIVALENT_PLASTIC_STRAIN, YIELD,
    };
    use igimp::basis::Basis;
    use igimp::material::constitutive::{ConstitutiveModel, InternalVariables, Material, MaterialState};
    use igimp::material::tensor::{contract, identity_outer, identity_sym, Tensor4};
    use igimp::problems::column::{AnalyticalColumn, ColumnSpec};
    use igimp::problems::norms::fitted_rate;
    use igimp::solver::load_stepping::LoadStepping;
    use igimp::study::material::MaterialTable;
    use nalgebra::Matrix3;

    #[test]
    fn the_hardening_example_runs() {
        super::runs(
            "hardening_von_mises",
            &[],
            &[
                "H = 0 against the built-in von Mises",
                "largest difference 0.0e0",
                "H = 5e5",
            ],
        );
    }

    /// At H = 0 the outside model is the built-in von Mises operation for operation, so the
    /// column reproduces it to 1e-12 (it is equal to the bit). With H = E/2 the base F and the
    /// top displacement converge to the hardening column's closed form at first order in h (as
    /// the perfectly plastic column's), and stay more than 10 % off the perfectly plastic one:
    /// the yielded zone stiffens, the base F moves towards 1 and the top settles less, as the
    /// closed form says. A model that ignored H, or hardened with the wrong sign, fails.
    #[test]
    fn the_outside_model_reproduces_von_mises_and_converges_to_the_hardening_closed_form() {
        let built_in = column(Material::von_mises(E, 0.0, YIELD), 64);
        let h0 = column(hardening(0.0), 64);
        let d = largest_difference(&h0, &built_in);
        assert!(d <= 1e-12, "H = 0 against the built-in von Mises: {d:e}");

        let h = 0.5 * E;
        let exact = HardeningColumn::of(h);
        let perfect: AnalyticalColumn = ColumnSpec {
            material: Material::von_mises(E, 0.0, YIELD),
            weight: crate::hardening_von_mises::WEIGHT,
            ..ColumnSpec::default()
        }
        .analytical();
        // The closed form at H = 0 is the library's perfectly plastic one.
        let (f0, f0_perfect) = (
            HardeningColumn::of(0.0).deformation_gradient(0.0),
            perfect.deformation_gradient(0.0),
        );
        assert!((f0 - f0_perfect).abs() < 1e-12, "{f0} against {f0_perfect}");
        let f_exact = exact.deformation_gradient(0.0);
        let u_exact = exact.displacement(exact.length);
        let elements = [64, 128, 256];
        let mut errors = vec![];
        for n in elements {
            let o = column(hardening(h), n);
            let e = (o.base_f - f_exact).abs() / f_exact;
            let e_perfect = (o.base_f - f0_perfect).abs() / f0_perfect;
            let e_u = (o.top_displacement - u_exact).abs() / u_exact.abs();
            println!("H = E/2, {n} elements: base F error {e:.3e} (perfectly plastic closed form {e_perfect:.3e}), top u error {e_u:.2e}");
            assert!(
                e < 5e-3 && e_u < 1e-3,
                "{n} elements: base F error {e:e}, top u error {e_u:e}"
            );
            assert!(
                e_perfect > 0.1,
                "{n} elements: as close to the perfectly plastic column ({e_perfect:e})"
            );
            assert!(o.base_f > h0.base_f && o.top_displacement > h0.top_displacement);
            errors.push(e);
        }
        let h_sizes: Vec<f64> = elements.iter().map(|&n| 1.0 / n as f64).collect();
        let rate = fitted_rate(&h_sizes, &errors).unwrap();
        assert!(
            (0.8..1.3).contains(&rate),
            "base F error rate {rate} ({errors:?})"
        );
        assert!(f_exact > f0 && u_exact > HardeningColumn::of(0.0).displacement(exact.length));
    }

    /// D^alg of the outside model against central differences of its update, from virgin and
    /// already hardened states (α_n > 0), with and without hardening (≤ 1e-6 relative), away
    /// from the elastic/plastic kink.
    #[test]
    fn the_hardening_tangent_matches_central_differences() {
        let mut rng = Rng::new(77);
        let mut plastic = 0;
        for h in [0.0, 0.3 * E] {
            let m = HardeningVonMises::try_new(E, 0.3, YIELD, h).unwrap();
            let elastic: Tensor4 = {
                let (l, mu) = igimp::material::constitutive::lame(E, 0.3);
                identity_outer() * l + identity_sym() * (2.0 * mu)
            };
            for alpha in [0.0, 0.01] {
                let state = MaterialState {
                    internal: InternalVariables::from_slice(&[alpha]),
                    ..MaterialState::default()
                };
                for _ in 0..60 {
                    let a = Matrix3::from_fn(|_, _| rng.uniform(-0.05, 0.05));
                    let eps = 0.5 * (a + a.transpose());
                    let trial = contract(&elastic, &eps);
                    let dev = trial - Matrix3::identity() * (trial.trace() / 3.0);
                    let f = (1.5 * dev.norm_squared()).sqrt() - (YIELD + h * alpha);
                    if f.abs() < 1e-3 * YIELD {
                        continue; // too close to the kink for differences
                    }
                    let r = m.update(&eps, &state).unwrap();
                    if r.internal.get(0) > alpha {
                        plastic += 1;
                    }
                    let d_alg = m.tangent(&eps, &state);
                    let step = 1e-8;
                    for k in 0..3 {
                        for l in 0..3 {
                            let mut d = Matrix3::zeros();
                            d[(k, l)] += 0.5;
                            d[(l, k)] += 0.5;
                            let fd = (m.update(&(eps + d * step), &state).unwrap().tau
                                - m.update(&(eps - d * step), &state).unwrap().tau)
                                / (2.0 * step);
                            let an = contract(&d_alg, &d);
                            assert!(
                                (fd - an).amax() <= 1e-6 * d_alg.amax(),
                                "H = {h}, α = {alpha}: {fd} against {an}"
                            );
                        }
                    }
                }
            }
        }
        assert!(plastic > 60, "{plastic} plastic states checked");
    }

    /// The registry knows the outside model by name (a `[material]` table names it; an unknown
    /// name lists it; a missing parameter names its key), and the ParaView and point files
    /// write its internal variable under its own name.
    #[test]
    fn the_registered_model_is_named_by_tables_and_written_by_its_variable() {
        hardening(0.0);
        let table: MaterialTable = toml::from_str(
            "model = \"von-mises-hardening\"\nyoung_modulus = 1.0e6\npoisson_ratio = 0.0\n\
             yield_stress = 3.0e4\nhardening_modulus = 1.0e5\n",
        )
        .unwrap();
        assert_eq!(table.resolve("material").unwrap(), hardening(1e5));
        let unknown: MaterialTable = toml::from_str("model = \"hardening\"\n").unwrap();
        let e = unknown.resolve("material").unwrap_err();
        assert!(
            e.field == "material.model" && e.allowed.contains("von-mises-hardening"),
            "{e}"
        );
        let missing: MaterialTable = toml::from_str(
            "model = \"von-mises-hardening\"\nyoung_modulus = 1.0e6\npoisson_ratio = 0.0\nyield_stress = 3.0e4\n",
        )
        .unwrap();
        assert_eq!(
            missing.resolve("materials.hard").unwrap_err().field,
            "materials.hard.hardening_modulus"
        );

        let spec = ColumnSpec {
            material: hardening(0.5 * E),
            weight: crate::hardening_von_mises::WEIGHT,
            elements: 16,
            ..ColumnSpec::default()
        };
        let mut solver = spec.mpm_solver(Basis::Gimp).unwrap();
        solver.run().unwrap();
        let declared = solver.model().internal_variables();
        assert_eq!(declared, [EQUIVALENT_PLASTIC_STRAIN]);
        let xml = igimp::study::vtk::material_points(&solver.points, declared).to_xml();
        assert!(xml.contains("Name=\"equivalent_plastic_strain\""));
        assert!(!xml.contains("plastic_multiplier"));
        let o = igimp::problems::column::solve_column(&spec, igimp::problems::column::Method::IGIMP).unwrap();
        let csv = igimp::study::column::kind::points_csv(&o.points, true, declared);
        let header = csv.lines().next().unwrap();
        assert_eq!(
            header,
            "z0,z,volume0,sigma_zz,f_zz,sigma_xx,equivalent_plastic_strain"
        );
        let yielded = o.points.iter().filter(|p| p.inelastic).count();
        assert!(
            yielded > 0 && yielded < o.points.len(),
            "{yielded} of {} points yielded",
            o.points.len()
        );
        assert!(o.yield_height.is_some());
    }
}
