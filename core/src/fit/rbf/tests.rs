use super::*;

fn cube_corners() -> Vec<Point3> {
    let mut v = Vec::new();
    for i in 0..8 {
        v.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
    }
    v.push([0.3, 0.7, 0.2]);
    v
}

#[test]
fn interpolates_exactly_at_centres() {
    let c = cube_corners();
    // Arbitrary non-affine values (hand-picked numbers).
    let vals: Vec<Point3> =
        (0..c.len()).map(|i| [i as f64 * 0.1, (i * i) as f64 * 0.01, -(i as f64)]).collect();
    for kernel in [Kernel::Linear, Kernel::Cubic] {
        let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
        for (p, v) in c.iter().zip(&vals) {
            let e = f.eval(*p);
            for k in 0..3 {
                assert!((e[k] - v[k]).abs() < 1e-10, "{kernel:?} {e:?} vs {v:?}");
            }
        }
    }
}

#[test]
fn reproduces_an_affine_map_everywhere() {
    let c = cube_corners();
    // d(x) = A x + b, hand-chosen.
    let a = [[0.5, 0.1, 0.0], [-0.2, 0.3, 0.4], [0.0, 0.0, -0.7]];
    let b = [1.0, -2.0, 0.5];
    let d = |p: Point3| -> Point3 {
        let mut r = b;
        for i in 0..3 {
            for j in 0..3 {
                r[i] += a[i][j] * p[j];
            }
        }
        r
    };
    let vals: Vec<Point3> = c.iter().map(|&p| d(p)).collect();
    let f = Rbf::fit(&c, &vals, Kernel::Linear, "test").unwrap();
    for p in [[5.0, -3.0, 2.0], [0.5, 0.5, 0.5], [-10.0, 0.0, 7.5]] {
        let (e, t) = (f.eval(p), d(p));
        for k in 0..3 {
            assert!((e[k] - t[k]).abs() < 1e-9 * (1.0 + t[k].abs()), "{e:?} vs {t:?}");
        }
    }
}

#[test]
fn simd_and_scalar_sums_agree() {
    // 23 centres (not a multiple of 4: the tail runs too), pseudo-random values.
    let c: Vec<Point3> = (0..23)
        .map(|i| [(i as f64 * 0.37).sin(), (i as f64 * 0.91).cos(), (i * i % 7) as f64 * 0.1])
        .collect();
    let vals: Vec<Point3> =
        (0..23).map(|i| [(i as f64).sin(), 0.1 * i as f64, -0.05 * (i % 5) as f64]).collect();
    for kernel in [Kernel::Linear, Kernel::Cubic] {
        let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
        for q in [[0.1, 0.2, 0.3], [-2.0, 1.0, 0.5]] {
            let a = match kernel {
                Kernel::Linear => f.radial_sum(q, |r| r),
                Kernel::Cubic => f.radial_sum(q, |r| r * r * r),
            };
            let b = f.radial(q);
            for (x, y) in [(a.0, b.0), (a.1, b.1), (a.2, b.2)] {
                assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{kernel:?}: {x} vs {y}");
            }
        }
    }
}

/// Centres on a Fibonacci sphere (no two alike, none coplanar) and a smooth displacement.
fn sphere_data(n: usize) -> (Vec<Point3>, Vec<Point3>) {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let c: Vec<Point3> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            [r * t.cos(), r * t.sin(), z]
        })
        .collect();
    let v = c.iter().map(|p| [0.1 * p[1], 0.05 * p[0] * p[2], -0.02 * p[2] * p[2]]).collect();
    (c, v)
}

#[test]
fn fits_run_by_every_worker_of_the_global_pool_finish() {
    // Each worker waits (not as a rayon task) for its factorisation thread. Had that thread
    // asked the same pool for faer's tasks, no worker would be free to run them: a hang.
    let (c, v) = sphere_data(800);
    assert!(c.len() >= CHOLESKY_CENTRES && spread_ratios(&c)[0] >= CHOLESKY_MIN_SPREAD);
    let n = rayon::current_num_threads();
    let ok = (0..n)
        .into_par_iter()
        .map(|_| Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &Progress::new()).is_ok())
        .filter(|&ok| ok)
        .count();
    assert_eq!(ok, n);
}

