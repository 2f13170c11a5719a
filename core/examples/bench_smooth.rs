//! Smoothing benchmark (Meshwork's side). Run by `bench/smooth.sh`, which runs the peers on the
//! same files in the same session and prints the ratios.
//!
//! usage: bench_smooth [--write-subdivided OUT.obj LEVELS] MESH.obj [MESH.obj ...]
//!
//! Prints one tab-separated line per (mesh, operation): `mesh  V  operation  meshwork  ms`
//! (best of a few runs), plus the machine's copy bandwidth and the Taubin bandwidth bound.

use std::time::Instant;

use meshwork_core::io::{self, Format};
use meshwork_core::job::{run, JobKind, Progress};
use meshwork_core::laplacian::{self, MassKind, OperatorKind, Stencil};
use meshwork_core::mesh::{Faces, Mesh};
use meshwork_core::solve::{from_column_major, pcg, to_column_major, Cholesky};
use rayon::prelude::*;
use serde_json::json;

fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut t = f64::INFINITY;
    let mut out = None;
    for _ in 0..reps {
        let s = Instant::now();
        let r = f();
        t = t.min(s.elapsed().as_secs_f64() * 1e3);
        out = Some(r);
    }
    (t, out.unwrap())
}

/// Drops vertices no face uses (peers' loaders do the same), so every tool sees the same mesh.
fn compact(m: &Mesh) -> Mesh {
    let mut map = vec![u32::MAX; m.vertex_count()];
    let mut pos = Vec::new();
    let mut faces = Faces::new();
    for f in m.faces.iter() {
        let g: Vec<u32> = f
            .iter()
            .map(|&v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = pos.len() as u32;
                    pos.push(m.positions[v as usize]);
                }
                map[v as usize]
            })
            .collect();
        faces.push(&g, 0);
    }
    Mesh::new(pos, faces)
}

fn load(path: &str) -> Mesh {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    compact(&io::read(&bytes, &Default::default()).unwrap_or_else(|e| panic!("{path}: {e}")).mesh)
}

/// STREAM-like copy bandwidth (bytes read + written per second), all threads.
fn copy_bandwidth() -> f64 {
    let n = 1usize << 26; // 64 Mi f64 = 512 MiB per array
    let a = vec![1.0f64; n];
    let mut b = vec![0.0f64; n];
    let (ms, _) = best(5, || {
        b.par_chunks_mut(1 << 16).zip(a.par_chunks(1 << 16)).for_each(|(b, a)| b.copy_from_slice(a));
    });
    std::hint::black_box(&b);
    (2 * 8 * n) as f64 / (ms * 1e-3)
}

fn line(name: &str, n: usize, op: &str, ms: f64) {
    println!("{name}\tV={n}\t{op}\tmeshwork\t{ms:.1} ms");
}

