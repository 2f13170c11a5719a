//! The walk of Appendix A along a segment's cutting plane ([`super::cut`]): from u, across the
//! faces the plane crosses, to w or to a free vertex close enough to the plane to snap onto the
//! segment (then on from there, in pieces). A walked strip is re-filled with the same face count
//! ([`super::fill`]), or its crossed edges are split ([`super::split`]) when it has no valid
//! re-filling.

use std::collections::HashSet;
use std::hash::BuildHasherDefault;

use crate::geometry::{add, cross, dot, norm, normalize, scale, sub};

use super::super::trimesh::{IntHasher, TriMesh};
use super::cut::{crossing, Cut};
use super::fill::retriangulate;
use super::snap::keeps_orientation;
use super::split::split_strip;
use super::{EdgeSet, Work};

enum Walk {
    /// u–w is an edge already.
    Edge,
    /// Snap this neighbour of the start vertex (no face crossed).
    SnapAtStart(u32),
    /// Faces crossed and the (left, right) edges between them, ending at `end` (w, or a vertex to snap).
    Strip {
        faces: Vec<u32>,
        crossed: Vec<(u32, u32)>,
        end: u32,
    },
    Fail(FailReason),
}

#[derive(Debug, Clone, Copy)]
enum FailReason {
    Start,
    Boundary,
    CurveEdge,
    Lost,
}

impl Work<'_> {
    /// Walks and re-triangulates from u to w, possibly in pieces at snapped vertices. Pushes chain
    /// vertices after u; returns false when the fallback is needed (from the last chain vertex).
    pub(super) fn walk_segment(&mut self, u: u32, w: u32, chain: &mut Vec<u32>) -> bool {
        let Some(cut) = cut_of(self.mesh, u, w) else {
            self.stats.walk_fail_start += 1;
            return false;
        };
        let mut cur = u;
        for _piece in 0..10_000 {
            let step = walk(self.mesh, &cut, cur, w, self.snap_fraction, &self.on_curve, &self.locked);
            match step {
                Walk::Edge => {
                    chain.push(w);
                    return true;
                }
                Walk::SnapAtStart(z) => {
                    let target = cut.on_line(self.mesh.pos[z as usize]);
                    self.uv_moves.extend(super::super::uvs::record(self.mesh, z, target));
                    self.mesh.pos[z as usize] = target;
                    self.on_curve[z as usize] = true;
                    self.stats.snapped_vertices += 1;
                    chain.push(z);
                    cur = z;
                }
                Walk::Strip { faces, crossed, end } => {
                    if !self.realise_strip(&cut, cur, end, w, &faces, &crossed, chain) {
                        return false;
                    }
                    if end == w {
                        return true;
                    }
                    cur = end;
                }
                Walk::Fail(r) => {
                    match r {
                        FailReason::Start => self.stats.walk_fail_start += 1,
                        FailReason::Boundary => self.stats.walk_fail_boundary += 1,
                        FailReason::CurveEdge => self.stats.walk_fail_curve_edge += 1,
                        FailReason::Lost => self.stats.walk_fail_lost += 1,
                    }
                    return false;
                }
            }
        }
        false
    }

    /// Makes the walked strip from `cur` to `end` (w, or a vertex snapped onto the segment) a
    /// chain: re-filled with the same face count, else its crossed edges split. False (nothing
    /// moved) when neither works.
    #[allow(clippy::too_many_arguments)]
    fn realise_strip(
        &mut self,
        cut: &Cut,
        cur: u32,
        end: u32,
        w: u32,
        faces: &[u32],
        crossed: &[(u32, u32)],
        chain: &mut Vec<u32>,
    ) -> bool {
        let mesh = &mut *self.mesh;
        let old = mesh.pos[end as usize];
        let mut moved = None;
        if end != w {
            let target = cut.on_line(old);
            moved = super::super::uvs::record(mesh, end, target);
            mesh.pos[end as usize] = target;
        }
        let curved = strip_is_curved(mesh, cut, faces, crossed);
        if curved {
            self.stats.curved_strips += 1;
        }
        if curved || !retriangulate(mesh, cur, end, faces, crossed) {
            // No valid re-triangulation of the strip with the same face count (it wraps around a
            // vertex, or an ear would need an existing edge): split every edge the segment crosses
            // instead, at the crossing (Li's insertion; +2 faces per crossed edge). The walk
            // already proved the strip connects cur to end.
            if !curved {
                self.stats.walk_fail_fill += 1;
            }
            let n0 = chain.len();
            if !split_strip(mesh, cut, crossed, &mut self.on_curve, &mut self.added, chain) {
                if chain.len() == n0 {
                    mesh.pos[end as usize] = old;
                }
                return false;
            }
            self.stats.split_vertices += chain.len() - n0;
            self.stats.split_segments += 1;
        }
        self.uv_moves.extend(moved);
        chain.push(end);
        if end != w {
            self.on_curve[end as usize] = true;
            self.stats.snapped_vertices += 1;
        }
        true
    }
}

