//! The common boundary of several disks: the union of all disks' boundary angles is inserted into
//! every disk's boundary edges (the new vertices lie on the 3D boundary edges, so the surface is
//! unchanged), so that all disks cover the same convex polygon, which the 2-D overlay needs; and
//! the tiny interior jitter that keeps symmetric inputs out of degenerate positions.

use std::collections::HashMap;
use std::f64::consts::TAU;

use super::{foldovers, lift, DiskMap};
use crate::error::{Error, Result};
use crate::geometry::{add, dist, sub};
use crate::mesh::Point3;
use crate::morph::trimesh::TriMesh;

/// Angles closer than this are one boundary vertex of the common boundary.
const ANGLE_MERGE: f64 = 1e-9;

/// The sorted union of all disks' boundary angles (near-equal angles merged).
pub fn union_angles(maps: &[DiskMap]) -> Vec<f64> {
    let mut all: Vec<f64> = maps.iter().flat_map(|m| m.angles.iter().copied()).collect();
    all.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::with_capacity(all.len());
    for a in all {
        if out.last().is_none_or(|&l| a - l > ANGLE_MERGE) {
            out.push(a);
        }
    }
    // The wrap-around pair (last near 2π, first near 0).
    if out.len() > 1 && out[0] + TAU - out[out.len() - 1] <= ANGLE_MERGE {
        out.pop();
    }
    out
}

/// A disk with the common boundary: lifted positions, 3D positions, triangles, and for each
/// vertex its index in the common boundary (`u32::MAX` inside).
#[derive(Clone, Debug)]
pub struct CommonDisk {
    pub plane: Vec<Point3>,
    pub pos: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
    pub bnd: Vec<u32>,
    pub inserted: usize,
}

/// Index in `union` of the angle nearest to `a` (cyclic).
fn nearest(union: &[f64], a: f64) -> usize {
    let i = union.partition_point(|&u| u < a);
    let cands = [i % union.len(), (i + union.len() - 1) % union.len()];
    let d = |j: usize| {
        let x = (union[j] - a).rem_euclid(TAU);
        x.min(TAU - x)
    };
    if d(cands[0]) <= d(cands[1]) {
        cands[0]
    } else {
        cands[1]
    }
}

/// Inserts the common boundary angles into one disk (see the module docs). Boundary vertices
/// are snapped to their common angle (they are within [`ANGLE_MERGE`] of it).
pub fn with_common_boundary(m: &TriMesh, map: &DiskMap, union: &[f64]) -> Result<CommonDisk> {
    let nu = union.len();
    let on_circle = |j: usize| lift(union[j].cos(), union[j].sin());
    let mut plane = map.plane.clone();
    let mut pos = m.pos.clone();
    let mut bnd = vec![u32::MAX; pos.len()];
    let nb = map.boundary.len();
    let mut own: Vec<usize> = Vec::with_capacity(nb);
    for &v in &map.boundary {
        let p = plane[v as usize];
        let j = nearest(union, p[1].atan2(p[0]).rem_euclid(TAU));
        bnd[v as usize] = j as u32;
        plane[v as usize] = on_circle(j);
        own.push(j);
    }
    // Face of each boundary edge a → b, and the edge's corner in it.
    let mut edge_face = HashMap::with_capacity(nb);
    for (fi, t) in m.tris.iter().enumerate() {
        for k in 0..3 {
            edge_face.insert((t[k], t[(k + 1) % 3]), (fi, k));
        }
    }
    // New vertices on each face's edges (a face can have two or three boundary edges).
    let mut on_edge: HashMap<usize, [Vec<u32>; 3]> = HashMap::new();
    let mut inserted = 0;
    for i in 0..nb {
        let (a, b) = (map.boundary[i], map.boundary[(i + 1) % nb]);
        let (ja, jb) = (own[i], own[(i + 1) % nb]);
        let gap = (jb + nu - ja) % nu;
        if gap == 0 {
            return Err(Error::numerical(
                "common boundary",
                format!("boundary vertices {a} and {b} fell on the same common angle"),
            ));
        }
        if gap == 1 {
            continue;
        }
        let &(fi, k) = edge_face
            .get(&(a, b))
            .ok_or_else(|| Error::Internal(format!("boundary edge {a}→{b} has no face")))?;
        let (pa, pb) = (m.pos[a as usize], m.pos[b as usize]);
        let span = (union[jb] - union[ja]).rem_euclid(TAU);
        let list = &mut on_edge.entry(fi).or_default()[k];
        for s in 1..gap {
            let j = (ja + s) % nu;
            let f = (union[j] - union[ja]).rem_euclid(TAU) / span;
            list.push(pos.len() as u32);
            pos.push(add(pa, crate::geometry::scale(sub(pb, pa), f)));
            plane.push(on_circle(j));
            bnd.push(j as u32);
            inserted += 1;
        }
    }
    let tris = refan_split_faces(&m.tris, &on_edge);
    Ok(CommonDisk { plane, pos, tris, bnd, inserted })
}

