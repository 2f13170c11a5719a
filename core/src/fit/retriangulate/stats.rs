//! What the realisation reports: counts per method, the fallbacks used and the segments that
//! could not be made chains (with why), for the job's report and for diagnosis.

use serde::Serialize;

use super::super::trimesh::TriMesh;

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
    /// Of those, strips split because they bend too much to be re-filled through one plane
    /// (faces more than 35° from the strip's mean normal).
    pub curved_strips: usize,
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
    /// Of those, segments whose ends lie on pieces of the template that no edge joins (different
    /// components, or the two sides of an unwelded seam): no chain of edges can exist, whatever
    /// the re-triangulation does. Weld or repair the template to realise them.
    pub failed_pieces: usize,
    /// Of those, segments with no surface under them: the straight way between their ends crosses
    /// a hole of the template or runs past its outer rim (a scan with a gap under a curve), so no
    /// chain of edges can follow them and a route around the gap would cut a spurious region off
    /// ([`super::off_surface`]). Close the template's holes (the repair job) to realise them.
    pub off_surface_segments: usize,
    /// Of those, segments whose ends realised curves separate on one piece (route "separated":
    /// crossing input, or curve vertices the fine stage left in a tangled order around a fold)
    /// and segments whose route search ran out of budget: unlike the two above, these could be
    /// chains on this template.
    pub failed_separated: usize,
    pub failed_budget: usize,
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
    /// Why the route fallback found no way: "off_surface" (the segment crosses a hole of the
    /// template or runs past its rim: no fallback is tried), "pieces" (the ends are on pieces of the template that
    /// no edge joins: different components or the two sides of an unwelded seam), "separated"
    /// (curve edges realised earlier separate the ends on the surface: crossing or tangled input,
    /// no chain exists without crossing a curve) or "budget" (search limit reached).
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
pub(super) enum Fallback {
    Dijkstra(usize),
    Route(usize),
}

/// A route chain longer than this × its ends' distance is counted as a long detour.
pub const LONG_DETOUR: f64 = 3.0;

/// Chain length over end-to-end distance.
pub(super) fn detour(mesh: &TriMesh, chain: &[u32]) -> f64 {
    let (Some(&a), Some(&b)) = (chain.first(), chain.last()) else { return 1.0 };
    let len: f64 = chain.windows(2).map(|p| mesh.len(p[0], p[1])).sum();
    let d = mesh.len(a, b);
    if d > 0.0 {
        len / d
    } else {
        1.0
    }
}

impl RetriStats {
    pub(super) fn record_fallback(&mut self, segment: usize, how: Fallback, detour: f64) {
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
    pub(super) fn clone_counts(&self) -> [usize; 5] {
        [
            self.walk_fail_start,
            self.walk_fail_boundary,
            self.walk_fail_curve_edge,
            self.walk_fail_lost,
            self.walk_fail_fill,
        ]
    }
    /// The walk failure counted since `before` (the last one when several pieces failed).
    pub(super) fn fail_reason_since(&self, before: [usize; 5]) -> &'static str {
        let now = self.clone_counts();
        let names = ["start", "boundary", "curve_edge", "lost", "fill"];
        (0..5).rev().find(|&k| now[k] > before[k]).map_or("unknown", |k| names[k])
    }
}
