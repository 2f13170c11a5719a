//! Template refinement near dense curves, after the approach and before the fine fit: every template face that holds
//! the feet (closest points) of more than `max_feet` curve vertices is split 1→4, with conforming
//! closure, and the count is made again, until no face holds too many or the budget is spent.
//!
//! Why: the insertion ([`super::insert`]) gives every curve vertex a template vertex of its own by
//! splitting the face under its foot. A coarse face under a dense curve (measured: an 80-face
//! icosphere under 5040 curve vertices, ~60 feet per face) is then cut into a fan of slivers that
//! all share the face's three corners; the fine RBF moves the feet onto the curved surface while
//! the corners stay where the flat face put them, and the slivers fold (301 flipped faces, min
//! angle 0.1°), with nothing free between the curve vertices for the untangling to move. With at
//! most `max_feet` feet per face, every curve vertex has template vertices of its own scale around
//! it, and the seed's local subdivision (§2.3.2) is applied where it is needed before the
//! deformation rather than after it folds.
//!
//! The split is red–green: a face with two or more split edges is split 1→4 too (repeated until
//! stable), so the only partial splits are bisections across one edge, and angles stay those of
//! the template in the red faces. New vertices are edge midpoints (their parents are recorded for
//! UVs and template groups); they lie on the approached template's flat faces, and the fine RBF
//! that follows moves them with their neighbours.

use std::collections::HashMap;

use serde::Serialize;

use crate::error::Result;
use crate::geometry::dist;
use crate::job::Progress;
use crate::mesh::Point3;

use super::curves::CurveNetwork;
use super::insert::FootSearch;

/// What the refinement did (the report's `refine`).
#[derive(Debug, Clone, Default, Serialize)]
pub struct RefineReport {
    /// A face holding more feet than this starts the refinement (0: refinement off).
    pub dense_feet: u32,
    /// Feet of dense curve vertices a face may hold when the refinement ends.
    pub max_feet_per_face: u32,
    /// Curve vertices whose foot was in a face holding more than `dense_feet` feet.
    pub dense_curve_vertices: usize,
    pub rounds: u32,
    /// Faces that held too many feet and were longer than the curve spacing there, per round
    /// (each split 1→4).
    pub over_full_per_round: Vec<usize>,
    /// Template faces split (red 1→4 and green closure bisections), over all rounds.
    pub faces_refined: usize,
    /// Faces the refinement added (output faces − input faces).
    pub faces_added: usize,
    pub vertices_added: usize,
    /// Largest number of feet in one face before, and of dense feet in one face after.
    pub feet_per_face_max_before: usize,
    pub feet_per_face_max_after: usize,
    /// True when the face budget or the round cap stopped the refinement with faces still
    /// over-full.
    pub budget_reached: bool,
    /// Milliseconds (part of the `fine` stage, after the approach).
    pub ms: f64,
}

