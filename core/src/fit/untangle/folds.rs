//! A reference-free fold measure: what a user without a truth surface (and without the job's
//! internal reference normals) can check on the output alone.
//!
//! An interior edge is *folded* when the normals of its two faces make an angle above
//! [`FOLD_ANGLE_DEG`], i.e. the two faces are turned back onto each other to within
//! 180° − [`FOLD_ANGLE_DEG`] (a crease sharper than that). A face turned over among unfolded
//! neighbours has normals nearly opposite to theirs, so each of its edges to them counts; a
//! whole mirrored patch counts along its border. Real models can have creases that sharp (the
//! template's own count is reported next to the output's, so the fit's contribution is the
//! difference), but a smooth surface sampled finely enough has none.
//!
//! Degenerate faces (zero normal) have no direction to fold; they are counted separately.

use serde::Serialize;

use crate::geometry::{dot, norm2, triangle_cross};
use crate::mesh::Point3;

use rayon::prelude::*;

use crate::topology::Csr;

/// Angle between adjacent face normals (degrees) above which their common edge counts as folded.
/// 150° = the two faces meet at an interior dihedral angle under 30°: sharper than any crease of
/// the shared test meshes (their largest is measured in `core/tests/fit_folds.rs`), and far from
/// the ~180° of a face turned over.
pub const FOLD_ANGLE_DEG: f64 = 150.0;

/// Whether two adjacent faces with unnormalised normals `n`, `m` fold onto each other (normals
/// more than [`FOLD_ANGLE_DEG`] apart; a degenerate face never folds): [`fold_stats`]'s rule for
/// one pair, for the repairs that judge an edit by the folds it adds.
pub fn folded_pair(n: Point3, m: Point3) -> bool {
    let d = (dot(n, n) * dot(m, m)).sqrt();
    d != 0.0 && dot(n, m) / d < FOLD_ANGLE_DEG.to_radians().cos()
}

#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct FoldStats {
    /// Interior edges whose two faces' normals differ by more than [`FOLD_ANGLE_DEG`].
    pub folded_edges: usize,
    /// Faces with at least one folded edge.
    pub folded_faces: usize,
    /// Largest angle between the normals of two adjacent non-degenerate faces (degrees).
    pub max_normal_angle_deg: f64,
    /// Faces with zero area (no normal; not counted above).
    pub degenerate_faces: usize,
}

/// Fold statistics of the triangle mesh `pos`/`tris` (edges used by more than two faces are
/// compared pairwise: each later face with the edge's first face in index order).
///
/// Per face, in parallel: the faces on an edge are looked up in the vertex → faces lists (a
/// counting sort), not in an edge hash map (~50 ms of serial CPU on the headline's 200k faces,
/// docs/benchmarks.md, session 11). The counts and the largest angle are the same as the map's.
pub fn fold_stats(pos: &[Point3], tris: &[[u32; 3]]) -> FoldStats {
    let normals: Vec<Point3> = tris
        .par_iter()
        .map(|t| triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]))
        .collect();
    let vertex_faces = Csr::vertex_triangles(pos.len(), tris);
    let cos_fold = FOLD_ANGLE_DEG.to_radians().cos();
    // The cosine of the angle between the normals of faces f and g, None when one is degenerate.
    let cos = |f: usize, g: usize| {
        let d = (norm2(normals[f]) * norm2(normals[g])).sqrt();
        (d != 0.0).then(|| dot(normals[f], normals[g]) / d)
    };
    let per_face = |f: usize| {
        let t = tris[f];
        let mut folded = false;
        let mut s =
            FaceFolds { degenerate_faces: usize::from(norm2(normals[f]) == 0.0), ..FaceFolds::default() };
        for k in 0..3 {
            let mut on_edge = vertex_faces.triangles_on_edge(tris, t[k], t[(k + 1) % 3]);
            let Some(first) = on_edge.next().map(|g| g as usize) else { continue };
            if first != f {
                // The edge's pair (f, first) is counted here, once.
                if let Some(c) = cos(f, first) {
                    s.min_cos = s.min_cos.min(c);
                    s.folded_edges += usize::from(c < cos_fold);
                    folded |= c < cos_fold;
                }
            } else {
                // f is the first face: its pairs are counted by the later faces; f is folded when any is.
                folded |=
                    on_edge.any(|g| g as usize != f && cos(f, g as usize).is_some_and(|c| c < cos_fold));
            }
        }
        s.folded_faces = usize::from(folded);
        s
    };
    let total = (0..tris.len()).into_par_iter().map(per_face).reduce(FaceFolds::default, FaceFolds::sum);
    FoldStats {
        folded_edges: total.folded_edges,
        folded_faces: total.folded_faces,
        max_normal_angle_deg: total.min_cos.clamp(-1.0, 1.0).acos().to_degrees(),
        degenerate_faces: total.degenerate_faces,
    }
}

