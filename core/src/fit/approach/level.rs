//! One approach level's field and how far it moves: the RBF through the level's samples (with
//! the in-plane polynomial on nearly flat centres), the samples left out where it folds, and the
//! largest step of it that folds nothing ([`super`] runs the levels).

use rayon::prelude::*;

use crate::error::Result;
use crate::geometry::{add, dot, scale, triangle_centroid, triangle_cross};
use crate::job::Progress;
use crate::mesh::Point3;

use super::super::orientation::{det, field_step, Jacobian};
use super::super::rbf::{self, Kernel, Rbf};

/// Centres thinner than this share of their extent (the smallest principal spread over the
/// largest, [`rbf::spread_ratios`]) may get the in-plane polynomial ([`level_field`]).
const NEAR_FLAT_CENTRES: f64 = 0.1;

/// A level's field, its displacements and gradients at `pos`, and whether it is the in-plane fit;
/// `None` when the centres admit no field (the level is skipped).
///
/// Why not always the full affine part: on nearly flat centres (a flat template under wavy curves)
/// its column along the normal is set by the centres' small out-of-plane spread alone and can come
/// out arbitrary. Measured (docs/benchmarks.md, session 17): alligator under the held-out wave,
/// centres 0.039 thick, det(I + ∇s) was −0.6 at every vertex: the surface was right (4 faces
/// against the truth), but the map had turned space inside out, so the count's carried normal
/// J⁻ᵀ·n called 6,765 faces flipped. Then, and only then (most vertices inside out), the field is
/// fitted again with the in-plane polynomial: even about the centres' plane, its normal
/// derivative comes from the kernel terms and vanishes on the plane, and it still interpolates the
/// displacements. Switching on thinness alone was measured worse: on a 4 %-thick ellipsoid the
/// normal column is real (the bend), and regions and edges were lost.
pub(super) fn level_field(
    centres: &[Point3],
    values: &[Point3],
    kernel: Kernel,
    pos: &[Point3],
    progress: &Progress,
) -> Result<Option<LevelField>> {
    let Ok(field) = Rbf::fit(centres, values, kernel, "fine") else { return Ok(None) };
    let (disp, gradients) = field.eval_with_gradients(pos, progress)?;
    let full = LevelField { field, disp, gradients, in_plane: false };
    if rbf::spread_ratios(centres)[0] >= NEAR_FLAT_CENTRES || !mostly_inside_out(&full.gradients) {
        return Ok(Some(full));
    }
    let Ok(field) = Rbf::fit_in_plane(centres, values, kernel, "fine") else { return Ok(Some(full)) };
    let (disp, gradients) = field.eval_with_gradients(pos, progress)?;
    Ok(Some(LevelField { field, disp, gradients, in_plane: true }))
}

/// An approach level's field with its displacements and gradients at every vertex.
pub(super) struct LevelField {
    pub field: Rbf,
    pub disp: Vec<Point3>,
    pub gradients: Vec<Jacobian>,
    /// Fitted with the in-plane polynomial ([`level_field`]).
    pub in_plane: bool,
}

/// Whether x ↦ x + s(x) has det ≤ 0 at more than half of the points (`gradients`: ∇s there).
fn mostly_inside_out(gradients: &[Jacobian]) -> bool {
    // A NaN determinant (a non-finite gradient) counts as inside out.
    let inside_out = gradients
        .iter()
        .map(|g| det(&super::super::coarse::plus_identity(*g)))
        .filter(|d| *d <= 0.0 || d.is_nan())
        .count();
    2 * inside_out > gradients.len()
}

