//! Welding: merge vertices closer than a tolerance.
//!
//! Spatial hashing without a hash map: every vertex gets an integer cell key (cell size = 8 ×
//! tolerance), the vertices are sorted by key, and each vertex looks only into the neighbouring
//! cells it is within `tol` of (usually none but its own, because cells are 8× the tolerance).
//! Pairs within `tol` are merged with union-find, so chains of close vertices collapse to one
//! (the lowest index, whose position is kept: exact duplicates keep exact positions).
//! With `tol == 0` only bit-identical positions merge.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::norm2;
use crate::job::Progress;
use crate::mesh::Mesh;
use crate::topology::{find, union};

#[derive(Debug, Clone, Serialize, Default)]
pub struct WeldReport {
    /// Absolute tolerance used (relative tolerance × bbox diagonal).
    pub tolerance: f64,
    /// Vertices merged into another one (their faces now use the survivor).
    pub merged_vertices: usize,
    /// Surviving vertices that absorbed at least one other (clusters of coincident vertices).
    pub groups: usize,
}

/// Merges vertices within `tol` (absolute) of each other; faces and curves are rewritten to the
/// survivor. Positions are not removed here (the compact step does that).
pub fn weld(mesh: &mut Mesh, tol: f64, progress: &Progress) -> Result<WeldReport> {
    let n = mesh.positions.len();
    let rep = representatives(&mesh.positions, tol, progress)?;
    let merged = (0..n).filter(|&i| rep[i] != i as u32).count();
    let mut has_partner = vec![false; n];
    for i in 0..n {
        if rep[i] != i as u32 {
            has_partner[rep[i] as usize] = true;
        }
    }
    let groups = has_partner.iter().filter(|&&b| b).count();
    for v in mesh.faces.indices_mut() {
        *v = rep[*v as usize];
    }
    for c in &mut mesh.curves {
        for v in c {
            *v = rep[*v as usize];
        }
    }
    Ok(WeldReport { tolerance: tol, merged_vertices: merged, groups })
}

/// `rep[i]` = the lowest index of the cluster of vertices within `tol` (transitively) of `i`.
pub fn representatives(p: &[[f64; 3]], tol: f64, progress: &Progress) -> Result<Vec<u32>> {
    let n = p.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    if tol == 0.0 {
        // Exact: sort by bit pattern (+0.0 and −0.0 normalised), union equal runs.
        let key = |i: u32| p[i as usize].map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_unstable_by_key(|&i| (key(i), i));
        for w in order.windows(2) {
            if key(w[0]) == key(w[1]) {
                union(&mut parent, w[0], w[1]);
            }
        }
    } else {
        let cell = 8.0 * tol;
        let cell_of = |x: f64| (x / cell).floor() as i64;
        let key = |i: usize| [cell_of(p[i][0]), cell_of(p[i][1]), cell_of(p[i][2])];
        let mut order: Vec<([i64; 3], u32)> = (0..n).map(|i| (key(i), i as u32)).collect();
        order.sort_unstable();
        let tol2 = tol * tol;
        for (k, &(ck, i)) in order.iter().enumerate() {
            if k % 65536 == 0 {
                progress.check()?;
            }
            let pi = p[i as usize];
            // Which neighbour cells can hold a point within tol, per axis.
            let mut range = [[0i64; 2]; 3];
            for a in 0..3 {
                let f = pi[a] / cell - ck[a] as f64;
                range[a] = [if f * cell < tol { -1 } else { 0 }, if (1.0 - f) * cell <= tol { 1 } else { 0 }];
            }
            for dx in range[0][0]..=range[0][1] {
                for dy in range[1][0]..=range[1][1] {
                    for dz in range[2][0]..=range[2][1] {
                        let nk = [ck[0] + dx, ck[1] + dy, ck[2] + dz];
                        // Only look "forward" (nk ≥ ck) in the sorted order so each pair is seen once
                        // from one side; the own cell is scanned from position k + 1.
                        if nk < ck {
                            continue;
                        }
                        let start = if nk == ck { k + 1 } else { order.partition_point(|e| e.0 < nk) };
                        for &(ok, j) in &order[start..] {
                            if ok != nk {
                                break;
                            }
                            if norm2(crate::geometry::sub(pi, p[j as usize])) <= tol2 {
                                union(&mut parent, i, j);
                            }
                        }
                    }
                }
            }
        }
    }
    Ok((0..n as u32).map(|i| find(&mut parent, i)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    #[test]
    fn weld_within_tolerance_only() {
        // 0 and 1 are 0.5e-3 apart, 2 is 2e-3 from 0; tol 1e-3 merges only 0 and 1.
        let p = vec![[0.0, 0.0, 0.0], [0.5e-3, 0.0, 0.0], [0.0, 2e-3, 0.0], [1.0, 1.0, 1.0]];
        let r = representatives(&p, 1e-3, &Progress::new()).unwrap();
        assert_eq!(r, vec![0, 0, 2, 3]);
        // Across a cell border (cells are 8e-3 wide, border at 8e-3).
        let p = vec![[7.9999e-3, 0.0, 0.0], [8.0001e-3, 0.0, 0.0], [-1e-9, 0.0, 0.0], [1e-9, 0.0, 0.0]];
        let r = representatives(&p, 1e-3, &Progress::new()).unwrap();
        assert_eq!(r, vec![0, 0, 2, 2]);
    }

    #[test]
    fn exact_weld_and_faces_rewritten() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [-0.0, 0.0, 0.0]];
        let mut m = Mesh::from_triangles(p, &[[0, 1, 2], [4, 2, 3]]);
        let r = weld(&mut m, 0.0, &Progress::new()).unwrap();
        assert_eq!(r.merged_vertices, 2);
        assert_eq!(m.faces.get(1), &[0, 2, 1]);
    }

    #[test]
    fn chains_merge_transitively() {
        let p: Vec<[f64; 3]> = (0..10).map(|i| [i as f64 * 0.9e-3, 0.0, 0.0]).collect();
        let r = representatives(&p, 1e-3, &Progress::new()).unwrap();
        assert!(r.iter().all(|&x| x == 0));
    }
}
