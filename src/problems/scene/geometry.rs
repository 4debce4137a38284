//! The geometry of a scene's bodies: boxes (2D and 3D) and convex polygons of 3 or 4 vertices
//! (2D): their bounding boxes, point tests, overlap (separating axes), the part of a lattice
//! cell inside a polygon (Sutherland–Hodgman clipping, for points with volumes cut to the
//! body) and the bilinear map of a quadrilateral (its mapped FEM mesh).

use crate::solver::error::{shortest, InputError};

/// The axis names of a scene, in order.
pub const AXES: [&str; 3] = ["x", "y", "z"];

fn err(key: impl Into<String>, value: impl ToString, allowed: impl Into<String>) -> InputError {
    InputError::new(key, value, allowed)
}

/// Does the convex polygon `p` hold `x` (within `tol`, relative to its edges' lengths)?
pub fn polygon_contains(p: &[[f64; 2]], x: &[f64], tol: f64) -> bool {
    let s = orientation(p);
    (0..p.len()).all(|i| s * cross(p[i], p[(i + 1) % p.len()], [x[0], x[1]]) >= -tol * edge(p, i))
}

fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn edge(p: &[[f64; 2]], i: usize) -> f64 {
    let (a, b) = (p[i], p[(i + 1) % p.len()]);
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt()
}

/// +1 for counter-clockwise vertices, −1 for clockwise (by the signed area).
fn orientation(p: &[[f64; 2]]) -> f64 {
    signed_area(p).signum()
}

fn signed_area(p: &[[f64; 2]]) -> f64 {
    0.5 * (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// A polygon body at `key`: 3 or 4 finite vertices, strictly convex (every turn the same way
/// and none straight), in 2D.
pub fn check_polygon(key: &str, p: &[[f64; 2]], dimension: usize) -> Result<(), InputError> {
    if dimension != 2 {
        return Err(err(key, "polygon", "is a 2D shape: a 3D body is a box"));
    }
    if !(3..=4).contains(&p.len()) {
        return Err(err(
            key,
            format!("{} vertices", p.len()),
            "must have 3 or 4 vertices",
        ));
    }
    for (i, v) in p.iter().enumerate() {
        if let Some(a) = (0..2).find(|&a| !v[a].is_finite()) {
            return Err(err(format!("{key}[{i}][{a}]"), v[a], "must be finite"));
        }
    }
    let scale = (0..p.len()).map(|i| edge(p, i)).fold(0.0, f64::max);
    let s = orientation(p);
    for i in 0..p.len() {
        let turn = s * cross(p[i], p[(i + 1) % p.len()], p[(i + 2) % p.len()]);
        if turn.is_nan() || turn <= 1e-9 * scale * scale {
            return Err(err(
                format!("{key}[{}]", (i + 1) % p.len()),
                format!("{:?}", p[(i + 1) % p.len()]),
                "must make the polygon strictly convex (no reflex or straight corner, no repeated vertex)",
            ));
        }
    }
    Ok(())
}

/// Do two convex polygons overlap with positive area (separating axis theorem)?
pub fn overlap(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    for poly in [a, b] {
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let n = [q[1] - p[1], p[0] - q[0]];
            let project = |s: &[[f64; 2]]| {
                s.iter()
                    .map(|v| v[0] * n[0] + v[1] * n[1])
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x), hi.max(x))
                    })
            };
            let ((a0, a1), (b0, b1)) = (project(a), project(b));
            let tol = 1e-12 * (n[0].abs() + n[1].abs()) * (a1 - a0).abs().max(b1 - b0).max(1.0);
            if a1 <= b0 + tol || b1 <= a0 + tol {
                return false;
            }
        }
    }
    true
}

/// The part of the square `[lo, hi]` inside the convex polygon `p`: its area and centroid
/// (area 0 if none).
pub fn clip_square(p: &[[f64; 2]], lo: [f64; 2], hi: [f64; 2]) -> (f64, [f64; 2]) {
    let mut piece = vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    let s = orientation(p);
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let side = |v: [f64; 2]| s * cross(a, b, v);
        let mut next = Vec::with_capacity(piece.len() + 1);
        for k in 0..piece.len() {
            let (u, v) = (piece[k], piece[(k + 1) % piece.len()]);
            let (su, sv) = (side(u), side(v));
            if su >= 0.0 {
                next.push(u);
            }
            if (su >= 0.0) != (sv >= 0.0) {
                let t = su / (su - sv);
                next.push([u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])]);
            }
        }
        piece = next;
        if piece.len() < 3 {
            return (0.0, lo);
        }
    }
    let area = signed_area(&piece);
    if area.abs() <= 0.0 {
        return (0.0, lo);
    }
    let mut c = [0.0; 2];
    for k in 0..piece.len() {
        let (u, v) = (piece[k], piece[(k + 1) % piece.len()]);
        let w = u[0] * v[1] - v[0] * u[1];
        c[0] += (u[0] + v[0]) * w;
        c[1] += (u[1] + v[1]) * w;
    }
    (area.abs(), [c[0] / (6.0 * area), c[1] / (6.0 * area)])
}

/// The quadrilateral `q` (4 vertices, made counter-clockwise) and the point of its bilinear
/// map at (ξ, η) ∈ [0, 1]²: ξ runs from vertex 0 to vertex 1, η from edge 0–1 to edge 3–2.
pub fn bilinear(q: &[[f64; 2]], xi: f64, eta: f64) -> [f64; 2] {
    let q = counter_clockwise(q);
    let w = [
        (1.0 - xi) * (1.0 - eta),
        xi * (1.0 - eta),
        xi * eta,
        (1.0 - xi) * eta,
    ];
    let mut x = [0.0; 2];
    for (k, v) in q.iter().enumerate() {
        x[0] += w[k] * v[0];
        x[1] += w[k] * v[1];
    }
    x
}

/// The vertices in counter-clockwise order (reversed if clockwise, the first kept first).
pub fn counter_clockwise(p: &[[f64; 2]]) -> Vec<[f64; 2]> {
    if orientation(p) > 0.0 {
        p.to_vec()
    } else {
        std::iter::once(p[0])
            .chain(p[1..].iter().rev().copied())
            .collect()
    }
}

/// The elements of the mapped mesh of `q` at element size `h`: along ξ as many as its longer
/// ξ edge needs, along η as many as its longer η edge needs (at least one each).
pub fn mapped_cells(q: &[[f64; 2]], h: f64) -> Result<[usize; 2], InputError> {
    let q = counter_clockwise(q);
    let len = |a: [f64; 2], b: [f64; 2]| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let along = [
        len(q[0], q[1]).max(len(q[3], q[2])),
        len(q[1], q[2]).max(len(q[0], q[3])),
    ];
    let mut n = [0; 2];
    for a in 0..2 {
        let c = (along[a] / h - 1e-9).ceil().max(1.0);
        if !(c.is_finite() && c <= 100_000.0) {
            return Err(err(
                "element_sizes",
                shortest(h),
                "must give a polygon's mapped mesh at most 100000 elements per side",
            ));
        }
        n[a] = c as usize;
    }
    Ok(n)
}
