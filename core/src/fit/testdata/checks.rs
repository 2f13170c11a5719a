//! Checks of a fit's output against a known truth, shared by the tests and the sweeps so that each
//! one is written once: faces turned against the truth's outward normal, or against a truth
//! surface given as a mesh.

use crate::geometry::{dot, triangle_cross};
use crate::mesh::{Faces, Mesh, Point3};
use crate::spatial::Bvh;

/// A truth given as a mesh (e.g. a template carried by a known deformation), for comparing a fit's
/// output with it by closest points.
pub struct TruthSurface {
    positions: Vec<Point3>,
    tris: Vec<[u32; 3]>,
    bvh: Bvh,
}

impl TruthSurface {
    pub fn new(truth: &Mesh) -> TruthSurface {
        let tris = truth.faces.triangles();
        let bvh = Bvh::new(&truth.positions, &Faces::from_triangles(&tris));
        TruthSurface { positions: truth.positions.clone(), tris, bvh }
    }

    /// Faces of `out` whose normal opposes that of the truth face closest to their centroid
    /// (meaningful where `out` lies within a part's thickness of the truth).
    pub fn faces_against(&self, out: &Mesh) -> usize {
        out.faces
            .triangles()
            .iter()
            .filter(|t| {
                let q = |k: usize| out.positions[t[k] as usize];
                let c = [0, 1, 2].map(|k| (q(0)[k] + q(1)[k] + q(2)[k]) / 3.0);
                self.bvh.closest(c).is_some_and(|h| {
                    let g = |k: usize| self.positions[self.tris[h.face as usize][k] as usize];
                    dot(triangle_cross(q(0), q(1), q(2)), triangle_cross(g(0), g(1), g(2))) < 0.0
                })
            })
            .count()
    }

    /// The largest distance of an output vertex to the truth surface.
    pub fn max_distance(&self, out: &Mesh) -> f64 {
        out.positions.iter().map(|&q| self.bvh.closest(q).map_or(0.0, |h| h.dist2.sqrt())).fold(0.0, f64::max)
    }
}

/// Indices of the (fan-triangulated) faces of `mesh` whose normal does not point along
/// `outward(centroid)`: `n · outward ≤ 0`, so a zero-area face counts too (it faces nowhere).
/// `outward` is the truth's outward direction at a point, unnormalised is fine.
pub fn faces_against(mesh: &Mesh, outward: impl Fn(Point3) -> Point3) -> Vec<usize> {
    mesh.faces
        .triangles()
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let centroid = [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0);
            dot(triangle_cross(a, b, c), outward(centroid)) <= 0.0
        })
        .map(|(i, _)| i)
        .collect()
}

/// The outward normal direction of the ellipsoid x²/a² + y²/b² + z²/c² = 1 at `p` (its gradient,
/// up to a factor 2); with `[1, 1, 1]` the sphere's, `p` itself.
pub fn ellipsoid_outward(axes: [f64; 3]) -> impl Fn(Point3) -> Point3 {
    move |p| [0, 1, 2].map(|k| p[k] / (axes[k] * axes[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::icosphere;

    #[test]
    fn an_outward_icosphere_has_none_and_a_turned_face_is_found() {
        let mut m = icosphere(2, 1.0);
        assert!(faces_against(&m, ellipsoid_outward([1.0, 1.0, 1.0])).is_empty());
        // Squashed into an ellipsoid's shape, still outward by the ellipsoid's own normal.
        let axes = [1.0, 0.6, 0.04];
        let squashed = Mesh {
            positions: m.positions.iter().map(|p| [0, 1, 2].map(|k| p[k] * axes[k])).collect(),
            ..m.clone()
        };
        assert!(faces_against(&squashed, ellipsoid_outward(axes)).is_empty());
        // Reverse face 7: it, and only it, is against.
        let tris = m.faces.triangles();
        let mut turned: Vec<[u32; 3]> = tris.clone();
        turned[7].swap(1, 2);
        m = Mesh::from_triangles(m.positions.clone(), &turned);
        assert_eq!(faces_against(&m, ellipsoid_outward([1.0, 1.0, 1.0])), vec![7]);
        // Everything is against the inward direction.
        assert_eq!(faces_against(&m, |p| p.map(|x| -x)).len(), tris.len() - 1);
    }

    #[test]
    fn a_zero_area_face_counts_as_against() {
        let m = Mesh::from_triangles(vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [2.0, 0.0, 1.0]], &[[0, 1, 2]]);
        assert_eq!(faces_against(&m, |_| [0.0, 0.0, 1.0]), vec![0]);
    }
}
