//! Refinement of the template where a displacement field bends faster than the template's faces
//! can follow: an edge whose midpoint the field moves differently (by more than a tolerance) from
//! the mean of its two ends is split, with its faces, and the new vertices take the field's own
//! value. Used by the approach levels ([`super::approach`]).
//!
//! Why: a template vertex moves by the field, but a point inside a face moves with the face's
//! corners, linearly. Where the field varies on a scale below the edge length, the foot of a
//! curve vertex inside a face misses the curve vertex by that nonlinearity even though the field
//! interpolates it exactly. Measured on a flattened ellipsoid 1 × 0.6 × 0.04 (a bent section
//! network, a level-4 icosphere squashed the same way): at the rim, whose radius of curvature
//! (0.0008) is far below the edge length (0.033), the last approach level left its own samples
//! up to 6.4e-3 off the curves (5 % of the thickness and 8× the rim radius), the insertion put the
//! curve vertices there out of order, and 160 faces ended folded. Thin parts (rims, fins, ears,
//! legs the coarse template only begins to reach) are where this happens; smooth fits have a field
//! that is nearly linear across every face and refine nothing.

use crate::error::Result;
use crate::geometry::{add, dist, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::flips;
use super::rbf::Rbf;

/// Rounds of splitting per field (each can halve the edges it touches).
const MAX_ROUNDS: usize = 4;

/// What the refinement did for one approach level.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct FieldRefineStats {
    pub rounds: usize,
    pub faces_added: usize,
    /// Largest midpoint deviation left (the field minus the linear interpolation of the ends).
    pub deviation_max: f64,
}

/// Splits the faces of every edge of `tris` whose midpoint deviation exceeds `tolerance`, in up
/// to [`MAX_ROUNDS`] rounds, keeping the face count under `max_faces`; `disp` (the field at every
/// vertex of `pos`) is extended with the field at the new vertices, and `parents` with their
/// edge ends (for the UVs). Edges shorter than `min_edge` are never split.
#[allow(clippy::too_many_arguments)]
pub fn refine_for_field(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    parents: &mut Vec<[(u32, f64); 3]>,
    disp: &mut Vec<Point3>,
    field: &Rbf,
    tolerance: f64,
    min_edge: f64,
    max_faces: usize,
    progress: &Progress,
) -> Result<FieldRefineStats> {
    let mut stats = FieldRefineStats::default();
    for _ in 0..MAX_ROUNDS {
        progress.check()?;
        let (flagged, worst) = deviating_faces(pos, tris, disp, field, tolerance, min_edge, progress)?;
        stats.deviation_max = worst;
        if flagged.is_empty() || tris.len() + 3 * flagged.len() > max_faces {
            break;
        }
        let p0 = pos.len();
        stats.faces_added += flips::subdivide(pos, tris, &flagged, parents);
        disp.extend(field.eval_many(&pos[p0..], progress)?);
        stats.rounds += 1;
    }
    Ok(stats)
}

/// Faces with an edge (longer than `min_edge`) whose midpoint deviation exceeds `tolerance`, and
/// the largest deviation seen.
fn deviating_faces(
    pos: &[Point3],
    tris: &[[u32; 3]],
    disp: &[Point3],
    field: &Rbf,
    tolerance: f64,
    min_edge: f64,
    progress: &Progress,
) -> Result<(Vec<u32>, f64)> {
    let mut seen: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tris.len() * 3 / 2);
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            // Short edges first (most of a fine template): no hashing for them.
            let key = (a.min(b), a.max(b));
            if dist(pos[a as usize], pos[b as usize]) > min_edge && seen.insert(key) {
                edges.push(key);
            }
        }
    }
    let mids: Vec<Point3> =
        edges.iter().map(|&(a, b)| scale(add(pos[a as usize], pos[b as usize]), 0.5)).collect();
    let at_mid = field.eval_many(&mids, progress)?;
    let mut bad: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let mut worst = 0.0f64;
    for (&(a, b), m) in edges.iter().zip(&at_mid) {
        let linear = scale(add(disp[a as usize], disp[b as usize]), 0.5);
        let dev = crate::geometry::norm(sub(*m, linear));
        worst = worst.max(dev);
        if dev > tolerance {
            bad.insert((a, b));
        }
    }
    let flagged: Vec<u32> = tris
        .iter()
        .enumerate()
        .filter(|(_, t)| (0..3).any(|k| bad.contains(&(t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))))
        .map(|(f, _)| f as u32)
        .collect();
    Ok((flagged, worst))
}
