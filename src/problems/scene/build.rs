//! What a case builds from a scene's bodies: the material points (a box filled as
//! [`MaterialPoints::fill_box`] does; a polygon's lattice cells cut to it) and the FEM mesh
//! (a box as a structured mesh, a quadrilateral as a mapped one), and the checks of a
//! resolution before anything is built.

use super::geometry::{bilinear, clip_square, mapped_cells};
use super::spec::{axis_index, region, Bounds, LoadKind, Region, Scene, SceneSettings, Shape};
use crate::basis::method::Method;
use crate::fem::{ElementFamily, ElementMesh, HexElement, QuadElement};
use crate::mesh::grid::Grid;
use crate::mpm::particles::MaterialPoints;
use crate::solver::error::{require_positive, InputError};
use crate::solver::ramp::Ramp;
use nalgebra::SVector;

fn fixed_array<const D: usize>(v: &[f64]) -> [f64; D] {
    std::array::from_fn(|a| v[a])
}

/// The points of every body on `grid`, `ppc` per cell and axis.
pub(super) fn fill_points<const D: usize>(
    scene: &Scene,
    grid: &Grid<D>,
    ppc: usize,
) -> Result<MaterialPoints<D>, InputError> {
    let mut points: Option<MaterialPoints<D>> = None;
    for b in &scene.bodies {
        let filled = match b.shape() {
            Shape::Box(bx) => MaterialPoints::fill_box(
                grid,
                fixed_array::<D>(&bx.min),
                fixed_array::<D>(&bx.max),
                [ppc; D],
                b.density,
            )?,
            Shape::Polygon(p) => fill_polygon(grid, p, ppc, b.density)?,
        };
        match &mut points {
            None => points = Some(filled),
            Some(all) => {
                for p in 0..filled.len() {
                    all.push_with_volume(
                        filled.position[p],
                        filled.half_length[p],
                        filled.volume0[p],
                        b.density,
                    );
                }
            }
        }
    }
    points.ok_or_else(|| InputError::new("bodies", "[]", "must list at least one body"))
}

/// A convex polygon's points: one per lattice cell (spacing h / `ppc` from the grid's origin)
/// it cuts, at the centroid of the part inside, with that part's area as its volume and a
/// square domain of the same area, shrunk where it would leave the lattice cell.
fn fill_polygon<const D: usize>(
    grid: &Grid<D>,
    p: &[[f64; 2]],
    ppc: usize,
    density: f64,
) -> Result<MaterialPoints<D>, InputError> {
    require_positive("density", density)?;
    let origin = grid.origin();
    let s = grid.spacing()[0] / ppc as f64;
    let lo = (0..2)
        .map(|a| p.iter().map(|v| v[a]).fold(f64::INFINITY, f64::min))
        .collect::<Vec<_>>();
    let hi = (0..2)
        .map(|a| p.iter().map(|v| v[a]).fold(f64::NEG_INFINITY, f64::max))
        .collect::<Vec<_>>();
    let first = |a: usize| ((lo[a] - origin[a]) / s + 1e-9).floor() as i64;
    let last = |a: usize| ((hi[a] - origin[a]) / s - 1e-9).ceil() as i64;
    let mut points = MaterialPoints::<D>::default();
    let full = s * s;
    for j in first(1)..last(1) {
        for i in first(0)..last(0) {
            let c0 = [origin[0] + i as f64 * s, origin[1] + j as f64 * s];
            let c1 = [c0[0] + s, c0[1] + s];
            let (area, c) = clip_square(p, c0, c1);
            if area <= 1e-12 * full {
                continue;
            }
            let side = 0.5 * s * (area / full).sqrt();
            let mut half = SVector::<f64, D>::zeros();
            let mut x = SVector::<f64, D>::zeros();
            for a in 0..2 {
                x[a] = c[a];
                half[a] = side.min(c[a] - c0[a]).min(c1[a] - c[a]);
            }
            points.push_with_volume(x, half, area, density);
        }
    }
    Ok(points)
}