/// One face's share of [`FoldStats`] (its folded edges are those it does not come first on),
/// summed over faces.
#[derive(Clone, Copy)]
struct FaceFolds {
    folded_edges: usize,
    folded_faces: usize,
    degenerate_faces: usize,
    /// Smallest cosine between the normals of two adjacent non-degenerate faces.
    min_cos: f64,
}

impl Default for FaceFolds {
    fn default() -> FaceFolds {
        FaceFolds { folded_edges: 0, folded_faces: 0, degenerate_faces: 0, min_cos: 1.0 }
    }
}

impl FaceFolds {
    fn sum(a: FaceFolds, b: FaceFolds) -> FaceFolds {
        FaceFolds {
            folded_edges: a.folded_edges + b.folded_edges,
            folded_faces: a.folded_faces + b.folded_faces,
            degenerate_faces: a.degenerate_faces + b.degenerate_faces,
            min_cos: a.min_cos.min(b.min_cos),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turned_face_folds_its_three_edges_and_a_flat_grid_none() {
        let g = crate::shapes::grid(4, 4, 1.0, false);
        let tris = crate::shapes::fan_triangles(&g.faces);
        let s = fold_stats(&g.positions, &tris);
        assert_eq!((s.folded_edges, s.folded_faces, s.degenerate_faces), (0, 0, 0));
        assert!(s.max_normal_angle_deg < 1e-6);
        // Move one interior vertex across its ring: the faces between it and the far side turn over.
        let mut pos = g.positions.clone();
        let v = 6; // (1, 1) on the 5×5 vertex grid
        pos[v][0] += 1.6;
        let s = fold_stats(&pos, &tris);
        assert!(s.folded_edges > 0 && s.folded_faces > 0, "{s:?}");
        assert!((s.max_normal_angle_deg - 180.0).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn a_cube_crease_is_not_a_fold() {
        // Two faces at a right angle: normals 90° apart.
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let tris = vec![[0, 1, 2], [1, 0, 3]];
        let s = fold_stats(&pos, &tris);
        assert_eq!(s.folded_edges, 0);
        assert!((s.max_normal_angle_deg - 90.0).abs() < 1e-9, "{s:?}");
        // Folded to 20° (normals 160° apart): a fold.
        let a = 20f64.to_radians();
        let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, a.cos(), a.sin()]];
        let tris = vec![[0, 1, 2], [1, 0, 3]];
        let s = fold_stats(&pos, &tris);
        assert_eq!((s.folded_edges, s.folded_faces), (1, 2));
        assert!((s.max_normal_angle_deg - 160.0).abs() < 1e-9, "{s:?}");
    }

    /// Three faces on one edge: the second folded onto the first (normals 160° apart), the third
    /// at 90° to the first. Each later face is compared with the first only: one folded edge, two
    /// folded faces, the largest angle 160° (the 2nd–3rd pair is not compared).
    #[test]
    fn faces_on_a_non_manifold_edge_are_compared_with_the_first() {
        let a = 20f64.to_radians();
        let pos =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, a.cos(), a.sin()], [0.0, 0.0, 1.0]];
        let tris = vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let s = fold_stats(&pos, &tris);
        assert_eq!((s.folded_edges, s.folded_faces, s.degenerate_faces), (1, 2, 0), "{s:?}");
        assert!((s.max_normal_angle_deg - 160.0).abs() < 1e-9, "{s:?}");
        // The first face degenerate (its third corner on the edge): nothing is compared with it.
        let mut flat = pos.clone();
        flat[2] = [0.5, 0.0, 0.0];
        let s = fold_stats(&flat, &tris);
        assert_eq!((s.folded_edges, s.folded_faces, s.degenerate_faces), (0, 0, 1), "{s:?}");
    }
}
