//! Feet that follow their curve: each curve vertex's foot is searched only on the part of the
//! template connected to the previous vertex's foot within a ball around it, not anywhere.
//!
//! Why: a closest point is a global choice. Where two sheets of the template come close (homer's
//! two feet, 0.019 apart, with the coarsely aligned template 0.02 off the curves), the closest
//! point of a curve vertex lands on the other sheet, and its neighbours' stay on the right one:
//! the curve's vertices are then inserted in a different order than along the curve, the fine RBF
//! folds the surface carrying them back, and the curve's own chains enclose the ends of its next
//! segment ("separated" in the re-triangulation). Measured on the bent homer with pairs: feet
//! steps of 0.05 for curve steps of 0.005, then feet piled 0.0003 apart.
//!
//! The bound is exact for the true closest point: if the previous vertex `x₀` is `d₀` from its
//! foot `f₀`, the next vertex `x` (a step `|x − x₀|` on) has a surface point within
//! `d₀ + |x − x₀|` (that foot), so its closest point lies within `R = 2 d₀ + 2 |x − x₀|` of `f₀`.
//! Searching the faces reachable from `f₀`'s face without leaving that ball keeps the global
//! answer whenever it is on the same sheet, and refuses the jump to another sheet that only
//! passes near. Walks start afresh at every anchor (feature point, curve end, user pair), whose
//! own closest point is kept.

use crate::error::Result;
use crate::geometry::dist;
use crate::job::Progress;
use crate::mesh::Point3;
use crate::spatial::closest_on_triangle;

use super::super::curves::CurveNetwork;

/// Most faces one walked foot may search (the ball is a few curve steps wide).
const FACE_BUDGET: usize = 20_000;

/// Replaces the feet of non-anchor points by walked feet along each polyline; returns how many
/// changed. `feet` = (face, point, distance) per curve point, the closest points on entry.
pub fn walk_feet(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    net: &CurveNetwork,
    feet: &mut [(u32, Point3, f64)],
    anchor: &[bool],
    progress: &Progress,
) -> Result<usize> {
    walk_feet_directed(pos, tris, vf, net, feet, anchor, false, progress)
}

/// [`walk_feet`] along each polyline's order, or against it (`backward`): a walk that went
/// astray from one side is caught by the other side's disagreeing (the approach levels use both).
#[allow(clippy::too_many_arguments)]
pub fn walk_feet_directed(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    net: &CurveNetwork,
    feet: &mut [(u32, Point3, f64)],
    anchor: &[bool],
    backward: bool,
    progress: &Progress,
) -> Result<usize> {
    let mut changed = 0;
    let mut done = vec![false; net.points.len()];
    let mut seen = SeenFaces::new(tris.len());
    let mut heap = std::collections::BinaryHeap::new();
    let mut reversed: Vec<u32> = Vec::new();
    let mut walks = 0;
    for line in &net.polylines {
        let line: &[u32] = if backward {
            reversed.clear();
            reversed.extend(line.iter().rev());
            &reversed
        } else {
            line
        };
        for w in line.windows(2) {
            // A walk searches up to a ball of faces: a poll every 256 walks is a few ms.
            walks += 1;
            progress.check_every(walks, 256)?;
            let (p0, p) = (w[0] as usize, w[1] as usize);
            if anchor[p] || done[p] {
                continue;
            }
            done[p] = true;
            let (f0, x0, d0) = feet[p0];
            let step = dist(net.points[p0], net.points[p]);
            let radius = 2.0 * (d0 + step) * (1.0 + 1e-9) + 1e-12;
            let target = (feet[p].0, feet[p].1);
            let Some(walked) =
                nearest_connected(pos, tris, vf, &mut seen, &mut heap, f0, x0, net.points[p], radius, target)
            else {
                continue;
            };
            if walked.0 != feet[p].0 && walked.2 > feet[p].2 * (1.0 + 1e-9) {
                changed += 1;
                feet[p] = walked;
            }
        }
    }
    Ok(changed)
}

/// Component of each face, numbered from 0 in face order (faces sharing a vertex are connected,
/// as in the walk): all 0 for a template in one piece.
pub fn face_components(nv: usize, tris: &[[u32; 3]]) -> Vec<u32> {
    use crate::topology::{find, union};
    let mut parent: Vec<u32> = (0..nv as u32).collect();
    for t in tris {
        union(&mut parent, t[0], t[1]);
        union(&mut parent, t[0], t[2]);
    }
    let mut label = vec![u32::MAX; nv];
    let mut next = 0;
    tris.iter()
        .map(|t| {
            let r = find(&mut parent, t[0]) as usize;
            if label[r] == u32::MAX {
                label[r] = next;
                next += 1;
            }
            label[r]
        })
        .collect()
}

/// The faces one walk has met: a mark per face, cleared in O(1) per walk by a new generation
/// (a hash set per walk cost ~10 % of the headline's fit: 2k walks of ~100 faces each).
struct SeenFaces {
    mark: Vec<u32>,
    generation: u32,
    count: usize,
}

impl SeenFaces {
    fn new(faces: usize) -> Self {
        SeenFaces { mark: vec![0; faces], generation: 0, count: 0 }
    }

    /// Forgets every face (a new walk).
    fn clear(&mut self) {
        self.generation += 1;
        self.count = 0;
        if self.generation == u32::MAX {
            self.mark.fill(0);
            self.generation = 1;
        }
    }

