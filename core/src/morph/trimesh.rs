//! The triangle mesh the morph pipeline works on, and the topology checks that decide which
//! parametric domain an input can use (seed 002 §1.1: closed genus-0 → sphere).
//!
//! Kept private to the morph job: a compact `positions + triangles` pair plus the few adjacency
//! queries the pipeline needs (vertex → faces, edge → faces), derived on demand.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::mesh::{Mesh, Point3};

/// A triangle mesh with no unreferenced vertices.
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    pub pos: Vec<Point3>,
    pub tris: Vec<[u32; 3]>,
}

/// What converting an input to a [`TriMesh`] changed (reported, never silent).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Conversion {
    /// Polygons with more than 3 corners, fan-triangulated.
    pub polygons_triangulated: usize,
    /// Faces with fewer than 3 corners, dropped.
    pub faces_dropped: usize,
    /// Vertices no face refers to, dropped.
    pub unreferenced_vertices_dropped: usize,
}

impl TriMesh {
    /// Triangulates polygons (fan) and drops unreferenced vertices. `old_to_new[i]` maps an input
    /// vertex index to its index here (`u32::MAX` when dropped).
    pub fn from_mesh(mesh: &Mesh) -> (TriMesh, Vec<u32>, Conversion) {
        let mut conv = Conversion::default();
        let mut tris = Vec::with_capacity(mesh.faces.len());
        // Fans that never reuse an existing edge (see `Faces::fan_apexes`).
        let apex = mesh.faces.fan_apexes();
        for (f, &a) in mesh.faces.iter().zip(&apex) {
            if f.len() < 3 {
                conv.faces_dropped += 1;
                continue;
            }
            if f.len() > 3 {
                conv.polygons_triangulated += 1;
            }
            crate::mesh::fan_of(f, a as usize, |t| tris.push(t));
        }
        let mut map = vec![u32::MAX; mesh.positions.len()];
        let mut pos = Vec::with_capacity(mesh.positions.len());
        for t in &mut tris {
            for v in t.iter_mut() {
                let m = &mut map[*v as usize];
                if *m == u32::MAX {
                    *m = pos.len() as u32;
                    pos.push(mesh.positions[*v as usize]);
                }
                *v = *m;
            }
        }
        conv.unreferenced_vertices_dropped = mesh.positions.len() - pos.len();
        (TriMesh { pos, tris }, map, conv)
    }

    pub fn to_mesh(&self) -> Mesh {
        Mesh::from_triangles(self.pos.clone(), &self.tris)
    }

    /// Faces around each vertex (unordered).
    pub fn vertex_faces(&self) -> Vec<Vec<u32>> {
        let mut vf = vec![Vec::new(); self.pos.len()];
        for (fi, t) in self.tris.iter().enumerate() {
            for &v in t {
                vf[v as usize].push(fi as u32);
            }
        }
        vf
    }

    /// For each face and each of its edges k (from corner k to k+1), the face across it
    /// (`u32::MAX` on a boundary). Assumes a manifold, consistently oriented mesh.
    pub fn face_neighbours(&self) -> Vec<[u32; 3]> {
        let mut half: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.tris.len() * 3);
        for (fi, t) in self.tris.iter().enumerate() {
            for k in 0..3 {
                half.insert((t[k], t[(k + 1) % 3]), fi as u32);
            }
        }
        self.tris
            .iter()
            .map(|t| {
                let mut n = [u32::MAX; 3];
                for k in 0..3 {
                    n[k] = half.get(&(t[(k + 1) % 3], t[k])).copied().unwrap_or(u32::MAX);
                }
                n
            })
            .collect()
    }

    /// Edges as (min, max) vertex pairs, each once.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = self
            .tris
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .collect();
        e.sort_unstable();
        e.dedup();
        e
    }
}

/// The topological facts that decide the domain.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct TopologyInfo {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub components: usize,
    pub boundary_loops: usize,
    /// Edges with more than two faces, or two faces listing it in the same direction.
    pub non_manifold_edges: usize,
    /// Vertices whose faces form more than one fan.
    pub non_manifold_vertices: usize,
    pub euler_characteristic: i64,
    /// Genus of a closed, connected, manifold mesh; None otherwise.
    pub genus: Option<i64>,
}

