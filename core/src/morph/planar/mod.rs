//! The planar domain for disk-like inputs (one boundary loop, genus 0): seed 002 §3.4 ELRP.
//!
//! - Boundary on the unit circle by arc length (eq. IV.41–IV.43: α_{i+1} − α_i ∝ 3D edge length).
//! - Interior: the spring system Σ_j w_ij (φ_j − φ_i) = 0 with ELRP weights w_ij = l_ij (the 3D edge
//!   length, *proportional* to length as printed in eq. IV.44–IV.46; symmetric, so one sparse
//!   Cholesky factorisation serves both coordinates), or uniform (Tutte) weights.
//!   Every weight is positive and the boundary is strictly convex, so Tutte/Floater's theorem says
//!   the map is an embedding; we still count flipped triangles (floating point can flip slivers)
//!   and fall back to Tutte weights if ELRP's map has any, saying so in the report.
//! - Points of the plane are carried *lifted* as (x, y, 1): then the sphere code's predicates
//!   (`orient` = det(a, b, c), `bary_on_chord`, the walking `Locator`, AD/SD) compute exactly
//!   the planar quantities (det of lifted points = twice the signed area; the ray from the origin
//!   through a lifted point meets the plane z = 1 at the point itself).
//! - Boundary correspondence: each disk is rotated so its boundary matches input 0's (least squares
//!   over the normalised 3D boundary curves; with feature pairs, the mean angle between them).
//! - Feature alignment: the same stepwise CTPS C²a warp as on the sphere, in the plane, with the
//!   boundary vertices projected back onto the circle after every step and a fold-over check.
//! - Common boundary: the union of all inputs' boundary angles is inserted into every disk's
//!   boundary edges (splitting the boundary triangles; the new vertex lies on the 3D boundary edge,
//!   so the surface is unchanged). All disks then cover the *same* convex polygon, which is what a
//!   2-D overlay of two triangulations needs.
//!
//! This file holds the disk map's entry point ([`parameterise`]), the topology tests and the
//! boundary loop; [`springs`] the spring system, [`rotation`] the boundary correspondence,
//! [`features`] the feature warp, [`common_rim`] the common boundary and the interior jitter.

use crate::error::{Error, Result};
use crate::mesh::Point3;

use super::param::{count_foldovers, orient};
use super::trimesh::{TopologyInfo, TriMesh};

mod common_rim;
mod features;
mod rotation;
mod springs;

pub use common_rim::{jitter_interior, union_angles, with_common_boundary, CommonDisk};
pub use features::{align_features, PlaneAlignReport};
pub use rotation::{boundary_rotation, feature_rotation, rotate};
pub use springs::arc_length_angles;
use springs::solve_interior;
pub(in crate::morph) use springs::solve_springs;

/// Lifts a plane point to (x, y, 1).
#[inline]
pub fn lift(x: f64, y: f64) -> Point3 {
    [x, y, 1.0]
}

/// Whether the topology is a disk: connected, manifold, one boundary loop, V − E + F = 1.
pub fn is_disk(info: &TopologyInfo) -> bool {
    info.faces >= 1
        && info.components == 1
        && info.boundary_loops == 1
        && info.non_manifold_edges == 0
        && info.non_manifold_vertices == 0
        && info.euler_characteristic == 1
}

/// Genus of a connected manifold surface with `b` boundary loops: χ = 2 − 2g − b.
pub fn genus_of(info: &TopologyInfo) -> Option<i64> {
    (info.components == 1 && info.non_manifold_edges == 0 && info.non_manifold_vertices == 0)
        .then(|| 2 - info.boundary_loops as i64 - info.euler_characteristic)
        .filter(|x| x % 2 == 0)
        .map(|x| x / 2)
}

/// The refusal for an input that is neither a closed genus-0 surface nor a disk.
pub fn describe(info: &TopologyInfo) -> String {
    let mut s = info.defects();
    match genus_of(info) {
        Some(g) => s.push(format!("genus {g} with {} boundary loops", info.boundary_loops)),
        None => s.push(format!(
            "{} boundary loops, Euler characteristic {}",
            info.boundary_loops, info.euler_characteristic
        )),
    }
    s.join(", ")
}