/// The FEM mesh of the scene's one body at element size `h` with `element`: a box as a
/// structured mesh of cubes of h, a quadrilateral as a mapped mesh ([`mapped_cells`]).
pub(super) fn body_mesh<const D: usize, E: ElementFamily<D>>(
    scene: &Scene,
    h: f64,
    element: E,
) -> Result<ElementMesh<D, E>, InputError> {
    let [body] = &scene.bodies[..] else {
        return Err(InputError::new(
            "bodies",
            format!("{} bodies", scene.bodies.len()),
            "must be one body for the FEM methods (meshes of several bodies are not joined)",
        ));
    };
    match body.shape() {
        Shape::Box(bx) => {
            let mut n = [0; D];
            for a in 0..D {
                n[a] = cells(&format!("bodies[0].box.max[{a}]"), bx.max[a] - bx.min[a], h)
                    .map_err(|e| side(e, a))?;
            }
            let lo = SVector::<f64, D>::from_iterator(bx.min.iter().copied());
            let hi = SVector::<f64, D>::from_iterator(bx.max.iter().copied());
            ElementMesh::structured(lo, hi - lo, n, element)
        }
        Shape::Polygon(p) if p.len() == 4 && D == 2 => {
            let m = mapped_cells(p, h)?;
            let mut mesh = ElementMesh::structured(
                SVector::zeros(),
                SVector::repeat(1.0),
                std::array::from_fn(|a| m[a.min(1)]),
                element,
            )?;
            for x in mesh.nodes.iter_mut() {
                let y = bilinear(p, x[0], x[1]);
                x[0] = y[0];
                x[1] = y[1];
            }
            Ok(mesh)
        }
        Shape::Polygon(_) => Err(InputError::new(
            "bodies[0].polygon",
            "3 vertices",
            "must have 4 vertices for the FEM methods (a triangle has no mapped quadrilateral mesh here)",
        )),
    }
}

/// The positions of `mesh`'s nodes, for [`region_dofs`].
fn visit<const D: usize, E>(mesh: &ElementMesh<D, E>, f: &mut dyn FnMut(usize, &[f64])) {
    for (k, x) in mesh.nodes.iter().enumerate() {
        f(k, x.as_slice());
    }
}

/// What a case needs of its resolution, checked without solving it: h divides the grid's
/// extent; box bodies lie on the point lattice of h / points per cell (material points) or
/// are whole multiples of h (FEM); the FEM mesh can be built; every support and displacement
/// load holds a node (of the grid, or of the mesh). Errors name the key.
pub fn check_resolution(scene: &Scene, s: &SceneSettings, method: Method) -> Result<(), InputError> {
    let h = s.element_size;
    let d = scene.dimension;
    let mut n = vec![0usize; d];
    for a in 0..d {
        n[a] = cells(&format!("grid.extent[{a}]"), scene.grid.extent[a], h)?;
    }
    if method.uses_material_points() {
        let step = h / s.points_per_cell as f64;
        for (i, b) in scene.bodies.iter().enumerate() {
            let Shape::Box(bx) = b.shape() else { continue };
            for a in 0..d {
                cells(
                    &format!("bodies[{i}].box.min[{a}]"),
                    bx.min[a] - scene.grid.origin[a] + step,
                    step,
                )
                .and_then(|_| cells(&format!("bodies[{i}].box.max[{a}]"), bx.max[a] - bx.min[a], step))
                .map_err(|e| {
                    InputError::new(
                        e.field,
                        e.value,
                        format!(
                            "must lie on the lattice of h / points per cell = {step} from the grid's origin"
                        ),
                    )
                })?;
            }
        }
        let upper: Vec<f64> = (0..d)
            .map(|a| scene.grid.origin[a] + scene.grid.extent[a])
            .collect();
        return lattice_regions(scene, &scene.grid.origin, &upper, h, h);
    }
    let quadratic = matches!(method, Method::FEM_Q8 | Method::FEM_HEX20);
    match (d, scene.bodies.first().map(|b| b.shape())) {
        // A box's structured mesh: its nodes lie on the lattice of h (h / 2 with the
        // mid-edge nodes) over the box, checked without building it (a 3D mesh at a fine h
        // would cost a parse seconds).
        (_, Some(Shape::Box(bx))) if scene.bodies.len() == 1 => {
            for a in 0..d {
                cells(&format!("bodies[0].box.max[{a}]"), bx.max[a] - bx.min[a], h)
                    .map_err(|e| side(e, a))?;
            }
            lattice_regions(scene, &bx.min, &bx.max, if quadratic { 0.5 * h } else { h }, h)
        }
        (2, _) if method == Method::FEM_Q4 => fem_regions::<2, _>(scene, h, QuadElement::Q4),
        (2, _) if method == Method::FEM_Q8 => fem_regions::<2, _>(scene, h, QuadElement::Q8),
        (3, _) if method == Method::FEM_HEX8 => fem_regions::<3, _>(scene, h, HexElement::Hex8),
        (3, _) if method == Method::FEM_HEX20 => fem_regions::<3, _>(scene, h, HexElement::Hex20),
        _ => Ok(()),
    }
}

