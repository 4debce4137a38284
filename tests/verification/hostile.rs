//! Hostile input: random and malformed study files and random problem parameters must give a
//! clear error naming the field, or a valid result, and never a panic.
//!
//! Property tests with a fixed seed and a fixed number of cases (1,600 in all), so CI runs the
//! same inputs every time; a failure is saved to `proptest-regressions/hostile.txt` (commit it)
//! and replayed first on the next run.

use igimp::material::constitutive::Material;
use igimp::problems::cantilever::CantileverSpec;
use igimp::problems::column::{solve_column, ColumnSpec, Method};
use igimp::problems::compaction::CompactionSpec;
use igimp::solver::newton::NewtonSettings;
use igimp::study::column::ColumnStudy;
use igimp::study::engine::StudyKind;
use igimp::study::store::confined;
use igimp::study::{StudyError, Tier};
use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence, RngSeed};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use toml::Value;

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x1619_2026),
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "proptest-regressions/hostile.txt",
        ))),
        ..Config::default()
    }
}

fn study_text(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("studies/{name}.toml")))
        .unwrap()
}

/// Field names of a study file, its sections and the problem structs.
const FIELDS: &[&str] = &[
    "schema",
    "name",
    "summary",
    "problem",
    "report_file",
    "expected_failures",
    "column",
    "material",
    "model",
    "length",
    "young_modulus",
    "poisson_ratio",
    "density",
    "yield_stress",
    "load_steps",
    "newton",
    "tolerance",
    "max_iterations",
    "line_search",
    "sweeps",
    "id",
    "title",
    "methods",
    "weights",
    "elements",
    "points_per_cell",
    "fit_points",
    "quick",
    "skip",
    "expect",
    "sweep",
    "method",
    "weight",
    "measure",
    "rate",
    "source",
    "compare",
    "lower",
    "higher",
    "paper",
    "table",
    "top_displacement",
    "base_f",
    "f_error",
    "analytical_base_f",
    "figures",
    "kind",
    "slope_triangles",
];

/// Hencky elasticity, or von Mises with a yield stress.
fn material(young_modulus: f64, poisson_ratio: f64, yield_stress: Option<f64>) -> Material {
    match yield_stress {
        Some(y) => Material::von_mises(young_modulus, poisson_ratio, y),
        None => Material::linear_elastic(young_modulus, poisson_ratio),
    }
}

/// Parse in `catch_unwind`; a panic fails the property with the input.
fn parse(text: &str) -> Result<Result<ColumnStudy, StudyError>, TestCaseError> {
    catch_unwind(AssertUnwindSafe(|| ColumnStudy::parse(text, "hostile.toml")))
        .map_err(|_| TestCaseError::fail(format!("ColumnStudy::parse panicked on:\n{text}")))
}

/// A parsed study is usable: every case of both tiers is a valid column, and every id is a
/// plain file name inside the output folder.
fn check_accepted(spec: &ColumnStudy) -> Result<(), TestCaseError> {
    confined(Path::new("out"), &spec.name).map_err(|e| TestCaseError::fail(e.to_string()))?;
    for tier in [Tier::Quick, Tier::Full] {
        for case in spec.cases(tier) {
            prop_assert!(
                case.spec.validate().is_ok(),
                "{}: {:?}",
                case.id,
                case.spec.validate()
            );
            prop_assert!(
                confined(Path::new("out"), &format!("{}.json", case.id)).is_ok(),
                "{}",
                case.id
            );
        }
    }
    Ok(())
}

/// The error names a field: a validation error carries the key path (whose first segment
/// is a study key), a parse error the key (toml quotes the offending line) or the missing
/// or unknown field.
fn check_error(e: &StudyError, expected_key: Option<&str>) -> Result<(), TestCaseError> {
    let msg = e.to_string();
    prop_assert!(msg.starts_with("hostile.toml"), "{msg}");
    match e {
        StudyError::Invalid { key, .. } => {
            let root = key.split(['.', '[']).next().unwrap_or("");
            prop_assert!(FIELDS.contains(&root), "unknown key in error: {msg}");
        }
        StudyError::Parse { message, .. } => {
            prop_assert!(!message.is_empty());
            if let Some(k) = expected_key {
                prop_assert!(
                    message.contains(k) || message.contains("missing field") || message.contains("expected"),
                    "parse error does not name `{k}`: {msg}"
                );
            }
        }
        StudyError::Io { .. }
        | StudyError::ShardDone { .. }
        | StudyError::MissingCases { .. }
        | StudyError::CaseInput(_)
        | StudyError::NoResults { .. } => {
            prop_assert!(false, "unexpected error from parsing {msg}")
        }
    }
    Ok(())
}