/// The largest step of 1, ½, ¼, ⅛ at which the level's displacements fold no face and turn space
/// inside out at no vertex, with the moved positions; a step under 0.1 means none. Why the
/// inversion too: a map with det(I + step ∇s) ≤ 0 at a vertex reverses the count's reference there
/// ([`super::super::orientation`]), so the faces around count as flipped though none folded
/// (fandisk twisted: 191 flipped faces from one level that folded nothing; session 21).
pub(super) fn step_search(
    pos: &[Point3],
    disp: &[Point3],
    gradients: &[Jacobian],
    tris: &[[u32; 3]],
) -> (f64, Vec<Point3>) {
    let mut step = 1.0;
    loop {
        let moved = moved_by(pos, disp, step);
        if step < 0.1 || (folds(pos, &moved, tris) == 0 && !gradients.iter().any(|g| inverts(g, step))) {
            return (step, moved);
        }
        step *= 0.5;
    }
}

/// `pos` moved by `step` × `disp`.
pub(super) fn moved_by(pos: &[Point3], disp: &[Point3], step: f64) -> Vec<Point3> {
    pos.iter().zip(disp).map(|(p, d)| add(*p, scale(*d, step))).collect()
}

/// Rounds of [`drop_folding_centres`] per level.
const DROP_ROUNDS: usize = 3;

/// Where the level at full step folds a face (its centroid) or inverts the map (the vertex), the
/// nearest centre with a non-zero value (pairs' centres hold zero) is left out and the field solved
/// again, up to [`DROP_ROUNDS`] times while something folds. Returns the centres left out and
/// whether the last field was found clean at full step (nothing folds or inverts: the level needs
/// no [`step_search`]); the field's displacements and gradients at `pos` are those of the last
/// solve.
///
/// Measured (session 21; the sweeps' first deformed set / held-out set): flipped faces 474 → 272 /
/// 604 → 611, folded edges 383 → 264 / 503 → 478, regions right 29 → 31 / 57 → 56 (the twisted
/// bunny, `auto`: level 2 folded at every step and was skipped, 189 flips; 3 of its 136 samples
/// left out, 15). Only dropping when the level would be skipped changed 3 rows (189 → 63).
#[allow(clippy::too_many_arguments)]
pub(super) fn drop_folding_centres(
    centres: &mut Vec<Point3>,
    values: &mut Vec<Point3>,
    disp: &mut Vec<Point3>,
    gradients: &mut Vec<Jacobian>,
    pos: &[Point3],
    tris: &[[u32; 3]],
    kernel: Kernel,
    progress: &Progress,
) -> Result<(usize, bool)> {
    let mut dropped = 0;
    for _ in 0..DROP_ROUNDS {
        progress.check()?;
        let spots = folding_spots(pos, disp, gradients, tris);
        if spots.is_empty() {
            return Ok((dropped, true));
        }
        let tree = super::super::kdtree::KdTree::new(centres);
        let mut drop = vec![false; centres.len()];
        for &c in &spots {
            if let Some((i, _)) = tree.nearest_filtered(c, |i| values[i as usize] != [0.0; 3]) {
                drop[i as usize] = true;
            }
        }
        let n = drop.iter().filter(|&&d| d).count();
        if n == 0 || centres.len() - n < 4 {
            break;
        }
        let keep: Vec<usize> = (0..centres.len()).filter(|&i| !drop[i]).collect();
        let kept_centres: Vec<Point3> = keep.iter().map(|&i| centres[i]).collect();
        let kept_values: Vec<Point3> = keep.iter().map(|&i| values[i]).collect();
        let Some(level) = level_field(&kept_centres, &kept_values, kernel, pos, progress)? else { break };
        *centres = kept_centres;
        *values = kept_values;
        *disp = level.disp;
        *gradients = level.gradients;
        dropped += n;
    }
    Ok((dropped, false))
}