/// Every support and displacement load holds a node of the lattice of `spacing` over the box
/// `[lower, upper]`: a plane on a lattice coordinate within the box, a box meeting one along
/// every axis. The error is [`region_dofs`]'s.
fn lattice_regions(
    scene: &Scene,
    lower: &[f64],
    upper: &[f64],
    spacing: f64,
    h: f64,
) -> Result<(), InputError> {
    let d = scene.dimension;
    let tol = 1e-9 * h;
    // Is there a lattice coordinate along `a` in [lo, hi]?
    let meets = |a: usize, lo: f64, hi: f64| {
        let (lo, hi) = (lo.max(lower[a]), hi.min(upper[a]));
        let first = ((lo - tol - lower[a]) / spacing).ceil();
        let last = ((hi + tol - lower[a]) / spacing).floor();
        first <= last
    };
    let check = |key: String, r: Region<'_>| -> Result<(), InputError> {
        let held = match r {
            Region::Plane(a, at) => meets(a, at, at) && (0..d).all(|b| b == a || lower[b] <= upper[b]),
            Region::Box(b) => (0..d).all(|a| meets(a, b.min[a], b.max[a])),
        };
        if held {
            Ok(())
        } else {
            Err(InputError::new(
                key,
                "no node",
                format!("must hold at least one node at h = {h}"),
            ))
        }
    };
    for (i, s) in scene.supports.iter().enumerate() {
        let key = format!("supports[{i}]");
        check(key.clone(), region(&key, &s.plane, &s.bounds, d)?)?;
    }
    for (i, l) in scene
        .loads
        .iter()
        .enumerate()
        .filter(|(_, l)| l.kind == LoadKind::Displacement)
    {
        let key = format!("loads[{i}]");
        check(key.clone(), region(&key, &l.plane, &l.bounds, d)?)?;
    }
    Ok(())
}

/// The mesh of `element` builds and every region holds one of its nodes.
fn fem_regions<const D: usize, E: ElementFamily<D>>(
    scene: &Scene,
    h: f64,
    element: E,
) -> Result<(), InputError> {
    let mesh = body_mesh::<D, E>(scene, h, element)?;
    region_dofs(scene, h, &|f| visit(&mesh, f)).map(|_| ())
}

/// Cells of `length` at `h`, which must divide it.
/// A box side's error, its value the side's length (named by the key of its `max`, which
/// locates the line).
fn side(mut e: InputError, axis: usize) -> InputError {
    e.value = format!("{} (the side max − min along axis {axis})", e.value);
    e
}

pub(super) fn cells(key: &str, length: f64, h: f64) -> Result<usize, InputError> {
    let n = length / h;
    if !(n.is_finite()
        && (n - n.round()).abs() <= 1e-9 * n.max(1.0)
        && n.round() >= 1.0
        && n.round() <= 100_000.0)
    {
        return Err(InputError::new(
            key,
            length,
            format!("must be a whole multiple (1 to 100000) of the element size {h}"),
        ));
    }
    Ok(n.round() as usize)
}

/// Calls its argument with every node and its position.
pub(super) type NodeVisitor<'a> = &'a dyn Fn(&mut dyn FnMut(usize, &[f64]));

pub(super) type NamedDofs = Vec<(
    String,
    Vec<(usize, usize)>,
    Option<(Vec<(usize, usize, f64)>, Ramp)>,
)>;

