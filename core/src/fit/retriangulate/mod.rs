//! Partitioning, part 1 (Ch. 3): make every curve segment a chain of mesh edges.
//!
//! For a segment (u, w) whose ends are already mesh vertices (after the fine deformation), we walk
//! from u to w across the faces its projection crosses (Appendix A), remove those faces (the
//! "clear-out region"), insert the edge u–w and fill the two polygons on either side by greedy
//! smallest-angle ear cutting (Fig. 3.3). The face count of the region is unchanged.
//!
//! Differences from the thesis, each fixing a failure it leaves open:
//! - The projection is a *cutting plane* through u and w containing the mean surface normal, with
//!   the side of every vertex decided once from its signed distance. The walk is therefore
//!   consistent across faces and cannot lose its way when the path runs through a vertex.
//! - A crossing within `snap_fraction` of an edge length from a free vertex snaps that vertex
//!   onto the segment and makes it a chain vertex (instead of creating a sliver triangle).
//! - When the walk fails (mesh boundary, crossing another curve's edge, lost in a fold, no valid
//!   re-triangulation) the segment waits until every other segment was walked, then the fallback
//!   of §3.2 runs (a Dijkstra path between the ends, its inner vertices moved onto the segment:
//!   [`dijkstra`]) if that turns no face over, else the route across faces split into a chain
//!   ([`route`]), which exists whenever the realised curves do not separate the ends. A segment
//!   with no route is reported as "separated" (crossing or tangled input), never dropped silently.
//!
//! Files: this one (the walk, the snapping, the order of segments and fallbacks), `fill.rs` (the
//! ear-cut re-filling of a walked strip), `dijkstra.rs`, `route.rs`.

use std::collections::HashSet;
use std::hash::BuildHasherDefault;

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{add, cross, dot, norm, normalize, scale, sub};
use crate::job::Progress;
use crate::mesh::Point3;

use super::curves::CurveNetwork;
use super::trimesh::{IntHasher, IntMap, TriMesh};

mod dijkstra;
mod fill;
mod route;

use dijkstra::{dijkstra_project, Projected};
use fill::retriangulate;

type EdgeSet = HashSet<(u32, u32), BuildHasherDefault<IntHasher>>;

#[derive(Debug, Clone, Default, Serialize)]
pub struct RetriStats {
    pub segments: usize,
    /// Segments that were mesh edges already.
    pub already_edges: usize,
    /// Segments realised by walk + re-triangulation (possibly in several snapped pieces).
    pub walked: usize,
    /// Free mesh vertices snapped onto a segment (they become chain vertices).
    pub snapped_vertices: usize,
    /// Segments (or pieces) whose strip could not be re-triangulated and had their crossed edges
    /// split instead, and the vertices that added.
    pub split_segments: usize,
    pub split_vertices: usize,
    /// Segments (or their rest after a partial walk) realised by the Dijkstra-and-project fallback
    /// (§3.2), taken only when moving its path onto the segment turns no face over.
    pub fallback_segments: usize,
    /// Vertices the fallback moved onto a segment.
    pub fallback_moved_vertices: usize,
    /// Dijkstra paths found but not taken because projecting them would turn a face over.
    pub fallback_refused_flips: usize,
    /// Segments realised by the route across faces made a chain by edge splits ([`route`]), the
    /// vertices the splits added and how many of those could then move onto the segment.
    pub route_segments: usize,
    pub route_vertices: usize,
    pub route_vertices_on_segment: usize,
    /// Route chains more than [`LONG_DETOUR`] times longer than their ends' distance: realised
    /// curves blocked the straight way (crossing input, or curve vertices placed in a tangled
    /// order by the fine stage) and the chain goes around them, so the regions next to it may
    /// differ from the input's.
    pub route_long_detours: usize,
    /// Which fallback realised which segment (the first 50).
    pub fallbacks: Vec<FallbackUse>,
    /// Segments that could not be realised at all.
    pub failed_segments: usize,
    /// Why walks stopped (one count per failed walk piece).
    pub walk_fail_start: usize,
    pub walk_fail_boundary: usize,
    pub walk_fail_curve_edge: usize,
    pub walk_fail_lost: usize,
    pub walk_fail_fill: usize,
    /// The first segments that could not be realised (up to 20): why the walk stopped and
    /// whether the fallback ran, for diagnosis.
    pub failed: Vec<FailedSegment>,
}

