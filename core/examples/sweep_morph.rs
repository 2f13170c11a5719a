//! Morph sweep: the morph job over many pairs nobody tuned it for (shared meshes after repair,
//! analytic shapes with sharp corners, long thin parts, very coarse and very dense meshes, very
//! different sizes, a mesh with itself, a rotated+scaled+mirrored copy, a 3-input blend, feature
//! pairs, disks on the planar side). Prints per case: ok or the error, foldovers, AD/SD per input,
//! the job's Hausdorff of the first/last frame, an own check of the first frame (meshes[0] against
//! input 0 as given, BVH closest points at vertices and face centroids, relative to the input's
//! bbox diagonal), metamesh vertices and the time. A check of the general case, not a benchmark.
//!
//! Run from the repository root:
//! `CARGO_TARGET_DIR=/work/target-release cargo build --release -p meshwork-core --example sweep_morph`
//! then copy `/work/target-release/release/examples/sweep_morph` out and run it `[FILTER…]`
//! (cases whose name contains any FILTER; all without).

use std::time::{Duration, Instant};

use meshwork_core::geometry::{normalize, Aabb};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::job::{self, JobKind, Progress};
use meshwork_core::mesh::{Faces, Mesh, Point3};
use meshwork_core::shapes::{cube, fan_triangles, icosphere, octahedron as octa, tetrahedron as tetra};
use meshwork_core::spatial::Bvh;
use serde_json::{json, Value};

fn shared(name: &str) -> Mesh {
    let p = format!("../shared/meshes/{name}.obj");
    let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{p}: {e}"));
    read(&bytes, &ReadOptions { name_hint: Some(p.clone()), ..Default::default() })
        .unwrap_or_else(|e| panic!("{p}: {e}"))
        .mesh
}

fn map(m: &Mesh, f: impl Fn(Point3) -> Point3) -> Mesh {
    let mut o = m.clone();
    for p in &mut o.positions {
        *p = f(*p);
    }
    o
}

fn ellipsoid(levels: u32, a: Point3) -> Mesh {
    map(&icosphere(levels, 1.0), |p| [p[0] * a[0], p[1] * a[1], p[2] * a[2]])
}

/// Two balls joined by a thin neck along x (radius 0.25 at the middle, 1 at the ends).
fn dumbbell(levels: u32) -> Mesh {
    map(&icosphere(levels, 1.0), |p| {
        let r = 0.25 + 0.75 * (p[0] * p[0]).sqrt();
        [3.0 * p[0], r * p[1], r * p[2]]
    })
}

/// A capsule 8× longer than wide, bent through 180° (a U).
fn bent_capsule(levels: u32) -> Mesh {
    map(&icosphere(levels, 1.0), |p| {
        let x = 8.0 * p[0];
        let radius = 4.0 / std::f64::consts::PI * 2.0; // arc radius: length 8 → half circle of r ≈ 2.55
        let th = x / radius;
        let rr = radius + 0.8 * p[1];
        [rr * th.sin(), rr * th.cos(), 0.8 * p[2]]
    })
}

/// Icosphere pushed onto the cube [-1,1]³ (sharp edges and corners, vertices on the cube).
fn cube_like(levels: u32) -> Mesh {
    map(&icosphere(levels, 1.0), |p| {
        let m = p[0].abs().max(p[1].abs()).max(p[2].abs());
        [p[0] / m, p[1] / m, p[2] / m]
    })
}