/// The boundary loop, ordered along the boundary half-edges (a → b where a face lists a → b):
/// with counter-clockwise faces this runs counter-clockwise around the disk.
pub fn boundary_loop(m: &TriMesh) -> Result<Vec<u32>> {
    use std::collections::HashMap;
    let mut half: HashMap<(u32, u32), ()> = HashMap::with_capacity(m.tris.len() * 3);
    for t in &m.tris {
        for k in 0..3 {
            half.insert((t[k], t[(k + 1) % 3]), ());
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in half.keys() {
        if !half.contains_key(&(b, a)) && next.insert(a, b).is_some() {
            return Err(Error::Topology(format!("vertex {a} has two outgoing boundary edges")));
        }
    }
    let start = *next.keys().min().ok_or_else(|| Error::Topology("no boundary".into()))?;
    let mut lp = vec![start];
    let mut v = start;
    loop {
        v = *next.get(&v).ok_or_else(|| Error::Topology("boundary does not close".into()))?;
        if v == start {
            break;
        }
        lp.push(v);
        if lp.len() > next.len() {
            return Err(Error::Topology("boundary loop does not close".into()));
        }
    }
    if lp.len() != next.len() {
        return Err(Error::Topology(format!(
            "more than one boundary loop ({} of {} boundary edges in the first)",
            lp.len(),
            next.len()
        )));
    }
    Ok(lp)
}

/// Interior weights of the spring system.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize, utoipa::ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum PlanarMethod {
    /// Seed 002's ELRP: w_ij = 3D edge length (eq. IV.44, as printed), boundary by arc length.
    #[default]
    Elrp,
    /// Tutte's uniform weights (w_ij = 1), boundary by arc length.
    Tutte,
    /// Inverse edge length (w_ij = 1/l_ij: Greiner–Hormann r = 1, the reading of eq. IV.44 with
    /// the proportionality inverted), boundary by arc length.
    InverseLength,
}

/// A disk map: lifted plane positions, the boundary loop and each boundary vertex's angle.
#[derive(Clone, Debug)]
pub struct DiskMap {
    pub plane: Vec<Point3>,
    pub boundary: Vec<u32>,
    pub angles: Vec<f64>,
    pub report: PlanarReport,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PlanarReport {
    pub method: String,
    pub fallback_reason: Option<String>,
    pub boundary_vertices: usize,
    /// Flipped (non-positive) plane triangles of the final map: must be 0.
    pub foldovers: usize,
    /// AD (eq. IV.64, radians) and SD (eq. IV.65) between the 3D mesh and its plane triangles.
    pub angle_distortion: f64,
    pub area_distortion: f64,
}

/// The disk map of a disk-topology mesh (counter-clockwise faces), with the embedding check and
/// the Tutte fallback.
pub fn parameterise(m: &TriMesh, method: PlanarMethod) -> Result<DiskMap> {
    let lp = boundary_loop(m)?;
    let angles = arc_length_angles(&m.pos, &lp);
    let mut rep = PlanarReport {
        method: match method {
            PlanarMethod::Elrp => "elrp",
            PlanarMethod::Tutte => "tutte",
            PlanarMethod::InverseLength => "inverse_length",
        }
        .into(),
        boundary_vertices: lp.len(),
        ..Default::default()
    };
    let mut plane = solve_interior(m, &lp, &angles, method)?;
    let mut folds = count_foldovers(&plane, &m.tris);
    if folds > 0 && method != PlanarMethod::Tutte {
        rep.fallback_reason = Some(format!(
            "{folds} flipped triangles in the {} map (floating point on slivers); used Tutte weights",
            rep.method
        ));
        rep.method = "tutte".into();
        plane = solve_interior(m, &lp, &angles, PlanarMethod::Tutte)?;
        folds = count_foldovers(&plane, &m.tris);
    }
    rep.foldovers = folds;
    let (ad, sd) = crate::morph::param::distortion(&m.pos, &plane, &m.tris);
    rep.angle_distortion = ad;
    rep.area_distortion = sd;
    Ok(DiskMap { plane, boundary: lp, angles, report: rep })
}

/// Signed area test used by the job's checks: flipped triangles of a lifted map.
pub fn foldovers(plane: &[Point3], tris: &[[u32; 3]]) -> usize {
    tris.iter()
        .filter(|t| !(orient(plane[t[0] as usize], plane[t[1] as usize], plane[t[2] as usize]) > 0.0))
        .count()
}

#[cfg(test)]
mod tests {
    use super::rotation::restart_at_min;
    use super::*;
    use crate::geometry::dist;
    use crate::shapes;
    use std::f64::consts::TAU;

    fn disk(n: usize) -> TriMesh {
        // A grid in a circle: the square grid's points pushed radially onto the disk (the
        // "concentric" square→disk map), so the boundary is a circle and the interior is uneven.
        let (mut g, _, _) = TriMesh::from_mesh(&shapes::grid(n, n, 2.0 / n as f64, false));
        for p in &mut g.pos {
            let (x, y) = (p[0] - 1.0, p[1] - 1.0);
            let r = x.abs().max(y.abs());
            let l = x.hypot(y);
            let f = if l > 0.0 { r / l } else { 0.0 };
            p[0] = x * f;
            p[1] = y * f;
        }
        g
    }

    #[test]
    fn a_flat_disk_maps_without_flips_and_with_its_boundary_on_the_circle() {
        let g = disk(8);
        for method in [PlanarMethod::Elrp, PlanarMethod::Tutte, PlanarMethod::InverseLength] {
            let m = parameterise(&g, method).unwrap();
            assert_eq!(m.report.foldovers, 0);
            assert_eq!(m.report.fallback_reason, None);
            for &v in &m.boundary {
                let p = m.plane[v as usize];
                assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12);
            }
            // Each interior vertex is the weighted mean of its neighbours (the system's equation).
            let mut nb = vec![Vec::new(); g.pos.len()];
            for (a, b) in g.edges() {
                nb[a as usize].push(b);
                nb[b as usize].push(a);
            }
            let is_b: std::collections::HashSet<u32> = m.boundary.iter().copied().collect();
            for v in 0..g.pos.len() {
                if is_b.contains(&(v as u32)) {
                    continue;
                }
                let w = |u: u32| match method {
                    PlanarMethod::Tutte => 1.0,
                    PlanarMethod::Elrp => dist(g.pos[v], g.pos[u as usize]),
                    PlanarMethod::InverseLength => 1.0 / dist(g.pos[v], g.pos[u as usize]),
                };
                let ws: f64 = nb[v].iter().map(|&u| w(u)).sum();
                for c in 0..2 {
                    let mean: f64 = nb[v].iter().map(|&u| w(u) * m.plane[u as usize][c]).sum::<f64>() / ws;
                    assert!((mean - m.plane[v][c]).abs() < 1e-10);
                }
            }
        }
    }

    #[test]
    fn arc_length_angles_follow_edge_lengths() {
        // A square boundary with sides 1, 1, 1, 1 split at one extra point on side 0 (0.25/0.75).
        let pos = vec![[0.0, 0.0, 0.0], [0.25, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let a = arc_length_angles(&pos, &[0, 1, 2, 3, 4]);
        let want = [0.0, 0.25, 1.0, 2.0, 3.0].map(|x| TAU * x / 4.0);
        for (x, y) in a.iter().zip(want) {
            assert!((x - y).abs() < 1e-12, "{a:?}");
        }
    }

    #[test]
    fn rotation_of_a_shifted_parameterisation_is_recovered() {
        let g = disk(6);
        let m = parameterise(&g, PlanarMethod::Elrp).unwrap();
        // B is the same surface with every boundary angle advanced by 0.3 (and re-sorted): B's
        // point at θ + 0.3 is A's at θ, so the best rotation is 0.3.
        let mut mb = m.clone();
        for a in &mut mb.angles {
            *a = (*a + 0.3).rem_euclid(TAU);
        }
        restart_at_min(&mut mb);
        let phi = boundary_rotation(&g.pos, &m.boundary, &m.angles, &g.pos, &mb.boundary, &mb.angles);
        assert!((phi - 0.3).abs() < 1e-3, "{phi}");
        // Rotating B by it brings its angles back onto A's.
        rotate(&mut mb, phi);
        let want: std::collections::HashMap<u32, f64> =
            m.boundary.iter().copied().zip(m.angles.clone()).collect();
        for (v, a) in mb.boundary.iter().zip(&mb.angles) {
            let d = (a - want[v]).rem_euclid(TAU);
            assert!(d.min(TAU - d) < 1e-3, "vertex {v}: {a} vs {}", want[v]);
        }
    }

    #[test]
    fn common_boundary_keeps_the_surface_and_the_embedding() {
        let g = disk(6);
        let h = disk(9);
        let mg = parameterise(&g, PlanarMethod::Elrp).unwrap();
        let mut mh = parameterise(&h, PlanarMethod::Elrp).unwrap();
        rotate(&mut mh, 0.1234);
        assert!(foldovers(&mh.plane, &h.tris) == 0);
        let u = union_angles(&[mg.clone(), mh.clone()]);
        assert_eq!(u.len(), mg.boundary.len() + mh.boundary.len());
        for (m, map) in [(&g, &mg), (&h, &mh)] {
            let cd = with_common_boundary(m, map, &u).unwrap();
            assert_eq!(foldovers(&cd.plane, &cd.tris), 0);
            assert_eq!(cd.bnd.iter().filter(|&&b| b != u32::MAX).count(), u.len());
            // 3D area unchanged (the new vertices lie on the boundary edges).
            let area = |p: &[Point3], t: &[[u32; 3]]| {
                t.iter()
                    .map(|t| {
                        crate::geometry::triangle_area(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize])
                    })
                    .sum::<f64>()
            };
            assert!((area(&cd.pos, &cd.tris) - area(&m.pos, &m.tris)).abs() < 1e-12);
            // Plane area is the common polygon's.
            let poly: f64 =
                (0..u.len()).map(|j| 0.5 * (u[(j + 1) % u.len()] - u[j]).rem_euclid(TAU).sin()).sum();
            assert!((area(&cd.plane, &cd.tris) - poly).abs() < 1e-9);
        }
    }
}