#[derive(Debug, Clone)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Every leaf (and every table/array) of a TOML document, as a path.
fn paths(v: &Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                prefix.push(Seg::Key(k.clone()));
                out.push(prefix.clone());
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(Seg::Index(i));
                out.push(prefix.clone());
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Seg]) -> &'a mut Value {
    path.iter().fold(v, |v, s| match s {
        Seg::Key(k) => &mut v[k.as_str()],
        Seg::Index(i) => &mut v[*i],
    })
}

fn last_key(path: &[Seg]) -> &str {
    path.iter()
        .rev()
        .find_map(|s| match s {
            Seg::Key(k) => Some(k.as_str()),
            Seg::Index(_) => None,
        })
        .unwrap_or("")
}

fn hostile_float() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            -1.0,
            1e-320,
            1e308,
            -1e308,
            0.5,
            1.0,
            2.0
        ]),
        any::<f64>(),
        -1e7..1e7f64,
    ]
}

fn hostile_count() -> impl Strategy<Value = i64> {
    prop_oneof![
        prop::sample::select(vec![
            i64::MIN,
            -1,
            0,
            1,
            2,
            64,
            65,
            1000,
            1_000_001,
            1 << 40,
            i64::MAX
        ]),
        any::<i64>(),
        -10..300i64,
    ]
}

fn hostile_string() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "",
            "..",
            "../x",
            "a/b",
            "/etc/passwd",
            ".hidden",
            "C:\\x",
            "column",
            "igimp",
            "fem-linear",
            "stress_error",
            "profile",
            "x.md",
            "UPPER",
            "a b",
            "\u{0}",
            "é"
        ])
        .prop_map(String::from),
        prop::collection::vec(any::<char>(), 0..12).prop_map(|c| c.into_iter().collect()),
    ]
}

fn hostile_value() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        hostile_count().prop_map(Value::Integer),
        hostile_float().prop_map(Value::Float),
        hostile_string().prop_map(Value::String),
        any::<bool>().prop_map(Value::Boolean),
    ];
    leaf.prop_recursive(2, 8, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::btree_map("[a-z_]{1,8}", inner, 0..3)
                .prop_map(|m| Value::Table(m.into_iter().collect())),
        ]
    })
}

#[derive(Debug, Clone)]
enum Mutation {
    Replace(Value),
    Remove,
    AddUnknownKey(String, Value),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => hostile_value().prop_map(Mutation::Replace),
        1 => Just(Mutation::Remove),
        1 => ("[a-z_]{1,12}", hostile_value()).prop_map(|(k, v)| Mutation::AddUnknownKey(k, v)),
    ]
}

fn mutate_and_check(base: &str, pick: prop::sample::Index, m: Mutation) -> Result<(), TestCaseError> {
    let mut doc: Value = toml::from_str(base).unwrap();
    let mut all = vec![];
    paths(&doc, &mut vec![], &mut all);
    let path = pick.get(&all).clone();
    let mut expected = Some(last_key(&path).to_string());
    match m {
        Mutation::Replace(v) => *at(&mut doc, &path) = v,
        Mutation::Remove => {
            let (parent, last) = path.split_at(path.len() - 1);
            match (at(&mut doc, parent), &last[0]) {
                (Value::Table(t), Seg::Key(k)) => {
                    t.remove(k);
                }
                (Value::Array(a), Seg::Index(i)) => {
                    a.remove(*i);
                    expected = None;
                }
                _ => unreachable!(),
            }
        }
        Mutation::AddUnknownKey(k, v) => {
            // Into the table at `path`, or the root if it is not a table.
            let target = match at(&mut doc, &path) {
                Value::Table(_) => path.clone(),
                _ => vec![],
            };
            if let Value::Table(t) = at(&mut doc, &target) {
                if !t.contains_key(&k) && !FIELDS.contains(&k.as_str()) {
                    t.insert(k.clone(), v);
                    expected = Some(k);
                }
            }
        }
    }
    let text = toml::to_string(&doc).map_err(|e| TestCaseError::reject(e.to_string()))?;
    match parse(&text)? {
        Ok(spec) => check_accepted(&spec),
        Err(e) => check_error(&e, expected.as_deref()),
    }
}