/// The cosine of the largest angle a strip face may make with the strip's mean normal and still
/// be re-filled flat (35°).
const FLAT_STRIP_COS: f64 = 0.82;

/// Is the walked strip too curved to be re-filled through one plane? The ear cutting works in
/// the plane of the strip's mean normal and puts the straight edge u–end in: on a strip bent by
/// more than ~35° whose crossings lie deeper under that edge than the crossed edges are long (a
/// sparse curve over a dense template: one 90° segment crosses a hundred faces of an icosphere of
/// 20k faces) the edge is a chord far under the surface and the re-filled faces fold over it
/// (measured: 141 folds and 7 s of untangling). Such strips are split at their crossings
/// instead, which keeps the chain on the surface. Short strips over a crease (dense curves)
/// keep the re-filling.
fn strip_is_curved(mesh: &TriMesh, cut: &Cut, faces: &[u32], crossed: &[(u32, u32)]) -> bool {
    let mut mean = [0.0; 3];
    for &f in faces {
        mean = add(mean, mesh.face_normal(f));
    }
    let mean = normalize(mean);
    // (Zero-area faces have no normal and no say.)
    let bent = faces.iter().any(|&f| {
        let n = normalize(mesh.face_normal(f));
        n != [0.0; 3] && dot(n, mean) < FLAT_STRIP_COS
    });
    if !bent || crossed.is_empty() {
        return false;
    }
    let mut edge_len = 0.0;
    let mut deepest: f64 = 0.0;
    for &(l, r) in crossed {
        edge_len += norm(sub(mesh.pos[l as usize], mesh.pos[r as usize]));
        let x = crossing(mesh, cut, l, r).0;
        deepest = deepest.max(norm(sub(x, cut.on_line(x))));
    }
    deepest > 0.5 * edge_len / crossed.len() as f64
}

/// The cutting plane of u–w: through both, containing their mean vertex normal. None for a
/// zero-length segment or a normal along it.
fn cut_of(mesh: &TriMesh, u: u32, w: u32) -> Option<Cut> {
    let (a, b) = (mesh.pos[u as usize], mesh.pos[w as usize]);
    let d = sub(b, a);
    let len = norm(d);
    if len == 0.0 {
        return None;
    }
    let dir = scale(d, 1.0 / len);
    let n = add(mesh.vertex_normal(u), mesh.vertex_normal(w));
    let n = normalize(sub(n, scale(dir, dot(n, dir))));
    if n == [0.0; 3] {
        return None;
    }
    Some(Cut { a, dir, side: cross(n, dir), len })
}

/// Can `z` move onto the cut line without flipping a face of its star?
fn snappable(mesh: &TriMesh, cut: &Cut, z: u32, on_curve: &[bool]) -> bool {
    if on_curve[z as usize] || mesh.is_boundary_vertex(z) {
        return false;
    }
    let target = cut.on_line(mesh.pos[z as usize]);
    let tz = cut.t(mesh.pos[z as usize]);
    if tz <= 0.0 || tz >= cut.len {
        return false;
    }
    // Only "not turned over" here: the bound the route's pull has (SNAP_MAX_TURN_COS) measured
    // mixed on the walk's snaps (session 21: held-out flips 604 -> 578, truth 21,707 -> 21,825).
    keeps_orientation(mesh, z, target, |_| None, 0.0)
}

