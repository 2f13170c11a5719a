//! The rest of a segment after a failed walk, from wherever the walk stopped: the seed's
//! Dijkstra-and-project (§3.2) when it turns no face over, else the route across faces made a
//! chain by edge splits ([`super::route`]); a segment with neither is recorded as failed.

use crate::mesh::Point3;

use super::super::trimesh::IntMap;
use super::dijkstra::{dijkstra_project, Projected};
use super::snap::{keeps_orientation, SNAP_MAX_TURN_COS};
use super::split::split_crossings;
use super::stats::{detour, FailedSegment, Fallback};
use super::{lock_chain, off_surface, route, Work};
use crate::geometry::closest_on_segment;

/// Largest number of faces the route fallback settles for one segment.
const ROUTE_BUDGET: usize = 1_000_000;

impl Work<'_> {
    /// Completes segment `si` (curve points `seg`, mesh vertices `(u, w)`) whose walk stopped
    /// for `walk`; `chain` holds what the walk made. Records the method, or the failure.
    pub(super) fn finish_segment(
        &mut self,
        si: usize,
        seg: [u32; 2],
        (u, w): (u32, u32),
        walk: &'static str,
        chain: &mut Vec<u32>,
    ) {
        let from = *chain.last().unwrap_or(&u);
        let seg_ends = (self.mesh.pos[u as usize], self.mesh.pos[w as usize]);
        let n0 = chain.len();
        // A segment over a gap of the template has no chain; a fallback would go around the gap.
        let over_gap = self.goes_around_a_gap(u, w, from, seg_ends);
        let result =
            if over_gap { Err(route::NoRoute::Separated) } else { self.fallback(from, w, seg_ends, chain) };
        match result {
            Ok(m) => {
                let d = detour(self.mesh, &chain[n0 - 1..]);
                self.stats.record_fallback(si, m, d);
                lock_chain(&mut self.locked, &chain[n0 - 1..]);
            }
            Err(why) => {
                // A separated segment whose ends no edge path joins at all cannot be a chain.
                let pieces =
                    !over_gap && why == route::NoRoute::Separated && !route::on_one_piece(self.mesh, from, w);
                self.stats.failed_pieces += usize::from(pieces);
                self.stats.off_surface_segments += usize::from(over_gap);
                let other = !pieces && !over_gap;
                self.stats.failed_separated += usize::from(other && why == route::NoRoute::Separated);
                self.stats.failed_budget += usize::from(other && why == route::NoRoute::Budget);
                if self.stats.failed.len() < 20 {
                    self.stats.failed.push(FailedSegment {
                        segment: si,
                        points: seg,
                        vertices: [u, w],
                        stopped_at: from,
                        walk,
                        route: match why {
                            _ if over_gap => "off_surface",
                            _ if pieces => "pieces",
                            route::NoRoute::Separated => "separated",
                            route::NoRoute::Budget => "budget",
                        },
                    });
                }
                self.stats.failed_segments += 1;
                chain.push(w);
            }
        }
    }

    /// Whether segment u–w (walked up to `from`) crosses a gap of the template, so that any
    /// fallback would go around it: both ends on the rim, the straight way off the surface over
    /// the rim ([`off_surface`]), and no route across faces at most [`super::LONG_DETOUR`] × the
    /// ends' distance. (A segment just past the rim of a misaligned open template, with a short
    /// way along the rim, keeps its fallback: measured on woody `auto` and the bunny's pairs.)
    fn goes_around_a_gap(&self, u: u32, w: u32, from: u32, seg: (Point3, Point3)) -> bool {
        if !(self.mesh.is_boundary_vertex(u) && self.mesh.is_boundary_vertex(w)) {
            return false;
        }
        if !off_surface::is_off_surface(self.mesh, u, w) {
            return false;
        }
        match route::find(self.mesh, from, w, seg, &self.locked, ROUTE_BUDGET) {
            Err(_) => true,
            Ok(crossings) => {
                let pos = &self.mesh.pos;
                route_length(pos, from, w, &crossings)
                    > super::LONG_DETOUR * crate::geometry::dist(pos[from as usize], pos[w as usize])
            }
        }
    }

    /// Realises the rest of a segment from `from` (the last chain vertex) to `to`. Pushes the
    /// chain after `from` including `to`.
    fn fallback(
        &mut self,
        from: u32,
        to: u32,
        seg: (Point3, Point3),
        chain: &mut Vec<u32>,
    ) -> Result<Fallback, route::NoRoute> {
        match dijkstra_project(self.mesh, from, to, &self.on_curve, &mut self.uv_moves) {
            Projected::Done(path) => {
                for &v in &path[1..] {
                    self.on_curve[v as usize] = true;
                    chain.push(v);
                }
                return Ok(Fallback::Dijkstra(path.len().saturating_sub(2)));
            }
            Projected::WouldFlip => self.stats.fallback_refused_flips += 1,
            Projected::NoPath => {}
        }
        let crossings = route::find(self.mesh, from, to, seg, &self.locked, ROUTE_BUDGET)?;
        let n0 = chain.len();
        if !split_crossings(self.mesh, &crossings, &mut self.on_curve, &mut self.added, chain) {
            // Cannot happen for a route of distinct faces (each split leaves the next edge in
            // place); kept as a named failure rather than a panic.
            return Err(route::NoRoute::Budget);
        }
        let new: Vec<u32> = chain[n0..].to_vec();
        self.pull_onto_segment(&new, seg);
        chain.push(to);
        Ok(Fallback::Route(new.len()))
    }

    /// The split points lie on the surface; each moves onto the straight segment where that turns
    /// no face of its star over (against the normals before any move).
    fn pull_onto_segment(&mut self, new: &[u32], seg: (Point3, Point3)) {
        let mesh = &mut *self.mesh;
        let mut before: IntMap<u32, Point3> = IntMap::default();
        for &m in new {
            for &f in mesh.faces_of(m) {
                before.insert(f, mesh.face_normal(f));
            }
        }
        for &m in new {
            let target = closest_on_segment(mesh.pos[m as usize], seg.0, seg.1);
            if keeps_orientation(mesh, m, target, |f| before.get(&f).copied(), SNAP_MAX_TURN_COS) {
                self.uv_moves.extend(super::super::uvs::record(mesh, m, target));
                mesh.pos[m as usize] = target;
                self.stats.route_vertices_on_segment += 1;
            }
        }
    }
}

/// Length of the polyline from `from` through the route's crossing points to `to`.
fn route_length(pos: &[Point3], from: u32, to: u32, crossings: &[route::Crossing]) -> f64 {
    use crate::geometry::{add, dist, scale, sub};
    let mut at = pos[from as usize];
    let mut len = 0.0;
    for c in crossings {
        let (pl, pr) = (pos[c.l as usize], pos[c.r as usize]);
        let x = add(pl, scale(sub(pr, pl), c.lam));
        len += dist(at, x);
        at = x;
    }
    len + dist(at, pos[to as usize])
}