proptest! {
    #![proptest_config(config(500))]

    /// A study file with one value replaced by a hostile one (wrong type, negative, zero, NaN,
    /// ±inf, huge, path-like string, nested table), one key removed, or an unknown key added:
    /// a clear error naming the field, or a study whose every case is a valid column.
    #[test]
    fn mutated_column_study_is_rejected_naming_the_field_or_valid(
        pick in any::<prop::sample::Index>(), m in mutation(), plastic in any::<bool>()
    ) {
        let base = study_text(if plastic { "column-plastic" } else { "column" });
        mutate_and_check(&base, pick, m)?;
    }
}

fn fragment() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "schema = 1\n",
            "name = \"",
            "[column]\n",
            "[[sweeps]]\n",
            "[sweeps.quick]\n",
            "elements = [",
            "]",
            "=",
            "\"",
            "'''",
            "{",
            "}",
            ",",
            "nan",
            "-inf",
            "1e400",
            "0x7f",
            "\n",
            "#",
            "\\u0000",
            "points_per_cell = ",
            "9223372036854775808",
            "-",
            ".",
            "[[",
            "]]",
            "true",
        ])
        .prop_map(String::from),
        prop::collection::vec(any::<char>(), 0..6).prop_map(|c| c.into_iter().collect()),
    ]
}

proptest! {
    #![proptest_config(config(400))]

    /// Random text built from TOML fragments and random characters, and the real study file
    /// cut at a random character: a parse or validation error, never a panic.
    #[test]
    fn random_and_truncated_study_text_never_panics(
        parts in prop::collection::vec(fragment(), 0..40),
        cut in any::<prop::sample::Index>(),
    ) {
        let text: String = parts.concat();
        if let Ok(spec) = parse(&text)? {
            check_accepted(&spec)?;
        }
        let full = study_text("column");
        let chars: Vec<char> = full.chars().collect();
        let truncated: String = chars[..cut.index(chars.len())].iter().collect();
        match parse(&truncated)? {
            Ok(spec) => check_accepted(&spec)?,
            Err(e) => check_error(&e, None)?,
        }
    }

    /// Study names that could leave the output folder (`..`, `/`, absolute, hidden) are
    /// rejected naming `name`.
    #[test]
    fn study_name_outside_the_output_folder_is_rejected(
        prefix in prop::sample::select(vec!["..", "../", "/", "a/", "./", ".", "..\\", "/tmp/", ""]),
        stem in "[a-z]{0,6}",
        suffix in prop::sample::select(vec!["", "/..", "/x", "..", "/"]),
    ) {
        let name = format!("{prefix}{stem}{suffix}");
        prop_assume!(name.contains(['.', '/', '\\']) || name.is_empty());
        let text = study_text("column").replacen("name = \"column\"", &format!("name = {}", Value::String(name.clone())), 1);
        match parse(&text)? {
            Ok(_) => prop_assert!(false, "name {name:?} accepted"),
            Err(StudyError::Invalid { key, .. }) => prop_assert_eq!(key, "name"),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }
}

fn float_or_hostile(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![3 => lo..hi, 1 => hostile_float()]
}

fn count_or_hostile(lo: usize, hi: usize) -> impl Strategy<Value = usize> {
    prop_oneof![
        4 => lo..=hi,
        1 => prop::sample::select(vec![0usize, 1 << 20, 1 << 40, usize::MAX / 2, usize::MAX]),
    ]
}

fn newton() -> impl Strategy<Value = NewtonSettings> {
    (
        float_or_hostile(1e-12, 1e-3),
        count_or_hostile(1, 40),
        any::<bool>(),
    )
        .prop_map(|(tolerance, max_iterations, line_search)| NewtonSettings {
            tolerance,
            max_iterations,
            line_search,
            ..Default::default()
        })
}

/// Run `f` in `catch_unwind`; a panic fails the property, an error must name a field.
fn no_panic<T>(
    what: &str,
    f: impl FnOnce() -> Result<T, igimp::solver::error::InputError>,
) -> Result<Option<T>, TestCaseError> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Err(_) => Err(TestCaseError::fail(format!("{what} panicked"))),
        Ok(Err(e)) => {
            prop_assert!(!e.field.is_empty() && !e.allowed.is_empty(), "{what}: {e}");
            Ok(None)
        }
        Ok(Ok(v)) => Ok(Some(v)),
    }
}

