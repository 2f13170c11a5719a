//! Points at one place, by the RBF's duplicate tolerance.

use crate::geometry::Aabb;
use crate::mesh::Point3;

use super::super::kdtree::KdTree;

/// Points closer than this × the set's bounding-box diagonal are one place: 10× the tolerance
/// of [`super::super::rbf::check_centres`], so the kept points always pass it.
pub const SAME_PLACE: f64 = 1e-8;

/// Indices of the points to keep, in order: every point but those within `relative` × the
/// bounding-box diagonal of an earlier kept one (a pile of any size keeps its first point).
pub fn first_of_each_place(points: &[Point3], relative: f64) -> Vec<usize> {
    let Some(bb) = Aabb::of(points) else { return Vec::new() };
    let tol = relative * bb.diagonal();
    let tree = KdTree::new(points);
    let mut keep = vec![true; points.len()];
    for i in 0..points.len() {
        // The filtered search only for points in a pile (it visits more of the tree).
        let piled =
            tree.nearest_filtered(points[i], |j| j as usize != i).is_some_and(|(_, d2)| d2.sqrt() <= tol);
        if piled {
            if let Some((_, d2)) = tree.nearest_filtered(points[i], |j| (j as usize) < i && keep[j as usize])
            {
                keep[i] = d2.sqrt() > tol;
            }
        }
    }
    (0..points.len()).filter(|&i| keep[i]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pile_of_three_keeps_its_first_point_only() {
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1e-12, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 1e-12],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 1e-6],
        ];
        // Points 2, 4 and 5 are at point 1's place; point 6 is 1e-6 from point 3 (diag √3: not one place).
        assert_eq!(first_of_each_place(&pts, SAME_PLACE), vec![0, 1, 3, 6]);
    }

    #[test]
    fn no_points_no_indices() {
        assert!(first_of_each_place(&[], SAME_PLACE).is_empty());
    }
}
