//! Interpolation between corresponding shapes (seed 002 §7, eq. VI.18: pᵗ = pˢ + t(pᵀ − pˢ)):
//! frames along a sequence through the shapes, and one blend at given weights (multi-morph).

use crate::mesh::Point3;

/// Where frame `j` of `frames` sits on a path through `shapes` shapes: (leg, t in the leg).
pub fn frame_position(j: usize, frames: usize, shapes: usize) -> (usize, f64) {
    let legs = shapes.saturating_sub(1).max(1);
    let u = if frames <= 1 { 0.0 } else { j as f64 / (frames - 1) as f64 * legs as f64 };
    let leg = (u.floor() as usize).min(legs - 1);
    (leg, u - leg as f64)
}

/// Linear interpolation of shape `leg` towards shape `leg + 1`.
pub fn frame(shapes: &[Vec<Point3>], leg: usize, t: f64) -> Vec<Point3> {
    let a = &shapes[leg];
    let b = &shapes[(leg + 1).min(shapes.len() - 1)];
    a.iter()
        .zip(b)
        .map(|(p, q)| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])])
        .collect()
}

/// Σ wₖ·shapeₖ with weights normalised to sum 1 (affine combination).
pub fn blend(shapes: &[Vec<Point3>], weights: &[f64]) -> Vec<Point3> {
    let s: f64 = weights.iter().sum();
    let n = shapes[0].len();
    let mut out = vec![[0.0; 3]; n];
    for (sh, &w) in shapes.iter().zip(weights) {
        let w = w / s;
        for (o, p) in out.iter_mut().zip(sh) {
            for k in 0..3 {
                o[k] += w * p[k];
            }
        }
    }
    out
}

/// GLB keyframes matching [`frame_position`]: weights of targets 1.. (shape 0 is the base).
pub fn keyframes(frames: usize, shapes: usize, duration: f64) -> Vec<(f32, Vec<f32>)> {
    let targets = shapes - 1;
    (0..frames)
        .map(|j| {
            let (leg, t) = frame_position(j, frames, shapes);
            let mut w = vec![0.0f32; targets];
            if leg > 0 {
                w[leg - 1] = (1.0 - t) as f32;
            }
            w[leg] += t as f32;
            let time = if frames <= 1 { 0.0 } else { duration * j as f64 / (frames - 1) as f64 };
            (time as f32, w)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_cover_the_path_end_to_end() {
        assert_eq!(frame_position(0, 30, 2), (0, 0.0));
        assert_eq!(frame_position(29, 30, 2), (0, 1.0));
        assert_eq!(frame_position(4, 5, 3), (1, 1.0));
        assert_eq!(frame_position(2, 5, 3), (1, 0.0));
        let k = keyframes(5, 3, 2.0);
        assert_eq!(k[0].1, vec![0.0, 0.0]);
        assert_eq!(k[2].1, vec![1.0, 0.0]);
        assert_eq!(k[4].1, vec![0.0, 1.0]);
        assert_eq!(k[3].1, vec![0.5, 0.5]);
    }
}
