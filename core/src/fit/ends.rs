//! Curve ends on an open template's boundary.
//!
//! A curve that runs to the edge of an open template (a section across a scan with holes, a seam
//! of a shoe upper) only cuts the surface into regions if its end becomes a *boundary* vertex.
//! Matched by plain closest point, the end lands wherever the coarsely aligned surface happens to
//! be nearest: on the bunny fitted to bent sections, 7 of 12 ends landed inside the surface and 5
//! of 29 regions stayed merged. So a curve end (a point of network degree 1) whose closest point
//! on the template boundary is within the snap distance is matched there instead; the fine RBF
//! then carries that boundary vertex onto the end. Ends farther from the boundary are treated as
//! ends inside the surface (a curve that stops mid-surface) and keep their surface foot.

use std::collections::HashSet;

use crate::geometry::{closest_on_segment, dist};
use crate::mesh::Point3;

use super::curves::CurveNetwork;

/// A curve end's match on the boundary: the face holding the boundary edge, the point, its distance.
pub struct BoundaryFoot {
    pub point_index: u32,
    pub face: u32,
    pub foot: Point3,
    pub distance: f64,
}

/// Boundary feet of the network's ends within `max_distance` of the template boundary. The
/// template is an oriented manifold (checked before the fit), so a directed edge whose reverse is
/// absent is a boundary edge, with exactly one face.
pub fn boundary_feet(
    pos: &[Point3],
    tris: &[[u32; 3]],
    net: &CurveNetwork,
    max_distance: f64,
) -> Vec<BoundaryFoot> {
    let ends: Vec<u32> = (0..net.points.len() as u32).filter(|&p| net.degree[p as usize] == 1).collect();
    if ends.is_empty() || max_distance <= 0.0 {
        return Vec::new();
    }
    let directed: HashSet<(u32, u32)> =
        tris.iter().flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3]))).collect();
    let boundary: Vec<(u32, u32, u32)> = tris
        .iter()
        .enumerate()
        .flat_map(|(f, t)| (0..3).map(move |k| (f as u32, t[k], t[(k + 1) % 3])))
        .filter(|&(_, a, b)| !directed.contains(&(b, a)))
        .collect();
    if boundary.is_empty() {
        return Vec::new();
    }
    ends.into_iter()
        .filter_map(|p| {
            let x = net.points[p as usize];
            let (face, foot, distance) = boundary
                .iter()
                .map(|&(f, a, b)| {
                    let q = closest_on_segment(x, pos[a as usize], pos[b as usize]);
                    (f, q, dist(x, q))
                })
                .min_by(|a, b| a.2.total_cmp(&b.2))?;
            (distance <= max_distance).then_some(BoundaryFoot { point_index: p, face, foot, distance })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    fn net(lines: Vec<Vec<Point3>>) -> CurveNetwork {
        let mut m = Mesh::default();
        for l in lines {
            let base = m.positions.len() as u32;
            m.positions.extend(l.iter().copied());
            m.curves.push((base..m.positions.len() as u32).collect());
        }
        CurveNetwork::from_mesh(&m, 1e-9).unwrap()
    }

    /// Unit square as two triangles; boundary = its four sides.
    fn square() -> (Vec<Point3>, Vec<[u32; 3]>) {
        (vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn ends_near_the_rim_get_the_rim_point_inner_ends_do_not() {
        let (pos, tris) = square();
        // A line from just inside the left side (x = 0.03) to the middle (x = 0.5).
        let n = net(vec![vec![[0.03, 0.4, 0.1], [0.25, 0.4, 0.0], [0.5, 0.4, 0.0]]]);
        let feet = boundary_feet(&pos, &tris, &n, 0.11);
        assert_eq!(feet.len(), 1, "only the end near the rim snaps");
        let f = &feet[0];
        assert_eq!(n.points[f.point_index as usize], [0.03, 0.4, 0.1]);
        // Hand value: the closest point of the side x = 0 is (0, 0.4, 0), at √(0.03² + 0.1²).
        assert!(dist(f.foot, [0.0, 0.4, 0.0]) < 1e-15);
        assert!((f.distance - (0.03f64.powi(2) + 0.01).sqrt()).abs() < 1e-15);
        // Face 1 = (0, 2, 3) holds the side 3 → 0.
        assert_eq!(f.face, 1);
        assert!(boundary_feet(&pos, &tris, &n, 0.1).is_empty(), "beyond the snap distance (0.104)");
    }

    #[test]
    fn closed_surfaces_and_loops_have_nothing_to_snap() {
        let ico = crate::shapes::icosphere(1, 1.0);
        let tris = crate::shapes::fan_triangles(&ico.faces);
        let n = net(vec![vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]]);
        assert!(boundary_feet(&ico.positions, &tris, &n, 10.0).is_empty());
        let (pos, tris) = square();
        let ring = net(vec![vec![[0.1, 0.1, 0.0], [0.9, 0.1, 0.0], [0.5, 0.9, 0.0], [0.1, 0.1, 0.0]]]);
        assert!(boundary_feet(&pos, &tris, &ring, 10.0).is_empty(), "a closed loop has no end");
    }
}
