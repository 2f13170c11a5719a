//! Discrete Laplace operators and mass matrices (uniform, cotangent, hybrid quad/triangle, boundary).
