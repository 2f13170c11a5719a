//! Partitioning, part 2: label faces by the region the curves enclose (flood fill across edges
//! that are not curve edges).

use std::collections::HashSet;
use std::hash::BuildHasherDefault;

use super::trimesh::IntHasher;
use crate::error::Result;
use crate::job::Progress;
use crate::topology::Csr;

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

/// [`regions`], reporting its fraction done (and so polling) every [`POLL_FACES`] faces labelled.
///
/// Faces meet across an edge when both contain its two ends: the fill looks them up in the
/// vertex → faces lists (a counting sort), not in an edge → faces hash map, which cost ~118 ms of
/// serial CPU on the headline's 200k faces (docs/benchmarks.md, session 11). All faces on a
/// non-manifold edge are joined to each other.
pub fn regions_polled(
    tris: &[[u32; 3]],
    curve_edges: &HashSet<(u32, u32), BuildHasherDefault<IntHasher>>,
    progress: &Progress,
) -> Result<(Vec<u32>, usize)> {
    let nv = tris.iter().flatten().max().map_or(0, |&v| v as usize + 1);
    let vertex_faces = Csr::vertex_triangles(nv, tris);
    // Only an edge with both ends on curve edges can be one: most edges skip the hash lookup.
    let mut on_curve = vec![false; nv];
    for &(a, b) in curve_edges {
        for v in [a, b] {
            if let Some(x) = on_curve.get_mut(v as usize) {
                *x = true;
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
                progress.fraction(labelled as f64 / tris.len() as f64)?;
            }
            labelled += 1;
            let t = tris[f as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if on_curve[a as usize] && on_curve[b as usize] && curve_edges.contains(&(a.min(b), a.max(b)))
                {
                    continue;
                }
                for g in vertex_faces.triangles_on_edge(tris, a, b) {
                    if region[g as usize] == u32::MAX {
                        region[g as usize] = count;
                        stack.push(g);
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
        // 81,920 / 4096 = 20 polls of the fill.
        assert_eq!(p.checks(), 20);
        assert_eq!(count, 2);
        let first = region.iter().filter(|&&r| r == region[0]).count();
        assert_eq!(first, 80 * 512, "each half has 80 strips of 512 triangles");
        assert_eq!((region, count), regions(&tris, &cut));
        let p = Progress::new();
        p.cancel_at_check(7);
        assert!(matches!(regions_polled(&tris, &cut, &p), Err(crate::error::Error::Cancelled)));
        assert_eq!(p.checks(), 7, "stopped at the cancel, not after the pass");
    }

    /// Three triangles on one edge (a fin) and a fourth beyond one of them, no curves: one region.
    /// The edge → [first, last] face map before session 11 reached the middle fin face from the
    /// others only one way, and the fill seeded at face 0 left it as a second region.
    #[test]
    fn all_faces_on_a_non_manifold_edge_are_one_region() {
        let tris = vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 3, 5]];
        let none = HashSet::default();
        assert_eq!(regions(&tris, &none), (vec![0, 0, 0, 0], 1));
        // The fin's edge as a curve edge separates all three, and the fourth goes with the second.
        let cut: HashSet<(u32, u32), BuildHasherDefault<IntHasher>> = [(0, 1)].into_iter().collect();
        assert_eq!(regions(&tris, &cut), (vec![0, 1, 2, 1], 3));
    }
}