proptest! {
    #![proptest_config(config(300))]

    /// Random column parameters: `validate` names the bad field or accepts; accepted small
    /// columns are solved by every method without a panic (a failed load step is a result).
    #[test]
    fn column_spec_with_hostile_fields_never_panics(
        length in float_or_hostile(0.1, 100.0),
        young_modulus in float_or_hostile(1.0, 1e8),
        poisson_ratio in float_or_hostile(-0.2, 0.6),
        density in float_or_hostile(0.1, 1e4),
        weight in float_or_hostile(1.0, 1e7),
        elements in count_or_hostile(1, 12),
        points_per_cell in count_or_hostile(1, 4),
        load_steps in count_or_hostile(1, 3),
        newton in newton(),
        yield_stress in prop::option::of(float_or_hostile(1.0, 1e6)),
        gauss_points in prop::option::of(count_or_hostile(0, 6)),
        dimension in prop::sample::select(vec![1usize, 2, 3]),
    ) {
        let spec = ColumnSpec {
            length, material: material(young_modulus, poisson_ratio, yield_stress), density, weight,
            elements, points_per_cell, load_steps, newton, gauss_points, ghost: Default::default(),
            dimension,
            f_bar: false,
        };
        let ok = no_panic("ColumnSpec::validate", || spec.validate())?.is_some();
        let small = elements * points_per_cell <= 64 && load_steps <= 3 && newton.max_iterations <= 40;
        if ok && small {
            for m in [Method::MPM, Method::IGIMP, Method::FEM_LINEAR, Method::FEM_QUADRATIC] {
                no_panic(&format!("solve_column {m:?} {spec:?}"), || solve_column(&spec, m))?;
            }
        }
    }

    /// Random compaction parameters: validated and, when small, the solver is built and one
    /// load step taken, without a panic.
    #[test]
    fn compaction_spec_with_hostile_fields_never_panics(
        half_width in float_or_hostile(0.5, 4.0),
        height in float_or_hostile(0.5, 4.0),
        gx in float_or_hostile(1.0, 6.0),
        gy in float_or_hostile(1.0, 6.0),
        element_size in prop_oneof![3 => prop::sample::select(vec![0.5, 1.0, 2.0]), 1 => hostile_float()],
        points_per_cell in count_or_hostile(1, 3),
        young_modulus in float_or_hostile(1.0, 1e6),
        poisson_ratio in float_or_hostile(-0.2, 0.6),
        weight in float_or_hostile(1.0, 1e6),
        yield_stress in prop::option::of(float_or_hostile(1.0, 1e5)),
        load_steps in count_or_hostile(1, 3),
        newton in newton(),
        weak_node_tolerance in float_or_hostile(0.0, 0.1),
    ) {
        let spec = CompactionSpec {
            half_width, height, grid_extent: [gx.round(), gy.round()], element_size,
            points_per_cell, material: material(young_modulus, poisson_ratio, yield_stress), weight,
            load_steps, newton, weak_node_tolerance, ..CompactionSpec::default()
        };
        let solver = no_panic("CompactionSpec::mpm_solver", || spec.mpm_solver())?;
        if let Some(mut s) = solver {
            use igimp::solver::load_stepping::LoadStepping;
            if s.points.len() <= 200 && s.grid.num_nodes() <= 400 && newton.max_iterations <= 40 {
                let _ = catch_unwind(AssertUnwindSafe(|| s.step()))
                    .map_err(|_| TestCaseError::fail(format!("compaction step panicked: {spec:?}")))?;
            }
        }
    }

    /// Random cantilever parameters: validated and the solver built without a panic.
    #[test]
    fn cantilever_spec_with_hostile_fields_never_panics(
        length in float_or_hostile(1.0, 6.0),
        depth in float_or_hostile(0.5, 2.0),
        young_modulus in float_or_hostile(1.0, 1e8),
        poisson_ratio in float_or_hostile(-0.2, 0.6),
        load in hostile_float(),
        load_steps in count_or_hostile(1, 3),
        element_size in prop_oneof![3 => prop::sample::select(vec![0.25, 0.5, 1.0]), 1 => hostile_float()],
        points_per_cell in count_or_hostile(1, 4),
        grid_below in float_or_hostile(0.5, 4.0),
        grid_margin in float_or_hostile(0.5, 2.0),
        newton in newton(),
        weak_node_tolerance in float_or_hostile(0.0, 0.1),
    ) {
        let spec = CantileverSpec {
            length: length.round(), depth: depth.round(),
            material: Material::linear_elastic(young_modulus, poisson_ratio), load,
            load_steps, element_size, points_per_cell, grid_below: grid_below.round(),
            grid_margin: grid_margin.round(), newton, weak_node_tolerance,
            ..CantileverSpec::default()
        };
        no_panic("CantileverSpec::mpm_solver", || spec.mpm_solver().map(|_| ()))?;
    }
}

