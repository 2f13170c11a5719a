//! Partitioning, part 1 (Ch. 3): make every curve segment a chain of mesh edges.
//!
//! For a segment (u, w) whose ends are already mesh vertices (after the fine deformation), we walk
//! from u to w across the faces its projection crosses (Appendix A), remove those faces (the
//! "clear-out region"), insert the edge u–w and fill the two polygons on either side by greedy
//! smallest-angle ear cutting (Fig. 3.3). The face count of the region is unchanged.
//!
//! Differences from the thesis, each fixing a failure it leaves open:
//! - The projection is a *cutting plane* through u and w containing the mean surface normal, with
//!   the side of every vertex decided once from its signed distance ([`cut`]). The walk is
//!   therefore consistent across faces and cannot lose its way when the path runs through a vertex.
//! - A crossing within `snap_fraction` of an edge length from a free vertex snaps that vertex
//!   onto the segment and makes it a chain vertex (instead of creating a sliver triangle).
//! - When the walk fails (mesh boundary, crossing another curve's edge, lost in a fold, no valid
//!   re-triangulation) the segment waits until every other segment was walked, then the fallback
//!   of §3.2 runs (a Dijkstra path between the ends, its inner vertices moved onto the segment:
//!   [`dijkstra`]) if that turns no face over, else the route across faces split into a chain
//!   ([`route`]), which exists whenever the realised curves do not separate the ends. A segment
//!   with no route is reported as "separated" (crossing or tangled input), never dropped silently.
//! - A segment whose straight way crosses a hole of the template (or runs past its rim) is not
//!   routed around the hole: it is counted as `off_surface_segments` ([`off_surface`]).
//!
//! Files: this one (the order of segments: walks first, fallbacks after), `walk.rs` (the walk
//! along the cutting plane of `cut.rs` and the snapping), `fill.rs` (the ear-cut re-filling of a
//! walked strip), `split.rs` (edge splits along a segment), `fallback.rs` with `dijkstra.rs` and
//! `route.rs`, `off_surface.rs` (segments over a hole), `snap.rs` (moves onto a segment that turn no face over), `stats.rs` (the report).

use crate::error::Result;
use crate::job::Progress;

use super::curves::CurveNetwork;
use super::trimesh::TriMesh;

mod cut;
mod dijkstra;
mod fallback;
mod fill;
mod off_surface;
mod route;
mod snap;
mod split;
mod stats;
mod walk;

pub use stats::{FailedSegment, FallbackUse, RetriStats, LONG_DETOUR};

use super::trimesh::EdgeSet;

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

/// The mesh and everything the realisation records while it makes segments chains.
struct Work<'m> {
    mesh: &'m mut TriMesh,
    /// Fraction of an edge within which a crossing snaps its vertex onto the segment.
    snap_fraction: f64,
    on_curve: Vec<bool>,
    /// Edges of the chains made so far: no later walk or route crosses them.
    locked: EdgeSet,
    added: Vec<[(u32, f64); 3]>,
    stats: RetriStats,
    uv_moves: Vec<super::uvs::UvMove>,
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
    let mut work = Work {
        mesh,
        snap_fraction,
        on_curve,
        locked: EdgeSet::default(),
        added: Vec::new(),
        stats: RetriStats { segments: net.segments.len(), ..Default::default() },
        uv_moves: Vec::new(),
    };
    let (mut chains, pending) = walk_all(&mut work, net, vertex_of_point, progress)?;
    for (k, &(si, walk)) in pending.iter().enumerate() {
        if k % 64 == 0 {
            progress.fraction(0.8 + 0.2 * k as f64 / pending.len() as f64)?;
            work.mesh.check_growth("retriangulate")?;
        }
        let seg = net.segments[si];
        let (u, w) = (vertex_of_point[seg[0] as usize], vertex_of_point[seg[1] as usize]);
        work.finish_segment(si, seg, (u, w), walk, &mut chains[si]);
    }
    let Work { on_curve, added, stats, uv_moves, .. } = work;
    Ok(Realised { chains, on_curve, added, stats, uv_moves })
}

/// Walks every segment in network order; returns the chains (complete, or up to where the walk
/// stopped) and the segments whose walk failed, with why. Their fallbacks run after every walk,
/// so a route (which may leave the straight line) sees all the walked chains and cannot pass on
/// the wrong side of a curve vertex whose own segments are yet to come.
#[allow(clippy::type_complexity)]
fn walk_all(
    work: &mut Work,
    net: &CurveNetwork,
    vertex_of_point: &[u32],
    progress: &Progress,
) -> Result<(Vec<Vec<u32>>, Vec<(usize, &'static str)>)> {
    let mut chains = Vec::with_capacity(net.segments.len());
    let mut pending = Vec::new();
    for (si, seg) in net.segments.iter().enumerate() {
        if si % 256 == 0 {
            progress.fraction(0.8 * si as f64 / net.segments.len().max(1) as f64)?;
            work.mesh.check_growth("retriangulate")?;
        }
        let (u, w) = (vertex_of_point[seg[0] as usize], vertex_of_point[seg[1] as usize]);
        let mut chain = vec![u];
        if work.mesh.has_edge(u, w) {
            work.stats.already_edges += 1;
            chain.push(w);
        } else {
            let before = work.stats.clone_counts();
            if work.walk_segment(u, w, &mut chain) {
                work.stats.walked += 1;
            } else {
                pending.push((si, work.stats.fail_reason_since(before)));
            }
        }
        lock_chain(&mut work.locked, &chain);
        chains.push(chain);
    }
    Ok((chains, pending))
}

fn lock_chain(locked: &mut EdgeSet, chain: &[u32]) {
    for p in chain.windows(2) {
        locked.insert((p[0].min(p[1]), p[0].max(p[1])));
    }
}

#[cfg(test)]
mod tests {
    use super::cut::Cut;
    use super::split::{split_crossings, split_strip};
    use super::*;
    use crate::geometry::{add, scale};
    use crate::mesh::Point3;

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

    #[test]
    fn a_strip_whose_cut_passes_through_a_vertex_is_not_split_there() {
        // The strip of the test above with vertex 3 moved onto the segment's line, to (1.5, 0):
        // the cutting plane (y = 0) crosses edge 3–2 exactly at vertex 3 (fraction 0, hand
        // value). A split there would add a vertex at vertex 3's place and two zero-area faces;
        // the strip is refused with nothing changed, so the fallback realises the segment.
        let pos = vec![
            [0.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.5, 0.0, 0.0],
            [2.0, -1.0, 0.0],
            [3.0, 0.0, 0.0],
        ];
        let tris = vec![[0, 2, 1], [1, 2, 3], [2, 4, 3], [3, 4, 5]];
        let mut mesh = TriMesh::new(pos.clone(), tris.clone()).unwrap();
        let cut = Cut { a: [0.0; 3], dir: [1.0, 0.0, 0.0], side: [0.0, 1.0, 0.0], len: 3.0 };
        assert_eq!(super::cut::crossing(&mesh, &cut, 3, 2).1, 0.0);
        let crossed = [(1, 2), (3, 2), (3, 4)];
        let (mut on_curve, mut added, mut chain) = (vec![false; 6], Vec::new(), vec![0]);
        assert!(!split_strip(&mut mesh, &cut, &crossed, &mut on_curve, &mut added, &mut chain));
        assert_eq!((mesh.live_triangles(), mesh.pos), (tris, pos));
        assert_eq!((chain, added.len(), on_curve.len()), (vec![0], 0, 6));
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
