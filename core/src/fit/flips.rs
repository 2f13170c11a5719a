//! Face-flip prevention (§2.3): find faces the fine deformation would flip, and subdivide them
//! locally so the next closest-point pass has more, closer vertices to choose from.
//!
//! Detection uses both the seed's flip counter (each vertex's projected motion against the line
//! of its opposite edge; odd count = flipped) and a direct orientation test of the moved triangle
//! projected on the original plane; a face is flagged when either test says so. The counter is
//! exact only when one vertex moves (seed note): with the absolute motion the seed uses, a plain
//! translation larger than the triangle counts as a crossing and flagged a fifth of a real fit, so
//! each vertex's motion is taken relative to its opposite edge's midpoint.

use std::collections::HashMap;

use crate::geometry::{cross, dot, norm, normalize, scale, sub};
use crate::mesh::Point3;

#[derive(Debug, Clone, Default)]
pub struct FlipScan {
    pub flipped: Vec<u32>,
    pub by_counter: usize,
    pub by_orientation: usize,
}

pub fn detect(before: &[Point3], after: &[Point3], tris: &[[u32; 3]]) -> FlipScan {
    detect_range(before, after, tris, 0..tris.len(), FlipScan::default())
}

/// Faces per poll of [`detect_polled`] (~5 ms at load 1).
const DETECT_CHUNK: usize = 1 << 15;

/// [`detect`], polling `progress` every [`DETECT_CHUNK`] faces (the headline's 192k faces take
/// ~40 ms at load 1: the fine stage calls it once per flip round).
pub fn detect_polled(
    before: &[Point3],
    after: &[Point3],
    tris: &[[u32; 3]],
    progress: &crate::job::Progress,
) -> crate::error::Result<FlipScan> {
    let mut scan = FlipScan::default();
    for lo in (0..tris.len()).step_by(DETECT_CHUNK) {
        progress.check()?;
        scan = detect_range(before, after, tris, lo..(lo + DETECT_CHUNK).min(tris.len()), scan);
    }
    Ok(scan)
}

/// [`detect`] on the faces `range`, added to `scan` (faces in order).
fn detect_range(
    before: &[Point3],
    after: &[Point3],
    tris: &[[u32; 3]],
    range: std::ops::Range<usize>,
    mut scan: FlipScan,
) -> FlipScan {
    for f in range {
        let t = &tris[f];
        let p = [before[t[0] as usize], before[t[1] as usize], before[t[2] as usize]];
        let q = [after[t[0] as usize], after[t[1] as usize], after[t[2] as usize]];
        let n = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        if n == [0.0; 3] {
            continue; // degenerate before: no orientation to lose
        }
        // Projection of the moved points on the original plane Π (Fig. 2.9).
        let proj: [Point3; 3] = q.map(|x| sub(x, scale(n, dot(sub(x, p[0]), n))));
        let orient = dot(cross(sub(proj[1], proj[0]), sub(proj[2], proj[0])), n);
        let by_orient = orient <= 0.0;
        let mut counter = 0;
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            // The vertex's motion relative to its opposite edge (the seed uses the absolute motion,
            // which counts a plain translation larger than the triangle as a crossing).
            let edge_motion = scale(crate::geometry::add(sub(proj[j], p[j]), sub(proj[k], p[k])), 0.5);
            let t_i = sub(sub(proj[i], p[i]), edge_motion);
            let d_i = sub(p[k], p[j]);
            // p_i + r t_i = p_j + s d_i, solved in the plane via cross products with n.
            let den = dot(cross(t_i, d_i), n);
            if den.abs() <= 1e-300 || norm(t_i) == 0.0 {
                continue;
            }
            let r = dot(cross(sub(p[j], p[i]), d_i), n) / den;
            if (0.0..=1.0).contains(&r) {
                counter += 1;
            }
        }
        let by_counter = counter % 2 == 1;
        scan.by_counter += by_counter as usize;
        scan.by_orientation += by_orient as usize;
        if by_counter || by_orient {
            scan.flipped.push(f as u32);
        }
    }
    scan
}

