//! Exact re-evaluation of the composite Jacobians where single-precision bounds leave a face's
//! decision open: the maps since the first bounded one, replayed per vertex in f64.

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::mesh::Point3;

use super::super::rbf::Rbf;
use super::{field_step, mat_mul, Jacobian, Orientation};

/// A map whose Jacobians were summed in single precision ([`Orientation::push_field`]): what it
/// takes to evaluate them again exactly.
#[derive(Clone)]
pub(super) enum Step {
    /// x ↦ x + step · field(x), from the positions `before` it.
    Field { field: Arc<Rbf>, step: f64, before: Vec<Point3> },
    /// An exact map after a bounded one: its Jacobian per vertex.
    Exact(Vec<Jacobian>),
}

/// From the first bounded map on, what re-evaluating a vertex's composite Jacobian exactly takes:
/// the composite before that map, every map since, and the lineage of the vertices added since.
#[derive(Clone)]
pub(super) struct Replay {
    pub(super) origin: Vec<Jacobian>,
    pub(super) steps: Vec<Step>,
    /// Per vertex added after `origin`: its parents and how many `steps` it had then.
    pub(super) added: Vec<([(u32, f64); 3], usize)>,
    /// False once a rollback removed a vertex older than the first bounded map (no caller does):
    /// faces the bounds leave open are then decided by their approximate Jacobians.
    pub(super) valid: bool,
}

impl Orientation {
    /// Exact Jacobians (error 0) at `vertices`, replayed from the first bounded map (in parallel,
    /// each vertex with its own memo: lineages rarely overlap); the stored approximation (with its
    /// bound) where no replay is kept.
    pub(super) fn exact_at(
        &self,
        vertices: impl Iterator<Item = u32>,
    ) -> impl Fn(u32) -> (Jacobian, f64) + '_ {
        let mut wanted: Vec<u32> = vertices.collect();
        wanted.sort_unstable();
        wanted.dedup();
        let replay = self.replay.as_ref().filter(|r| r.valid);
        let found: HashMap<u32, (Jacobian, f64)> = wanted
            .par_iter()
            .map(|&v| {
                let stored = (self.jacobians[v as usize], self.errors[v as usize]);
                let exact = replay.and_then(|r| {
                    let w = self.working.as_ref().map_or(v, |m| m[v as usize]);
                    replay_jacobian(r, w, r.steps.len(), &mut HashMap::new()).map(|j| (j, 0.0))
                });
                (v, exact.unwrap_or(stored))
            })
            .collect();
        move |v| found.get(&v).copied().unwrap_or((self.jacobians[v as usize], self.errors[v as usize]))
    }
}

/// Working vertex `v`'s composite Jacobian after the first `upto` steps of the replay, in f64:
/// its origin (or its parents' blend when it was added), times each step since. None when the
/// lineage does not reach (a vertex the replay does not know).
fn replay_jacobian(
    r: &Replay,
    v: u32,
    upto: usize,
    memo: &mut HashMap<(u32, usize), Jacobian>,
) -> Option<Jacobian> {
    if let Some(j) = memo.get(&(v, upto)) {
        return Some(*j);
    }
    let (mut j, from) = match r.origin.get(v as usize) {
        Some(j) => (*j, 0),
        None => {
            let &(parents, epoch) = r.added.get(v as usize - r.origin.len())?;
            let mut j = [[0.0; 3]; 3];
            for &(p, w) in parents.iter().filter(|x| x.1 > 0.0) {
                let jp = replay_jacobian(r, p, epoch, memo)?;
                for row in 0..3 {
                    for c in 0..3 {
                        j[row][c] += w * jp[row][c];
                    }
                }
            }
            (j, epoch)
        }
    };
    for step in &r.steps[from.min(upto)..upto] {
        let s = match step {
            Step::Field { field, step, before } => {
                field_step(&field.gradient(*before.get(v as usize)?), *step)
            }
            Step::Exact(per_vertex) => *per_vertex.get(v as usize)?,
        };
        j = mat_mul(&s, &j);
    }
    memo.insert((v, upto), j);
    Some(j)
}
