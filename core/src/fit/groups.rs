//! The template's face groups carried to the output: every face the fit makes lies inside one
//! template face (insertion and subdivision only split faces) or, after re-triangulation, among
//! faces that did; it keeps that face's group. The output groups are then the intersections
//! "region_i/<template group>".

use std::collections::HashMap;

use crate::error::Result;
use crate::job::Progress;
use crate::mesh::{Faces, Mesh, Point3};

use super::insert::barycentric;

/// The labels of the output faces: the region, and the template group when the template has
/// several (kept through the fine stage's splits, then by [`after_retriangulation`] for every face
/// list the later stages make).
pub struct Labelling {
    /// The template has several groups, every face fanned (the groups are carried).
    pub keep_groups: bool,
    /// The fine stage's triangles and their template groups (empty when no groups are kept).
    fine_tris: Vec<[u32; 3]>,
    fine_groups: Vec<u32>,
}

impl Labelling {
    /// From the fine stage's mesh (`tris`, positions `pos` before the fine deformation; `parents`
    /// of the vertices it added after the template's).
    pub fn new(
        template: &Mesh,
        template_tris: &[[u32; 3]],
        tris: &[[u32; 3]],
        pos: &[Point3],
        parents: &[[(u32, f64); 3]],
    ) -> Labelling {
        let keep_groups = template.groups.len() > 1
            && template.faces.iter().map(|f| f.len().saturating_sub(2)).sum::<usize>() == template_tris.len();
        if !keep_groups {
            return Labelling { keep_groups, fine_tris: Vec::new(), fine_groups: Vec::new() };
        }
        let template_groups: Vec<u32> = (0..template.faces.len())
            .flat_map(|i| {
                std::iter::repeat_n(template.faces.group(i), template.faces.arity(i).saturating_sub(2))
            })
            .collect();
        let fine_groups =
            after_refinement(tris, pos, template_tris, &template_groups, template.vertex_count(), parents);
        Labelling { keep_groups, fine_tris: tris.to_vec(), fine_groups }
    }

    /// Template group of each face of `tris` (over `n` vertices); all 0 when no groups are kept.
    pub fn groups_of(&self, tris: &[[u32; 3]], n: usize) -> Vec<u32> {
        if self.keep_groups {
            after_retriangulation(&self.fine_tris, &self.fine_groups, tris, n)
        } else {
            vec![0; tris.len()]
        }
    }

    /// Regions of `tris` (cut along `curve_edges`), their count, and the template groups (`old`
    /// unchanged when no groups are kept: nothing reads them then).
    pub fn relabel(
        &self,
        tris: &[[u32; 3]],
        curve_edges: &super::untangle::EdgeSet,
        n: usize,
        old: Vec<u32>,
        progress: &Progress,
    ) -> Result<(Vec<u32>, usize, Vec<u32>)> {
        let (region, count) = super::partition::regions_polled(tris, curve_edges, progress)?;
        let tg = if self.keep_groups { self.groups_of(tris, n) } else { old };
        Ok((region, count, tg))
    }
}

/// Template group of each triangle of `tris` (the fine stage's mesh, positions `pos` before the
/// fine deformation). `parents[i]` are the weighted parents of vertex `nv0 + i`.
pub fn after_refinement(
    tris: &[[u32; 3]],
    pos: &[Point3],
    template_tris: &[[u32; 3]],
    template_groups: &[u32],
    nv0: usize,
    parents: &[[(u32, f64); 3]],
) -> Vec<u32> {
    let mut vf: Vec<Vec<u32>> = vec![Vec::new(); nv0];
    for (f, t) in template_tris.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
    // An original template vertex at or behind each vertex (new vertices: follow a parent with
    // a non-zero weight back to the template).
    let root = |mut v: u32| -> u32 {
        while v as usize >= nv0 {
            let p = &parents[v as usize - nv0];
            v = p.iter().find(|x| x.1 > 0.0).map_or(p[0].0, |x| x.0);
        }
        v
    };
    tris.iter()
        .map(|t| {
            let c = [
                (pos[t[0] as usize][0] + pos[t[1] as usize][0] + pos[t[2] as usize][0]) / 3.0,
                (pos[t[0] as usize][1] + pos[t[1] as usize][1] + pos[t[2] as usize][1]) / 3.0,
                (pos[t[0] as usize][2] + pos[t[1] as usize][2] + pos[t[2] as usize][2]) / 3.0,
            ];
            let mut best = (f64::NEG_INFINITY, 0u32);
            for &v in t {
                for &f in &vf[root(v) as usize] {
                    let tt = template_tris[f as usize];
                    let l = barycentric(c, &[pos[tt[0] as usize], pos[tt[1] as usize], pos[tt[2] as usize]]);
                    let m = l[0].min(l[1]).min(l[2]);
                    if m > best.0 {
                        best = (m, template_groups[f as usize]);
                    }
                }
                if best.0 >= -1e-9 {
                    break;
                }
            }
            best.1
        })
        .collect()
}

/// Groups of the re-triangulated faces: a face that existed before keeps its group; a new one
/// takes the group most of its corners' old faces have.
pub fn after_retriangulation(
    before: &[[u32; 3]],
    before_groups: &[u32],
    after: &[[u32; 3]],
    nv: usize,
) -> Vec<u32> {
    let key = |t: &[u32; 3]| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    let old: HashMap<[u32; 3], u32> = before.iter().zip(before_groups).map(|(t, &g)| (key(t), g)).collect();
    let mut vg: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (t, &g) in before.iter().zip(before_groups) {
        for &v in t {
            vg[v as usize].push(g);
        }
    }
    after
        .iter()
        .map(|t| {
            if let Some(&g) = old.get(&key(t)) {
                return g;
            }
            let mut count: HashMap<u32, usize> = HashMap::new();
            for &v in t {
                for &g in &vg[v as usize] {
                    *count.entry(g).or_default() += 1;
                }
            }
            count.into_iter().max_by_key(|&(g, c)| (c, std::cmp::Reverse(g))).map_or(0, |x| x.0)
        })
        .collect()
}

/// The output's faces in group order (stable: an OBJ gets one `g` block per group, not one per
/// change), their groups and the group names: one group per region, or per region × template
/// group when `template_groups` (each face's group, and the template naming them) is given.
pub fn grouped_faces(
    tris: Vec<[u32; 3]>,
    region: &[u32],
    region_count: usize,
    template_groups: Option<(&[u32], &Mesh)>,
) -> (Vec<[u32; 3]>, Faces, Vec<String>) {
    let tg = |i: usize| template_groups.map_or(0, |(g, _)| g[i]);
    let mut order: Vec<usize> = (0..tris.len()).collect();
    order.sort_by_key(|&i| (region[i], tg(i)));
    let sorted: Vec<[u32; 3]> = order.iter().map(|&i| tris[i]).collect();
    let mut faces = Faces::with_capacity(sorted.len(), sorted.len() * 3);
    let Some((_, template)) = template_groups else {
        for (t, &i) in sorted.iter().zip(&order) {
            faces.push(t, region[i]);
        }
        return (sorted, faces, (0..region_count).map(|i| format!("region_{i}")).collect());
    };
    let mut names = Vec::new();
    let mut id: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for (t, &i) in sorted.iter().zip(&order) {
        let (r, g) = (region[i], tg(i));
        let gid = *id.entry((r, g)).or_insert_with(|| {
            names.push(format!("region_{r}/{}", template.group_name(g)));
            (names.len() - 1) as u32
        });
        faces.push(t, gid);
    }
    (sorted, faces, names)
}
