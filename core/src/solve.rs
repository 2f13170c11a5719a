//! Sparse and dense solvers behind one small API (faer sparse Cholesky, LU for indefinite systems).
