//! Hand-computed values for every operator (seed 004 §1.7 anchors and textbook cases).

use super::*;
use crate::mesh::Mesh;
use crate::shapes::{grid, parallelogram_grid, triangle_grid};

fn op(m: &Mesh, kind: OperatorKind) -> Operator {
    operator(&m.positions, &m.faces, kind, MassKind::Voronoi).unwrap()
}

#[test]
fn unit_square_quads_case_b_weight_2_and_normalised_quarter() {
    // 4×4 unit quads; vertex (2,2) = index 2*5+2 is interior.
    let m = grid(4, 4, 1.0, true);
    let i = 12;
    let o = op(&m, OperatorKind::Tqlbo);
    let s = &o.stiffness;
    for j in [11, 13, 7, 17] {
        // S_ij = −w/2 with w = 2 (case b).
        assert!((s.get(i, j) + 1.0).abs() < 1e-14, "edge {j}: {}", s.get(i, j));
    }
    for j in [6, 8, 16, 18] {
        // Diagonal vertices of rectangles: case c weight 0, but in the stencil.
        assert!(s.get(i, j).abs() < 1e-14);
        assert!(s.row(i).0.contains(&(j as u32)));
    }
    assert!((s.get(i, i) - 4.0).abs() < 1e-14);
    // Ring area (3-4): 4 quads × ½(0.5 + 0.5 + 0.5) = 3; L_ij = −w/(2A) = −1/3.
    assert!((o.scale[i] - 3.0).abs() < 1e-14);
    let l = o.row_matrix();
    assert!((l.get(i, 11) + 1.0 / 3.0).abs() < 1e-14);
    let n = op(&m, OperatorKind::TqlboNormalized).row_matrix();
    assert!((n.get(i, i) - 1.0).abs() < 1e-14);
    for j in [11, 13, 7, 17] {
        assert!((n.get(i, j) + 0.25).abs() < 1e-14);
    }
}

#[test]
fn equilateral_triangles_weight_two_over_sqrt3() {
    let m = triangle_grid(6, 6, 1.0);
    // Interior vertex of valence 6: row 2 (odd rows offset), column 2.
    let i = 2 * 6 + 2;
    let o = op(&m, OperatorKind::Cotan);
    let (cols, vals) = o.stiffness.row(i);
    assert_eq!(cols.len(), 7);
    let w = 2.0 / 3f64.sqrt();
    for (&j, &v) in cols.iter().zip(vals) {
        if j as usize != i {
            assert!((v + w / 2.0).abs() < 1e-13, "{v}");
        }
    }
    let n = op(&m, OperatorKind::TqlboNormalized).row_matrix();
    for (&j, _) in cols.iter().zip(vals) {
        let expect = if j as usize == i { 1.0 } else { -1.0 / 6.0 };
        assert!((n.get(i, j as usize) - expect).abs() < 1e-13);
    }
    // Voronoi mass of a regular vertex = hexagonal cell = √3/2 · h²; barycentric the same here.
    assert!((o.scale[i] - 3f64.sqrt() / 2.0).abs() < 1e-13);
}

#[test]
fn parallelogram_case_c_has_the_half_factor() {
    // Cells with edges u = (1,0), v = (0.5,1). In the cell A=(0,0) B=(1,0) C=(1.5,1) D=(0.5,1):
    // angle ABC has cot = (BA·BC)/|BA×BC| = −0.5/1, angle ADC the same, so the A–C diagonal weight is
    // ½(−0.5 − 0.5) = −0.5 and S_AC = +0.25; angles BCD, BAD have cot +0.5, so S_BD = −0.25.
    // The printed eq. 3-5 (no ½) would give ±0.5.
    let m = parallelogram_grid(3, 3, [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], true);
    let s = op(&m, OperatorKind::Tqlbo).stiffness;
    let id = |i: usize, j: usize| j * 4 + i;
    let (a, b, c, d) = (id(1, 1), id(2, 1), id(2, 2), id(1, 2));
    assert!((s.get(a, c) - 0.25).abs() < 1e-14, "{}", s.get(a, c));
    assert!((s.get(b, d) + 0.25).abs() < 1e-14, "{}", s.get(b, d));
}

