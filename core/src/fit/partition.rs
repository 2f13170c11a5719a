//! Partitioning, part 2: label faces by the region the curves enclose (flood fill across edges
//! that are not curve edges).

use std::collections::HashSet;
use std::hash::BuildHasherDefault;

use super::trimesh::{IntHasher, IntMap};
use crate::error::Result;
use crate::job::Progress;

/// Faces handled between two polls: ~5 ms of work in release on the headline's meshes (the whole
/// stage, unpolled, took 200–290 ms of CPU on 200k faces; docs/benchmarks.md → Cancellation).
const POLL_FACES: usize = 4096;

/// Region id per triangle and the number of regions. `curve_edges` are undirected (min, max).
pub fn regions(
    tris: &[[u32; 3]],
    curve_edges: &HashSet<(u32, u32), BuildHasherDefault<IntHasher>>,
) -> (Vec<u32>, usize) {
    Progress::unpolled(|p| regions_polled(tris, curve_edges, p))
}

/// [`regions`], reporting its fraction done (and so polling) every [`POLL_FACES`] faces of each
/// of its two passes: the edge → faces map (the first half) and the flood fill (the second).
pub fn regions_polled(
    tris: &[[u32; 3]],
    curve_edges: &HashSet<(u32, u32), BuildHasherDefault<IntHasher>>,
    progress: &Progress,
) -> Result<(Vec<u32>, usize)> {
    let half = |done: usize, pass: usize| 0.5 * (pass as f64 + done as f64 / tris.len().max(1) as f64);
    let mut edge_faces: IntMap<(u32, u32), [u32; 2]> = IntMap::default();
    edge_faces.reserve(tris.len() * 3 / 2);
    for (f, t) in tris.iter().enumerate() {
        if f % POLL_FACES == 0 {
            progress.fraction(half(f, 0))?;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = edge_faces.entry((a.min(b), a.max(b))).or_insert([u32::MAX; 2]);
            if e[0] == u32::MAX {
                e[0] = f as u32;
            } else {
                e[1] = f as u32;
            }
        }
    }
    let mut region = vec![u32::MAX; tris.len()];
    let mut count = 0u32;
    let mut stack = Vec::new();
    // Faces labelled so far: the fill polls by faces done, whatever the regions' sizes.
    let mut labelled = 0usize;
    for seed in 0..tris.len() {
        if region[seed] != u32::MAX {
            continue;
        }
        region[seed] = count;
        stack.push(seed as u32);
        while let Some(f) = stack.pop() {
            if labelled % POLL_FACES == 0 {
                progress.fraction(half(labelled, 1))?;
            }
            labelled += 1;
            let t = tris[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                if curve_edges.contains(&key) {
                    continue;
                }
                if let Some(e) = edge_faces.get(&key) {
                    for &g in e {
                        if g != u32::MAX && region[g as usize] == u32::MAX {
                            region[g as usize] = count;
                            stack.push(g);
                        }
                    }
                }
            }
        }
        count += 1;
    }
    Ok((region, count as usize))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An equilateral grid of 257 × 161 vertices (81,920 triangles) cut along its middle row of
    /// vertices (row 80): 2 regions of 80 strips of 512 triangles each, by hand.
    fn halves() -> (Vec<[u32; 3]>, HashSet<(u32, u32), BuildHasherDefault<IntHasher>>) {
        let m = crate::shapes::triangle_grid(257, 161, 1.0);
        let cut = (0..256u32).map(|i| (80 * 257 + i, 80 * 257 + i + 1)).collect();
        (m.faces.triangles(), cut)
    }

    #[test]
    fn the_polled_partition_polls_per_4096_faces_and_stops_at_a_cancel() {
        let (tris, cut) = halves();
        assert_eq!(tris.len(), 81_920);
        let p = Progress::new();
        let (region, count) = regions_polled(&tris, &cut, &p).unwrap();
        // 81,920 / 4096 = 20 polls in each of the two passes.
        assert_eq!(p.checks(), 40);
        assert_eq!(count, 2);
        let first = region.iter().filter(|&&r| r == region[0]).count();
        assert_eq!(first, 80 * 512, "each half has 80 strips of 512 triangles");
        assert_eq!((region, count), regions(&tris, &cut));
        let p = Progress::new();
        p.cancel_at_check(7);
        assert!(matches!(regions_polled(&tris, &cut, &p), Err(crate::error::Error::Cancelled)));
        assert_eq!(p.checks(), 7, "stopped at the cancel, not after the pass");
    }
}
