//! Partitioning, part 2: label faces by the region the curves enclose (flood fill across edges
//! that are not curve edges).

use std::collections::HashSet;
use std::hash::BuildHasherDefault;

use super::trimesh::{IntHasher, IntMap};

/// Region id per triangle and the number of regions. `curve_edges` are undirected (min, max).
pub fn regions(
    tris: &[[u32; 3]],
    curve_edges: &HashSet<(u32, u32), BuildHasherDefault<IntHasher>>,
) -> (Vec<u32>, usize) {
    let mut edge_faces: IntMap<(u32, u32), [u32; 2]> = IntMap::default();
    edge_faces.reserve(tris.len() * 3 / 2);
    for (f, t) in tris.iter().enumerate() {
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
    for seed in 0..tris.len() {
        if region[seed] != u32::MAX {
            continue;
        }
        region[seed] = count;
        stack.push(seed as u32);
        while let Some(f) = stack.pop() {
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
    (region, count as usize)
}
