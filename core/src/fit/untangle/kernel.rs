//! The best-centred point of a vertex's *kernel*: where the vertex can sit so that every face of
//! its star is turned the right way. Seen along the vertex's reference normal n, face (v, x, y)
//! is turned right exactly when v lies left of the directed ring edge x → y, so the kernel is the
//! intersection of one half-plane per star face (a convex polygon, empty when the ring is too
//! twisted). Its Chebyshev centre (the point farthest inside all half-planes) is found by a small
//! linear programme solved by enumeration: the optimum sits where three constraints are tight,
//! and a ring has a dozen faces at most in practice. The ring mean is in the kernel of a convex
//! ring only; this point is in it whenever it is not empty (e.g. the quadrilateral ring of a
//! vertex split onto the free edge of a face folded at a sharp turn of a curve).

use crate::geometry::{add, cross, dot, normalize, scale, sub};
use crate::mesh::Point3;

/// Rings larger than this are not searched (cost grows as faces³).
const MAX_RING: usize = 24;

/// The kernel's Chebyshev centre of `v`'s star `faces` (each given as its two other corners
/// (x, y) in the face's order after `v`) seen along unit normal `n`, lifted to the mean height of
/// the ring over the plane; None when the kernel is empty or the ring too large.
pub(crate) fn kernel_centre(ring_edges: &[(Point3, Point3)], n: Point3) -> Option<Point3> {
    if ring_edges.is_empty() || ring_edges.len() > MAX_RING {
        return None;
    }
    let frame = RingFrame::new(ring_edges, n)?;
    let flat = |p: Point3| frame.flat(p);
    // Half-plane of edge x → y: cross2(y − x, p − x) ≥ r·|y − x|, i.e. a·p − r ≥ b with a the
    // unit left normal of the edge.
    let mut cons: Vec<([f64; 2], f64)> = Vec::with_capacity(ring_edges.len());
    for &(x, y) in ring_edges {
        let (x, y) = (flat(x), flat(y));
        let e = [y[0] - x[0], y[1] - x[1]];
        let l = (e[0] * e[0] + e[1] * e[1]).sqrt();
        if l == 0.0 {
            return None;
        }
        let a = [-e[1] / l, e[0] / l];
        cons.push((a, a[0] * x[0] + a[1] * x[1]));
    }
    let scale_len = ring_edges.iter().map(|&(x, y)| crate::geometry::dist(x, y)).fold(0.0, f64::max);
    let mut best: Option<([f64; 2], f64)> = None;
    let k = cons.len();
    for i in 0..k {
        for j in i + 1..k {
            for l in j + 1..k {
                // a·p − r = b for the three: solve the 3×3 system by Cramer's rule.
                let m = [cons[i], cons[j], cons[l]];
                let det3 = |c: [[f64; 3]; 3]| {
                    c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
                        - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
                        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0])
                };
                let a: [[f64; 3]; 3] = std::array::from_fn(|r| [m[r].0[0], m[r].0[1], -1.0]);
                let d = det3(a);
                if d.abs() < 1e-14 {
                    continue;
                }
                let rhs = [m[0].1, m[1].1, m[2].1];
                let col = |c: usize| {
                    let mut b = a;
                    for r in 0..3 {
                        b[r][c] = rhs[r];
                    }
                    det3(b) / d
                };
                let (p, r) = ([col(0), col(1)], col(2));
                if r <= 0.0 || best.is_some_and(|b| r <= b.1) {
                    continue;
                }
                let tol = 1e-12 * scale_len.max(f64::MIN_POSITIVE);
                if cons.iter().all(|&(a, b)| a[0] * p[0] + a[1] * p[1] - r >= b - tol) {
                    best = Some((p, r));
                }
            }
        }
    }
    let (p, _) = best?;
    Some(frame.lift(p))
}

/// A frame (u, w) of the plane ⊥ n through the mean of a ring's edge ends: ring positions seen
/// along n as plane coordinates, and plane points lifted back at the ring's mean height.
pub(crate) struct RingFrame {
    o: Point3,
    u: Point3,
    w: Point3,
}

impl RingFrame {
    /// None for a zero `n` or an empty ring.
    pub(crate) fn new(ring_edges: &[(Point3, Point3)], n: Point3) -> Option<Self> {
        if ring_edges.is_empty() {
            return None;
        }
        let o = scale(
            ring_edges.iter().fold([0.0; 3], |s, e| add(add(s, e.0), e.1)),
            0.5 / ring_edges.len() as f64,
        );
        Self::at(o, n)
    }

    /// The frame through `o` across `n` ((u, w, n) right-handed, so a face turned along n runs
    /// counter-clockwise in plane coordinates); None for a zero `n`.
    pub(crate) fn at(o: Point3, n: Point3) -> Option<Self> {
        let n = normalize(n);
        if n == [0.0; 3] {
            return None;
        }
        let t = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
        let u = normalize(cross(n, t));
        Some(Self { o, u, w: cross(n, u) })
    }

    pub(crate) fn flat(&self, p: Point3) -> [f64; 2] {
        let d = sub(p, self.o);
        [dot(d, self.u), dot(d, self.w)]
    }

    /// The point at plane coordinates `p`, at the ring's mean height along n.
    pub(crate) fn lift(&self, p: [f64; 2]) -> Point3 {
        add(self.o, add(scale(self.u, p[0]), scale(self.w, p[1])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ring edges of a fan around a vertex, given the ring polygon in order.
    fn edges(ring: &[Point3]) -> Vec<(Point3, Point3)> {
        (0..ring.len()).map(|i| (ring[i], ring[(i + 1) % ring.len()])).collect()
    }

    #[test]
    fn a_square_ring_has_its_centre_and_a_reflex_quad_a_point_that_sees_all_sides() {
        let sq = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]];
        let c = kernel_centre(&edges(&sq), [0.0, 0.0, 1.0]).unwrap();
        assert!((c[0] - 1.0).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12 && c[2].abs() < 1e-12, "{c:?}");
        // A dart (arrowhead): reflex corner at (1, 0.5); its mean (1, 0.625) is outside the kernel,
        // the returned point must see every edge (all four fan triangles counter-clockwise).
        let dart = [[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.0, 0.0], [1.0, 2.0, 0.0]];
        let c = kernel_centre(&edges(&dart), [0.0, 0.0, 1.0]).unwrap();
        for (x, y) in edges(&dart) {
            let z = crate::geometry::triangle_cross(c, x, y)[2];
            assert!(z > 0.0, "{c:?} does not see {x:?}→{y:?}");
        }
        // A bow tie ring (self-crossing) has an empty kernel.
        let bow = [[0.0, 0.0, 0.0], [2.0, 2.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        assert!(kernel_centre(&edges(&bow), [0.0, 0.0, 1.0]).is_none());
    }
}