/// The face of `from`'s star whose opposite edge the cutting plane crosses most forward, with
/// that edge as (left, right).
fn start_face(mesh: &TriMesh, cut: &Cut, from: u32) -> Option<(u32, u32, u32)> {
    let s = |v: u32| cut.s(mesh.pos[v as usize]);
    let pf = mesh.pos[from as usize];
    let mut best: Option<(u32, u32, u32, f64)> = None; // face, left, right, forwardness
    for &f in mesh.faces_of(from) {
        let t = mesh.tris[f as usize];
        let k = t.iter().position(|&v| v == from).unwrap_or(0);
        let (x, y) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let (sx, sy) = (s(x), s(y));
        if (sx >= 0.0) == (sy >= 0.0) {
            continue;
        }
        let (l, r) = if sx >= 0.0 { (x, y) } else { (y, x) };
        let c = crossing(mesh, cut, l, r).0;
        let fwd = dot(normalize(sub(c, pf)), cut.dir);
        // The most forward of the (usually two) crossings; it may point slightly backwards when
        // the chord leaves the surface steeply, the later checks catch a wrong start.
        if best.is_none_or(|b| fwd > b.3) {
            best = Some((f, l, r, fwd));
        }
    }
    best.map(|(f, l, r, _)| (f, l, r))
}

/// One piece of the walk from `from` towards `to`.
fn walk(
    mesh: &TriMesh,
    cut: &Cut,
    from: u32,
    to: u32,
    snap: f64,
    on_curve: &[bool],
    locked_edges: &EdgeSet,
) -> Walk {
    if mesh.has_edge(from, to) {
        return Walk::Edge;
    }
    let s = |v: u32| cut.s(mesh.pos[v as usize]);
    let t_end = cut.t(mesh.pos[to as usize]);
    let Some((f0, mut l, mut r)) = start_face(mesh, cut, from) else { return Walk::Fail(FailReason::Start) };
    let (_, lam) = crossing(mesh, cut, l, r);
    for (v, near) in [(l, lam < snap), (r, 1.0 - lam < snap)] {
        if near && cut.t(mesh.pos[v as usize]) < t_end && snappable(mesh, cut, v, on_curve) {
            return Walk::SnapAtStart(v);
        }
    }
    let locked = |a: u32, b: u32| locked_edges.contains(&(a.min(b), a.max(b)));
    if locked(l, r) {
        return Walk::Fail(FailReason::CurveEdge);
    }
    let mut faces = vec![f0];
    let mut crossed = vec![(l, r)];
    let mut seen: HashSet<u32, BuildHasherDefault<IntHasher>> = HashSet::default();
    seen.insert(f0);
    let mut cur = f0;
    for _step in 0..mesh.tris.len().min(1_000_000) {
        let Some(g) = mesh.across(cur, l, r) else { return Walk::Fail(FailReason::Boundary) };
        if !seen.insert(g) {
            return Walk::Fail(FailReason::Lost);
        }
        let t = mesh.tris[g as usize];
        let Some(&z) = t.iter().find(|&&v| v != l && v != r) else { return Walk::Fail(FailReason::Lost) };
        faces.push(g);
        if z == to {
            return Walk::Strip { faces, crossed, end: to };
        }
        let z_left = s(z) >= 0.0;
        let (nl, nr) = if z_left { (z, r) } else { (l, z) };
        let (c, lam) = crossing(mesh, cut, nl, nr);
        if cut.t(c) > t_end + 0.25 * cut.len {
            return Walk::Fail(FailReason::Lost); // passed the end without meeting it
        }
        let near_z = if z_left { lam < snap } else { 1.0 - lam < snap };
        if near_z && cut.t(mesh.pos[z as usize]) < t_end && snappable(mesh, cut, z, on_curve) {
            return Walk::Strip { faces, crossed, end: z };
        }
        if locked(nl, nr) {
            return Walk::Fail(FailReason::CurveEdge);
        }
        crossed.push((nl, nr));
        (l, r, cur) = (nl, nr, g);
    }
    Walk::Fail(FailReason::Lost)
}
