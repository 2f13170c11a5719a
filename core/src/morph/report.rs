//! Quality measures of the morph that do not belong to one stage: how well the end frames
//! reproduce the inputs (symmetric Hausdorff distance, relative to the input's bounding-box
//! diagonal).

use crate::error::Result;
use crate::geometry::Aabb;
use crate::job::Progress;
use crate::mesh::Faces;
use crate::mesh::Point3;
use crate::spatial::Bvh;

/// One-sided max distance from points (vertices and face centroids of A) to surface B.
fn one_sided(pa: &[Point3], ta: &[[u32; 3]], b: &Bvh, centroids: bool, progress: &Progress) -> Result<f64> {
    let v = b.max_distance2(pa, progress)?;
    if !centroids {
        return Ok(v.sqrt());
    }
    let c: Vec<Point3> = ta
        .iter()
        .map(|t| {
            let (x, y, z) = (pa[t[0] as usize], pa[t[1] as usize], pa[t[2] as usize]);
            [(x[0] + y[0] + z[0]) / 3.0, (x[1] + y[1] + z[1]) / 3.0, (x[2] + y[2] + z[2]) / 3.0]
        })
        .collect();
    Ok(v.max(b.max_distance2(&c, progress)?).sqrt())
}

/// Symmetric Hausdorff distance (sampled at vertices and face centroids) between two triangle
/// surfaces, divided by the bounding-box diagonal of the second (the reference input).
/// `a_centroids`: also sample A's face centroids (not needed when every face of A is known to lie
/// inside one face of B, as for the overlay metamesh: then A's vertices bound the distance).
pub fn relative_hausdorff(
    pa: &[Point3],
    ta: &[[u32; 3]],
    pb: &[Point3],
    tb: &[[u32; 3]],
    a_centroids: bool,
    progress: &Progress,
) -> Result<f64> {
    let (ia, ib) = rayon::join(
        || Bvh::new_polled(pa, &Faces::from_triangles(ta), progress),
        || Bvh::new_polled(pb, &Faces::from_triangles(tb), progress),
    );
    let (ia, ib) = (ia?, ib?);
    let d = one_sided(pa, ta, &ib, a_centroids, progress)?.max(one_sided(pb, tb, &ia, true, progress)?);
    let diag = Aabb::of(pb).map(|b| b.diagonal()).unwrap_or(1.0).max(1e-300);
    Ok(d / diag)
}

/// Largest feature gap (radians on the sphere, units of the unit disk in the plane) above which
/// the report warns that the pairs did not meet.
pub const FEATURE_GAP_WARN: f64 = 1e-6;

/// The report's `warnings`: says when feature pairs were asked for but did not meet, so a stalled
/// warp (it stops rather than fold the map) is not silent.
pub fn feature_warnings(feature_points: usize, gap_after: f64, unit: &str) -> Vec<String> {
    if feature_points == 0 || gap_after <= FEATURE_GAP_WARN {
        return Vec::new();
    }
    vec![format!(
        "feature pairs did not meet: the largest remaining gap is {gap_after:.3e} {unit} (the warp stops \
         before it would fold the map; see features.warp_steps); try fewer or more consistent pairs"
    )]
}
