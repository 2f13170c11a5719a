//! The template's creases, which smoothing may hold (`smooth_hold_creases_deg`): tangential steps
//! slide vertices off a crease or a tip and the chords then cut it.

use rayon::prelude::*;

use crate::geometry::{dot, norm2, triangle_cross};
use crate::mesh::Point3;
use crate::topology::Csr;

/// An edge of exactly two faces `f` < `g` (in index order), with the cosine of the angle between
/// their normals (0 when one has zero area: it counts as perpendicular).
#[derive(Debug, Clone, Copy)]
pub struct EdgeBend {
    pub a: u32,
    pub b: u32,
    pub f: u32,
    pub g: u32,
    pub cos: f64,
}

/// Every edge of exactly two faces, once (a boundary or non-manifold edge is left out), with its
/// bend. The faces on an edge come from the vertex → faces lists, as in [`fold_stats`], each edge
/// judged once from its first face.
///
/// [`fold_stats`]: super::super::untangle::fold_stats
pub fn edge_bends(pos: &[Point3], tris: &[[u32; 3]]) -> Vec<EdgeBend> {
    let normals: Vec<Point3> = tris
        .par_iter()
        .map(|t| triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]))
        .collect();
    let vertex_faces = Csr::vertex_triangles(pos.len(), tris);
    let mut out = Vec::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let mut on_edge = vertex_faces.triangles_on_edge(tris, a, b);
            let (Some(f0), Some(g), None) = (on_edge.next(), on_edge.next(), on_edge.next()) else {
                continue;
            };
            if f0 as usize != f {
                continue;
            }
            let (n, m) = (normals[f0 as usize], normals[g as usize]);
            let d = (norm2(n) * norm2(m)).sqrt();
            let cos = if d > 0.0 { dot(n, m) / d } else { 0.0 };
            out.push(EdgeBend { a, b, f: f0, g, cos });
        }
    }
    out
}

/// The vertices of a crease: an edge of exactly two faces whose normals differ by more than `deg`
/// degrees ([`edge_bends`]).
pub fn crease_vertices(pos: &[Point3], tris: &[[u32; 3]], deg: f64) -> Vec<bool> {
    let cos = deg.to_radians().cos();
    let mut on = vec![false; pos.len()];
    for e in edge_bends(pos, tris).into_iter().filter(|e| e.cos < cos) {
        on[e.a as usize] = true;
        on[e.b as usize] = true;
    }
    on
}

/// Adds to `held` (per output vertex; template vertices keep their indices through the fit) every
/// template vertex on a crease of the template (`smooth_hold_creases_deg`); returns how many it
/// added.
pub fn hold_template_creases(
    held: &mut [bool],
    template_pos: &[Point3],
    template_tris: &[[u32; 3]],
    deg: f64,
) -> usize {
    let mut added = 0;
    for (h, c) in held.iter_mut().zip(crease_vertices(template_pos, template_tris, deg)) {
        added += usize::from(c && !*h);
        *h |= c;
    }
    added
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::icosphere;

    /// A strip of 4 × 2 squares in the plane z = 0, its right half turned up about x = 2 by
    /// `fold` degrees: the crease is the 3 vertices on x = 2 (hand-placed, 2 triangles a square).
    fn folded_strip(fold: f64) -> (Vec<Point3>, Vec<[u32; 3]>) {
        let (c, s) = (fold.to_radians().cos(), fold.to_radians().sin());
        let mut pos = Vec::new();
        for j in 0..3 {
            for i in 0..5 {
                let x = i as f64;
                let p = if x <= 2.0 {
                    [x, j as f64, 0.0]
                } else {
                    [2.0 + (x - 2.0) * c, j as f64, (x - 2.0) * s]
                };
                pos.push(p);
            }
        }
        let mut tris = Vec::new();
        for j in 0..2u32 {
            for i in 0..4u32 {
                let (a, b, d, e) = (j * 5 + i, j * 5 + i + 1, (j + 1) * 5 + i, (j + 1) * 5 + i + 1);
                tris.push([a, b, e]);
                tris.push([a, e, d]);
            }
        }
        (pos, tris)
    }

    #[test]
    fn crease_vertices_are_those_of_edges_folded_past_the_angle() {
        let on_crease = |on: Vec<bool>| (0..on.len()).filter(|&v| on[v]).collect::<Vec<_>>();
        // Folded by 40°: the edges on x = 2 (vertices 2, 7, 12) are past 30°, the others flat.
        let (pos, tris) = folded_strip(40.0);
        assert_eq!(on_crease(crease_vertices(&pos, &tris, 30.0)), vec![2, 7, 12]);
        // Folded by 20°: no crease at 30°, the same one at 10°.
        let (pos, tris) = folded_strip(20.0);
        assert!(on_crease(crease_vertices(&pos, &tris, 30.0)).is_empty());
        assert_eq!(on_crease(crease_vertices(&pos, &tris, 10.0)), vec![2, 7, 12]);
        // A level-3 icosphere's neighbouring faces differ by less than 30°: no crease.
        let ico = icosphere(3, 1.0);
        assert!(!crease_vertices(&ico.positions, &ico.faces.triangles(), 30.0).contains(&true));
    }
}