/// Refines `pos`/`tris` near dense curves (see the module doc): the curve vertices whose feet
/// share a face with more than `dense_feet` others' are dense, and faces holding more than
/// `max_feet` dense feet are split until none does. `parents` gets one entry per new vertex, in
/// order. The face budget is `max_faces` in total.
///
/// `search` is the closest-point search on `pos`/`tris` as given; on return it is the one on the
/// refined template (the same when nothing was split), for the insertion that follows: one BVH
/// over the template instead of one here and one there (~75 ms on the headline's 190k faces).
#[allow(clippy::too_many_arguments)]
pub fn refine_near_curves(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    net: &CurveNetwork,
    search: &mut FootSearch,
    dense_feet: u32,
    max_feet: u32,
    max_faces: usize,
    parents: &mut Vec<[(u32, f64); 3]>,
    progress: &Progress,
) -> Result<RefineReport> {
    let max_feet = max_feet.max(1).min(dense_feet.max(1));
    let mut report = RefineReport { dense_feet, max_feet_per_face: max_feet, ..Default::default() };
    if dense_feet == 0 || net.points.is_empty() {
        return Ok(report);
    }
    let (f0, v0) = (tris.len(), pos.len());
    // Dense curve vertices: those whose foot shares a face with too many others. Only they drive
    // the refinement, so a template already as fine as its curves is left as it is.
    let all_feet = search.all_feet(&net.points)?;
    let mut count = vec![0usize; tris.len()];
    for f in all_feet {
        count[f.0 as usize] += 1;
    }
    report.feet_per_face_max_before = count.iter().copied().max().unwrap_or(0);
    let dense: Vec<u32> = (0..net.points.len() as u32)
        .filter(|&p| count[all_feet[p as usize].0 as usize] > dense_feet as usize)
        .collect();
    report.dense_curve_vertices = dense.len();
    if dense.is_empty() {
        return Ok(report);
    }
    let spacing = super::insert::shortest_segments(net);
    for round in 0..=MAX_ROUNDS {
        progress.check()?;
        if round > 0 {
            *search = FootSearch::new_polled(pos, tris, progress)?;
        }
        let (face, count) = feet_per_face(search, tris.len(), net, &dense)?;
        report.feet_per_face_max_after = count.iter().copied().max().unwrap_or(0);
        // A face already shorter than the curve's own spacing is not split again: feet crowded
        // there come from a curve passing beyond a convex corner or crease of the surface (their
        // closest points pile up), which no finer face separates.
        let mut finest = vec![f64::INFINITY; tris.len()];
        for &p in &dense {
            let f = face[p as usize] as usize;
            finest[f] = finest[f].min(spacing[p as usize]);
        }
        let longest = |f: usize| {
            let t = tris[f];
            (0..3).map(|k| dist(pos[t[k] as usize], pos[t[(k + 1) % 3] as usize])).fold(0.0, f64::max)
        };
        let over: Vec<u32> = (0..tris.len() as u32)
            .filter(|&f| count[f as usize] > max_feet as usize && longest(f as usize) > finest[f as usize])
            .collect();
        if over.is_empty() {
            break;
        }
        let red = red_closure(tris, &over);
        // A red face becomes 4, a green one 2: stop before the budget is passed.
        if round == MAX_ROUNDS || tris.len() + 6 * red.len() > max_faces {
            report.budget_reached = true;
            break;
        }
        report.over_full_per_round.push(over.len());
        let before = tris.len();
        super::flips::subdivide(pos, tris, &red, parents);
        // Faces touched: every red face, and one per green bisection (each adds one face).
        let green = tris.len() - before - 3 * red.len();
        report.faces_refined += red.len() + green;
        report.rounds += 1;
    }
    report.faces_added = tris.len() - f0;
    report.vertices_added = pos.len() - v0;
    Ok(report)
}

/// Rounds of 1→4 splits at most: 6 rounds take a face to 4⁶ = 4096 pieces.
const MAX_ROUNDS: u32 = 6;

/// The face of each curve point's foot (indexed by curve point; `which` only) and the number of
/// those feet in each face.
fn feet_per_face(
    search: &FootSearch,
    faces: usize,
    net: &CurveNetwork,
    which: &[u32],
) -> Result<(Vec<u32>, Vec<usize>)> {
    let feet = search.feet(&net.points, which)?;
    let mut count = vec![0usize; faces];
    let mut face = vec![u32::MAX; net.points.len()];
    for (&p, (f, _, _)) in which.iter().zip(feet) {
        count[f as usize] += 1;
        face[p as usize] = f;
    }
    Ok((face, count))
}