impl TopologyInfo {
    /// What keeps the mesh from being one manifold piece (several components, non-manifold
    /// edges or vertices), in words; empty when nothing does.
    pub fn defects(&self) -> Vec<String> {
        let mut s = Vec::new();
        if self.components != 1 {
            s.push(format!("{} connected components", self.components));
        }
        if self.non_manifold_edges > 0 {
            s.push(format!("{} non-manifold edges", self.non_manifold_edges));
        }
        if self.non_manifold_vertices > 0 {
            s.push(format!("{} non-manifold vertices", self.non_manifold_vertices));
        }
        s
    }
}

/// Counts of the mesh's topology (edges, boundary loops, non-manifold parts, components, genus).
pub fn topology(m: &TriMesh) -> TopologyInfo {
    let nv = m.pos.len();
    let (edges, boundary_edges, non_manifold_edges) = classify_edges(&m.tris);
    let boundary_loops = count_boundary_loops(&boundary_edges);
    let non_manifold_vertices = count_non_manifold_vertices(m);
    let components = count_components(nv, &m.tris);
    let chi = nv as i64 - edges as i64 + m.tris.len() as i64;
    let genus = (components == 1
        && boundary_loops == 0
        && non_manifold_edges == 0
        && non_manifold_vertices == 0
        && (2 - chi) % 2 == 0)
        .then_some((2 - chi) / 2);
    TopologyInfo {
        vertices: nv,
        edges,
        faces: m.tris.len(),
        components,
        boundary_loops,
        non_manifold_edges,
        non_manifold_vertices,
        euler_characteristic: chi,
        genus,
    }
}