#[test]
fn a_large_solve_stops_at_a_cancel_during_the_factorisation() {
    // 1,500 centres: the factorisation takes tens of ms, far more than the 1 ms between the
    // polls made while it runs. Poll 1 is the entry check, poll 2 the first one during the
    // factorisation: cancelled there, the fit returns Cancelled without waiting for it.
    let (c, v) = sphere_data(1500);
    assert!(c.len() >= INTERRUPTIBLE_CENTRES);
    let p = Progress::new();
    p.cancel_at_check(2);
    assert!(matches!(Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &p), Err(Error::Cancelled)));
    assert_eq!(p.checks(), 2);
    // Not cancelled, the same fit interpolates (the worker thread's result is used).
    let f = Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &Progress::new()).unwrap();
    for i in [0, 777, 1499] {
        let e = f.eval(c[i]);
        for k in 0..3 {
            assert!((e[k] - v[i][k]).abs() < 1e-9, "{e:?} vs {:?}", v[i]);
        }
    }
    // Below the threshold nothing is polled inside the fit.
    let (c, v) = sphere_data(100);
    let p = Progress::new();
    Rbf::fit_polled(&c, &v, Kernel::Linear, "test", &p).unwrap();
    assert_eq!(p.checks(), 0);
}

#[test]
fn duplicate_and_coplanar_centres_are_rejected() {
    let mut c = cube_corners();
    c.push(c[3]);
    assert_eq!(check_centres(&c), Err(Degenerate::Duplicate(3, 9)));
    let flat: Vec<Point3> = (0..10).map(|i| [i as f64, (i * i % 7) as f64, 2.0]).collect();
    assert!(matches!(check_centres(&flat), Err(Degenerate::Coplanar(_))));
    assert_eq!(check_centres(&c[..3]), Err(Degenerate::TooFew(3)));
    assert!(Rbf::fit(&flat, &flat, Kernel::Linear, "x").is_err());
}

/// 600 centres on a sphere (`sphere_data`) with centre 400 moved to `gap` × the diagonal from
/// centre 100 and its value 0.5 from centre 100's: two centres a hair apart going to distant
/// values, as two feet on either side of a twisted bunny's ear.
fn hair_apart(gap: f64) -> (Vec<Point3>, Vec<Point3>) {
    let (mut c, mut v) = sphere_data(600);
    v[400] = [v[100][0] + 0.5, v[100][1], v[100][2]];
    let diag = Aabb::of(&c).map(|b| b.diagonal()).unwrap_or(1.0);
    c[400] = [c[100][0] + gap * diag, c[100][1], c[100][2]];
    (c, v)
}

#[test]
fn a_system_the_cholesky_solves_too_roughly_is_solved_by_the_lblt() {
    let (c, v) = hair_apart(GAP);
    let bb = Aabb::of(&c).expect("centres");
    let (origin, scale) = (bb.center(), bb.diagonal() / 2.0);
    let q: Vec<Point3> = c.iter().map(|p| [0, 1, 2].map(|k| (p[k] - origin[k]) / scale)).collect();
    let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut rhs = Mat::<f64>::zeros(604, 3);
    for i in 0..600 {
        for k in 0..3 {
            rhs[(i, k)] = v[i][k];
        }
    }
    let bound = 1e-6 * v.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
    // The precondition: the null-space Cholesky is taken here and misses the guard's bound.
    let a = system::matrix(&q, Kernel::Linear, &axes);
    let (x, used) =
        system::solver(a, rhs, &q, Kernel::Linear, &axes, system::Method::Fastest)().expect("solve");
    assert_eq!(used, system::Factorisation::NullSpaceCholesky);
    let frame = Frame { q: &q, values: &v, kernel: Kernel::Linear, origin, scale, directions: &axes };
    let rough = frame.solved(x);
    assert!(!rough.within(bound), "Cholesky residual {:.3e} within {bound:.3e}", rough.residual);
    // The fit falls back to the LBLᵀ and interpolates every centre, the close pair included.
    let f = Rbf::fit(&c, &v, Kernel::Linear, "test").expect("fit");
    for (p, want) in c.iter().zip(&v) {
        let got = f.eval(*p);
        assert!(crate::geometry::dist(got, *want) <= 10.0 * bound, "{got:?} vs {want:?}");
    }
}

const GAP: f64 = 5e-9;