/// Latitude–longitude sphere (pole fans, thin triangles near the poles): nu·(nv−1)·2 faces.
fn uv_sphere(nu: usize, nv: usize) -> Mesh {
    let mut pos = vec![[0.0, 0.0, 1.0]];
    for j in 1..nv {
        let th = std::f64::consts::PI * j as f64 / nv as f64;
        for i in 0..nu {
            let ph = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            pos.push([th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()]);
        }
    }
    pos.push([0.0, 0.0, -1.0]);
    let s = pos.len() as u32 - 1;
    let ring = |j: usize, i: usize| (1 + (j - 1) * nu + i % nu) as u32;
    let mut tris = Vec::new();
    for i in 0..nu {
        tris.push([0, ring(1, i), ring(1, i + 1)]);
        tris.push([s, ring(nv - 1, i + 1), ring(nv - 1, i)]);
    }
    for j in 1..nv - 1 {
        for i in 0..nu {
            let (a, b, c, d) = (ring(j, i), ring(j, i + 1), ring(j + 1, i), ring(j + 1, i + 1));
            tris.push([a, c, d]);
            tris.push([a, d, b]);
        }
    }
    Mesh::from_triangles(pos, &tris)
}

/// Rotation about (1,2,3) by 0.7 rad, scale 3.5, then the y axis mirrored (orientation flips).
fn rotated_mirrored(m: &Mesh) -> Mesh {
    let k = normalize([1.0, 2.0, 3.0]);
    let (s, c) = 0.7f64.sin_cos();
    map(m, |p| {
        let kxp = [k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2], k[0] * p[1] - k[1] * p[0]];
        let kdp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
        let r: Vec<f64> = (0..3).map(|i| p[i] * c + kxp[i] * s + k[i] * kdp * (1.0 - c)).collect();
        [3.5 * r[0] + 10.0, -3.5 * r[1], 3.5 * r[2] - 4.0]
    })
}

/// Rotation about (1,2,3) by 0.7 rad, scale 3.5, moved: the same shape, so after the PCA
/// normalisation the morph should not move at all (if the axis sign rule is deterministic).
fn rotated_scaled(m: &Mesh) -> Mesh {
    let k = normalize([1.0, 2.0, 3.0]);
    let (s, c) = 0.7f64.sin_cos();
    map(m, |p| {
        let kxp = [k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2], k[0] * p[1] - k[1] * p[0]];
        let kdp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
        let r: Vec<f64> = (0..3).map(|i| p[i] * c + kxp[i] * s + k[i] * kdp * (1.0 - c)).collect();
        [3.5 * r[0] + 10.0, 3.5 * r[1], 3.5 * r[2] - 4.0]
    })
}

/// Largest distance a metamesh vertex travels between the first two output meshes (same
/// connectivity), over the first's bbox diagonal.
fn motion(a: &Mesh, b: &Mesh) -> f64 {
    if a.positions.len() != b.positions.len() {
        return f64::NAN;
    }
    let d = a
        .positions
        .iter()
        .zip(&b.positions)
        .map(|(p, q)| meshwork_core::geometry::dist(*p, *q))
        .fold(0.0, f64::max);
    d / Aabb::of(&a.positions).map_or(1.0, |x| x.diagonal())
}

/// Max distance at a's vertices and face centroids to surface b, and vice versa, over b's diagonal.
fn own_hausdorff(a: &Mesh, b: &Mesh) -> f64 {
    let samples = |m: &Mesh| -> Vec<Point3> {
        let mut s = m.positions.clone();
        for t in fan_triangles(&m.faces) {
            let p: Vec<Point3> = t.iter().map(|&v| m.positions[v as usize]).collect();
            s.push([0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0));
        }
        s
    };
    let tri = |m: &Mesh| Faces::from_triangles(&fan_triangles(&m.faces));
    let (ba, bb) = (Bvh::new(&a.positions, &tri(a)), Bvh::new(&b.positions, &tri(b)));
    let d = bb.max_distance(&samples(a)).max(ba.max_distance(&samples(b)));
    d / Aabb::of(&b.positions).map_or(1.0, |x| x.diagonal())
}

struct Case {
    name: String,
    inputs: Vec<Mesh>,
    params: Value,
}

fn case(name: &str, inputs: Vec<Mesh>, params: Value) -> Case {
    Case { name: name.into(), inputs, params }
}

