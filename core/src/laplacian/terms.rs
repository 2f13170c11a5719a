//! Per-face geometric terms (cotangent weights per face pair, masses, ring areas) from one pass
//! over the faces; polygons by the fan average described in the module docs.

use rayon::prelude::*;

use super::stencil::local_pairs;
use super::{PairLayout, Stencil, DEGENERATE_SHAPE};
use crate::geometry::{cross, dot, norm, sub};
use crate::mesh::{Faces, Point3};

/// Per-face geometric terms, from one pass over the faces.
#[derive(Debug, Clone)]
pub struct FaceTerms {
    /// Cotangent weight per face pair (stencil layout), fan-averaged on polygons.
    pub pair_w: Vec<f64>,
    /// Per-vertex barycentric mass (⅓ incident triangle area).
    pub mass_barycentric: Vec<f64>,
    /// Per-vertex mixed Voronoi mass.
    pub mass_voronoi: Vec<f64>,
    /// Per-vertex ring area of eq. 3-4 (full incident triangle areas, mean over quad diagonals).
    pub ring_area: Vec<f64>,
    /// Triangles (or fan triangles of polygons) below the shape threshold: no cotangent weight.
    pub degenerate_triangles: usize,
}

/// Per-corner terms of one triangle: cot at each corner, barycentric, Voronoi, ring area.
#[inline]
fn triangle_terms(p: [Point3; 3]) -> ([f64; 3], [f64; 3], f64, bool) {
    let e = [sub(p[2], p[1]), sub(p[0], p[2]), sub(p[1], p[0])]; // edge opposite corner c
    let l2 = [dot(e[0], e[0]), dot(e[1], e[1]), dot(e[2], e[2])];
    let twice_area = norm(cross(e[2], sub(p[2], p[0])));
    let lmax2 = l2[0].max(l2[1]).max(l2[2]);
    let area = 0.5 * twice_area;
    if !(twice_area > DEGENERATE_SHAPE * lmax2) {
        return ([0.0; 3], [area / 3.0; 3], area, true);
    }
    // cot at corner c = (u·v)/|u×v| with u, v the edges leaving c; u·v = (l_u² + l_v² − l_opp²)/2.
    let cot = [
        (l2[1] + l2[2] - l2[0]) / (2.0 * twice_area),
        (l2[2] + l2[0] - l2[1]) / (2.0 * twice_area),
        (l2[0] + l2[1] - l2[2]) / (2.0 * twice_area),
    ];
    let mut vor = [0.0; 3];
    if cot[0] < 0.0 || cot[1] < 0.0 || cot[2] < 0.0 {
        for c in 0..3 {
            vor[c] = if cot[c] < 0.0 { area / 2.0 } else { area / 4.0 };
        }
    } else {
        // Voronoi part of corner c: (|e_{c+1}|² cot_{c+1} + |e_{c+2}|² cot_{c+2}) / 8.
        for c in 0..3 {
            let (a, b) = ((c + 1) % 3, (c + 2) % 3);
            vor[c] = (l2[a] * cot[a] + l2[b] * cot[b]) / 8.0;
        }
    }
    (cot, vor, area, false)
}

/// Computes the per-pair cotangent weights and the per-vertex areas (stencil layout AllPairs, or
/// Edges for a triangle-only mesh, where both layouts coincide).
pub fn face_terms(positions: &[Point3], faces: &Faces, stencil: &Stencil) -> FaceTerms {
    let n = positions.len();
    let nf = faces.len();
    let mut pair_w = vec![0.0; stencil.pair_count()];
    let corners = faces.indices().len();
    // Per-corner (bary, voronoi, ring) contributions, then scattered to vertices.
    let mut corner = vec![[0.0f64; 3]; corners];
    let offsets = faces.offsets();
    let degenerate: usize = if let Some(tris) = faces.as_triangles() {
        pair_w
            .par_chunks_mut(3)
            .zip(corner.par_chunks_mut(3))
            .zip(tris.par_chunks(3))
            .with_min_len(2048)
            .map(|((w, c), t)| {
                let p = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
                let (cot, vor, area, deg) = triangle_terms(p);
                // pair c = corners (c, c+1): opposite corner c+2.
                for k in 0..3 {
                    w[k] = cot[(k + 2) % 3];
                    c[k] = [area / 3.0, vor[k], area];
                }
                deg as usize
            })
            .sum()
    } else {
        let mut deg = 0;
        for f in 0..nf {
            let face = faces.get(f);
            let w = &mut pair_w[stencil.pair_offset[f] as usize..stencil.pair_offset[f + 1] as usize];
            let c = &mut corner[offsets[f] as usize..offsets[f + 1] as usize];
            deg += polygon_terms(positions, face, stencil.layout, w, c);
        }
        deg
    };
    let mut mass_barycentric = vec![0.0; n];
    let mut mass_voronoi = vec![0.0; n];
    let mut ring_area = vec![0.0; n];
    for (&v, c) in faces.indices().iter().zip(&corner) {
        let v = v as usize;
        mass_barycentric[v] += c[0];
        mass_voronoi[v] += c[1];
        ring_area[v] += c[2];
    }
    FaceTerms { pair_w, mass_barycentric, mass_voronoi, ring_area, degenerate_triangles: degenerate }
}

/// Fan-average terms of one polygon (see module docs); returns the number of degenerate fan
/// triangles. `w` is in the stencil's pair layout, `c` per corner (bary, voronoi, ring).
fn polygon_terms(
    positions: &[Point3],
    face: &[u32],
    layout: PairLayout,
    w: &mut [f64],
    c: &mut [[f64; 3]],
) -> usize {
    let k = face.len();
    if k < 3 {
        return 0;
    }
    let pairs = local_pairs(k, layout);
    let mut index = vec![usize::MAX; k * k];
    for (p, &(a, b)) in pairs.iter().enumerate() {
        index[a * k + b] = p;
        index[b * k + a] = p;
    }
    let fans = if k == 3 { 1 } else { k };
    let share = 1.0 / fans as f64;
    let mut deg = 0;
    for apex in 0..fans {
        for i in 1..k - 1 {
            let t = [apex, (apex + i) % k, (apex + i + 1) % k];
            let p = [
                positions[face[t[0]] as usize],
                positions[face[t[1]] as usize],
                positions[face[t[2]] as usize],
            ];
            let (cot, vor, area, d) = triangle_terms(p);
            deg += d as usize;
            for q in 0..3 {
                let (a, b) = (t[(q + 1) % 3], t[(q + 2) % 3]);
                let slot = index[a * k + b];
                if slot != usize::MAX {
                    w[slot] += share * cot[q];
                }
                c[t[q]][0] += share * area / 3.0;
                c[t[q]][1] += share * vor[q];
                c[t[q]][2] += share * area;
            }
        }
    }
    deg
}