#[derive(Debug, Clone, Serialize)]
pub struct FailedSegment {
    /// Index into the network's segments, and its two curve points.
    pub segment: usize,
    pub points: [u32; 2],
    /// Mesh vertices of the ends and where the walk stopped.
    pub vertices: [u32; 2],
    pub stopped_at: u32,
    /// "start", "boundary", "curve_edge", "lost" or "fill".
    pub walk: &'static str,
    /// Why the route fallback found no way: "separated" (curve edges realised earlier separate the
    /// ends on the surface: crossing or tangled input, no chain exists without crossing a curve) or
    /// "budget" (search limit reached).
    pub route: &'static str,
}

#[derive(Debug, Clone, Serialize)]
pub struct FallbackUse {
    pub segment: usize,
    /// "dijkstra" or "route".
    pub method: &'static str,
    /// Vertices moved (dijkstra) or added (route) for this segment.
    pub vertices: usize,
    /// Length of the chain the fallback made over the straight distance of its ends: well above
    /// 1 when realised curves block the straight way (crossing or tangled input) and the chain
    /// goes around them.
    pub detour: f64,
}

/// How a fallback realised a segment.
enum Fallback {
    Dijkstra(usize),
    Route(usize),
}

/// A route chain longer than this × its ends' distance is counted as a long detour.
pub const LONG_DETOUR: f64 = 3.0;

/// Chain length over end-to-end distance.
fn detour(mesh: &TriMesh, chain: &[u32]) -> f64 {
    let (Some(&a), Some(&b)) = (chain.first(), chain.last()) else { return 1.0 };
    let len: f64 = chain.windows(2).map(|p| mesh.len(p[0], p[1])).sum();
    let d = mesh.len(a, b);
    if d > 0.0 {
        len / d
    } else {
        1.0
    }
}

pub struct Realised {
    /// Per network segment: the mesh vertex chain from `segments[i][0]`'s vertex to `[1]`'s.
    pub chains: Vec<Vec<u32>>,
    /// Vertices on some chain (curve vertices and those added to chains).
    pub on_curve: Vec<bool>,
    /// Vertices added by splitting crossed edges (ids after the input mesh's, in order): the two
    /// edge ends and weights (third entry unused, weight 0), for attribute interpolation.
    pub added: Vec<[(u32, f64); 3]>,
    pub stats: RetriStats,
    /// Vertices moved over the surface (snapped or pulled onto a segment), in move order, with
    /// where their new position lies on the mesh before the move: their UVs follow ([`super::uvs`]).
    pub uv_moves: Vec<super::uvs::UvMove>,
}

impl RetriStats {
    fn record_fallback(&mut self, segment: usize, how: Fallback, detour: f64) {
        let (method, vertices) = match how {
            Fallback::Dijkstra(n) => {
                self.fallback_segments += 1;
                self.fallback_moved_vertices += n;
                ("dijkstra", n)
            }
            Fallback::Route(n) => {
                self.route_segments += 1;
                self.route_long_detours += usize::from(detour > LONG_DETOUR);
                self.route_vertices += n;
                ("route", n)
            }
        };
        if self.fallbacks.len() < 50 {
            self.fallbacks.push(FallbackUse { segment, method, vertices, detour });
        }
    }
    fn clone_counts(&self) -> [usize; 5] {
        [
            self.walk_fail_start,
            self.walk_fail_boundary,
            self.walk_fail_curve_edge,
            self.walk_fail_lost,
            self.walk_fail_fill,
        ]
    }
    /// The walk failure counted since `before` (the last one when several pieces failed).
    fn fail_reason_since(&self, before: [usize; 5]) -> &'static str {
        let now = self.clone_counts();
        let names = ["start", "boundary", "curve_edge", "lost", "fill"];
        (0..5).rev().find(|&k| now[k] > before[k]).map_or("unknown", |k| names[k])
    }
}

