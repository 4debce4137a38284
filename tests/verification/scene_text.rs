//! A scene from the TOML of its sections (a study file's `grid`, `bodies`, `supports`, `loads`
//! and `measures`) with one material named `m`, validated: shared by the verification tests
//! and the benches (`#[path]`), which build small scenes without a whole study file.

use igimp::material::constitutive::Material;
use igimp::problems::scene::{self, Scene};

/// The `dimension`-D scene of `toml_text`'s sections in `material`.
pub fn scene(dimension: usize, toml_text: &str, material: Material) -> Scene {
    #[derive(serde::Deserialize)]
    struct Parts {
        grid: scene::GridSection,
        bodies: Vec<scene::Body>,
        #[serde(default)]
        supports: Vec<scene::Support>,
        loads: Vec<scene::Load>,
        #[serde(default)]
        measures: Vec<scene::Measure>,
    }
    let p: Parts = toml::from_str(toml_text).unwrap();
    let s = Scene {
        dimension,
        grid: p.grid,
        materials: [("m".to_string(), material)].into_iter().collect(),
        bodies: p.bodies,
        supports: p.supports,
        loads: p.loads,
        measures: p.measures,
        strength_reduction: None,
    };
    s.validate().unwrap();
    s
}
