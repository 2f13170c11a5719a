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
    let mut changed = 0;
    let mut done = vec![false; net.points.len()];
    let mut seen = SeenFaces::new(tris.len());
    let mut walks = 0;
    for line in &net.polylines {
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
            let Some(walked) = nearest_connected(pos, tris, vf, &mut seen, f0, x0, net.points[p], radius)
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

/// The closest point to `x` on the faces reachable from `start` (through shared vertices)
/// without leaving the ball of `radius` around `centre`; None past the face budget.
#[allow(clippy::too_many_arguments)]
fn nearest_connected(
    pos: &[Point3],
    tris: &[[u32; 3]],
    vf: &[Vec<u32>],
    seen: &mut SeenFaces,
    start: u32,
    centre: Point3,
    x: Point3,
    radius: f64,
) -> Option<(u32, Point3, f64)> {
    let corners = |f: u32| tris[f as usize].map(|v| pos[v as usize]);
    seen.clear();
    let mut stack = vec![start];
    seen.insert(start);
    let mut best: Option<(u32, Point3, f64)> = None;
    while let Some(f) = stack.pop() {
        let q = closest_on_triangle(x, &corners(f));
        let d = dist(q, x);
        if best.is_none_or(|b| d < b.2) {
            best = Some((f, q, d));
        }
        for &v in &tris[f as usize] {
            for &g in &vf[v as usize] {
                if !seen.insert(g) {
                    continue;
                }
                if dist(closest_on_triangle(centre, &corners(g)), centre) <= radius {
                    stack.push(g);
                }
            }
        }
        if seen.count > FACE_BUDGET {
            return None;
        }
    }
    best
}
