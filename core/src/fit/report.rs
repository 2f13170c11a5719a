//! Quality measures of the fit report.

use serde::Serialize;

use crate::geometry::{
    add, corner_angle, dist, dot, norm2, normalize, sub, triangle_centroid, triangle_cross,
};
use crate::mesh::{Mesh, Point3};

use super::curves::CurveNetwork;
use super::retriangulate::Realised;
use super::trimesh::IntMap;

#[derive(Debug, Clone, Copy, Serialize)]
pub struct AngleStats {
    pub min_deg: f64,
    pub mean_min_deg: f64,
    pub below_10: usize,
}

/// Smallest corner angle over all triangles, the mean of the per-triangle minimum, and the number
/// of triangles with a corner below 10°.
pub fn angle_stats(pos: &[Point3], tris: &[[u32; 3]]) -> AngleStats {
    let (mut min, mut sum, mut below) = (180.0f64, 0.0, 0);
    for t in tris {
        let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        // The smallest angle is opposite the shortest edge: one atan2 per triangle.
        let (la, lb, lc) = (norm2(sub(b, c)), norm2(sub(c, a)), norm2(sub(a, b)));
        let m = if la <= lb && la <= lc {
            corner_angle(a, b, c)
        } else if lb <= lc {
            corner_angle(b, c, a)
        } else {
            corner_angle(c, a, b)
        }
        .to_degrees();
        min = min.min(m);
        sum += m;
        below += (m < 10.0) as usize;
    }
    AngleStats { min_deg: min, mean_min_deg: sum / tris.len().max(1) as f64, below_10: below }
}

/// Area-weighted unit vertex normals.
pub fn vertex_normals(pos: &[Point3], tris: &[[u32; 3]]) -> Vec<Point3> {
    let mut n = vec![[0.0; 3]; pos.len()];
    for t in tris {
        let f = triangle_cross(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        for &v in t {
            n[v as usize] = add(n[v as usize], f);
        }
    }
    n.into_iter().map(normalize).collect()
}

/// The input polylines as chains of output mesh vertices.
pub fn polyline_chains(net: &CurveNetwork, chains: &[Vec<u32>]) -> Vec<Vec<u32>> {
    let mut seg_of: IntMap<(u32, u32), usize> = IntMap::default();
    for (i, s) in net.segments.iter().enumerate() {
        seg_of.insert((s[0], s[1]), i);
    }
    net.polylines
        .iter()
        .map(|line| {
            let mut out: Vec<u32> = Vec::new();
            for w in line.windows(2) {
                let key = (w[0].min(w[1]), w[0].max(w[1]));
                let Some(&si) = seg_of.get(&key) else { continue };
                let mut c = chains[si].clone();
                if net.segments[si][0] != w[0] {
                    c.reverse();
                }
                let skip = usize::from(!out.is_empty());
                out.extend_from_slice(&c[skip..]);
            }
            out
        })
        .collect()
}

/// The segments that are not edge chains in the output, by why: the two the template's topology
/// leaves no chain for (`pieces`: ends on two pieces no edge joins; `off_surface`: the straight way
/// crosses a hole or runs past the rim), the two a chain could exist for (`separated`, `budget`:
/// [`super::retriangulate::RetriStats`]), and `broken_after_retriangulation`: chains a later stage
/// (clean-up, zero-area removal) left with a non-edge (none measured so far; counted so that it
/// cannot hide).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct SegmentsNotEdges {
    pub total: usize,
    pub pieces: usize,
    pub off_surface: usize,
    pub separated: usize,
    pub budget: usize,
    pub broken_after_retriangulation: usize,
}

/// How many of the turned faces the report locates (`flipped_faces_at`).
pub const FLIPPED_AT_LISTED: usize = 20;