fn cases() -> Vec<Case> {
    let rep = json!({"repair": true, "frames": 10});
    let plain = json!({"frames": 10});
    let mut v = Vec::new();
    let pairs = [
        ("fandisk", "homer"),
        ("homer", "spot"),
        ("spot", "cow"),
        ("cow", "fandisk"),
        ("stanford-bunny", "homer"),
        ("teapot", "homer"),
        ("suzanne", "spot"),
        ("beetle", "fandisk"),
        ("woody", "alligator"),
        ("alligator", "beetle"),
    ];
    for (a, b) in pairs {
        v.push(case(&format!("{a}-{b}"), vec![shared(a), shared(b)], rep.clone()));
    }
    v.push(case(
        "icosphere-ellipsoid",
        vec![icosphere(4, 1.0), ellipsoid(3, [2.0, 1.0, 0.5])],
        plain.clone(),
    ));
    v.push(case("dumbbell-icosphere", vec![dumbbell(5), icosphere(3, 1.0)], plain.clone()));
    v.push(case(
        "bentcapsule-ellipsoid",
        vec![bent_capsule(5), ellipsoid(4, [3.0, 1.0, 1.0])],
        plain.clone(),
    ));
    v.push(case("cube-icosphere", vec![cube_like(4), icosphere(3, 1.0)], plain.clone()));
    v.push(case("cube12-homer", vec![cube(), shared("homer")], plain.clone()));
    v.push(case("tetra-octa", vec![tetra(), octa()], plain.clone()));
    v.push(case("tetra-cube12", vec![tetra(), cube()], plain.clone()));
    v.push(case("uvsphere200k-homer", vec![uv_sphere(320, 314), shared("homer")], plain.clone()));
    v.push(case("ico500-ell100k", vec![icosphere(3, 1.0), ellipsoid(7, [1.5, 1.0, 0.7])], plain.clone()));
    v.push(case("homer-self", vec![shared("homer"), shared("homer")], plain.clone()));
    v.push(case("fandisk-self", vec![shared("fandisk"), shared("fandisk")], plain.clone()));
    v.push(case("homer-rotscale", vec![shared("homer"), rotated_scaled(&shared("homer"))], plain.clone()));
    v.push(case(
        "fandisk-rotscale",
        vec![shared("fandisk"), rotated_scaled(&shared("fandisk"))],
        plain.clone(),
    ));
    v.push(case("cow-rotscale", vec![shared("cow"), rotated_scaled(&shared("cow"))], rep.clone()));
    v.push(case(
        "teapot-homer-sphere",
        vec![shared("teapot"), shared("homer")],
        json!({"frames": 10, "repair": true, "domain": "sphere"}),
    ));
    v.push(case(
        "beetle-fandisk-sphere",
        vec![shared("beetle"), shared("fandisk")],
        json!({"frames": 10, "repair": true, "domain": "sphere"}),
    ));
    v.push(case("woody-self", vec![shared("woody"), shared("woody")], rep.clone()));
    v.push(case(
        "features-woody-alligator",
        vec![shared("woody"), shared("alligator")],
        json!({"frames": 10, "repair": true, "features": [[0, 0], [300, 1500], [600, 3000]]}),
    ));
    v.push(case(
        "pseudo-woody-alligator",
        vec![shared("woody"), shared("alligator")],
        json!({"frames": 10, "repair": true, "correspondence": "pseudo"}),
    ));
    v.push(case("homer-rotmirror", vec![shared("homer"), rotated_mirrored(&shared("homer"))], plain.clone()));
    v.push(case(
        "fandisk-rotmirror-icp",
        vec![shared("fandisk"), rotated_mirrored(&shared("fandisk"))],
        json!({"frames": 10, "registration": "pca_icp"}),
    ));
    v.push(case(
        "multi3-blend",
        vec![icosphere(3, 1.0), ellipsoid(4, [2.0, 1.0, 0.5]), cube_like(3)],
        json!({"frames": 10, "blend_weights": [0.2, 0.3, 0.5]}),
    ));
    v.push(case(
        "multi3-seq",
        vec![shared("homer"), shared("fandisk"), shared("spot")],
        json!({"frames": 10, "repair": true}),
    ));
    v.push(case(
        "features-ico-ell",
        vec![icosphere(3, 1.0), ellipsoid(3, [2.0, 1.0, 0.5])],
        json!({"frames": 10, "features": [[0, 3], [5, 9], [11, 40]]}),
    ));
    v.push(case(
        "features-fandisk-homer",
        vec![shared("fandisk"), shared("homer")],
        json!({"frames": 10, "features": [[0, 0], [3000, 3000], [6000, 5000]]}),
    ));
    v.push(case(
        "pseudo-fandisk-homer",
        vec![shared("fandisk"), shared("homer")],
        json!({"frames": 10, "correspondence": "pseudo"}),
    ));
    v.push(case(
        "tutte-homer-spot",
        vec![shared("homer"), shared("spot")],
        json!({"frames": 10, "repair": true, "sphere_method": "tutte"}),
    ));
    v
}