/// The number of undirected edges, the boundary half-edges (used once, in the direction a face
/// uses them) and the number of non-manifold edges (any other use count).
fn classify_edges(tris: &[[u32; 3]]) -> (usize, Vec<(u32, u32)>, usize) {
    // Directed half-edge counts.
    let mut half: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3);
    for t in tris {
        for k in 0..3 {
            *half.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut undirected: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(half.len());
    for (&(a, b), &c) in &half {
        let e = undirected.entry((a.min(b), a.max(b))).or_insert((0, 0));
        if a < b {
            e.0 += c
        } else {
            e.1 += c
        }
    }
    let mut non_manifold_edges = 0;
    let mut boundary_edges: Vec<(u32, u32)> = Vec::new();
    for (&(a, b), &(fw, bw)) in &undirected {
        match (fw, bw) {
            (1, 1) => {}
            (1, 0) => boundary_edges.push((a, b)),
            (0, 1) => boundary_edges.push((b, a)),
            _ => non_manifold_edges += 1,
        }
    }
    (undirected.len(), boundary_edges, non_manifold_edges)
}

/// Boundary loops: follow boundary half-edges (a → b) and count the walks.
fn count_boundary_loops(boundary_edges: &[(u32, u32)]) -> usize {
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(a, b) in boundary_edges {
        next.entry(a).or_default().push(b);
    }
    let mut used: HashMap<(u32, u32), bool> = HashMap::new();
    let mut boundary_loops = 0;
    for &(a, b) in boundary_edges {
        if used.contains_key(&(a, b)) {
            continue;
        }
        boundary_loops += 1;
        let (mut x, mut y) = (a, b);
        loop {
            used.insert((x, y), true);
            let Some(cands) = next.get(&y) else { break };
            let Some(&z) = cands.iter().find(|&&z| !used.contains_key(&(y, z))) else { break };
            x = y;
            y = z;
        }
        let _ = x;
    }
    boundary_loops
}

/// Vertices whose faces form more than one fan (faces around the vertex joined through an edge
/// at it).
fn count_non_manifold_vertices(m: &TriMesh) -> usize {
    let vf = m.vertex_faces();
    let mut non_manifold_vertices = 0;
    for (v, faces) in vf.iter().enumerate() {
        if faces.len() <= 1 {
            continue;
        }
        let v = v as u32;
        let mut parent: Vec<usize> = (0..faces.len()).collect();
        fn find(p: &mut [usize], i: usize) -> usize {
            let mut r = i;
            while p[r] != r {
                r = p[r];
            }
            let mut j = i;
            while p[j] != r {
                let n = p[j];
                p[j] = r;
                j = n;
            }
            r
        }
        let mut by_other: HashMap<u32, usize> = HashMap::new();
        for (i, &f) in faces.iter().enumerate() {
            for &w in &m.tris[f as usize] {
                if w == v {
                    continue;
                }
                if let Some(&j) = by_other.get(&w) {
                    let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                    parent[ri] = rj;
                } else {
                    by_other.insert(w, i);
                }
            }
        }
        let roots = (0..faces.len()).filter(|&i| find(&mut parent, i) == i).count();
        if roots > 1 {
            non_manifold_vertices += 1;
        }
    }
    non_manifold_vertices
}

/// Connected components by union-find over vertices (an unused vertex is its own component).
fn count_components(nv: usize, tris: &[[u32; 3]]) -> usize {
    let mut parent: Vec<u32> = (0..nv as u32).collect();
    fn root(p: &mut [u32], mut i: u32) -> u32 {
        while p[i as usize] != i {
            p[i as usize] = p[p[i as usize] as usize];
            i = p[i as usize];
        }
        i
    }
    for t in tris {
        let r0 = root(&mut parent, t[0]);
        for &v in &t[1..] {
            let r = root(&mut parent, v);
            if r != r0 {
                parent[r as usize] = r0;
            }
        }
    }
    (0..nv as u32).filter(|&i| root(&mut parent, i) == i).count()
}

/// Refuses anything but a closed, connected, manifold, genus-0 surface, saying what was found.
pub fn require_sphere_like(info: &TopologyInfo, which: &str) -> Result<()> {
    let mut problems = Vec::new();
    if info.faces < 4 {
        problems.push(format!("only {} faces", info.faces));
    }
    problems.extend(info.defects());
    if info.boundary_loops > 0 {
        // χ = 2 − 2g − b for a connected manifold surface with b boundary loops.
        let g = 2 - info.boundary_loops as i64 - info.euler_characteristic;
        if problems.is_empty() && g % 2 == 0 {
            problems.push(format!(
                "an open surface of genus {} with {} boundary loops (the planar domain takes exactly one)",
                g / 2,
                info.boundary_loops
            ));
        } else {
            problems.push(format!("open: {} boundary loops", info.boundary_loops));
        }
    }
    if problems.is_empty() {
        match info.genus {
            Some(0) => return Ok(()),
            Some(g) => {
                problems.push(format!("closed surface of genus {g} (V−E+F = {})", info.euler_characteristic))
            }
            None => problems.push(format!("Euler characteristic {}", info.euler_characteristic)),
        }
    }
    Err(Error::Topology(format!(
        "{which}: the morph needs a closed, connected, manifold genus-0 mesh (spherical domain) or a \
         disk (one boundary loop, genus 0: planar domain, decided by input 0); found {} \
         (set `repair: true` to mend holes and non-manifold parts first)",
        problems.join(", ")
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn icosphere_is_genus_0_and_torus_is_not() {
        let (s, _, _) = TriMesh::from_mesh(&shapes::icosphere(2, 1.0));
        let i = topology(&s);
        assert_eq!(i.genus, Some(0));
        assert!(require_sphere_like(&i, "source").is_ok());
        let (t, _, _) = TriMesh::from_mesh(&shapes::torus(16, 8, 1.0, 0.3, false));
        let i = topology(&t);
        assert_eq!(i.genus, Some(1));
        let e = require_sphere_like(&i, "target").unwrap_err().to_string();
        assert!(e.contains("genus 1"), "{e}");
    }

    #[test]
    fn open_grid_has_one_boundary_loop() {
        let (g, _, _) = TriMesh::from_mesh(&shapes::grid(3, 3, 1.0, false));
        let i = topology(&g);
        assert_eq!(i.boundary_loops, 1);
        assert_eq!(i.genus, None);
    }
}