/// Where the level at full step folds a face (the face's centroid before the move) or turns space
/// inside out (the vertex).
fn folding_spots(pos: &[Point3], disp: &[Point3], gradients: &[Jacobian], tris: &[[u32; 3]]) -> Vec<Point3> {
    let moved = moved_by(pos, disp, 1.0);
    let centroid =
        |t: [u32; 3]| triangle_centroid(pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
    let faces = folded_faces(pos, &moved, tris).into_iter().map(|f| centroid(tris[f]));
    let vertices = (0..gradients.len()).filter(|&v| inverts(&gradients[v], 1.0)).map(|v| pos[v]);
    faces.chain(vertices).collect()
}

/// Whether x ↦ x + step · s(x) turns space inside out where ∇s = `g` (det(I + step ∇s) ≤ 0, or
/// NaN from a non-finite gradient).
fn inverts(g: &Jacobian, step: f64) -> bool {
    let d = det(&field_step(g, step));
    d <= 0.0 || d.is_nan()
}

/// Whether face `t`'s normal turns by more than 90° between `before` and `after` (a face of zero
/// area before never counts).
fn turned_over(before: &[Point3], after: &[Point3], t: &[u32; 3]) -> bool {
    let p = |x: &[Point3], i: usize| x[t[i] as usize];
    let nb = triangle_cross(p(before, 0), p(before, 1), p(before, 2));
    let na = triangle_cross(p(after, 0), p(after, 1), p(after, 2));
    dot(nb, na) <= 0.0 && dot(nb, nb) > 0.0
}

/// The faces [`folds`] counts, by index (in order).
fn folded_faces(before: &[Point3], after: &[Point3], tris: &[[u32; 3]]) -> Vec<usize> {
    (0..tris.len()).into_par_iter().filter(|&f| turned_over(before, after, &tris[f])).collect()
}

/// How many faces turned over from `before` to `after` (the approach levels' and the warp's test).
pub fn folds(before: &[Point3], after: &[Point3], tris: &[[u32; 3]]) -> usize {
    tris.par_iter().filter(|t| turned_over(before, after, t)).count()
}

/// Drops centres that coincide (within 1e-7 of the extent) with an earlier kept one: two
/// samples can share a foot where the surface is concave. A pile of three or more keeps one (the
/// old rule, each centre against its nearest other only, kept two of a pile of three, the level's
/// RBF was then refused as singular and the whole level skipped: icosphere onto homer's sections).
pub(super) fn dedup_centres(centres: &mut Vec<Point3>, values: &mut Vec<Point3>) {
    let kept = super::super::insert::coincident::first_of_each_place(centres, 1e-7);
    if kept.len() == centres.len() {
        return;
    }
    *centres = kept.iter().map(|&i| centres[i]).collect();
    *values = kept.iter().map(|&i| values[i]).collect();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::dist;

    /// Centres on a gently waved plate (0.02 high on a unit square: 2 % thick) whose displacements
    /// flatten the wave and push it 1.5× beyond: the best affine part then maps height h to
    /// −0.5·h, so x ↦ x + s(x) turns space inside out everywhere. The level's field must not (the
    /// in-plane polynomial); the full affine fit is checked to do so, so the case is the one meant.
    /// A 6 × 6 grid on the unit square lifted by h = 0.02·sin(7x + 3y), each centre displaced by a
    /// small in-plane turn and `lift` · h along z.
    fn waved_plate(lift: f64) -> (Vec<Point3>, Vec<Point3>) {
        let mut centres = Vec::new();
        let mut values = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                let (x, y) = (i as f64 / 5.0, j as f64 / 5.0);
                let h = 0.02 * (7.0 * x + 3.0 * y).sin();
                centres.push([x, y, h]);
                values.push([0.01 * y, -0.01 * x, lift * h]);
            }
        }
        (centres, values)
    }

    /// A paraboloid cap z = 0.3 (x² + y²) over the unit square, as a 21 × 21 vertex grid.
    fn cap() -> (Vec<Point3>, Vec<[u32; 3]>) {
        let n = 21;
        let at = |i: usize, j: usize| {
            let (x, y) = (i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64);
            [x, y, 0.3 * (x * x + y * y)]
        };
        let pos: Vec<Point3> = (0..n * n).map(|k| at(k % n, k / n)).collect();
        let mut tris = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = (j * n + i) as u32;
                tris.push([v, v + 1, v + n as u32 + 1]);
                tris.push([v, v + n as u32 + 1, v + n as u32]);
            }
        }
        (pos, tris)
    }

    #[test]
    fn a_sample_that_folds_its_level_is_left_out() {
        // 6 × 6 samples lifting the cap by 0.005, but the one at (0.4, 0.4) sent 0.25 sideways,
        // more than the 0.2 to its neighbours: the field's x-slope there is about -0.25 / 0.2, so
        // det(I + ∇s) < 0 beside it and faces fold (hand estimate; checked below).
        let (pos, tris) = cap();
        let mut centres = Vec::new();
        let mut values = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                let (x, y) = (i as f64 / 5.0, j as f64 / 5.0);
                centres.push([x, y, 0.3 * (x * x + y * y)]);
                values.push(if (i, j) == (2, 2) { [0.25, 0.0, 0.0] } else { [0.0, 0.0, 0.005] });
            }
        }
        let outlier = centres[2 * 6 + 2];
        let progress = Progress::new();
        let level = level_field(&centres, &values, Kernel::default(), &pos, &progress).unwrap().unwrap();
        let (mut disp, mut gradients) = (level.disp, level.gradients);
        assert!(step_search(&pos, &disp, &gradients, &tris).0 < 1.0, "the full level should fold");
        let (dropped, _) = drop_folding_centres(
            &mut centres,
            &mut values,
            &mut disp,
            &mut gradients,
            &pos,
            &tris,
            Kernel::default(),
            &progress,
        )
        .unwrap();
        assert!((1..=4).contains(&dropped), "{dropped} samples left out");
        assert!(!centres.contains(&outlier));
        assert_eq!(centres.len(), 36 - dropped);
        // The level solved without it moves at full step, folding nothing, inverting nothing.
        let (step, moved) = step_search(&pos, &disp, &gradients, &tris);
        assert_eq!(step, 1.0);
        assert_eq!(folds(&pos, &moved, &tris), 0);
        // And it still lifts the cap by the samples' 0.005 at the samples kept.
        for (c, v) in centres.iter().zip(&values) {
            let k = pos.iter().position(|p| dist(*p, *c) < 1e-12).unwrap();
            assert!(dist(disp[k], *v) < 1e-9);
        }
    }

    #[test]
    fn a_level_on_nearly_flat_centres_does_not_turn_space_inside_out() {
        let (centres, values) = waved_plate(-1.5);
        assert!(rbf::spread_ratios(&centres)[0] < NEAR_FLAT_CENTRES);
        let grads = |f: &Rbf| -> Vec<Jacobian> { centres.iter().map(|&c| f.gradient(c)).collect() };
        let full = Rbf::fit(&centres, &values, Kernel::default(), "test").unwrap();
        assert!(mostly_inside_out(&grads(&full)), "the full affine fit should invert");
        let LevelField { field: level, disp, gradients, in_plane } =
            level_field(&centres, &values, Kernel::default(), &centres, &Progress::new()).unwrap().unwrap();
        assert!(in_plane);
        assert!(gradients.iter().all(|g| det(&crate::fit::coarse::plus_identity(*g)) > 0.0));
        // Still an interpolant of the displacements.
        for ((c, v), d) in centres.iter().zip(&values).zip(&disp) {
            assert!(dist(level.eval(*c), *v) < 1e-9 && dist(*d, *v) < 1e-9);
        }
    }

    /// The same plate with displacements that keep the heights' order (h ↦ 1.3·h): the full
    /// affine fit does not turn space inside out, so the level keeps it.
    #[test]
    fn a_level_on_nearly_flat_centres_keeps_a_valid_normal_column() {
        let (centres, values) = waved_plate(0.3);
        let level =
            level_field(&centres, &values, Kernel::default(), &centres, &Progress::new()).unwrap().unwrap();
        assert!(!level.in_plane);
    }
}