pub(super) fn region_dofs(
    scene: &Scene,
    h: f64,
    positions: NodeVisitor<'_>,
) -> Result<NamedDofs, InputError> {
    let tol = 1e-9 * h;
    let d = scene.dimension;
    let nodes_in = |key: &str, r: Region<'_>| -> Result<Vec<usize>, InputError> {
        let mut found = vec![];
        positions(&mut |n, x| {
            if r.holds(x, tol) {
                found.push(n)
            }
        });
        if found.is_empty() {
            return Err(InputError::new(
                key,
                "no node",
                format!("must hold at least one node at h = {h}"),
            ));
        }
        Ok(found)
    };
    let mut out = vec![];
    for (i, s) in scene.supports.iter().enumerate() {
        let key = format!("supports[{i}]");
        let nodes = nodes_in(&key, region(&key, &s.plane, &s.bounds, d)?)?;
        let mut dofs = vec![];
        for (j, c) in s.fix.iter().enumerate() {
            let a = axis_index(&format!("{key}.fix[{j}]"), c, d)?;
            dofs.extend(nodes.iter().map(|&n| (n, a)));
        }
        out.push((s.name.clone(), dofs, None));
    }
    for (i, l) in scene.loads.iter().enumerate() {
        if l.kind != LoadKind::Displacement {
            continue;
        }
        let key = format!("loads[{i}]");
        let nodes = nodes_in(&key, region(&key, &l.plane, &l.bounds, d)?)?;
        let given = l.displacement.as_ref().map(|c| c.given()).unwrap_or_default();
        let mut dofs = vec![];
        let mut values = vec![];
        for &(a, v) in &given {
            dofs.extend(nodes.iter().map(|&n| (n, a)));
            values.extend(nodes.iter().map(|&n| (n, a, v)));
        }
        out.push((
            l.name.clone().unwrap_or_default(),
            dofs,
            Some((values, l.ramp.clone())),
        ));
    }
    Ok(out)
}

/// One traction: the loaded body's index, the face's axis, side and coordinate, the traction
/// vector and the box that picks part of the face (none: all of it).
struct FaceLoad<'a> {
    body: usize,
    axis: usize,
    side: f64,
    at: f64,
    vector: Vec<f64>,
    part: Option<&'a Bounds>,
}

impl FaceLoad<'_> {
    /// The length of `[lo, hi]` along axis `a` that the loaded part of the face covers.
    fn covered(&self, a: usize, lo: f64, hi: f64) -> f64 {
        match self.part {
            Some(b) => (hi.min(b.max[a]) - lo.max(b.min[a])).max(0.0),
            None => hi - lo,
        }
    }
}

/// The ramp every traction of `scene` follows (validation makes it one): linear if none.
pub(super) fn traction_ramp(scene: &Scene) -> Ramp {
    scene
        .loads
        .iter()
        .find(|l| l.kind == LoadKind::Traction)
        .map_or(Ramp::Linear, |l| l.ramp.clone())
}

/// Every traction of the scene.
fn tractions(scene: &Scene) -> Vec<FaceLoad<'_>> {
    scene
        .loads
        .iter()
        .filter(|l| l.kind == LoadKind::Traction)
        .filter_map(|l| {
            let b = scene
                .bodies
                .iter()
                .position(|b| Some(&b.name) == l.body.as_ref())?;
            let (axis, side) = super::spec::face_of("", l.face.as_deref()?, scene.dimension).ok()?;
            let at = scene.bodies[b].face_at(axis, side);
            Some(FaceLoad {
                body: b,
                axis,
                side,
                at,
                vector: l.vector.clone()?,
                part: l.bounds.as_ref(),
            })
        })
        .collect()
}

