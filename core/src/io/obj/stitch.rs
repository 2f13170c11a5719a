//! Stitching parsed chunks together in file order into one [`Loaded`] mesh.
//!
//! Everything that depends on earlier chunks is resolved here: relative indices (fixups), the
//! current group, line numbers of errors, the size limits, and the final range check of every
//! index against the whole file. Per-corner `vt`/`vn` become per-vertex attributes at the end
//! ([`per_vertex`]), or are dropped with a warning when corners disagree.

use rayon::prelude::*;
use std::collections::HashMap;

use super::chunk::{line_of_statement, Chunk, Slot};
use super::{invalid, malformed, NONE};
use crate::error::{Error, Result};
use crate::io::{Format, Loaded, ReadOptions};
use crate::mesh::{Faces, Mesh};

/// The file so far: everything from the chunks added, in file order.
pub(super) struct Stitcher<'a> {
    opts: &'a ReadOptions,
    /// Lines in the chunks added so far (to turn chunk-local line numbers into the file's).
    pub(super) line_offset: usize,
    positions: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    faces: Faces,
    corner_uv: Option<Vec<u32>>,
    corner_normal: Option<Vec<u32>>,
    curves: Vec<Vec<u32>>,
    group_ids: HashMap<String, u32>,
    group_names: Vec<String>,
    /// Name of the group faces go to now (None before the first `g`/`o`).
    current_group: Option<String>,
    ignored: Vec<(String, usize)>,
    vertex_extras: usize,
}

impl<'a> Stitcher<'a> {
    pub(super) fn new(opts: &'a ReadOptions, chunks: &[Result<Chunk>]) -> Self {
        let ok = || chunks.iter().filter_map(|c| c.as_ref().ok());
        let nv: usize = ok().map(|c| c.positions.len()).sum();
        let nf: usize = ok().map(|c| c.face_ends.len()).sum();
        let ni: usize = ok().map(|c| c.corners.len()).sum();
        Stitcher {
            opts,
            line_offset: 0,
            positions: Vec::with_capacity(nv),
            uvs: Vec::new(),
            normals: Vec::new(),
            faces: Faces::with_capacity(nf, ni),
            corner_uv: None,
            corner_normal: None,
            curves: Vec::new(),
            group_ids: HashMap::new(),
            group_names: Vec::new(),
            current_group: None,
            ignored: Vec::new(),
            vertex_extras: 0,
        }
    }

    pub(super) fn add(&mut self, mut c: Chunk) -> Result<()> {
        self.apply_fixups(&mut c)?;
        self.check_limits(&c)?;
        let corner_base = self.faces.indices().len();
        self.append_faces(&c);
        append_attr(&mut self.corner_uv, c.corner_uv.take(), corner_base, c.corners.len());
        append_attr(&mut self.corner_normal, c.corner_normal.take(), corner_base, c.corners.len());
        self.positions.extend_from_slice(&c.positions);
        self.uvs.extend_from_slice(&c.uvs);
        self.normals.extend_from_slice(&c.normals);
        self.curves.append(&mut c.curves);
        for (k, n) in c.ignored {
            match self.ignored.iter_mut().find(|(kk, _)| *kk == k) {
                Some((_, m)) => *m += n,
                None => self.ignored.push((k, n)),
            }
        }
        self.vertex_extras += c.vertex_extras;
        self.line_offset += c.lines;
        Ok(())
    }

    /// Turns the chunk's relative indices into absolute ones now that the counts before it are known.
    fn apply_fixups(&self, c: &mut Chunk) -> Result<()> {
        for f in &c.fixups {
            let (base, what) = match f.slot {
                Slot::Vertex | Slot::Curve(_) => (self.positions.len(), "vertex"),
                Slot::Uv => (self.uvs.len(), "texture coordinate"),
                Slot::Normal => (self.normals.len(), "normal"),
            };
            let abs = base as i64 + f.rel;
            let line = self.line_offset + f.line;
            let abs = u32::try_from(abs).map_err(|_| {
                invalid(line, format!("relative {what} index points before the first {what}"))
            })?;
            match f.slot {
                Slot::Vertex => c.corners[f.pos] = abs,
                Slot::Uv => set_attr(&mut c.corner_uv, f.pos, abs),
                Slot::Normal => set_attr(&mut c.corner_normal, f.pos, abs),
                Slot::Curve(ci) => c.curves[ci as usize][f.pos] = abs,
            }
        }
        Ok(())
    }

