//! One implicit step's linear algebra: `(diag(d) + h S) x = diag(d) x₀` over the moving vertices,
//! fixed vertices eliminated, solved by sparse Cholesky (factored once, refactored on new values
//! with the symbolic analysis kept) or warm-started CG.

use std::time::Instant;

use serde::Serialize;

use crate::error::Result;
use crate::job::{interruptible, Progress};
use crate::laplacian::Csr;
use crate::mesh::Point3;
use crate::solve::{pcg, Cholesky, Dirichlet, SolverChoice};

/// Below this many unknowns `auto` always factors (Cholesky is fast and exact there).
pub const AUTO_CG_MIN_UNKNOWNS: usize = 20_000;
/// `auto` uses CG when the estimated CG iterations over the whole job stay below this.
pub const AUTO_CG_MAX_TOTAL_ITERATIONS: f64 = 400.0;
const CG_MAX_ITER: usize = 2000;
/// Systems with at least this many unknowns are analysed and factored on a thread of their own
/// while the job polls for cancellation ([`interruptible`]: faer cannot be interrupted); smaller
/// ones (a few ms) inline.
const OFF_THREAD_MIN_UNKNOWNS: usize = 20_000;

/// `f(a)` inline for a small `a`, else on a copy of `a` in [`interruptible`].
fn off_thread<T: Send + 'static>(
    progress: &Progress,
    a: &Csr,
    f: impl FnOnce(&Csr) -> Result<T> + Send + 'static,
) -> Result<T> {
    if a.n < OFF_THREAD_MIN_UNKNOWNS {
        progress.check()?;
        return f(a);
    }
    let a = a.clone();
    interruptible(progress, move || f(&a))?
}

/// What the report says about the solver.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SolverStats {
    /// "cholesky", "cg", or "none" (explicit methods).
    pub kind: String,
    pub unknowns: usize,
    pub matrix_nnz: usize,
    /// Stored entries of the Cholesky factor (0 for CG).
    pub factor_nnz: usize,
    pub factorizations: usize,
    pub analyze_ms: f64,
    pub factor_ms: f64,
    pub solve_ms: f64,
    pub cg_iterations: usize,
    pub cg_max_relative_residual: f64,
    /// CG did not converge and the step was redone with Cholesky.
    pub cg_fallbacks: usize,
}

enum Backend {
    Cholesky(Option<Cholesky>),
    Cg,
}

/// A symmetric system over a fixed pattern with some unknowns eliminated.
pub struct System {
    pub full: Csr,
    dirichlet: Dirichlet,
    backend: Backend,
    tol: f64,
    dirty: bool,
    pub stats: SolverStats,
}

/// `diag(d) + h·S` on `S`'s pattern.
pub fn shifted(s: &Csr, d: &[f64], h: f64) -> Csr {
    let mut a = s.clone();
    for v in &mut a.val {
        *v *= h;
    }
    for (i, p) in a.diagonal_positions().into_iter().enumerate() {
        a.val[p] += d[i];
    }
    a
}

/// Jacobi-Gershgorin bound on the condition number of `diag(d) + hS` after diagonal
/// preconditioning, and the CG iterations it implies for `tol`.
pub fn estimated_cg_iterations(s: &Csr, d: &[f64], h: f64, moving: &[bool], tol: f64) -> f64 {
    let diag = s.diagonal();
    let mut worst = 0.0f64;
    for i in 0..s.n {
        if moving[i] && d[i] > 0.0 {
            // Off-diagonal absolute row sum of hS equals h·S_ii for non-negative weights.
            let r = h * diag[i].abs() / (d[i] + h * diag[i]).max(f64::MIN_POSITIVE);
            worst = worst.max(r.min(1.0 - 1e-12));
        }
    }
    let kappa = (1.0 + worst) / (1.0 - worst);
    0.5 * kappa.sqrt() * (2.0 / tol).ln()
}