/// Counts far beyond the limits are rejected by validation, before anything is allocated
/// (the solver constructors would otherwise try to allocate them).
#[test]
fn huge_counts_are_rejected_before_allocating() {
    let huge = [usize::MAX, usize::MAX / 2, 1 << 40];
    for n in huge {
        let c = ColumnSpec {
            elements: n,
            ..ColumnSpec::default()
        };
        assert_eq!(c.validate().unwrap_err().field, "elements");
        let c = ColumnSpec {
            load_steps: n,
            ..ColumnSpec::default()
        };
        assert_eq!(c.validate().unwrap_err().field, "load_steps");
        let newton = NewtonSettings {
            max_iterations: n,
            ..NewtonSettings::default()
        };
        assert_eq!(newton.validate().unwrap_err().field, "newton.max_iterations");
        let c = CompactionSpec {
            points_per_cell: n,
            ..CompactionSpec::default()
        };
        assert_eq!(c.validate().unwrap_err().field, "points_per_cell");
        let c = CantileverSpec {
            load_steps: n,
            ..CantileverSpec::default()
        };
        assert_eq!(c.validate().unwrap_err().field, "load_steps");
    }
    // A grid of 10^5 × 10^5 elements around a small block.
    let c = CompactionSpec {
        grid_extent: [1e5, 1e5],
        ..CompactionSpec::default()
    };
    let e = c.mpm_solver().err().expect("rejected");
    assert!(e.field.starts_with("grid"), "{e}");
    // A study whose sweeps multiply out to millions of cases.
    let weights: Vec<String> = (1..=2000).map(|w| format!("{w}.0")).collect();
    let elements: Vec<String> = (1..=2000).map(|n| n.to_string()).collect();
    let text = study_text("column")
        .replacen(
            "weights = [40000.0]",
            &format!("weights = [{}]", weights.join(", ")),
            1,
        )
        .replacen(
            "elements = [50]",
            &format!("elements = [{}]", elements.join(", ")),
            1,
        );
    let e = ColumnStudy::parse(&text, "hostile.toml").unwrap_err().to_string();
    assert!(e.contains("sweeps[0]"), "{e}");
}

fn parse_path(p: &str) -> Vec<Seg> {
    let mut out = vec![];
    for part in p.split('.') {
        let mut it = part.split('[');
        out.push(Seg::Key(it.next().unwrap().to_string()));
        for idx in it {
            out.push(Seg::Index(idx.trim_end_matches(']').parse().unwrap()));
        }
    }
    out
}