#[test]
fn right_triangle_cotan_and_masses() {
    let m = Mesh::from_triangles(vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], &[[0, 1, 2]]);
    let s = cotan_stiffness(&m.positions, &m.faces).unwrap();
    // cot at the right angle is 0, the two 45° angles have cot 1.
    assert!((s.get(1, 2)).abs() < 1e-15);
    assert!((s.get(0, 1) + 0.5).abs() < 1e-15);
    assert!((s.get(0, 2) + 0.5).abs() < 1e-15);
    assert!((s.get(0, 0) - 1.0).abs() < 1e-15);
    let b = mass(&m.positions, &m.faces, MassKind::Barycentric).unwrap();
    assert!(b.iter().all(|x| (x - 1.0 / 6.0).abs() < 1e-15));
    // Voronoi: right angle (not obtuse) → circumcentre on the hypotenuse: 1/4, 1/8, 1/8.
    let v = mass(&m.positions, &m.faces, MassKind::Voronoi).unwrap();
    assert!((v[0] - 0.25).abs() < 1e-15 && (v[1] - 0.125).abs() < 1e-15 && (v[2] - 0.125).abs() < 1e-15);
    // Obtuse triangle: ½ area to the obtuse corner, ¼ to the others.
    let o = Mesh::from_triangles(vec![[0., 0., 0.], [2., 0., 0.], [1., 0.2, 0.]], &[[0, 1, 2]]);
    let v = mass(&o.positions, &o.faces, MassKind::Voronoi).unwrap();
    assert!((v[2] - 0.1).abs() < 1e-15 && (v[0] - 0.05).abs() < 1e-15);
}

/// A planar hybrid mesh with jittered interior vertices, a pentagon and a hexagon.
fn planar_hybrid() -> Mesh {
    let mut m = grid(6, 6, 1.0, true);
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 33) as f64 / (1u64 << 31) as f64) - 0.5
    };
    for j in 1..6 {
        for i in 1..6 {
            let p = &mut m.positions[j * 7 + i];
            p[0] += 0.3 * rnd();
            p[1] += 0.3 * rnd();
        }
    }
    // Rebuild faces: split some quads into triangles, merge two pairs of quads into a hexagon and
    // a pentagon (pentagon = quad + triangle sharing an edge).
    let id = |i: usize, j: usize| (j * 7 + i) as u32;
    let mut f = crate::mesh::Faces::new();
    for j in 0..6 {
        for i in 0..6 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match (i, j) {
                (1, 1) => f.push(&[a, b, id(i + 2, j), id(i + 2, j + 1), c, d], 0), // hexagon over 2 cells
                (2, 1) => {}
                (3, 3) => {
                    f.push(&[a, b, c, d], 0);
                }
                _ if (i + 2 * j) % 3 == 0 => {
                    f.push(&[a, b, c], 0);
                    f.push(&[a, c, d], 0);
                }
                _ => f.push(&[a, b, c, d], 0),
            }
        }
    }
    m.faces = f;
    m
}

#[test]
fn zero_row_sums_symmetry_and_linear_precision_on_hybrid_ngons() {
    let m = planar_hybrid();
    let o = op(&m, OperatorKind::Tqlbo);
    let s = &o.stiffness;
    assert!(s.asymmetry() < 1e-14);
    let boundary =
        Stencil::new(&m.faces, m.vertex_count(), PairLayout::AllPairs).unwrap().boundary_vertices();
    for i in 0..s.n {
        let (c, v) = s.row(i);
        assert!(v.iter().sum::<f64>().abs() < 1e-12);
        // Linear precision: on a planar mesh every triangulation's cotan Laplacian vanishes on
        // linear functions at interior vertices, hence so does their fan average.
        if !boundary[i] {
            for k in 0..2 {
                let lx: f64 = c.iter().zip(v).map(|(&j, &a)| a * m.positions[j as usize][k]).sum();
                assert!(lx.abs() < 1e-12, "vertex {i}: {lx}");
            }
        }
    }
    // The normalised operator has unit diagonal and zero row sums but is not symmetric.
    let n = op(&m, OperatorKind::TqlboNormalized).row_matrix();
    for i in 0..n.n {
        assert!((n.get(i, i) - 1.0).abs() < 1e-12);
        assert!(n.row(i).1.iter().sum::<f64>().abs() < 1e-12);
    }
    // Uniform: valence on the diagonal (hexagon corners count polygon edges only).
    let u = op(&m, OperatorKind::Uniform).stiffness;
    for i in 0..u.n {
        assert!(u.row(i).1.iter().sum::<f64>().abs() < 1e-15);
    }
}

