//! Building the tables of a [`Topology`] from a face list: corners bucketed by their smaller
//! vertex with a counting sort, each bucket sorted (no hash map per edge), then vertex → corners.

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::{Faces, Mesh};

use super::{Csr, EdgeUse, Topology, NONE, POLL_ITEMS};

impl Topology {
    /// Topology of a mesh's faces.
    pub fn new(mesh: &Mesh) -> Topology {
        Topology::from_faces(&mesh.faces, mesh.positions.len())
    }

    /// [`Topology::new`], polling `progress` between its passes and every [`POLL_ITEMS`]
    /// vertices of the edge pass (~50 ms of work on 280k faces otherwise out of reach of a cancel).
    pub fn new_polled(mesh: &Mesh, progress: &Progress) -> Result<Topology> {
        Topology::from_faces_polled(&mesh.faces, mesh.positions.len(), progress)
    }

    /// Topology of a face list over `n_vertices` vertices. Indices ≥ `n_vertices` (which
    /// [`Mesh::check`] rejects) do not panic: the vertex count grows to cover them.
    pub fn from_faces(faces: &Faces, n_vertices: usize) -> Topology {
        Progress::unpolled(|p| Topology::from_faces_polled(faces, n_vertices, p))
    }

    /// [`Topology::from_faces`], polling `progress` (see [`Topology::new_polled`]).
    pub fn from_faces_polled(faces: &Faces, n_vertices: usize, progress: &Progress) -> Result<Topology> {
        let idx = faces.indices();
        let offsets = faces.offsets();
        let n = idx.iter().map(|&v| v as usize + 1).max().unwrap_or(0).max(n_vertices);
        let nc = idx.len();

        let mut corner_face = vec![0u32; nc];
        for f in 0..faces.len() {
            corner_face[offsets[f] as usize..offsets[f + 1] as usize].fill(f as u32);
        }
        // Half-edge c runs from corner c to the next corner of its face (computed per face, which
        // avoids a corner → face lookup per half-edge).
        let half_edges = || {
            (0..faces.len()).flat_map(move |f| {
                let (s, e) = (offsets[f] as usize, offsets[f + 1] as usize);
                (s..e).map(move |c| (c, idx[c], idx[if c + 1 == e { s } else { c + 1 }]))
            })
        };

        // Bucket the half-edges by their smaller vertex (counting sort), each entry packed as
        // (larger vertex << 32 | corner) so that sorting a bucket orders it by edge, then corner.
        let mut start = vec![0u32; n + 1];
        let mut degenerate = 0usize;
        for (_, a, b) in half_edges() {
            if a == b {
                degenerate += 1;
            } else {
                start[a.min(b) as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        progress.check()?;
        let mut fill = start.clone();
        let mut packed = vec![0u64; nc - degenerate];
        for (c, a, b) in half_edges() {
            if a != b {
                let lo = a.min(b) as usize;
                packed[fill[lo] as usize] = ((a.max(b) as u64) << 32) | c as u64;
                fill[lo] += 1;
            }
        }
        drop(fill);
        progress.check()?;

        let mut corner_edge = vec![NONE; nc];
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(packed.len() / 2 + 1);
        let mut edge_offsets: Vec<u32> = Vec::with_capacity(packed.len() / 2 + 2);
        let mut uses: Vec<EdgeUse> = Vec::with_capacity(packed.len());
        let mut lo_start = vec![0u32; n + 1];
        for lo in 0..n {
            progress.check_every(lo, POLL_ITEMS)?;
            lo_start[lo] = edges.len() as u32;
            let bucket = &mut packed[start[lo] as usize..start[lo + 1] as usize];
            if bucket.len() > 1 {
                bucket.sort_unstable();
            }
            let mut prev_hi = NONE;
            for &p in bucket.iter() {
                let hi = (p >> 32) as u32;
                let c = (p & 0xffff_ffff) as usize;
                if hi != prev_hi {
                    edge_offsets.push(uses.len() as u32);
                    edges.push([lo as u32, hi]);
                    prev_hi = hi;
                }
                let f = corner_face[c];
                uses.push(EdgeUse {
                    face: f,
                    corner: c as u32 - offsets[f as usize],
                    forward: idx[c] as usize == lo,
                });
                corner_edge[c] = edges.len() as u32 - 1;
            }
        }
        lo_start[n] = edges.len() as u32;
        edge_offsets.push(uses.len() as u32);

        progress.check()?;
        // Vertex → corners, by counting sort (rows come out ascending).
        let mut vc_off = vec![0u32; n + 1];
        for &v in idx {
            vc_off[v as usize + 1] += 1;
        }
        for v in 0..n {
            vc_off[v + 1] += vc_off[v];
        }
        let mut fill = vc_off.clone();
        let mut vc = vec![0u32; nc];
        for (c, &v) in idx.iter().enumerate() {
            vc[fill[v as usize] as usize] = c as u32;
            fill[v as usize] += 1;
        }

        Ok(Topology {
            n_vertices: n,
            face_offsets: offsets.to_vec(),
            corner_vertex: idx.to_vec(),
            corner_face,
            corner_edge,
            edges,
            edge_offsets,
            uses,
            lo_start,
            vertex_corners: Csr { offsets: vc_off, items: vc },
            degenerate_half_edges: degenerate,
        })
    }
}