fn bench(path: &str, reps: usize, bandwidth: f64) {
    let m = load(path);
    // The machine is shared: small meshes get many repetitions so the best one is a quiet one.
    let reps = if m.vertex_count() < 200_000 { reps.max(10) } else { reps };
    let name = path.rsplit('/').next().unwrap_or(path);
    let n = m.vertex_count();
    let (x, f) = (&m.positions, &m.faces);

    // 1. Cotangent Laplacian + Voronoi mass from scratch (stencil, weights, masses) — libigl's
    //    cotmatrix + massmatrix do the same work from the same inputs.
    let (ms, _) = best(reps, || laplacian::operator(x, f, OperatorKind::Cotan, MassKind::Voronoi).unwrap());
    line(name, n, "cotan+mass_assembly", ms);

    // 2. Implicit step on (M + hS), h = mean edge², 3 right-hand sides: assemble, analyse,
    //    factor, solve; the same matrix as the peers' CHOLMOD run (M − h·L with L = −S).
    let st = Stencil::new(f, n, laplacian::layout_for(OperatorKind::Cotan, f)).unwrap();
    let e = laplacian::mean_edge_length(&st, x);
    let h = e * e;
    let (ms, _) = best(reps, || {
        let o = laplacian::operator(x, f, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
        let mut a = o.stiffness.clone();
        for v in &mut a.val {
            *v *= h;
        }
        for (i, p) in a.diagonal_positions().into_iter().enumerate() {
            a.val[p] += o.scale[i];
        }
        let mut ch = Cholesky::analyze(&a).unwrap();
        ch.factor(&a).unwrap();
        let b: Vec<f64> = x.iter().zip(&o.scale).flat_map(|(p, m)| [p[0] * m, p[1] * m, p[2] * m]).collect();
        let mut y = to_column_major(&b, 3);
        ch.solve_in_place(&mut y, 3).unwrap();
        (from_column_major(&y, 3), ch.factor_nnz())
    });
    line(name, n, "implicit_cholesky(assemble+analyze+factor+solve3)", ms);
    // The same system by warm-started Jacobi CG (what `solver: auto` picks on big meshes).
    let (ms, it) = best(reps, || {
        let o = laplacian::operator(x, f, OperatorKind::Cotan, MassKind::Voronoi).unwrap();
        let mut a = o.stiffness.clone();
        for v in &mut a.val {
            *v *= h;
        }
        for (i, p) in a.diagonal_positions().into_iter().enumerate() {
            a.val[p] += o.scale[i];
        }
        let b: Vec<f64> = x.iter().zip(&o.scale).flat_map(|(p, m)| [p[0] * m, p[1] * m, p[2] * m]).collect();
        let mut sol: Vec<f64> = x.as_flattened().to_vec();
        pcg(&a, &b, &mut sol, 3, 1e-10, 2000, &meshwork_core::Progress::new()).expect("pcg").iterations
    });
    line(name, n, &format!("implicit_cg(assemble+solve3,{it}it)"), ms);

    // 3. The whole smooth job, one implicit step. Two figures per job: `total` is the whole job
    //    as a user sees it (operator, set-up, solve, the full quality report without Hausdorff);
    //    `kernel` is the stages a peer's function also does (assemble + prepare + smooth).
    let job = |params: serde_json::Value| {
        let out = run(JobKind::Smooth, vec![m.clone()], params, &Progress::new()).unwrap();
        let st = &out.report["stages"];
        let kernel = st["assemble"].as_f64().unwrap()
            + st["prepare"].as_f64().unwrap()
            + st["smooth"].as_f64().unwrap();
        (out.report["total_ms"].as_f64().unwrap(), kernel, st["smooth"].as_f64().unwrap())
    };
    let best_job = |params: serde_json::Value| {
        let mut b = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
        for _ in 0..reps {
            let t = job(params.clone());
            b = (b.0.min(t.0), b.1.min(t.1), b.2.min(t.2));
        }
        b
    };
    let job_lines = |label: &str, params: serde_json::Value| {
        let (total, kernel, smooth) = best_job(params);
        line(name, n, &format!("job_{label}_total"), total);
        line(name, n, &format!("job_{label}_kernel"), kernel);
        smooth
    };
    job_lines("implicit1(cotan,auto)", json!({"method": "implicit", "hausdorff": false}));
    job_lines(
        "implicit1(cotan,cholesky)",
        json!({"method": "implicit", "solver": "cholesky", "hausdorff": false}),
    );
    // trimesh's implicit step: umbrella, λ = 0.5, volume kept (the same linear system).
    job_lines(
        "implicit1(uniform,h=0.5,volume,auto)",
        json!({"method": "implicit", "operator": "uniform", "relative_time_step": false, "time_step": 0.5,
               "preserve_volume": true, "hausdorff": false}),
    );
    // Seed 004's operator (normalised TQLBO), one implicit step, as Blender's modifier does.
    job_lines(
        "implicit1(tqlbo_normalized,curve,volume)",
        json!({"method": "implicit", "operator": "tqlbo_normalized", "boundary": "curve",
               "preserve_volume": true, "hausdorff": false}),
    );

    // 4. Taubin, umbrella operator built inside. trimesh's `iterations=10` is 10 half-steps
    //    (5 λ|μ pairs); Meshwork's `iterations` counts λ|μ pairs, so both are measured.
    let smooth20 = job_lines(
        "taubin10(20 half-steps)",
        json!({"method": "taubin", "iterations": 10, "hausdorff": false}),
    );
    job_lines("taubin5(10 half-steps)", json!({"method": "taubin", "iterations": 5, "hausdorff": false}));
    // The job's own iteration loop (its `smooth` stage: 20 half-steps and one copy of the
    // positions) against the memory-bandwidth bound of the same sparse products.
    let stu = Stencil::uniform(f, n).unwrap();
    let nnz = stu.pattern.nnz() as f64;
    let vectors = 2.0 * n as f64 * 24.0; // x gathered once, the new positions written
    let ptr = (n as f64 + 1.0) * 4.0;
    // A valued CSR product (u32 column + f64 value per entry), what the brief's bound counts…
    let bytes_valued = 20.0 * (nnz * 12.0 + ptr + vectors);
    // …and the umbrella kernel's real minimum: it reads column indices only.
    let bytes_index = 20.0 * (nnz * 4.0 + ptr + vectors);
    line(name, n, "taubin10_iterations_only(job smooth stage)", smooth20);
    // Bandwidth measured again next to the kernel (the machine is shared: it drifts with load).
    let _ = bandwidth; // the start-of-run figure is printed once by main
    let bandwidth = copy_bandwidth();
    println!("{name}\tV={n}\tcopy_bandwidth_now\tmeshwork\t{:.2} GB/s", bandwidth / 1e9);
    for (label, bytes) in [("valued_csr", bytes_valued), ("index_only", bytes_index)] {
        let bound = bytes / bandwidth * 1e3;
        println!(
            "{name}\tV={n}\ttaubin10_bandwidth_bound_{label}\tmeshwork\t{bound:.1} ms\t(kernel/bound {:.2}, {:.0} MB moved)",
            smooth20 / bound,
            bytes / 1e6
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut reps = 3;
    let mut files = Vec::new();
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--write-subdivided" => {
                // --write-subdivided OUT LEVELS SOURCE
                let (out, levels, src) = (&args[i + 1], args[i + 2].parse().unwrap(), &args[i + 3]);
                let m = compact(&meshwork_core::shapes::subdivide_midpoint(&load(src), levels));
                std::fs::write(out, io::write(&m, Format::Obj).unwrap()).unwrap();
                eprintln!("wrote {out}: {} vertices, {} faces", m.vertex_count(), m.face_count());
                return;
            }
            "--reps" => {
                reps = args[i + 1].parse().unwrap();
                i += 1;
            }
            f => files.push(f.to_string()),
        }
        i += 1;
    }
    faer::set_global_parallelism(faer::Par::Seq);
    let bw = copy_bandwidth();
    println!("machine\t-\tcopy_bandwidth\tmeshwork\t{:.2} GB/s", bw / 1e9);
    for f in &files {
        bench(f, reps, bw);
    }
}