/// The plane through the segment that contains the mean surface normal.
struct Cut {
    a: Point3,
    dir: Point3,
    side: Point3,
    len: f64,
}

impl Cut {
    fn s(&self, p: Point3) -> f64 {
        dot(sub(p, self.a), self.side)
    }
    fn t(&self, p: Point3) -> f64 {
        dot(sub(p, self.a), self.dir)
    }
    fn on_line(&self, p: Point3) -> Point3 {
        add(self.a, scale(self.dir, self.t(p).clamp(0.0, self.len)))
    }
}

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

pub fn realise(
    mesh: &mut TriMesh,
    net: &CurveNetwork,
    vertex_of_point: &[u32],
    snap_fraction: f64,
    progress: &Progress,
) -> Result<Realised> {
    let mut on_curve = vec![false; mesh.pos.len()];
    for &v in vertex_of_point {
        on_curve[v as usize] = true;
    }
    let mut locked_edges = EdgeSet::default();
    let mut stats = RetriStats { segments: net.segments.len(), ..Default::default() };
    let mut chains = Vec::with_capacity(net.segments.len());
    let mut added = Vec::new();
    let mut uv_moves = Vec::new();
    // Segments whose walk failed, with why: their fallbacks run after every walk, so a route
    // (which may leave the straight line) sees all the walked chains and cannot pass on the wrong
    // side of a curve vertex whose own segments are yet to come.
    let mut pending: Vec<(usize, &'static str)> = Vec::new();
    for (si, seg) in net.segments.iter().enumerate() {
        if si % 256 == 0 {
            progress.fraction(0.8 * si as f64 / net.segments.len().max(1) as f64)?;
        }
        let (u, w) = (vertex_of_point[seg[0] as usize], vertex_of_point[seg[1] as usize]);
        let mut chain = vec![u];
        if mesh.has_edge(u, w) {
            stats.already_edges += 1;
            chain.push(w);
        } else {
            let before = stats.clone_counts();
            let ok = walk_segment(
                mesh,
                u,
                w,
                snap_fraction,
                &mut on_curve,
                &locked_edges,
                &mut chain,
                &mut added,
                &mut stats,
                &mut uv_moves,
            );
            if ok {
                stats.walked += 1;
            } else {
                pending.push((si, stats.fail_reason_since(before)));
            }
        }
        lock_chain(&mut locked_edges, &chain);
        chains.push(chain);
    }
    for (k, &(si, walk)) in pending.iter().enumerate() {
        if k % 64 == 0 {
            progress.fraction(0.8 + 0.2 * k as f64 / pending.len() as f64)?;
        }
        let seg = net.segments[si];
        let (u, w) = (vertex_of_point[seg[0] as usize], vertex_of_point[seg[1] as usize]);
        // From wherever the walk stopped: the seed's Dijkstra-and-project when it turns no face
        // over, else the route across faces made a chain by edge splits.
        let mut chain = std::mem::take(&mut chains[si]);
        let from = *chain.last().unwrap_or(&u);
        let seg_ends = (mesh.pos[u as usize], mesh.pos[w as usize]);
        let n0 = chain.len();
        let method = fallback(
            mesh,
            from,
            w,
            seg_ends,
            &mut on_curve,
            &locked_edges,
            &mut chain,
            &mut added,
            &mut stats,
            &mut uv_moves,
        );
        match method {
            Ok(m) => {
                stats.record_fallback(si, m, detour(mesh, &chain[n0 - 1..]));
                lock_chain(&mut locked_edges, &chain[n0 - 1..]);
            }
            Err(why) => {
                if stats.failed.len() < 20 {
                    stats.failed.push(FailedSegment {
                        segment: si,
                        points: seg,
                        vertices: [u, w],
                        stopped_at: from,
                        walk,
                        route: match why {
                            route::NoRoute::Separated => "separated",
                            route::NoRoute::Budget => "budget",
                        },
                    });
                }
                stats.failed_segments += 1;
                chain.push(w);
            }
        }
        chains[si] = chain;
    }
    Ok(Realised { chains, on_curve, added, stats, uv_moves })
}

fn lock_chain(locked: &mut EdgeSet, chain: &[u32]) {
    for p in chain.windows(2) {
        locked.insert((p[0].min(p[1]), p[0].max(p[1])));
    }
}

/// Largest number of faces the route fallback settles for one segment.
const ROUTE_BUDGET: usize = 1_000_000;

/// Realises the rest of a segment from `from` (the last chain vertex) to `to` after a failed
/// walk: Dijkstra-and-project when it turns no face over, else the route across faces split into
/// a chain. Pushes the chain after `from` including `to`.
#[allow(clippy::too_many_arguments)]
fn fallback(
    mesh: &mut TriMesh,
    from: u32,
    to: u32,
    seg: (Point3, Point3),
    on_curve: &mut Vec<bool>,
    locked_edges: &EdgeSet,
    chain: &mut Vec<u32>,
    added: &mut Vec<[(u32, f64); 3]>,
    stats: &mut RetriStats,
    uv_moves: &mut Vec<super::uvs::UvMove>,
) -> std::result::Result<Fallback, route::NoRoute> {
    match dijkstra_project(mesh, from, to, on_curve, uv_moves) {
        Projected::Done(path) => {
            for &v in &path[1..] {
                on_curve[v as usize] = true;
                chain.push(v);
            }
            return Ok(Fallback::Dijkstra(path.len().saturating_sub(2)));
        }
        Projected::WouldFlip => stats.fallback_refused_flips += 1,
        Projected::NoPath => {}
    }
    let crossings = route::find(mesh, from, to, seg, locked_edges, ROUTE_BUDGET)?;
    let n0 = chain.len();
    if !split_crossings(mesh, &crossings, on_curve, added, chain) {
        // Cannot happen for a route of distinct faces (each split leaves the next edge in place);
        // kept as a named failure rather than a panic.
        return Err(route::NoRoute::Budget);
    }
    // The split points lie on the surface; each moves onto the straight segment where that turns
    // no face of its star over (against the normals before any move).
    let new: Vec<u32> = chain[n0..].to_vec();
    let mut before: IntMap<u32, Point3> = IntMap::default();
    for &m in &new {
        for &f in mesh.faces_of(m) {
            before.insert(f, mesh.face_normal(f));
        }
    }
    for &m in &new {
        let target = closest_on_segment(mesh.pos[m as usize], seg.0, seg.1);
        if keeps_orientation(mesh, m, target, |f| before.get(&f).copied()) {
            uv_moves.extend(super::uvs::record(mesh, m, target));
            mesh.pos[m as usize] = target;
            stats.route_vertices_on_segment += 1;
        }
    }
    chain.push(to);
    Ok(Fallback::Route(new.len()))
}

fn closest_on_segment(p: Point3, a: Point3, b: Point3) -> Point3 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 { (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    add(a, scale(ab, t))
}

/// Would moving `z` to `target` keep every face of its star turned the way `reference` says
/// (the face's current normal when `reference` has none) and of non-negligible area?
fn keeps_orientation(
    mesh: &TriMesh,
    z: u32,
    target: Point3,
    reference: impl Fn(u32) -> Option<Point3>,
) -> bool {
    mesh.faces_of(z).iter().all(|&f| {
        let t = mesh.tris[f as usize];
        let p = |v: u32| if v == z { target } else { mesh.pos[v as usize] };
        let n0 = mesh.face_normal(f);
        let r = reference(f).unwrap_or(n0);
        let n1 = cross(sub(p(t[1]), p(t[0])), sub(p(t[2]), p(t[0])));
        dot(r, n1) > 0.0 && dot(n0, n1) > 0.0 && norm(n1) > 1e-12 * norm(n0)
    })
}

/// Walks and re-triangulates from u to w, possibly in pieces at snapped vertices. Pushes chain
/// vertices after u; returns false when the fallback is needed (from the last chain vertex).
#[allow(clippy::too_many_arguments)]
fn walk_segment(
    mesh: &mut TriMesh,
    u: u32,
    w: u32,
    snap_fraction: f64,
    on_curve: &mut Vec<bool>,
    locked_edges: &EdgeSet,
    chain: &mut Vec<u32>,
    added: &mut Vec<[(u32, f64); 3]>,
    stats: &mut RetriStats,
    uv_moves: &mut Vec<super::uvs::UvMove>,
) -> bool {
    let (a, b) = (mesh.pos[u as usize], mesh.pos[w as usize]);
    let d = sub(b, a);
    let len = norm(d);
    if len == 0.0 {
        stats.walk_fail_start += 1;
        return false;
    }
    let dir = scale(d, 1.0 / len);
    let n = add(mesh.vertex_normal(u), mesh.vertex_normal(w));
    let n = normalize(sub(n, scale(dir, dot(n, dir))));
    if n == [0.0; 3] {
        stats.walk_fail_start += 1;
        return false;
    }
    let cut = Cut { a, dir, side: cross(n, dir), len };
    let mut cur = u;
    for _piece in 0..10_000 {
        match walk(mesh, &cut, cur, w, snap_fraction, on_curve, locked_edges) {
            Walk::Edge => {
                chain.push(w);
                return true;
            }
            Walk::SnapAtStart(z) => {
                let target = cut.on_line(mesh.pos[z as usize]);
                uv_moves.extend(super::uvs::record(mesh, z, target));
                mesh.pos[z as usize] = target;
                on_curve[z as usize] = true;
                stats.snapped_vertices += 1;
                chain.push(z);
                cur = z;
            }
            Walk::Strip { faces, crossed, end } => {
                let old = mesh.pos[end as usize];
                let mut moved = None;
                if end != w {
                    let target = cut.on_line(old);
                    moved = super::uvs::record(mesh, end, target);
                    mesh.pos[end as usize] = target;
                }
                if !retriangulate(mesh, cur, end, &faces, &crossed) {
                    // No valid re-triangulation of the strip with the same face count (it wraps
                    // around a vertex, or an ear would need an existing edge): split every edge
                    // the segment crosses instead, at the crossing (Li's insertion; +2 faces per
                    // crossed edge). The walk already proved the strip connects cur to end.
                    stats.walk_fail_fill += 1;
                    let n0 = chain.len();
                    if !split_strip(mesh, &cut, &crossed, on_curve, added, chain) {
                        if chain.len() == n0 {
                            mesh.pos[end as usize] = old;
                        }
                        return false;
                    }
                    stats.split_vertices += chain.len() - n0;
                    stats.split_segments += 1;
                }
                uv_moves.extend(moved);
                chain.push(end);
                if end == w {
                    return true;
                }
                on_curve[end as usize] = true;
                stats.snapped_vertices += 1;
                cur = end;
            }
            Walk::Fail(r) => {
                match r {
                    FailReason::Start => stats.walk_fail_start += 1,
                    FailReason::Boundary => stats.walk_fail_boundary += 1,
                    FailReason::CurveEdge => stats.walk_fail_curve_edge += 1,
                    FailReason::Lost => stats.walk_fail_lost += 1,
                }
                return false;
            }
        }
    }
    false
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
    keeps_orientation(mesh, z, target, |_| None)
}

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
    let pf = mesh.pos[from as usize];
    let t_end = cut.t(mesh.pos[to as usize]);
    // Start: the face of `from`'s star whose opposite edge the forward ray crosses.
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
        // The most forward of the (usually two) crossings; it may point slightly backwards when the
        // chord leaves the surface steeply, the later checks catch a wrong start.
        if best.is_none_or(|b| fwd > b.3) {
            best = Some((f, l, r, fwd));
        }
    }
    let Some((f0, mut l, mut r, _)) = best else { return Walk::Fail(FailReason::Start) };
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

/// Splits every crossed edge (l, r) of a strip where the cut plane crosses it, pushing the new
/// vertices onto `chain`. False if an edge is no longer there (nothing else done for it; the chain
/// stays valid up to its last vertex).
fn split_strip(
    mesh: &mut TriMesh,
    cut: &Cut,
    crossed: &[(u32, u32)],
    on_curve: &mut Vec<bool>,
    added: &mut Vec<[(u32, f64); 3]>,
    chain: &mut Vec<u32>,
) -> bool {
    // At the crossing itself (on the surface): moving it onto the straight segment would fold
    // the split faces where the strip is long and curved.
    let crossings: Vec<route::Crossing> =
        crossed.iter().map(|&(l, r)| route::Crossing { l, r, lam: crossing(mesh, cut, l, r).1 }).collect();
    split_crossings(mesh, &crossings, on_curve, added, chain)
}

/// Splits each crossed edge in order at its fraction, pushing the new vertices onto `chain`
/// (consecutive crossings of one face become an edge between their new vertices).
fn split_crossings(
    mesh: &mut TriMesh,
    crossings: &[route::Crossing],
    on_curve: &mut Vec<bool>,
    added: &mut Vec<[(u32, f64); 3]>,
    chain: &mut Vec<u32>,
) -> bool {
    for c in crossings {
        let (pl, pr) = (mesh.pos[c.l as usize], mesh.pos[c.r as usize]);
        let x = add(pl, scale(sub(pr, pl), c.lam));
        let Some(m) = split_edge(mesh, c.l, c.r, x) else { return false };
        added.push([(c.l, 1.0 - c.lam), (c.r, c.lam), (c.l, 0.0)]);
        on_curve.push(true);
        chain.push(m);
    }
    true
}

/// Splits edge (a, b) at `x` and the one or two faces on it; the new vertex's id.
fn split_edge(mesh: &mut TriMesh, a: u32, b: u32, x: Point3) -> Option<u32> {
    let faces: Vec<u32> =
        [mesh.face_with_edge(a, b), mesh.face_with_edge(b, a)].into_iter().flatten().collect();
    if faces.is_empty() {
        return None;
    }
    let m = mesh.add_vertex(x);
    for f in faces {
        let t = mesh.tris[f as usize];
        let k = (0..3).find(|&k| (t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a))?;
        let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        mesh.remove_face(f);
        // The removed face freed its directed edges; p→m, m→q and the edges at m are new.
        mesh.add_face([p, m, r]).ok()?;
        mesh.add_face([m, q, r]).ok()?;
    }
    Some(m)
}

/// Where the cut plane crosses edge (l, r) (s(l) ≥ 0 > s(r)): the point and its parameter from l.
fn crossing(mesh: &TriMesh, cut: &Cut, l: u32, r: u32) -> (Point3, f64) {
    let (pl, pr) = (mesh.pos[l as usize], mesh.pos[r as usize]);
    let (sl, sr) = (cut.s(pl), cut.s(pr));
    let lam = if sl - sr > 0.0 { (sl / (sl - sr)).clamp(0.0, 1.0) } else { 0.5 };
    (add(pl, scale(sub(pr, pl), lam)), lam)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitting_the_crossed_edges_makes_the_segment_a_chain() {
        // A strip of 4 triangles in the plane z = 0 between u = 0 at (0, 0) and w = 5 at (3, 0):
        // upper vertices 1 (0.5, 1), 3 (1.5, 1), lower 2 (1, -1), 4 (2, -1). The segment u–w
        // crosses edges 1-2, 2-3 and 3-4 (hand count), so 3 new vertices at y = 0 join u to w.
        let pos = vec![
            [0.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.5, 1.0, 0.0],
            [2.0, -1.0, 0.0],
            [3.0, 0.0, 0.0],
        ];
        let tris = vec![[0, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5]];
        let mut mesh = TriMesh::new(pos, tris).unwrap();
        let cut = Cut { a: [0.0; 3], dir: [1.0, 0.0, 0.0], side: [0.0, 1.0, 0.0], len: 3.0 };
        let crossed = [(1, 2), (3, 2), (3, 4)];
        let (mut on_curve, mut added, mut chain) = (vec![false; 6], Vec::new(), vec![0]);
        assert!(split_strip(&mut mesh, &cut, &crossed, &mut on_curve, &mut added, &mut chain));
        chain.push(5);
        assert_eq!(chain.len(), 5);
        for w in chain.windows(2) {
            assert!(mesh.has_edge(w[0], w[1]), "{w:?} is not an edge");
        }
        for &v in &chain[1..4] {
            assert!(mesh.pos[v as usize][1].abs() < 1e-12, "new vertex off the segment");
        }
        // Every crossed edge split its two faces (or one): 4 + 2 × 3 faces, all still
        // counter-clockwise (+z).
        let live = mesh.live_triangles();
        assert_eq!(live.len(), 10);
        for t in &live {
            let n = crate::geometry::triangle_cross(
                mesh.pos[t[0] as usize],
                mesh.pos[t[1] as usize],
                mesh.pos[t[2] as usize],
            );
            assert!(n[2] > 0.0, "{t:?} turned over");
        }
        assert_eq!((added.len(), on_curve.len()), (3, 9));
        // The interpolation weights reproduce the new positions.
        for (i, a) in added.iter().enumerate() {
            let p = add(scale(mesh.pos[a[0].0 as usize], a[0].1), scale(mesh.pos[a[1].0 as usize], a[1].1));
            assert!(crate::geometry::dist(p, mesh.pos[6 + i]) < 1e-12);
        }
    }

    /// The n × n unit grid of triangles in z = 0 (vertex (i, j) = j(n+1) + i at (i, j, 0)).
    fn grid_mesh(n: usize) -> TriMesh {
        let g = crate::shapes::grid(n, n, 1.0, false);
        TriMesh::new(g.positions, crate::shapes::fan_triangles(&g.faces)).unwrap()
    }

    fn all_up(mesh: &TriMesh) -> bool {
        mesh.alive_faces().all(|f| mesh.face_normal(f)[2] > 0.0)
    }

    /// Where the polyline through `chain` crosses the line x = x0 (all the y values).
    fn crossings_at_x(mesh: &TriMesh, chain: &[u32], x0: f64) -> Vec<f64> {
        chain
            .windows(2)
            .filter_map(|w| {
                let (p, q) = (mesh.pos[w[0] as usize], mesh.pos[w[1] as usize]);
                if (p[0] - x0) * (q[0] - x0) > 0.0 || p[0] == q[0] {
                    return None;
                }
                let t = (x0 - p[0]) / (q[0] - p[0]);
                Some(p[1] + t * (q[1] - p[1]))
            })
            .collect()
    }

    #[test]
    fn route_goes_around_a_curve_wall_and_splits_into_a_chain() {
        // A wall of curve edges on x = 5 from y = 3 to y = 7 between u = (2, 5) and w = (8, 5):
        // any chain from u to w must pass x = 5 at y ≤ 3 or y ≥ 7 (hand truth), and the splits
        // add 2 faces per crossed edge and turn none over.
        let n = 10;
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut mesh = grid_mesh(n);
        let mut locked = EdgeSet::default();
        lock_chain(&mut locked, &(3..=7).map(|j| id(5, j)).collect::<Vec<_>>());
        let (u, w) = (id(2, 5), id(8, 5));
        let seg = (mesh.pos[u as usize], mesh.pos[w as usize]);
        let crossings = route::find(&mesh, u, w, seg, &locked, 10_000).expect("a route exists");
        let faces0 = mesh.live_triangles().len();
        let (mut on_curve, mut added, mut chain) = (vec![false; mesh.pos.len()], Vec::new(), vec![u]);
        assert!(split_crossings(&mut mesh, &crossings, &mut on_curve, &mut added, &mut chain));
        chain.push(w);
        assert_eq!(mesh.live_triangles().len(), faces0 + 2 * crossings.len());
        assert!(all_up(&mesh));
        for p in chain.windows(2) {
            assert!(mesh.has_edge(p[0], p[1]), "{p:?} is not an edge");
            assert!(!locked.contains(&(p[0].min(p[1]), p[0].max(p[1]))));
        }
        // Only new vertices between the ends: the chain passes through no old vertex.
        assert!(chain[1..chain.len() - 1].iter().all(|&v| v as usize > id(n, n) as usize));
        let ys = crossings_at_x(&mesh, &chain, 5.0);
        assert!(!ys.is_empty() && ys.iter().all(|&y| y <= 3.0 + 1e-9 || y >= 7.0 - 1e-9), "{ys:?}");
    }

    #[test]
    fn route_reports_ends_separated_by_a_closed_curve() {
        // w = (5, 5) inside a closed loop of curve edges around it: no chain from (1, 1) exists.
        let n = 10;
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mesh = grid_mesh(n);
        let mut locked = EdgeSet::default();
        let ring = [(4, 4), (5, 4), (6, 4), (6, 5), (6, 6), (5, 6), (4, 6), (4, 5), (4, 4)];
        lock_chain(&mut locked, &ring.iter().map(|&(i, j)| id(i, j)).collect::<Vec<_>>());
        let (u, w) = (id(1, 1), id(5, 5));
        let seg = (mesh.pos[u as usize], mesh.pos[w as usize]);
        assert_eq!(route::find(&mesh, u, w, seg, &locked, 10_000), Err(route::NoRoute::Separated));
    }

    #[test]
    fn realise_makes_a_blocked_segment_a_chain_around_the_block() {
        // Curve 0: the wall x = 5, y = 3..7 through grid vertices; curve 1: one segment from (2, 5)
        // to (8, 6) across it (crossing input: the straight way is blocked by the wall's edges).
        // The walk stops at the wall; the fallback must still give an edge chain, around the wall
        // (so at least 2·√(3² + 2²) − long, hand bound: detour ≥ 7.2 / √37 ≈ 1.18).
        let n = 10;
        let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut mesh = grid_mesh(n);
        let mut pts: Vec<Point3> = (3..=7).map(|j| mesh.pos[id(5, j) as usize]).collect();
        pts.push(mesh.pos[id(2, 5) as usize]);
        pts.push(mesh.pos[id(8, 6) as usize]);
        let curves = crate::mesh::Mesh {
            positions: pts.clone(),
            curves: vec![vec![0, 1, 2, 3, 4], vec![5, 6]],
            ..Default::default()
        };
        let net = CurveNetwork::from_mesh(&curves, 1e-9).unwrap();
        let vop: Vec<u32> = net
            .points
            .iter()
            .map(|p| (0..mesh.pos.len() as u32).find(|&v| mesh.pos[v as usize] == *p).unwrap())
            .collect();
        let r = realise(&mut mesh, &net, &vop, 0.2, &Progress::new()).unwrap();
        assert_eq!(r.stats.failed_segments, 0, "{:?}", r.stats.failed);
        for c in &r.chains {
            for p in c.windows(2) {
                assert!(mesh.has_edge(p[0], p[1]), "{p:?} is not an edge");
            }
        }
        assert!(all_up(&mesh));
        let blocked = net
            .segments
            .iter()
            .position(|s| vop[s[0] as usize] == id(2, 5) || vop[s[1] as usize] == id(2, 5))
            .unwrap();
        let used: Vec<_> = r.stats.fallbacks.iter().filter(|f| f.segment == blocked).collect();
        assert_eq!(used.len(), 1);
        assert!(used[0].detour >= 7.2 / 37f64.sqrt(), "{}", used[0].detour);
        assert_eq!(r.stats.route_long_detours, usize::from(used[0].detour > LONG_DETOUR));
        let ys = crossings_at_x(&mesh, &r.chains[blocked], 5.0);
        assert!(!ys.is_empty() && ys.iter().all(|&y| y <= 3.0 + 1e-9 || y >= 7.0 - 1e-9), "{ys:?}");
    }
}