fn fmt_pair(r: &Value, k: &str) -> String {
    r[k].as_array()
        .map(|a| {
            a.iter()
                .map(|x| x.as_f64().map_or("-".into(), |f| format!("{f:.2}")))
                .collect::<Vec<_>>()
                .join("/")
        })
        .unwrap_or("-".into())
}

fn main() {
    let filters: Vec<String> = std::env::args().skip(1).collect();
    println!("| case | inputs (V) | result | foldovers | AD | SD | H first/last (job) | H first (own) | motion | metamesh V | time s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for c in cases() {
        if !filters.is_empty() && !filters.iter().any(|f| c.name.contains(f.as_str())) {
            continue;
        }
        let sizes: Vec<String> = c.inputs.iter().map(|m| m.vertex_count().to_string()).collect();
        let input0 = c.inputs[0].clone();
        let progress = Progress::new();
        progress.set_deadline(Instant::now() + Duration::from_secs(300));
        let t = Instant::now();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            job::run(JobKind::Morph, c.inputs, c.params.clone(), &progress)
        }));
        let secs = t.elapsed().as_secs_f64();
        let row = match r {
            Err(p) => {
                let msg =
                    p.downcast_ref::<String>().cloned().or(p.downcast_ref::<&str>().map(|s| s.to_string()));
                format!("PANIC {} | | | | | | | | ", msg.unwrap_or_default().replace('|', "/"))
            }
            Ok(Err(e)) => format!("error: {} | | | | | | | | ", e.to_string().replace('|', "/")),
            Ok(Ok(o)) => {
                let r = &o.report;
                let own = if r["domain"] == "spherical" && c.params.get("blend_weights").is_none() {
                    format!("{:.1e}", own_hausdorff(&o.meshes[0], &input0))
                } else {
                    "-".into()
                };
                let fold: Vec<String> = r["foldovers"]
                    .as_array()
                    .map_or(vec![r["foldovers"].to_string()], |a| a.iter().map(|x| x.to_string()).collect());
                let feat = r["features"]
                    .get("max_feature_gap_after")
                    .map_or(String::new(), |x| format!(" feat {x}"));
                format!(
                    "ok {} {}{} | {} | {} | {} | {:.1e}/{:.1e} | {} | {:.1e} | {} | ",
                    r["domain"].as_str().unwrap_or("?"),
                    r["correspondence"].as_str().unwrap_or(""),
                    feat,
                    fold.join("/"),
                    fmt_pair(r, "angle_distortion"),
                    fmt_pair(r, "area_distortion"),
                    r["hausdorff_first_frame"].as_f64().unwrap_or(f64::NAN),
                    r["hausdorff_last_frame"].as_f64().unwrap_or(f64::NAN),
                    own,
                    if o.meshes.len() >= 2 { motion(&o.meshes[0], &o.meshes[1]) } else { f64::NAN },
                    r["metamesh_vertices"],
                )
            }
        };
        println!("| {} | {} | {row}{secs:.2} |", c.name, sizes.join("/"));
    }
}