#[test]
fn boundary_curve_rows_are_second_differences() {
    let m = grid(4, 4, 0.5, true);
    let st = Stencil::new(&m.faces, m.vertex_count(), PairLayout::AllPairs).unwrap();
    let rows = boundary_curve_rows(&st, &m.positions, 0.0);
    // Bottom edge vertex 2 has boundary neighbours 1 and 3 at 0.5: B = (−1, 2, −1).
    let r = rows[2].as_ref().unwrap();
    assert_eq!(r.len(), 2);
    assert!(r.iter().all(|&(j, b)| (j == 1 || j == 3) && (b + 1.0).abs() < 1e-15));
    assert!(rows[12].is_none()); // interior
                                 // Corner 0: neighbours 1 and 5; row sums with the diagonal 2 are zero.
    let r0 = rows[0].as_ref().unwrap();
    assert!((r0.iter().map(|x| x.1).sum::<f64>() + 2.0).abs() < 1e-15);
}

#[test]
fn tiny_models_are_not_locked() {
    // Faces of area 1e-10: Blender's absolute 1e-5 threshold would lock every vertex.
    let m = triangle_grid(5, 5, 1e-5);
    let o = op(&m, OperatorKind::TqlboNormalized);
    assert!(o.locked.iter().all(|l| !l));
    let big = op(&triangle_grid(5, 5, 1.0), OperatorKind::TqlboNormalized);
    let (a, b) = (o.row_matrix(), big.row_matrix());
    for (x, y) in a.val.iter().zip(&b.val) {
        assert!((x - y).abs() < 1e-12);
    }
    let c = op(&m, OperatorKind::Cotan);
    assert!(c.locked.iter().all(|l| !l));
}

#[test]
fn degenerate_triangle_gives_no_weight_and_isolated_vertex_is_locked() {
    let m = Mesh::from_triangles(
        vec![[0., 0., 0.], [1., 0., 0.], [2., 0., 0.], [0., 1., 0.], [5., 5., 5.]],
        &[[0, 1, 2], [0, 1, 3]],
    );
    let o = op(&m, OperatorKind::Cotan);
    assert_eq!(o.degenerate_triangles, 1);
    assert!(o.locked[4]);
    assert!(!o.locked[3]);
    assert!(o.stiffness.val.iter().all(|v| v.is_finite()));
}

/// The uniform-only stencil has the same pattern, edge multiplicities and diagonal positions as
/// the full one (Edges layout), on triangles, a hybrid polygon mesh, a repeated corner, a
/// non-manifold fin and an isolated vertex; and its umbrella stiffness is the hand-known one.
#[test]
fn uniform_stencil_equals_the_edge_pattern_of_the_full_one() {
    let mut cases = vec![triangle_grid(5, 4, 1.0), grid(3, 3, 1.0, true), planar_hybrid()];
    let mut fin = grid(2, 1, 1.0, false);
    fin.positions.push([0.5, 0.5, 1.0]);
    fin.positions.push([9.0, 9.0, 9.0]); // isolated
    let apex = fin.positions.len() as u32 - 2;
    let mut faces = fin.faces.clone();
    faces.push(&[1, 4, apex], 0); // edge 1–4 now has three faces
    faces.push(&[0, 0, 1], 0); // repeated corner
    fin.faces = faces;
    cases.push(fin);
    for m in &cases {
        let n = m.vertex_count();
        let full = Stencil::new(&m.faces, n, PairLayout::Edges).unwrap();
        let uni = Stencil::uniform(&m.faces, n).unwrap();
        assert_eq!(uni.pattern, full.pattern);
        assert_eq!(uni.edge_mult, full.edge_mult);
        assert_eq!(uni.diag_pos, full.diag_pos);
        assert_eq!(uni.uniform_stiffness(), full.uniform_stiffness());
        assert_eq!(uni.boundary_vertices(), full.boundary_vertices());
        assert_eq!(uni.nonmanifold_edges(), full.nonmanifold_edges());
    }
    // Fin: vertex 1 has neighbours 0, 2, 4, 5 (grid, diagonal 1–5) and the apex: valence 5. Edge
    // 1–4 has three faces, and so has 0–1 (its grid triangle plus the face [0, 0, 1] twice).
    let m = &cases[3];
    let s = Stencil::uniform(&m.faces, m.vertex_count()).unwrap().uniform_stiffness();
    assert_eq!(s.get(1, 1), 5.0);
    assert_eq!(Stencil::uniform(&m.faces, m.vertex_count()).unwrap().nonmanifold_edges(), 2);
    assert_eq!(s.get(7, 7), 0.0, "isolated vertex: empty row but for the diagonal");
}