pub struct Quality {
    pub curve_residual_max: f64,
    pub curve_residual_mean: f64,
    pub chain_deviation_max: f64,
    pub segments_as_edges: f64,
    /// The share among the segments the template's topology allows as chains (all but
    /// `pieces` and `off_surface`): 1 when every failure is one no chain can fix.
    pub segments_as_edges_realisable: f64,
    pub segments_not_edges: SegmentsNotEdges,
    /// Output faces turned against the template's normals pushed forward by the fit's maps
    /// ([`super::orientation`]).
    pub flipped_faces: usize,
    /// Centroids of the first [`FLIPPED_AT_LISTED`] faces `flipped_faces` counts: where they are.
    pub flipped_faces_at: Vec<Point3>,
    /// Faces the maps themselves turned inside out (det J ≤ 0 at two or more corners).
    pub faces_inverted_by_maps: usize,
    /// Output faces turned against the fine-deformed surface (the measure before session 13).
    pub flipped_faces_against_fine_surface: usize,
}

impl Quality {
    /// `reference_pos`/`reference_normals`: the fine-deformed mesh before re-triangulation (the
    /// measure before session 13: a face opposing the sum of its corners' reference normals);
    /// `orientation`: the template's normals pushed forward by the fit's maps, per output vertex
    /// (`flipped_faces`, [`super::orientation`]).
    #[allow(clippy::too_many_arguments)]
    pub fn measure(
        out: &Mesh,
        net: &CurveNetwork,
        vertex_of_point: &[u32],
        realised: &Realised,
        tris: &[[u32; 3]],
        reference_pos: &[Point3],
        reference_normals: &[Point3],
        orientation: &super::orientation::Orientation,
    ) -> Quality {
        let pos = &out.positions;
        let res: Vec<f64> =
            (0..net.points.len()).map(|p| dist(pos[vertex_of_point[p] as usize], net.points[p])).collect();
        let mut dev = 0.0f64;
        for (si, c) in realised.chains.iter().enumerate() {
            let (a, b) = (net.points[net.segments[si][0] as usize], net.points[net.segments[si][1] as usize]);
            for &v in &c[1..c.len().saturating_sub(1)] {
                dev = dev.max(super::point_segment_distance(pos[v as usize], a, b));
            }
        }
        let mut edges: IntMap<(u32, u32), ()> = IntMap::default();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)), ());
            }
        }
        let ok = realised
            .chains
            .iter()
            .filter(|c| {
                c.len() >= 2 && c.windows(2).all(|w| edges.contains_key(&(w[0].min(w[1]), w[0].max(w[1]))))
            })
            .count();
        let st = &realised.stats;
        let not_edges = SegmentsNotEdges {
            total: realised.chains.len() - ok,
            pieces: st.failed_pieces,
            off_surface: st.off_surface_segments,
            separated: st.failed_separated,
            budget: st.failed_budget,
            broken_after_retriangulation: (realised.chains.len() - ok).saturating_sub(st.failed_segments),
        };
        let realisable = realised.chains.len().saturating_sub(st.failed_pieces + st.off_surface_segments);
        // Retriangulation adds no vertices, so each output face has reference normals at its own
        // corners (no nearest-point search).
        let _ = reference_pos;
        let flipped = tris
            .iter()
            .filter(|t| {
                let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
                let r = t.iter().fold([0.0; 3], |acc, &v| add(acc, reference_normals[v as usize]));
                dot(triangle_cross(a, b, c), r) < 0.0
            })
            .count();
        let against = orientation.faces_against_list(pos, tris);
        Quality {
            curve_residual_max: res.iter().cloned().fold(0.0, f64::max),
            curve_residual_mean: res.iter().sum::<f64>() / res.len().max(1) as f64,
            chain_deviation_max: dev,
            segments_as_edges: ok as f64 / realised.chains.len().max(1) as f64,
            segments_as_edges_realisable: if realisable == 0 {
                1.0
            } else {
                ok.min(realisable) as f64 / realisable as f64
            },
            segments_not_edges: not_edges,
            flipped_faces: against.len(),
            flipped_faces_at: against
                .iter()
                .take(FLIPPED_AT_LISTED)
                .map(|&f| {
                    let t = tris[f as usize];
                    triangle_centroid(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])
                })
                .collect(),
            faces_inverted_by_maps: orientation.faces_inverted(tris),
            flipped_faces_against_fine_surface: flipped,
        }
    }
}