    fn check_limits(&self, c: &Chunk) -> Result<()> {
        let nv = (self.positions.len() + c.positions.len()) as u64;
        if nv > self.opts.max_vertices as u64 {
            return Err(too_large("vertices", self.opts.max_vertices, nv));
        }
        let nf = (self.faces.len() + c.face_ends.len()) as u64;
        if nf > self.opts.max_faces as u64 {
            return Err(too_large("faces", self.opts.max_faces, nf));
        }
        let ni = (self.faces.indices().len() + c.corners.len()) as u64;
        if ni >= u32::MAX as u64 {
            return Err(too_large("face corners", u32::MAX as usize - 1, ni));
        }
        Ok(())
    }

    fn append_faces(&mut self, c: &Chunk) {
        let mut runs = c.group_runs.iter().peekable();
        let mut group = None;
        let mut start = 0usize;
        for (fi, &end) in c.face_ends.iter().enumerate() {
            while let Some((_, name)) = runs.next_if(|(first, _)| *first <= fi) {
                self.current_group = Some(name.clone());
                group = None;
            }
            let g = match group {
                Some(g) => g,
                None => *group.insert(self.group_id_now()),
            };
            self.faces.push(&c.corners[start..end as usize], g);
            start = end as usize;
        }
        if let Some((_, name)) = runs.last() {
            self.current_group = Some(name.clone());
        }
    }

    /// The id of the current group, registering its name on first use (so groups that never
    /// receive a face do not appear).
    fn group_id_now(&mut self) -> u32 {
        let name = self.current_group.clone().unwrap_or_default();
        if let Some(&id) = self.group_ids.get(&name) {
            return id;
        }
        let id = self.group_names.len() as u32;
        self.group_ids.insert(name.clone(), id);
        self.group_names.push(name);
        id
    }

    /// Checks indices against the whole file (they may point forward), then builds the mesh.
    pub(super) fn finish(self, bytes: &[u8]) -> Result<Loaded> {
        if self.positions.is_empty() {
            return Err(malformed(
                self.line_offset.max(1),
                "no `v` statements: the file defines no vertices",
            ));
        }
        self.check_ranges(bytes)?;
        let Stitcher { faces, positions, uvs, normals, curves, mut group_names, .. } = self;
        let mut warnings = Vec::new();
        let uvs = per_vertex(&faces, self.corner_uv.as_deref(), &uvs, positions.len(), "vt", &mut warnings);
        let normals =
            per_vertex(&faces, self.corner_normal.as_deref(), &normals, positions.len(), "vn", &mut warnings);
        // Group names only appear when some face was given one: a file without g/o keeps "one
        // unnamed group"; faces before the first g/o are in the group named "".
        if group_names.len() == 1 && group_names[0].is_empty() || faces.is_empty() {
            group_names.clear();
        }
        let degenerate =
            (0..faces.len()).into_par_iter().filter(|&i| distinct_count(faces.get(i)) < 3).count();
        if degenerate > 0 {
            warnings.push(format!(
                "{degenerate} faces repeat a vertex (fewer than 3 distinct); kept for validate/repair"
            ));
        }
        for (k, n) in &self.ignored {
            warnings.push(format!("ignored {n} `{k}` statements"));
        }
        if self.vertex_extras > 0 {
            warnings
                .push(format!("ignored extra values (vertex colours) on {} `v` lines", self.vertex_extras));
        }
        let mesh = Mesh { positions, faces, normals, uvs, groups: group_names, curves };
        Ok(Loaded { mesh, format: Format::Obj, warnings })
    }
}

