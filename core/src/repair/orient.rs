//! Orientation: consistent across manifold edges, then outward for closed components.

use serde::Serialize;

use crate::error::Result;
use crate::geometry::{cross, dot};
use crate::job::Progress;
use crate::mesh::{Faces, Mesh};
use crate::topology::{Connectivity, Topology};

#[derive(Debug, Clone, Serialize, Default)]
pub struct OrientReport {
    /// Faces whose winding was reversed.
    pub faces_flipped: usize,
    /// Manifold edges still inconsistent afterwards (non-orientable patches, e.g. a Möbius strip).
    pub conflicting_edges: usize,
}

/// Reverses faces so that every manifold edge is traversed in opposite directions by its two
/// faces, by breadth-first search over manifold edges. In each patch the majority winding wins
/// (the fewest faces are flipped).
pub fn make_consistent(mesh: &mut Mesh) -> OrientReport {
    let topo = Topology::new(mesh);
    let nf = topo.face_count();
    let mut flip = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    let mut patch = Vec::new();
    for start in 0..nf {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        queue.push_back(start as u32);
        patch.clear();
        while let Some(f) = queue.pop_front() {
            patch.push(f);
            for c in topo.face_corners(f) {
                let e = topo.corner_edge(c);
                if e == crate::topology::NONE {
                    continue;
                }
                let Some(o) = topo.other_use(e, c) else { continue };
                let g = o.face as usize;
                if seen[g] {
                    continue;
                }
                // This half-edge's direction along the edge, after f's flip.
                let fwd_f = (topo.corner_vertex(c) == topo.edge(e)[0]) ^ flip[f as usize];
                // g must run the other way: flip it if it currently runs the same way.
                flip[g] = o.forward == fwd_f;
                seen[g] = true;
                queue.push_back(g as u32);
            }
        }
        let flipped = patch.iter().filter(|&&f| flip[f as usize]).count();
        if 2 * flipped > patch.len() {
            for &f in &patch {
                flip[f as usize] = !flip[f as usize];
            }
        }
    }
    let faces_flipped = flip.iter().filter(|&&b| b).count();
    // Edges still traversed the same way by both faces after the flips (no rebuild needed).
    let conflicting_edges = (0..topo.edge_count() as u32)
        .filter(|&e| {
            let u = topo.edge_uses(e);
            u.len() == 2
                && (u[0].forward ^ flip[u[0].face as usize]) == (u[1].forward ^ flip[u[1].face as usize])
        })
        .count();
    if faces_flipped > 0 {
        flip_faces(&mut mesh.faces, &flip);
    }
    OrientReport { faces_flipped, conflicting_edges }
}

/// Reverses the winding of the faces marked in `flip`, keeping each face's first corner.
pub fn flip_faces(faces: &mut Faces, flip: &[bool]) {
    let offsets = faces.offsets().to_vec();
    let idx = faces.indices_mut();
    for (f, &fl) in flip.iter().enumerate() {
        if fl {
            idx[offsets[f] as usize + 1..offsets[f + 1] as usize].reverse();
        }
    }
}

/// A face's contribution to the signed volume (fan triangles against the origin, / 6).
fn face_volume(p: &[crate::mesh::Point3], f: &[u32]) -> f64 {
    let a = p[f[0] as usize];
    let mut v = 0.0;
    for k in 1..f.len().saturating_sub(1) {
        v += dot(a, cross(p[f[k] as usize], p[f[k + 1] as usize]));
    }
    v / 6.0
}

#[derive(Debug, Clone, Serialize, Default)]
pub struct OutwardReport {
    /// Components (by shared edges) that are closed, manifold and consistently oriented.
    pub closed_components: usize,
    /// Of those, the ones that had negative volume and were flipped.
    pub components_flipped: usize,
    /// Components left as they are because they are open (no inside to point away from).
    pub open_components: usize,
}

/// Edges or faces visited between two polls of [`outward`] (a few ms).
const POLL_ITEMS: usize = 65_536;

/// Flips closed, consistently oriented components whose signed volume is negative.
pub fn outward(mesh: &mut Mesh, progress: &Progress) -> Result<OutwardReport> {
    let topo = Topology::new_polled(mesh, progress)?;
    let comps = topo.components(Connectivity::SharedEdge);
    progress.check()?;
    let nc = comps.count();
    let mut closed = vec![true; nc];
    for e in 0..topo.edge_count() as u32 {
        progress.check_every(e as usize, POLL_ITEMS)?;
        let u = topo.edge_uses(e);
        if u.len() != 2 || u[0].forward == u[1].forward {
            closed[comps.face_label[u[0].face as usize] as usize] = false;
        }
    }
    // Signed volume per component.
    let mut vol = vec![0.0; nc];
    for f in 0..topo.face_count() {
        progress.check_every(f, POLL_ITEMS)?;
        vol[comps.face_label[f] as usize] += face_volume(&mesh.positions, topo.face_vertices(f as u32));
    }
    let flip: Vec<bool> = (0..topo.face_count())
        .map(|f| {
            let c = comps.face_label[f] as usize;
            closed[c] && vol[c] < 0.0
        })
        .collect();
    let components_flipped = (0..nc).filter(|&c| closed[c] && vol[c] < 0.0).count();
    flip_faces(&mut mesh.faces, &flip);
    let closed_components = closed.iter().filter(|&&b| b).count();
    Ok(OutwardReport { closed_components, components_flipped, open_components: nc - closed_components })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;
    use crate::validate::analyze;

    #[test]
    fn random_flips_become_consistent_and_outward() {
        let mut m = shapes::icosphere(2, 1.0);
        let n = m.faces.len();
        // Deterministic pseudo-random flips of ~60% of the faces (so the majority is wrong too).
        let mut s = 12345u64;
        let flips: Vec<bool> = (0..n)
            .map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (s >> 33) % 10 < 6
            })
            .collect();
        flip_faces(&mut m.faces, &flips);
        assert!(analyze(&m).inconsistent_orientation > 0);
        let r = make_consistent(&mut m);
        assert_eq!(r.conflicting_edges, 0);
        let o = outward(&mut m, &Progress::new()).unwrap();
        assert_eq!(o.closed_components, 1);
        let a = analyze(&m);
        assert_eq!(a.inconsistent_orientation, 0);
        assert!(a.volume.unwrap() > 4.0, "{:?}", a.volume); // inscribed in the unit sphere: ≈ 4.1
    }

    #[test]
    fn mobius_strip_reports_conflict() {
        // A Möbius strip of 6 quads: a band whose ends are glued with a half twist.
        let n = 6;
        let mut p = Vec::new();
        for i in 0..n {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let (c, s) = ((t / 2.0).cos(), (t / 2.0).sin());
            for w in [-0.3, 0.3] {
                let r = 1.0 + w * c;
                p.push([r * t.cos(), r * t.sin(), w * s]);
            }
        }
        let mut f = Faces::new();
        for i in 0..n {
            let (a, b) = (2 * i as u32, 2 * i as u32 + 1);
            let (c, d) = if i + 1 < n { (2 * (i + 1) as u32, 2 * (i + 1) as u32 + 1) } else { (1, 0) };
            f.push(&[a, c, d, b], 0);
        }
        let mut m = Mesh::new(p, f);
        let r = make_consistent(&mut m);
        assert_eq!(r.conflicting_edges, 1);
    }
}