/// The tractions as point loads: every point of the loaded body whose domain reaches the
/// face carries the traction times its domain's share of the face's loaded part.
pub(super) fn traction_point_loads<const D: usize>(
    scene: &Scene,
    points: &MaterialPoints<D>,
    h: f64,
) -> Vec<(usize, SVector<f64, D>)> {
    let mut loads = vec![];
    for t in tractions(scene) {
        let (body, axis) = (&scene.bodies[t.body], t.axis);
        for p in 0..points.len() {
            let (x, half) = (&points.position0[p], &points.half_length0[p]);
            if !body.contains(x.as_slice(), 1e-9 * h)
                || (x[axis] + t.side * half[axis] - t.at).abs() > 1e-9 * h
            {
                continue;
            }
            let area: f64 = (0..D)
                .filter(|&a| a != axis)
                .map(|a| t.covered(a, x[a] - half[a], x[a] + half[a]))
                .product();
            if area > 0.0 {
                loads.push((
                    p,
                    SVector::<f64, D>::from_iterator(t.vector.iter().map(|v| v * area)),
                ));
            }
        }
    }
    loads
}

/// The tractions as consistent nodal forces: ∫ N_a t dA over the faces of the elements on the
/// loaded face, each face clipped to the loaded part (a 3-point Gauss rule per face axis over
/// the clipped interval: exact for the straight faces of Q4/Q8 and Hex8/Hex20 of a box).
pub(super) fn traction_nodal_forces<const D: usize, E: ElementFamily<D>>(
    scene: &Scene,
    mesh: &ElementMesh<D, E>,
    h: f64,
) -> Result<Vec<(usize, SVector<f64, D>)>, InputError> {
    let rule = crate::mesh::quadrature::GaussRule::try_new(3)?;
    let (xs, ws) = (rule.points(), rule.weights());
    let mut forces = vec![];
    for load in tractions(scene) {
        let (axis, side, at) = (load.axis, load.side, load.at);
        let t = SVector::<f64, D>::from_iterator(load.vector.iter().copied());
        for e in 0..mesh.num_elements() {
            let ids = mesh.element_nodes(e);
            let on_face: Vec<usize> = (0..ids.len())
                .filter(|&k| mesh.element.local_node(k)[axis] == side)
                .collect();
            if !on_face
                .iter()
                .all(|&k| (mesh.nodes[ids[k]][axis] - at).abs() <= 1e-9 * h)
            {
                continue;
            }
            let others: Vec<usize> = (0..D).filter(|&a| a != axis).collect();
            // Per face axis, the loaded part of the face's ξ interval [−1, 1] as (centre, half).
            let mut clip = [(0.0, 1.0); 3];
            for &a in &others {
                let span = on_face.iter().map(|&k| mesh.nodes[ids[k]][a]);
                let lo = span.clone().fold(f64::INFINITY, f64::min);
                let hi = span.fold(f64::NEG_INFINITY, f64::max);
                let covered = load.covered(a, lo, hi);
                let start = load.part.map_or(lo, |b| lo.max(b.min[a]));
                let half = covered / (hi - lo);
                clip[a] = (-1.0 + 2.0 * (start - lo) / (hi - lo) + half, half);
            }
            if others.iter().any(|&a| clip[a].1 <= 0.0) {
                continue;
            }
            let count = xs.len().pow(others.len() as u32);
            for q in 0..count {
                let mut xi = SVector::<f64, D>::zeros();
                xi[axis] = side;
                let (mut r, mut w) = (q, 1.0);
                for &a in &others {
                    xi[a] = clip[a].0 + clip[a].1 * xs[r % xs.len()];
                    w *= ws[r % xs.len()] * clip[a].1;
                    r /= xs.len();
                }
                let (_, jac) = mesh.map(e, &xi);
                let da: f64 = others.iter().map(|&a| jac[(a, a)].abs()).product();
                let (n, _) = mesh.element.shape(&xi);
                for &k in &on_face {
                    forces.push((ids[k], t * (n[k] * w * da)));
                }
            }
        }
    }
    Ok(forces)
}

/// The supports' fixed dofs (node, axis) of `named`.
pub(super) fn fixed_dofs(named: &NamedDofs) -> Vec<(usize, usize)> {
    named
        .iter()
        .filter(|n| n.2.is_none())
        .flat_map(|n| n.1.iter().copied())
        .collect()
}

/// The displacement loads of `named`: their (node, axis, value) and ramp.
pub(super) fn prescribed(named: &NamedDofs) -> impl Iterator<Item = (&[(usize, usize, f64)], &Ramp)> {
    named
        .iter()
        .filter_map(|n| n.2.as_ref().map(|(v, r)| (&v[..], r)))
}