impl Stitcher<'_> {
    /// Every index must name an element the file defines. An out-of-range index is reported at
    /// the line of its statement (found by counting `f`/`l` statements: only on this error path).
    fn check_ranges(&self, bytes: &[u8]) -> Result<()> {
        let checks: [(&[u32], usize, &str); 3] = [
            (self.faces.indices(), self.positions.len(), "vertex"),
            (self.corner_uv.as_deref().unwrap_or(&[]), self.uvs.len(), "texture coordinate"),
            (self.corner_normal.as_deref().unwrap_or(&[]), self.normals.len(), "normal"),
        ];
        for (idx, n, what) in checks {
            if let Some(k) = idx.iter().position(|&i| i != NONE && i as usize >= n) {
                let face = self.faces.offsets().partition_point(|&o| o as usize <= k) - 1;
                let line = line_of_statement(bytes, b"f", face);
                let i = idx[k] as u64 + 1;
                return Err(invalid(line, format!("{what} index {i} out of range (the file defines {n})")));
            }
        }
        let nv = self.positions.len();
        for (ci, c) in self.curves.iter().enumerate() {
            if let Some(&i) = c.iter().find(|&&i| i as usize >= nv) {
                let line = line_of_statement(bytes, b"l", ci);
                let i = i as u64 + 1;
                return Err(invalid(line, format!("vertex index {i} out of range (the file defines {nv})")));
            }
        }
        Ok(())
    }
}

fn too_large(what: &str, limit: usize, actual: u64) -> Error {
    Error::TooLarge { what: what.into(), limit: limit as u64, actual }
}

fn set_attr(arr: &mut Option<Vec<u32>>, pos: usize, v: u32) {
    if let Some(a) = arr.as_mut() {
        a[pos] = v;
    }
}

/// Appends a chunk's per-corner attribute array to the file's, filling NONE where one side has none.
fn append_attr(dst: &mut Option<Vec<u32>>, src: Option<Vec<u32>>, base: usize, len: usize) {
    match (dst.as_mut(), src) {
        (Some(d), Some(s)) => d.extend_from_slice(&s),
        (Some(d), None) => d.resize(base + len, NONE),
        (None, Some(s)) => {
            let mut d = vec![NONE; base];
            d.extend_from_slice(&s);
            *dst = Some(d);
        }
        (None, None) => {}
    }
}

fn distinct_count(f: &[u32]) -> usize {
    if f.len() <= 8 {
        (0..f.len()).filter(|&i| !f[..i].contains(&f[i])).count()
    } else {
        let mut s = f.to_vec();
        s.sort_unstable();
        s.dedup();
        s.len()
    }
}

/// A per-vertex attribute from per-corner indices, or None (with a warning) when corners disagree.
fn per_vertex<const N: usize>(
    faces: &Faces,
    corner: Option<&[u32]>,
    values: &[[f64; N]],
    nv: usize,
    key: &str,
    warnings: &mut Vec<String>,
) -> Option<Vec<[f64; N]>> {
    let Some(corner) = corner else {
        if !values.is_empty() {
            warnings.push(format!("{} `{key}` lines are not used by any face; ignored", values.len()));
        }
        return None;
    };
    let mut slot = vec![NONE; nv];
    let (mut missing, mut conflicts) = (0usize, 0usize);
    for (&v, &a) in faces.indices().iter().zip(corner) {
        if a == NONE {
            missing += 1;
            continue;
        }
        let s = &mut slot[v as usize];
        if *s == NONE {
            *s = a;
        } else if *s != a && values[*s as usize] != values[a as usize] {
            conflicts += 1;
        }
    }
    if conflicts > 0 {
        warnings.push(format!(
            "`{key}` dropped: {conflicts} face corners give a vertex a different `{key}` than another corner \
             (seams/creases); vertices are not split so that indices stay the file's"
        ));
        return None;
    }
    if missing > 0 {
        warnings.push(format!("`{key}` dropped: {missing} face corners have none while others do"));
        return None;
    }
    Some(slot.iter().map(|&s| if s == NONE { [0.0; N] } else { values[s as usize] }).collect())
}
