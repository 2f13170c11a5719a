//! 3×3 Jacobian arithmetic for the carried orientation: cofactors, products, the step of a
//! field map.

use crate::geometry::{add, cross, dot, normalize, scale};
use crate::mesh::Point3;

use super::Jacobian;

/// `cof(J)·n` and `det J`: with the columns a, b, c of J, cof(J) = [b×c, c×a, a×b].
pub fn cofactor_times(j: &Jacobian, n: Point3) -> (Point3, f64) {
    let col = |k: usize| [j[0][k], j[1][k], j[2][k]];
    let (a, b, c) = (col(0), col(1), col(2));
    let (bc, ca, ab) = (cross(b, c), cross(c, a), cross(a, b));
    let v = add(add(scale(bc, n[0]), scale(ca, n[1])), scale(ab, n[2]));
    (v, dot(a, bc))
}

/// The unit covector J⁻ᵀ·n (the normal n pushed forward), zero where it vanishes.
pub fn push_normal(j: &Jacobian, n: Point3) -> Point3 {
    let (c, det) = cofactor_times(j, n);
    normalize(if det > 0.0 { c } else { scale(c, -1.0) })
}

/// cof(J) as a matrix: cof(J)·n = [b×c, c×a, a×b]·n for the columns a, b, c of J, as
/// [`cofactor_times`] computes it.
pub(super) fn cofactor(j: &Jacobian) -> Jacobian {
    let col = |k: usize| [j[0][k], j[1][k], j[2][k]];
    let (a, b, c) = (col(0), col(1), col(2));
    let (bc, ca, ab) = (cross(b, c), cross(c, a), cross(a, b));
    std::array::from_fn(|r| [bc[r], ca[r], ab[r]])
}

pub(super) fn mat_vec(m: &Jacobian, n: Point3) -> Point3 {
    [dot(m[0], n), dot(m[1], n), dot(m[2], n)]
}

/// `a · b` for 3×3 matrices.
pub fn mat_mul(a: &Jacobian, b: &Jacobian) -> Jacobian {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

pub(in crate::fit) fn det(j: &Jacobian) -> f64 {
    cofactor_times(j, [0.0; 3]).1
}

pub(super) fn frobenius(j: &Jacobian) -> f64 {
    j.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

/// I + step · g: the Jacobian of x ↦ x + step · s(x) from the field's gradient g.
pub(in crate::fit) fn field_step(g: &Jacobian, step: f64) -> Jacobian {
    std::array::from_fn(|r| std::array::from_fn(|c| step * g[r][c] + if r == c { 1.0 } else { 0.0 }))
}