impl System {
    /// `choice` must already be resolved (Cholesky or Cg).
    pub fn new(full: Csr, moving: &[bool], choice: SolverChoice, tol: f64) -> System {
        let pinned: Vec<bool> = moving.iter().map(|m| !m).collect();
        let dirichlet = Dirichlet::new(&full, &pinned);
        let backend = match choice {
            SolverChoice::Cg => Backend::Cg,
            _ => Backend::Cholesky(None),
        };
        let stats = SolverStats {
            kind: if matches!(backend, Backend::Cg) { "cg" } else { "cholesky" }.into(),
            unknowns: dirichlet.free.len(),
            matrix_nnz: dirichlet.reduced.nnz(),
            ..Default::default()
        };
        System { full, dirichlet, backend, tol, dirty: true, stats }
    }

    /// New values on the same pattern (re-assembled operator).
    pub fn update(&mut self, full: Csr) {
        self.full = full;
        self.dirichlet.refill(&self.full);
        self.dirty = true;
    }

    fn factor(&mut self, progress: &Progress) -> Result<()> {
        if let Backend::Cholesky(ch) = &mut self.backend {
            let a = &self.dirichlet.reduced;
            let c = match ch.take() {
                Some(c) => c,
                None => {
                    let t = Instant::now();
                    let c = off_thread(progress, a, |a| Cholesky::analyze(a))?;
                    self.stats.analyze_ms += t.elapsed().as_secs_f64() * 1e3;
                    c
                }
            };
            let t = Instant::now();
            let c = off_thread(progress, a, move |a| {
                let mut c = c;
                c.factor(a)?;
                Ok(c)
            })?;
            self.stats.factor_nnz = c.factor_nnz();
            *ch = Some(c);
            self.stats.factor_ms += t.elapsed().as_secs_f64() * 1e3;
            self.stats.factorizations += 1;
        }
        self.dirty = false;
        Ok(())
    }

    /// Solves for the moving vertices with right-hand side `b` (per vertex, 3 columns); fixed
    /// vertices take their values from `x`, moving ones are overwritten (and warm-start CG).
    pub fn solve(&mut self, b: &[Point3], x: &mut [Point3], progress: &Progress) -> Result<()> {
        if self.dirichlet.free.is_empty() {
            return Ok(());
        }
        if self.dirty {
            self.factor(progress)?;
        }
        progress.check()?;
        let t = Instant::now();
        let rhs = self.dirichlet.rhs(&self.full, b.as_flattened(), x.as_flattened(), 3);
        let mut y: Vec<f64> = self.dirichlet.free.iter().flat_map(|&i| x[i as usize]).collect();
        let mut fallback = false;
        match &self.backend {
            Backend::Cg => {
                let info = pcg(&self.dirichlet.reduced, &rhs, &mut y, 3, self.tol, CG_MAX_ITER, progress)?;
                self.stats.cg_iterations += info.iterations;
                self.stats.cg_max_relative_residual =
                    self.stats.cg_max_relative_residual.max(info.relative_residual);
                fallback = !info.converged;
            }
            Backend::Cholesky(ch) => {
                let mut cm = crate::solve::to_column_major(&rhs, 3);
                if let Some(c) = ch {
                    c.solve_in_place(&mut cm, 3)?;
                }
                y = crate::solve::from_column_major(&cm, 3);
            }
        }
        if fallback {
            // CG stalled (badly conditioned system): redo this and later steps exactly.
            self.stats.cg_fallbacks += 1;
            self.backend = Backend::Cholesky(None);
            self.stats.kind = "cholesky (after cg fallback)".into();
            self.factor(progress)?;
            return self.solve(b, x, progress);
        }
        for (f, &i) in self.dirichlet.free.iter().enumerate() {
            x[i as usize] = [y[3 * f], y[3 * f + 1], y[3 * f + 2]];
        }
        self.stats.solve_ms += t.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }
}