/// The faces to split 1→4: `over` plus every face that would otherwise have two or more split
/// edges (the closure that leaves only single-edge bisections to keep the mesh conforming).
pub(super) fn red_closure(tris: &[[u32; 3]], over: &[u32]) -> Vec<u32> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut faces_of_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            faces_of_edge.entry(key(t[k], t[(k + 1) % 3])).or_default().push(f as u32);
        }
    }
    let mut red = vec![false; tris.len()];
    let mut split: std::collections::HashSet<(u32, u32)> = std::collections::HashSet::new();
    let mut stack: Vec<u32> = over.to_vec();
    while let Some(f) = stack.pop() {
        if red[f as usize] {
            continue;
        }
        red[f as usize] = true;
        let t = tris[f as usize];
        for k in 0..3 {
            let e = key(t[k], t[(k + 1) % 3]);
            if !split.insert(e) {
                continue;
            }
            // The faces across this edge now have one more split edge: two or more make them red.
            for &g in faces_of_edge.get(&e).map(|v| v.as_slice()).unwrap_or(&[]) {
                if red[g as usize] {
                    continue;
                }
                let s = tris[g as usize];
                let n = (0..3).filter(|&j| split.contains(&key(s[j], s[(j + 1) % 3]))).count();
                if n >= 2 {
                    stack.push(g);
                }
            }
        }
    }
    (0..tris.len() as u32).filter(|&f| red[f as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense_circle(n: usize, z: f64) -> CurveNetwork {
        let r = (1.0 - z * z).sqrt();
        let positions: Vec<Point3> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                [r * t.cos(), r * t.sin(), z]
            })
            .collect();
        let mut line: Vec<u32> = (0..n as u32).collect();
        line.push(0);
        let m = crate::mesh::Mesh { positions, curves: vec![line], ..Default::default() };
        CurveNetwork::from_mesh(&m, 1e-9).expect("network")
    }

    #[test]
    fn no_face_holds_more_than_the_allowed_feet_and_the_mesh_stays_a_closed_manifold() {
        let ico = crate::shapes::icosphere(1, 1.0);
        let mut tris = crate::shapes::fan_triangles(&ico.faces);
        let mut pos = ico.positions.clone();
        let net = dense_circle(400, 0.3);
        let mut parents = Vec::new();
        let mut search = FootSearch::new(&pos, &tris).unwrap();
        let r = refine_near_curves(
            &mut pos,
            &mut tris,
            &net,
            &mut search,
            4,
            2,
            100_000,
            &mut parents,
            &Progress::new(),
        )
        .expect("refine");
        // The search handed back is the refined template's: the same feet as a fresh one.
        let all: Vec<u32> = (0..400).collect();
        let fresh = FootSearch::new(&pos, &tris).unwrap().feet(&net.points, &all).unwrap();
        assert_eq!(search.into_all_feet(&net.points).unwrap(), fresh);
        // 400 feet on a band of the 80 faces: far more than 2 per face before.
        assert!(r.feet_per_face_max_before > 10, "{r:?}");
        // Nearly every curve vertex of this circle is dense (faces under it hold more than 4; a
        // face the circle only grazes may hold fewer).
        assert!(r.dense_curve_vertices > 350, "{r:?}");
        let search = FootSearch::new(&pos, &tris).unwrap();
        let after = feet_per_face(&search, tris.len(), &net, &(0..400).collect::<Vec<_>>()).unwrap().1;
        assert!(after.into_iter().max().unwrap() <= 4);
        assert!(r.feet_per_face_max_after <= 2, "{r:?}");
        assert!(!r.budget_reached);
        assert_eq!(parents.len(), pos.len() - ico.positions.len());
        assert_eq!(r.faces_added, tris.len() - 80);
        // Closed, conforming, consistently oriented: every directed edge once, its twin once.
        crate::fit::trimesh::check_oriented_manifold(&tris).expect("manifold");
        let mut seen = std::collections::HashSet::new();
        for t in &tris {
            for k in 0..3 {
                assert!(seen.insert((t[k], t[(k + 1) % 3])));
            }
        }
        for &(a, b) in &seen {
            assert!(seen.contains(&(b, a)), "open edge {a}-{b}");
        }
        // Euler characteristic of a sphere.
        assert_eq!(pos.len() as i64 - seen.len() as i64 / 2 + tris.len() as i64, 2);
        // The refinement is local: faces far from the circle (z = 0.3) are the template's.
        let far = |pos: &[Point3], tris: &[[u32; 3]]| {
            tris.iter().filter(|t| t.iter().all(|&v| pos[v as usize][2] < -0.5)).count()
        };
        let template_far = far(&ico.positions, &crate::shapes::fan_triangles(&ico.faces));
        assert!(template_far > 0);
        assert_eq!(far(&pos, &tris), template_far);
    }

    #[test]
    fn the_budget_stops_the_refinement_and_says_so() {
        let ico = crate::shapes::icosphere(1, 1.0);
        let mut tris = crate::shapes::fan_triangles(&ico.faces);
        let mut pos = ico.positions.clone();
        let net = dense_circle(400, 0.3);
        let mut search = FootSearch::new(&pos, &tris).unwrap();
        let r = refine_near_curves(
            &mut pos,
            &mut tris,
            &net,
            &mut search,
            1,
            1,
            150,
            &mut Vec::new(),
            &Progress::new(),
        )
        .expect("refine");
        assert!(r.budget_reached);
        assert!(tris.len() <= 150);
    }

    #[test]
    fn off_or_sparse_curves_leave_the_template_untouched() {
        let ico = crate::shapes::icosphere(1, 1.0);
        for (n, dense_feet) in [(100, 0), (12, 4)] {
            // 12 points on the equator of an 80-face icosphere: at most 2 per face, none dense.
            let mut tris = crate::shapes::fan_triangles(&ico.faces);
            let mut pos = ico.positions.clone();
            let mut search = FootSearch::new(&pos, &tris).unwrap();
            let r = refine_near_curves(
                &mut pos,
                &mut tris,
                &dense_circle(n, 0.0),
                &mut search,
                dense_feet,
                1,
                1 << 20,
                &mut Vec::new(),
                &Progress::new(),
            )
            .expect("refine");
            assert_eq!((r.rounds, r.dense_curve_vertices, tris.len(), pos.len()), (0, 0, 80, 42));
        }
    }
}
