//! Boundary loops: closed walks along boundary edges, split at pinch vertices into simple cycles.

use super::{find, FanScratch, Topology, NONE};

/// A closed walk along boundary edges.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoundaryLoop {
    /// Vertices in walking order; the loop closes from the last back to the first. A pinch vertex
    /// may appear in several loops (each hole gets its own loop).
    pub vertices: Vec<u32>,
    /// The boundary edge ids, `edges[i]` joining `vertices[i]` and `vertices[i + 1]` (cyclically).
    pub edges: Vec<u32>,
    /// True when the walk returned to its first edge. False only around non-manifold vertices
    /// where the walk could not be continued; such a loop is a chain, not a cycle.
    pub closed: bool,
}

impl BoundaryLoop {
    /// Splits a closed walk that visits a vertex more than once (holes touching at that vertex
    /// inside one walk) into simple cycles, each visiting every vertex once.
    pub fn simple_cycles(&self) -> Vec<BoundaryLoop> {
        let n = self.vertices.len();
        let mut out = Vec::new();
        // Stack of (vertex, edge leaving it); position of each vertex on the stack.
        let mut stack: Vec<(u32, u32)> = Vec::with_capacity(n);
        let mut at: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for i in 0..n {
            let v = self.vertices[i];
            if let Some(&p) = at.get(&v) {
                let cycle: Vec<(u32, u32)> = stack.drain(p..).collect();
                for &(u, _) in &cycle {
                    at.remove(&u);
                }
                out.push(BoundaryLoop {
                    vertices: cycle.iter().map(|c| c.0).collect(),
                    edges: cycle.iter().map(|c| c.1).collect(),
                    closed: true,
                });
            }
            at.insert(v, stack.len());
            stack.push((v, self.edges[i]));
        }
        if !stack.is_empty() {
            out.push(BoundaryLoop {
                vertices: stack.iter().map(|c| c.0).collect(),
                edges: stack.iter().map(|c| c.1).collect(),
                closed: true,
            });
        }
        out
    }
}

impl Topology {
    /// All boundary loops; each boundary edge belongs to exactly one loop.
    ///
    /// The walk follows the half-edges' own direction where it can (so on a consistently oriented
    /// mesh a loop runs the same way as its faces). At a vertex with several boundary edges to
    /// choose from — a pinch where two holes touch (seed 003 Fig. 4.6) — it continues with an edge
    /// from a *different* fan than the one it arrived through, i.e. it crosses the gap, which is what
    /// keeps each hole a loop of its own. Where the walk cannot go on (a non-manifold tangle) the
    /// loop is returned as an unclosed chain (`closed == false`).
    pub fn boundary_loops(&self) -> Vec<BoundaryLoop> {
        let mut used = vec![false; self.edges.len()];
        let mut loops = Vec::new();
        let mut scratch = FanScratch::default();
        let mut cands: Vec<(usize, u32)> = Vec::new();
        for e0 in 0..self.edges.len() as u32 {
            if used[e0 as usize] || self.edge_valence(e0) != 1 {
                continue;
            }
            let c0 = self.use_corner(&self.edge_uses(e0)[0]);
            let start = self.corner_vertex[c0];
            let mut vertices = vec![start];
            let mut edges = vec![e0];
            used[e0 as usize] = true;
            let (mut h, mut to) = (c0, self.corner_vertex[self.next_corner(c0)]);
            let mut closed = false;
            while let Some((nh, ne)) = self.next_boundary(h, to, &used, e0, &mut scratch, &mut cands) {
                if ne == e0 {
                    closed = true;
                    break;
                }
                used[ne as usize] = true;
                vertices.push(to);
                edges.push(ne);
                let [a, b] = self.edges[ne as usize];
                to = if a == to { b } else { a };
                h = nh;
            }
            let walk = BoundaryLoop { vertices, edges, closed };
            if closed {
                loops.extend(walk.simple_cycles());
            } else {
                loops.push(walk);
            }
        }
        loops
    }

    /// Having arrived at `v` along boundary half-edge `h` (global corner), picks the boundary edge
    /// to continue with: returns (its half-edge corner, its edge id), `e0` when the loop closes.
    fn next_boundary(
        &self,
        h: usize,
        v: u32,
        used: &[bool],
        e0: u32,
        scratch: &mut FanScratch,
        cands: &mut Vec<(usize, u32)>,
    ) -> Option<(usize, u32)> {
        cands.clear();
        for &cc in self.vertex_corners(v) {
            let cc = cc as usize;
            for hh in [cc, self.prev_corner(cc)] {
                let e = self.corner_edge[hh];
                if hh != h
                    && e != NONE
                    && self.edge_valence(e) == 1
                    && (!used[e as usize] || e == e0)
                    && !cands.iter().any(|&(_, ce)| ce == e)
                {
                    cands.push((hh, e));
                }
            }
        }
        if cands.len() <= 1 {
            return cands.first().copied();
        }
        // Several choices: score "leaves v" (keeps the direction) and "another fan" (crosses a gap).
        self.fans_with(v, scratch);
        let corners = self.vertex_corners(v);
        let mut fan_of = |c: usize| -> u32 {
            match corners.binary_search(&(self.corner_at(c, v) as u32)) {
                Ok(i) => find(&mut scratch.parent, i as u32),
                Err(_) => NONE,
            }
        };
        let here = fan_of(h);
        let mut best: Option<((u8, u8), usize, u32)> = None;
        for &(hh, e) in cands.iter() {
            let leaves = u8::from(self.corner_vertex[hh] == v);
            let other_fan = u8::from(fan_of(hh) != here);
            let score = (leaves + other_fan, u8::from(e == e0));
            if best.is_none_or(|(s, _, _)| score > s) {
                best = Some((score, hh, e));
            }
        }
        best.map(|(_, hh, e)| (hh, e))
    }
}