/// The analytic gradient against central differences of the field, for both kernels, at points
/// away from the centres.
#[test]
fn the_gradient_matches_finite_differences() {
    let c: Vec<Point3> = (0..23)
        .map(|i| [(i as f64 * 0.37).sin(), (i as f64 * 0.91).cos(), (i * i % 7) as f64 * 0.1])
        .collect();
    let vals: Vec<Point3> = (0..23)
        .map(|i| [(i as f64 * 1.3).cos() * 0.2, (i as f64 * 0.4).sin() * 0.1, i as f64 * 0.01])
        .collect();
    for kernel in [Kernel::Linear, Kernel::Cubic] {
        let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
        for p in [[0.11, 0.23, 0.37], [-0.6, 0.4, 0.05], [1.5, -1.0, 2.0]] {
            let g = f.gradient(p);
            let h = 1e-6;
            for col in 0..3 {
                let (mut a, mut b) = (p, p);
                a[col] += h;
                b[col] -= h;
                let (ea, eb) = (f.eval(a), f.eval(b));
                for row in 0..3 {
                    let fd = (ea[row] - eb[row]) / (2.0 * h);
                    assert!((g[row][col] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{kernel:?} {g:?} at {p:?}");
                }
            }
        }
    }
}

/// `n` centres on a wobbly sphere with smooth displacements, and `m` scattered points around them
/// (the two gradient tests' field).
fn scattered_field(n: usize, m: usize) -> (Vec<Point3>, Vec<Point3>, Vec<Point3>) {
    let c: Vec<Point3> = (0..n)
        .map(|i| {
            let (a, b) = (i as f64 * 0.61, i as f64 * 0.237);
            [a.cos() * b.sin() * (1.0 + 0.1 * (3.0 * a).sin()), a.sin() * b.sin(), b.cos() + 0.05 * a.cos()]
        })
        .collect();
    let vals =
        c.iter().map(|p| [0.3 * p[1] * p[2], 0.2 * (3.0 * p[0]).sin(), -0.25 * p[0] * p[1] + 0.1]).collect();
    let points = (0..m)
        .map(|i| [(i as f64 * 0.77).sin() * 1.3, (i as f64 * 0.31).cos(), (i % 9) as f64 * 0.2 - 0.8])
        .collect();
    (c, vals, points)
}

/// The single-precision gradients ([`Rbf::gradients_bounded`]) stay within their error bounds of
/// the exact ones: far from the centres, 1e-7 from one and on one (where the exact gradient leaves
/// that centre out). Away from the centres the bounds are small, so the orientation count decides
/// nearly every face from them. The cubic kernel is exact (bound 0).
#[test]
fn single_precision_gradients_stay_within_their_bounds() {
    let (c, vals, mut points) = scattered_field(400, 50);
    let far = points.len();
    points.push(c[5]);
    points.push([c[17][0] + 1e-7, c[17][1], c[17][2]]);
    for kernel in [Kernel::Linear, Kernel::Cubic] {
        let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
        let got = f.gradients_bounded(&points, &Progress::new()).unwrap();
        for (i, (p, (g, bound))) in points.iter().zip(&got).enumerate() {
            let exact = f.gradient(*p);
            let (mut err, mut size) = (0.0f64, 0.0f64);
            for r in 0..3 {
                for k in 0..3 {
                    err += (g[r][k] - exact[r][k]).powi(2);
                    size += exact[r][k].powi(2);
                }
            }
            let (err, size) = (err.sqrt(), size.sqrt());
            assert!(err <= *bound, "{kernel:?} point {i}: error {err:e} over the bound {bound:e}");
            if kernel == Kernel::Cubic {
                assert_eq!(*bound, 0.0);
            } else if i <= far {
                // Far points, and the point on a centre (that term is left out exactly).
                assert!(*bound < 1e-3 * (1.0 + size), "point {i}: bound {bound:e}, gradient {size}");
            }
        }
    }
}

/// The fused pass ([`Rbf::eval_with_gradients`]) gives bitwise the values of [`Rbf::eval_many`]
/// (the fit's output must not change with it) and the gradients of [`Rbf::gradient`] up to
/// double-precision rounding, for 403 centres (not a multiple of 4: the scalar tail runs too), at
/// points away from the centres, on one and 1e-9 from one; the cubic kernel takes the plain path.
#[test]
fn fused_values_and_gradients_match_the_separate_ones() {
    let (c, vals, mut points) = scattered_field(403, 300);
    points.push(c[5]);
    points.push([c[17][0] + 1e-9, c[17][1], c[17][2]]);
    for kernel in [Kernel::Linear, Kernel::Cubic] {
        let f = Rbf::fit(&c, &vals, kernel, "test").unwrap();
        let (values, grads) = f.eval_with_gradients(&points, &Progress::new()).unwrap();
        let plain = f.eval_many(&points, &Progress::new()).unwrap();
        assert_eq!(values.len(), points.len());
        for (i, (a, b)) in values.iter().zip(&plain).enumerate() {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{kernel:?} point {i}: {a:?} vs {b:?}");
        }
        // Two double-precision sums of the same n terms, each |α_i|·|d|/r ≤ |α_i| (normalised
        // frame): they differ by at most ~(n + 10)·ε·Σ|α_i| / scale each (the polynomial part is
        // added alike).
        let w_sum: f64 =
            (0..c.len()).map(|i| f.w[0][i].abs().max(f.w[1][i].abs()).max(f.w[2][i].abs())).sum();
        let tol = 4.0 * (c.len() + 10) as f64 * f64::EPSILON * w_sum / f.scale;
        for (i, (g, p)) in grads.iter().zip(&points).enumerate() {
            let exact = f.gradient(*p);
            for r in 0..3 {
                for k in 0..3 {
                    let e = (g[r][k] - exact[r][k]).abs();
                    assert!(e <= tol, "{kernel:?} point {i}: {g:?} vs {exact:?} (tolerance {tol:e})");
                }
            }
        }
    }
}
