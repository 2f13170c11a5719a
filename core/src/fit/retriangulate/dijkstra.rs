//! The seed's fallback (§3.2): a shortest edge path between the segment's ends through free
//! vertices, whose inner vertices move onto the segment. Taken only when that turns no face over
//! (otherwise [`super::route`] realises the segment).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::geometry::{add, dot, norm, scale, sub};
use crate::mesh::Point3;

use super::super::trimesh::{IntMap, TriMesh};

pub(super) enum Projected {
    Done(Vec<u32>),
    /// A path exists but projecting it would turn a face over (nothing was moved).
    WouldFlip,
    NoPath,
}

/// §3.2 fallback: shortest edge path from `from` to `to` through free vertices, whose inner
/// vertices are then moved onto the segment (spaced by their arc length along the path), unless
/// that turns a face of their stars over.
pub(super) fn dijkstra_project(
    mesh: &mut TriMesh,
    from: u32,
    to: u32,
    on_curve: &[bool],
    uv_moves: &mut Vec<crate::fit::uvs::UvMove>,
) -> Projected {
    match dijkstra_path(mesh, from, to, on_curve) {
        None => Projected::NoPath,
        Some((path, total)) => project_path(mesh, path, total, uv_moves),
    }
}

fn dijkstra_path(mesh: &TriMesh, from: u32, to: u32, on_curve: &[bool]) -> Option<(Vec<u32>, f64)> {
    let mut dist: IntMap<u32, f64> = IntMap::default();
    let mut prev: IntMap<u32, u32> = IntMap::default();
    let mut heap = BinaryHeap::new();
    dist.insert(from, 0.0);
    heap.push(Reverse((0u64, from)));
    // A path much longer than the segment would drag far-away vertices onto it: give up instead.
    let reach = 4.0 * mesh.len(from, to);
    let mut pops = 0usize;
    while let Some(Reverse((dbits, v))) = heap.pop() {
        let dv = f64::from_bits(dbits);
        if dv > *dist.get(&v).unwrap_or(&f64::INFINITY) {
            continue;
        }
        if v == to {
            break;
        }
        pops += 1;
        if pops > 200_000 || dv > reach {
            return None;
        }
        for &f in mesh.faces_of(v) {
            for &nb in &mesh.tris[f as usize] {
                if nb == v || (nb != to && on_curve[nb as usize]) {
                    continue;
                }
                let nd = dv + mesh.len(v, nb);
                if nd < *dist.get(&nb).unwrap_or(&f64::INFINITY) {
                    dist.insert(nb, nd);
                    prev.insert(nb, v);
                    // Non-negative f64 bit patterns order like the values.
                    heap.push(Reverse((nd.to_bits(), nb)));
                }
            }
        }
    }
    let total = *dist.get(&to)?;
    let mut path = vec![to];
    let mut v = to;
    while v != from {
        v = *prev.get(&v)?;
        path.push(v);
    }
    path.reverse();
    Some((path, total))
}

fn project_path(
    mesh: &mut TriMesh,
    path: Vec<u32>,
    total: f64,
    uv_moves: &mut Vec<crate::fit::uvs::UvMove>,
) -> Projected {
    let (from, to) = (path[0], path[path.len() - 1]);
    let (a, b) = (mesh.pos[from as usize], mesh.pos[to as usize]);
    let mut acc = 0.0;
    let old: Vec<Point3> = path.iter().map(|&v| mesh.pos[v as usize]).collect();
    let mut targets = Vec::with_capacity(path.len());
    for k in 1..path.len().saturating_sub(1) {
        acc += crate::geometry::dist(old[k - 1], old[k]);
        let frac = if total > 0.0 { acc / total } else { 0.5 };
        let target = add(a, scale(sub(b, a), frac));
        targets.push(target);
    }
    let inner = &path[1..path.len().saturating_sub(1)];
    let mut stars: Vec<u32> = inner.iter().flat_map(|&v| mesh.faces_of(v).iter().copied()).collect();
    stars.sort_unstable();
    stars.dedup();
    let normals: Vec<Point3> = stars.iter().map(|&f| mesh.face_normal(f)).collect();
    for (&v, &t) in inner.iter().zip(&targets) {
        mesh.pos[v as usize] = t;
    }
    let turned = stars.iter().zip(&normals).any(|(&f, &n0)| {
        let n1 = mesh.face_normal(f);
        dot(n0, n1) <= 0.0 || norm(n1) <= 1e-12 * norm(n0)
    });
    for (&v, &p) in inner.iter().zip(&old[1..]) {
        mesh.pos[v as usize] = p;
    }
    if turned {
        return Projected::WouldFlip;
    }
    // Located on the mesh before any path vertex moves.
    for (&v, &t) in inner.iter().zip(&targets) {
        uv_moves.extend(crate::fit::uvs::record(mesh, v, t));
    }
    for (&v, t) in inner.iter().zip(targets) {
        mesh.pos[v as usize] = t;
    }
    Projected::Done(path)
}
