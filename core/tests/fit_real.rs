//! A real template (homer.obj, closed genus 0) fitted to curves cut from a known deformation of
//! itself: plane sections of the original surface, moved by `testdata::bend`. Truth: the bent
//! surface (distance of the fit to it), and the number of regions the planes cut the surface into
//! (counted independently on a finer copy of the original).

use meshwork_core::fit::kdtree::KdTree;
use meshwork_core::fit::smooth::closest_on_triangle;
use meshwork_core::fit::testdata::faces_against;
use meshwork_core::fit::testdata::{bend, crossing_pairs, plane_sections, section_regions, thin_network};
use meshwork_core::fit::{run, FitParams};
use meshwork_core::geometry::{dist, triangle_cross, Aabb};
use meshwork_core::io::{read, ReadOptions};
use meshwork_core::mesh::{Mesh, Point3};
use meshwork_core::shapes::{fan_triangles, subdivide_midpoint};
use meshwork_core::Progress;

fn homer() -> Mesh {
    let bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/meshes/homer.obj"))
        .or_else(|_| std::fs::read("../../shared/meshes/homer.obj"))
        .expect("homer.obj in ../shared/meshes");
    read(&bytes, &ReadOptions::default()).expect("read homer").mesh
}

/// Horizontal slices and two vertical ones (offsets chosen off the vertex coordinates).
fn planes() -> Vec<(Point3, f64)> {
    let mut p: Vec<(Point3, f64)> =
        [0.3013, 0.4517, 0.6021, 0.7519, 0.9011].iter().map(|&y| ([0.0, 1.0, 0.0], y)).collect();
    p.push(([1.0, 0.0, 0.0], 0.4987));
    p.push(([0.0, 0.0, 1.0], 0.4919));
    p
}

#[test]
fn homer_fits_sections_of_its_bent_self() {
    let original = homer();
    let planes = planes();
    // The template is twice as fine as the curves: sections of the original homer, every second
    // section point kept; the template is homer split once (same surface, 4× the faces).
    let mut curves = thin_network(&plane_sections(&original, &planes), 2);
    let template = subdivide_midpoint(&original, 1);
    // The user's pairs, as a user would pick them: where sections cross, the template vertex
    // nearest to the crossing ↔ the crossing on the bent target.
    let pairs = crossing_pairs(&curves, &template, 12, |p| bend(p, 1.0));
    for p in curves.positions.iter_mut() {
        *p = bend(*p, 1.0);
    }
    let truth_pos: Vec<Point3> = template.positions.iter().map(|&p| bend(p, 1.0)).collect();
    let truth_tris = fan_triangles(&template.faces);
    let expected = section_regions(&original, &planes);

    let params = FitParams { pairs, ..Default::default() };
    let out = run(vec![template.clone(), curves], &params, &Progress::new()).expect("fit");
    let r = &out.report;
    eprintln!("{}", serde_json::to_string_pretty(r).unwrap());
    let m = &out.meshes[0];

    // Distance of every output vertex to the bent surface: closest point over the one-rings of
    // the 8 nearest truth vertices (an upper bound of the true distance).
    let tree = KdTree::new(&truth_pos);
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); truth_pos.len()];
    for (f, t) in truth_tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
    let diag = Aabb::of(&truth_pos).unwrap().diagonal();
    let mut devs: Vec<f64> = m
        .positions
        .iter()
        .map(|&p| {
            let (v, _) = tree.nearest(p).unwrap();
            vf[v as usize]
                .iter()
                .map(|&f| dist(p, closest_on_triangle(p, truth_tris[f as usize], &truth_pos)))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    devs.sort_by(f64::total_cmp);
    let mean = devs.iter().sum::<f64>() / devs.len() as f64;
    let p99 = devs[devs.len() * 99 / 100];
    let max = *devs.last().unwrap();
    eprintln!(
        "expected regions {expected}; deviation / diag: mean {:.2e} p99 {:.2e} max {:.2e}",
        mean / diag,
        p99 / diag,
        max / diag
    );

    // Faces flipped against the truth: output normal vs the truth normal nearest to it.
    let flipped = faces_against(m, |centroid| {
        let (v, _) = tree.nearest(centroid).unwrap();
        vf[v as usize].iter().fold([0.0; 3], |acc, &g| {
            let t = truth_tris[g as usize];
            let n =
                triangle_cross(truth_pos[t[0] as usize], truth_pos[t[1] as usize], truth_pos[t[2] as usize]);
            [acc[0] + n[0], acc[1] + n[1], acc[2] + n[2]]
        })
    })
    .len();
    eprintln!("faces opposing the truth normal: {flipped}");

    // Every matched curve vertex is exactly on the output.
    assert!(r["curve_residual_max"].as_f64().unwrap() <= 1e-9 * diag);
    // The surface between the curves is close to the bent truth (the fit only sees the curves).
    assert!(mean < 0.004 * diag, "mean deviation {}", mean / diag);
    assert!(p99 < 0.02 * diag, "p99 deviation {}", p99 / diag);
    // Every segment is an edge chain, so the regions are exactly those the planes make.
    assert_eq!(r["segments_as_edges"], 1.0);
    assert_eq!(r["regions"].as_u64().unwrap() as usize, expected);
    // Known gap: a face or two may still oppose the truth normal (measured 1 of ~50k).
    assert!((flipped as f64) < 0.002 * m.face_count() as f64, "{flipped} faces oppose the truth");
}