    /// Marks `f`; false when it was already marked in this walk.
    fn insert(&mut self, f: u32) -> bool {
        let m = &mut self.mark[f as usize];
        if *m == self.generation {
            return false;
        }
        *m = self.generation;
        self.count += 1;
        true
    }
}

/// The search's frontier: (distance of the face's centroid from the closest point, as ordered
/// bits of a non-negative f64, face), nearest first.
type Frontier = std::collections::BinaryHeap<std::cmp::Reverse<(u64, u32)>>;

/// The closest point to `x` on the faces reachable from `start` (through shared vertices)
/// without leaving the ball of `radius` around `centre`; None past the face budget.
///
/// The search stops at `closest`, the face and point of the global closest point: once it is
/// reached nothing reachable can be closer. Faces nearest that point are visited first (the order
/// does not change the answer, only how soon it is found), so where the foot stays on the previous
/// foot's sheet (nearly always) the search is the few faces between the two feet instead of the
/// whole ball, which makes walking every curve point affordable in the approach levels
/// ([`super::super::approach`]).
#[allow(clippy::too_many_arguments)]
fn nearest_connected(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    seen: &mut SeenFaces,
    heap: &mut Frontier,
    start: u32,
    centre: Point3,
    x: Point3,
    radius: f64,
    closest: (u32, Point3),
) -> Option<(u32, Point3, f64)> {
    use std::cmp::Reverse;
    let corners = |f: u32| tris[f as usize].map(|v| pos[v as usize]);
    seen.clear();
    heap.clear();
    heap.push(Reverse((0u64, start)));
    seen.insert(start);
    let mut best: Option<(u32, Point3, f64)> = None;
    while let Some(Reverse((_, f))) = heap.pop() {
        let q = closest_on_triangle(x, &corners(f));
        let d = dist(q, x);
        if best.is_none_or(|b| d < b.2) {
            best = Some((f, q, d));
        }
        if f == closest.0 {
            return best;
        }
        for &v in &tris[f as usize] {
            for &g in &vf[v as usize] {
                if !seen.insert(g) {
                    continue;
                }
                let c = corners(g);
                if dist(closest_on_triangle(centre, &c), centre) <= radius {
                    let mid = [0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
                    heap.push(Reverse((dist(mid, closest.1).to_bits(), g)));
                }
            }
        }
        if seen.count > FACE_BUDGET {
            return None;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// A straight run of `n` points 0.03 above the lower sheet of the two-sheet plate, its
    /// network, its feet (closest points) and the plate's vertex-face lists.
    fn run_over_plate(
        n: usize,
    ) -> (Vec<Point3>, Vec<[u32; 3]>, Vec<Vec<u32>>, CurveNetwork, Vec<(u32, Point3, f64)>) {
        let (pos, tris) = crate::fit::insert::tests::two_sheet_plate();
        let mut vf = vec![Vec::new(); pos.len()];
        for (f, t) in tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(f as u32);
            }
        }
        let pts: Vec<Point3> = (0..n).map(|k| [0.05 + 0.9 * k as f64 / (n - 1) as f64, 0.45, 0.03]).collect();
        let curves = crate::mesh::Mesh {
            positions: pts.clone(),
            curves: vec![(0..n as u32).collect()],
            ..Default::default()
        };
        let net = CurveNetwork::from_mesh(&curves, 1e-9).unwrap();
        let all: Vec<u32> = (0..net.points.len() as u32).collect();
        let feet = crate::fit::insert::feet(&pos, &tris, &net.points, &all).unwrap();
        (pos, tris, vf, net, feet)
    }

    /// One walk per curve segment, each searching up to 20,000 faces, and ~2,000 of them per
    /// level on the headline: a poll every 256 walks. A 1,000-point run has 999 walks per
    /// direction: polls at walks 256, 512 and 768, three each way; a cancel stops the walks.
    #[test]
    fn walks_poll_every_256_segments_and_stop_at_a_cancel() {
        let (pos, tris, vf, net, feet) = run_over_plate(1000);
        assert_eq!(net.polylines.len(), 1);
        assert_eq!(net.polylines[0].len(), 1000, "the case: one run of 1,000 points");
        let anchor: Vec<bool> = net.degree.iter().map(|&d| d != 2).collect();
        for backward in [false, true] {
            let p = Progress::new();
            let mut walked = feet.clone();
            let changed =
                walk_feet_directed(&pos, &tris, &vf, &net, &mut walked, &anchor, backward, &p).unwrap();
            assert_eq!(p.checks(), 3, "backward {backward}");
            // Every point is nearest the lower sheet: the walks keep the closest points.
            assert_eq!(changed, 0);
            assert!(walked.iter().all(|f| f.1[2] == 0.0));
            let p = Progress::new();
            p.cancel_at_check(2);
            let mut walked = feet.clone();
            let r = walk_feet_directed(&pos, &tris, &vf, &net, &mut walked, &anchor, backward, &p);
            assert!(matches!(r, Err(Error::Cancelled)), "backward {backward}");
            assert_eq!(p.checks(), 2);
        }
        let p = Progress::new();
        let mut walked = feet.clone();
        walk_feet(&pos, &tris, &vf, &net, &mut walked, &anchor, &p).unwrap();
        assert_eq!(p.checks(), 3);
    }
}
