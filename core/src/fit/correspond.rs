//! Closest-point correspondences (§2.1): every curve vertex gets its own template vertex.
//!
//! Rule: user pairs are fixed first; then feature points (curve vertices where > 2 segments meet,
//! the seed's priority), then all other curve vertices in order of increasing distance to their
//! nearest template vertex. Each takes the nearest template vertex nobody has claimed yet, so a
//! conflict is won by the feature point, else by the closer curve vertex, and the loser falls
//! back to its next-nearest free vertex (the seed leaves this open). Nearest-vertex queries use a
//! k-d tree: O(n log m), not the seed's O(mn).

use crate::error::{Error, Result};
use crate::job::Progress;
use crate::mesh::Point3;

use super::curves::CurveNetwork;
use super::kdtree::KdTree;

#[derive(Debug, Clone)]
pub struct Correspondence {
    /// Template vertex of each curve point.
    pub vertex_of_point: Vec<u32>,
    /// Curve points that did not get their first-choice vertex.
    pub conflicts: usize,
    /// Distance from each curve point to its vertex before the fine deformation.
    pub distances: Vec<f64>,
}

/// `fixed`: (curve point, template vertex) from the user's pairs.
pub fn closest(
    template: &[Point3],
    net: &CurveNetwork,
    fixed: &[(u32, u32)],
    progress: &Progress,
) -> Result<Correspondence> {
    let n = net.points.len();
    if n > template.len() {
        return Err(Error::params(
            "curves",
            format!(
                "the curve network has {n} vertices but the template only {}: every curve vertex needs \
                 its own template vertex (use a finer template)",
                template.len()
            ),
        ));
    }
    let tree = KdTree::new(template);
    let mut claimed = vec![false; template.len()];
    let mut vop = vec![u32::MAX; n];
    for &(p, v) in fixed {
        vop[p as usize] = v;
        claimed[v as usize] = true;
    }
    let first: Vec<(u32, f64)> =
        net.points.iter().map(|&p| tree.nearest(p).unwrap_or((u32::MAX, f64::INFINITY))).collect();
    let mut order: Vec<u32> = (0..n as u32).filter(|&p| vop[p as usize] == u32::MAX).collect();
    order.sort_by(|&a, &b| {
        net.is_feature(b).cmp(&net.is_feature(a)).then(first[a as usize].1.total_cmp(&first[b as usize].1))
    });
    let mut conflicts = 0;
    for (k, &p) in order.iter().enumerate() {
        if k % 4096 == 0 {
            progress.fraction(k as f64 / n.max(1) as f64)?;
        }
        let (v, _) = tree
            .nearest_filtered(net.points[p as usize], |v| !claimed[v as usize])
            .ok_or_else(|| Error::Internal("no free template vertex left".into()))?;
        if v != first[p as usize].0 {
            conflicts += 1;
        }
        claimed[v as usize] = true;
        vop[p as usize] = v;
    }
    let distances = (0..n).map(|p| crate::geometry::dist(net.points[p], template[vop[p] as usize])).collect();
    Ok(Correspondence { vertex_of_point: vop, conflicts, distances })
}