/// The flagged faces plus every face around a matched vertex (`matched`: template vertex of each
/// curve point) that belongs to a flagged face.
pub fn with_matched_stars(tris: &[[u32; 3]], flagged: &[u32], matched: &[u32]) -> Vec<u32> {
    let nv = tris.iter().flat_map(|t| t.iter()).map(|&v| v as usize + 1).max().unwrap_or(0);
    let mut is_matched = vec![false; nv.max(matched.iter().map(|&v| v as usize + 1).max().unwrap_or(0))];
    for &v in matched {
        is_matched[v as usize] = true;
    }
    let mut culprit = vec![false; is_matched.len()];
    for &f in flagged {
        for &v in &tris[f as usize] {
            if is_matched[v as usize] {
                culprit[v as usize] = true;
            }
        }
    }
    let mut out: Vec<u32> = flagged.to_vec();
    for (f, t) in tris.iter().enumerate() {
        if t.iter().any(|&v| culprit[v as usize]) {
            out.push(f as u32);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Splits every edge of the `flagged` faces at its midpoint and re-triangulates each touched face
/// conformingly (1→2, 1→3 or 1→4, red-green style), so no T-junctions appear. Returns how many
/// faces were added. New vertices are appended to `pos`; their edge ends are appended to `parents`
/// in the same order (for attribute interpolation).
pub fn subdivide(
    pos: &mut Vec<Point3>,
    tris: &mut Vec<[u32; 3]>,
    flagged: &[u32],
    parents: &mut Vec<[(u32, f64); 3]>,
) -> usize {
    let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
    for &f in flagged {
        let t = tris[f as usize];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            mid.entry(key).or_insert_with(|| {
                let (pa, pb) = (pos[a as usize], pos[b as usize]);
                pos.push(scale(crate::geometry::add(pa, pb), 0.5));
                parents.push([(a, 0.5), (b, 0.5), (a, 0.0)]);
                (pos.len() - 1) as u32
            });
        }
    }
    let before = tris.len();
    let mut out = Vec::with_capacity(tris.len() + 3 * flagged.len());
    for &t in tris.iter() {
        let m: [Option<u32>; 3] = std::array::from_fn(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            mid.get(&(a.min(b), a.max(b))).copied()
        });
        match m.iter().filter(|x| x.is_some()).count() {
            0 => out.push(t),
            3 => {
                let (ab, bc, ca) = (m[0].unwrap_or(0), m[1].unwrap_or(0), m[2].unwrap_or(0));
                out.extend([[t[0], ab, ca], [t[1], bc, ab], [t[2], ca, bc], [ab, bc, ca]]);
            }
            1 => {
                let k = (0..3).find(|&k| m[k].is_some()).unwrap_or(0);
                let (a, b, c, x) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3], m[k].unwrap_or(0));
                out.extend([[a, x, c], [x, b, c]]);
            }
            _ => {
                // Two split edges: k is the unsplit one, (a, b) = its ends, c the apex.
                let k = (0..3).find(|&k| m[k].is_none()).unwrap_or(0);
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let (mbc, mca) = (m[(k + 1) % 3].unwrap_or(0), m[(k + 2) % 3].unwrap_or(0));
                out.push([mca, mbc, c]);
                // Quad a, b, mbc, mca: cut along the shorter diagonal.
                let d1 = norm(sub(pos[a as usize], pos[mbc as usize]));
                let d2 = norm(sub(pos[b as usize], pos[mca as usize]));
                if d1 <= d2 {
                    out.extend([[a, b, mbc], [a, mbc, mca]]);
                } else {
                    out.extend([[a, b, mca], [b, mbc, mca]]);
                }
            }
        }
    }
    *tris = out;
    tris.len() - before
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_vertex_crossing_its_opposite_edge_is_a_flip() {
        let before = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let tris = [[0, 1, 2]];
        // Vertex 2 moves to the other side of edge 0-1: flipped, by both tests.
        let after = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, -0.5, 0.2]];
        let s = detect(&before, &after, &tris);
        assert_eq!(s.flipped, vec![0]);
        assert_eq!((s.by_counter, s.by_orientation), (1, 1));
        // A move that stays on the same side is no flip.
        let after = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.6, 0.4, -0.3]];
        assert!(detect(&before, &after, &tris).flipped.is_empty());
    }

    /// The fine stage scans every face once per flip round (190k faces on the headline, ~40 ms
    /// without a poll before): the polled scan polls once per 32,768 faces, finds exactly what
    /// the plain scan finds and stops at a cancel.
    #[test]
    fn the_polled_scan_polls_per_chunk_and_stops_at_a_cancel() {
        let m = crate::shapes::icosphere(6, 1.0); // 81,920 faces: chunks of 32,768, 32,768, 16,384
        let tris = m.faces.triangles();
        // Every 7th vertex pushed through the centre: the faces around it turn over.
        let after: Vec<Point3> = m
            .positions
            .iter()
            .enumerate()
            .map(|(i, &p)| if i % 7 == 0 { scale(p, -0.5) } else { p })
            .collect();
        let p = crate::job::Progress::new();
        let polled = detect_polled(&m.positions, &after, &tris, &p).unwrap();
        assert_eq!(p.checks(), 3);
        let plain = detect(&m.positions, &after, &tris);
        assert!(plain.flipped.len() > 1000, "the case: {} flips", plain.flipped.len());
        assert_eq!(polled.flipped, plain.flipped);
        assert_eq!((polled.by_counter, polled.by_orientation), (plain.by_counter, plain.by_orientation));
        let p = crate::job::Progress::new();
        p.cancel_at_check(2);
        let r = detect_polled(&m.positions, &after, &tris, &p);
        assert!(matches!(r, Err(crate::error::Error::Cancelled)));
        assert_eq!(p.checks(), 2, "stopped at the cancel, not after the scan");
    }

    #[test]
    fn subdivision_is_conforming() {
        // Two triangles sharing edge 1-2; flag the first: it splits 1→4, its neighbour 1→2.
        let mut pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let mut tris = vec![[0, 1, 2], [1, 3, 2]];
        let mut parents = Vec::new();
        let added = subdivide(&mut pos, &mut tris, &[0], &mut parents);
        assert_eq!(parents.len(), 3);
        assert_eq!(added, 4);
        assert_eq!(pos.len(), 7);
        // Conforming: every interior edge is used exactly twice (once per direction).
        let mut count: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *count.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        assert!(count.values().all(|&c| c == 1));
        let area: f64 = tris
            .iter()
            .map(|t| {
                crate::geometry::triangle_area(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize])
            })
            .sum();
        assert!((area - 1.0).abs() < 1e-12);
    }
}