/// The table of the closing note: one hostile edit per row and what the parser said
/// (`cargo test --release --test hostile -- --nocapture hostile_inputs_table`). Each error
/// must name the edited key.
#[test]
fn hostile_inputs_table() {
    let nan = Value::Float(f64::NAN);
    let s = |x: &str| Value::String(x.into());
    let rows: Vec<(&str, &str, Option<Value>)> = vec![
        (
            "negative element count",
            "sweeps[1].elements[0]",
            Some(Value::Integer(-4)),
        ),
        (
            "zero element count",
            "sweeps[1].elements[0]",
            Some(Value::Integer(0)),
        ),
        (
            "huge element count",
            "sweeps[1].elements[0]",
            Some(Value::Integer(i64::MAX)),
        ),
        (
            "element count as float",
            "sweeps[1].elements[0]",
            Some(Value::Float(4.5)),
        ),
        ("element count as string", "sweeps[1].elements[0]", Some(s("4"))),
        (
            "zero points per cell",
            "sweeps[1].points_per_cell[0]",
            Some(Value::Integer(0)),
        ),
        (
            "65 points per cell",
            "sweeps[1].points_per_cell[0]",
            Some(Value::Integer(65)),
        ),
        (
            "1e6 elements × 4 points per cell",
            "sweeps[1].elements[0]",
            Some(Value::Integer(1_000_000)),
        ),
        ("NaN weight", "sweeps[0].weights[0]", Some(nan.clone())),
        (
            "-inf weight",
            "sweeps[0].weights[0]",
            Some(Value::Float(f64::NEG_INFINITY)),
        ),
        ("weight 1e308", "sweeps[0].weights[0]", Some(Value::Float(1e308))),
        ("NaN Young's modulus", "material.young_modulus", Some(nan.clone())),
        ("zero length", "column.length", Some(Value::Float(0.0))),
        ("negative density", "column.density", Some(Value::Float(-80.0))),
        (
            "Poisson's ratio 0.5",
            "material.poisson_ratio",
            Some(Value::Float(0.5)),
        ),
        (
            "yield stress of an elastic material",
            "material.yield_stress",
            Some(Value::Float(f64::INFINITY)),
        ),
        ("unknown model", "material.model", Some(s("von-mieses"))),
        ("missing material parameter", "material.poisson_ratio", None),
        ("missing material", "material", None),
        ("zero load steps", "load_steps", Some(Value::Integer(0))),
        ("huge load steps", "load_steps", Some(Value::Integer(1 << 40))),
        ("Newton tolerance 1", "newton.tolerance", Some(Value::Float(1.0))),
        (
            "max_iterations -1",
            "newton.max_iterations",
            Some(Value::Integer(-1)),
        ),
        ("unknown method", "sweeps[0].methods[0]", Some(s("sph"))),
        ("name with ..", "name", Some(s("../escape"))),
        ("name with /", "name", Some(s("a/b"))),
        ("absolute name", "name", Some(s("/tmp/x"))),
        ("report file with /", "report_file", Some(s("../x.md"))),
        ("figure id with /", "figures[0].id", Some(s("../../fig"))),
        ("unknown problem", "problem", Some(s("beam"))),
        ("schema 2", "schema", Some(Value::Integer(2))),
        (
            "table instead of number",
            "column.length",
            Some(Value::Table(Default::default())),
        ),
        ("missing key", "column.density", None),
        ("missing section", "newton", None),
        ("expectation on unknown sweep", "expect[0].sweep", Some(s("nope"))),
        ("fit_points 1", "sweeps[1].fit_points", Some(Value::Integer(1))),
    ];
    let base: Value = toml::from_str(&study_text("column")).unwrap();
    println!("| input | key | result |\n|---|---|---|");
    let print = |what: &str, key: &str, e: &str| {
        println!(
            "| {what} | `{key}` | {} |",
            e.replace('\n', " ").replace('|', "\\|")
        );
    };
    for (what, key, value) in rows {
        let mut doc = base.clone();
        let path = parse_path(key);
        let (parent, last) = path.split_at(path.len() - 1);
        match (value, at(&mut doc, parent), &last[0]) {
            (Some(v), Value::Table(t), Seg::Key(k)) => {
                t.insert(k.clone(), v);
            }
            (Some(v), Value::Array(a), Seg::Index(i)) => a[*i] = v,
            (None, Value::Table(t), Seg::Key(k)) => {
                t.remove(k);
            }
            _ => unreachable!("{key}"),
        }
        let text = toml::to_string(&doc).unwrap();
        let e = ColumnStudy::parse(&text, "hostile.toml")
            .expect_err(what)
            .to_string();
        let leaf = last_key(&path);
        assert!(e.contains(leaf), "{what}: error does not name `{leaf}`: {e}");
        print(what, key, &e);
    }
    let unknown = study_text("column").replacen("[newton]", "[newton]\ntolerence = 1e-9", 1);
    let e = ColumnStudy::parse(&unknown, "hostile.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("tolerence"), "{e}");
    print("misspelt key", "newton.tolerence", &e);
}