/// Re-triangulates each face that got new vertices on its edges (`on_edge[face][corner]`: the
/// vertices inserted on the edge from that corner to the next) as a fan: from the corner
/// opposite its one split edge (that corner sees the whole edge, see the module docs), or, with
/// two or three split (boundary) edges, from corner 0: then all corners lie on the circle, so
/// the polygon is convex and any fan is valid. The first triangle of each fan replaces the face;
/// the others are appended.
fn refan_split_faces(tris0: &[[u32; 3]], on_edge: &HashMap<usize, [Vec<u32>; 3]>) -> Vec<[u32; 3]> {
    let mut tris = tris0.to_vec();
    let mut extra: Vec<[u32; 3]> = Vec::new();
    let mut faces: Vec<usize> = on_edge.keys().copied().collect();
    faces.sort_unstable();
    for fi in faces {
        let t = tris0[fi];
        let lists = &on_edge[&fi];
        let split: Vec<usize> = (0..3).filter(|&k| !lists[k].is_empty()).collect();
        let start = if split.len() == 1 { (split[0] + 2) % 3 } else { 0 };
        let mut poly: Vec<u32> = Vec::new();
        for s in 0..3 {
            let k = (start + s) % 3;
            poly.push(t[k]);
            poly.extend_from_slice(&lists[k]);
        }
        tris[fi] = [poly[0], poly[1], poly[2]];
        for q in 2..poly.len() - 1 {
            extra.push([poly[0], poly[q], poly[q + 1]]);
        }
    }
    tris.extend(extra);
    tris
}

/// Moves every interior vertex of a disk by 10⁻⁷ of its shortest plane edge in a fixed
/// pseudo-random direction (`salt` varies it per input). Symmetric inputs (a grid disk and a
/// polar hemisphere both map their centre to the origin, and share radial edge directions) would
/// otherwise put vertices of two disks on each other or on each other's edges, which the overlay's
/// predicates cannot order consistently; shared boundary vertices are handled by labels and stay.
/// Undone if it flipped anything. Returns whether it was applied.
pub fn jitter_interior(d: &mut CommonDisk, salt: u64) -> bool {
    let n = d.plane.len();
    let mut shortest = vec![f64::INFINITY; n];
    for t in &d.tris {
        for k in 0..3 {
            let (u, v) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let l = dist(d.plane[u], d.plane[v]);
            shortest[u] = shortest[u].min(l);
            shortest[v] = shortest[v].min(l);
        }
    }
    let before = d.plane.clone();
    for v in 0..n {
        if d.bnd[v] != u32::MAX || !shortest[v].is_finite() {
            continue;
        }
        // SplitMix64 of (vertex, salt) → an angle.
        let mut z = (v as u64)
            .wrapping_add(salt.wrapping_mul(0x9E37_79B9_7F4A_7C15))
            .wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let a = TAU * (z >> 11) as f64 / (1u64 << 53) as f64;
        let e = 1e-7 * shortest[v];
        let p = d.plane[v];
        d.plane[v] = lift(p[0] + e * a.cos(), p[1] + e * a.sin());
    }
    if foldovers(&d.plane, &d.tris) > 0 {
        d.plane = before;
        return false;
    }
    true
}
