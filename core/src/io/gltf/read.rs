//! glTF document → one flattened [`Mesh`].
//!
//! Which nodes: the default `scene`'s; without one, every root node; without nodes, every mesh
//! untransformed. Each mesh instance is transformed by its node's world matrix (parents' matrices
//! composed down the hierarchy; a node reached twice — a cycle or a second parent — is an error).
//! Each triangle primitive (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) becomes a face group named
//! after its mesh (`name`, else the node's name, else `mesh{i}`; with several triangle
//! primitives, `/{p}` is appended). Primitives sharing the same attribute accessors under the
//! same transform share one vertex block, so vertex `i` of a file meshwork wrote stays vertex `i`.
//! LINES, LINE_STRIP and LINE_LOOP become curves; POINTS are skipped with a warning.
//! NORMAL and TEXCOORD_0 are kept only when every primitive read has them.

use std::collections::HashMap;

use serde_json::Value;

use super::accessor::{Header, Store};
use super::glb;
use super::json::{array, bad, index, index_value, invalid, join, object, string, uint, Obj};
use super::transform::{self, Mat4, IDENTITY};
use crate::error::{Error, Location, Result};
use crate::io::{Format, Loaded, ReadOptions};
use crate::mesh::{Faces, Mesh};

/// Extensions that change how geometry is stored; without them we would read garbage.
const UNSUPPORTED_REQUIRED: [&str; 3] =
    ["KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression"];

/// Decodes glTF 2.0 JSON (with `data:` buffers) or GLB bytes.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let (root, bin, format) = if bytes.starts_with(b"glTF") {
        let g = glb::parse(bytes)?;
        let root: Value = serde_json::from_slice(g.json).map_err(|e| {
            Error::malformed("GLB", Location::Byte(g.json_offset), format!("JSON chunk: {e}"))
        })?;
        (root, g.bin, Format::Glb)
    } else {
        let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        let root: Value = serde_json::from_slice(text)
            .map_err(|e| Error::malformed("glTF", Location::Line(e.line()), format!("JSON: {e}")))?;
        (root, None, Format::Gltf)
    };
    let root = object(&root, "(root)")?;
    check_asset(root)?;
    let mut reader = Reader::new(root, bin, opts)?;
    if array(root, "extensionsUsed", "")?.iter().any(|e| e.as_str() == Some("EXT_mesh_gpu_instancing")) {
        reader.warnings.push(
            "EXT_mesh_gpu_instancing: instances are not expanded, each mesh is read once per node".into(),
        );
    }
    let instances = reader.instances()?;
    let mesh = reader.flatten(&instances)?;
    Ok(Loaded { mesh, format, warnings: reader.warnings })
}

fn check_asset(root: &Obj) -> Result<()> {
    let asset = object(root.get("asset").ok_or_else(|| bad("asset", "is required"))?, "asset")?;
    let version = string(asset, "version", "asset")?.ok_or_else(|| bad("asset.version", "is required"))?;
    if version.split('.').next() != Some("2") {
        return Err(Error::UnsupportedFormat(format!("glTF version {version}; only glTF 2.x is read")));
    }
    for (i, e) in array(root, "extensionsRequired", "")?.iter().enumerate() {
        if let Some(name) = e.as_str().filter(|n| UNSUPPORTED_REQUIRED.contains(n)) {
            return Err(Error::UnsupportedFormat(format!(
                "extensionsRequired[{i}]: {name} (compressed geometry) is not supported"
            )));
        }
    }
    Ok(())
}

/// A mesh placed in the world by a node (or untransformed when the file has no nodes).
struct Instance {
    mesh: usize,
    world: Mat4,
    /// The node's name, used when the mesh has none.
    node_name: Option<String>,
}

/// A primitive's primitive-level facts, gathered before decoding anything.
struct Prim<'a> {
    path: String,
    obj: &'a Obj,
    mode: u64,
    position: usize,
    normal: Option<usize>,
    texcoord: Option<usize>,
}

/// Identifies a vertex block: world matrix (bit pattern), POSITION, NORMAL, TEXCOORD_0 accessors.
type BlockKey = ([u64; 16], usize, Option<usize>, Option<usize>);

/// Where a decoded vertex block sits in the output.
#[derive(Clone, Copy)]
struct Block {
    base: u32,
    count: usize,
}

struct Reader<'a> {
    root: &'a Obj,
    store: Store<'a>,
    nodes: &'a [Value],
    meshes: &'a [Value],
    opts: &'a ReadOptions,
    warnings: Vec<String>,
}

impl<'a> Reader<'a> {
    fn new(root: &'a Obj, bin: Option<&'a [u8]>, opts: &'a ReadOptions) -> Result<Reader<'a>> {
        Ok(Reader {
            root,
            store: Store::new(root, bin)?,
            nodes: array(root, "nodes", "")?,
            meshes: array(root, "meshes", "")?,
            opts,
            warnings: Vec::new(),
        })
    }

    fn max_vertices(&self) -> usize {
        self.opts.max_vertices.min(u32::MAX as usize)
    }

    /// The root nodes to read: the default scene's, else every node nobody lists as a child.
    fn roots(&mut self) -> Result<Vec<(usize, String)>> {
        let scenes = array(self.root, "scenes", "")?;
        if let Some(s) = index(self.root, "scene", "", scenes.len(), "scene")? {
            let path = format!("scenes[{s}]");
            let scene = object(&scenes[s], &path)?;
            return array(scene, "nodes", &path)?
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let p = format!("{path}.nodes[{k}]");
                    Ok((index_value(v, &p, self.nodes.len(), "node")?, p))
                })
                .collect();
        }
        let mut is_child = vec![false; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            let path = format!("nodes[{i}]");
            for (k, c) in array(object(n, &path)?, "children", &path)?.iter().enumerate() {
                is_child[index_value(c, &format!("{path}.children[{k}]"), self.nodes.len(), "node")?] = true;
            }
        }
        Ok((0..self.nodes.len()).filter(|&i| !is_child[i]).map(|i| (i, format!("nodes[{i}]"))).collect())
    }

    /// Every mesh instance with its world transform, in depth-first order.
    fn instances(&mut self) -> Result<Vec<Instance>> {
        if self.nodes.is_empty() {
            if !self.meshes.is_empty() {
                self.warnings.push("the file has no nodes: every mesh is read untransformed".into());
            }
            return Ok((0..self.meshes.len())
                .map(|m| Instance { mesh: m, world: IDENTITY, node_name: None })
                .collect());
        }
        let mut visited = vec![false; self.nodes.len()];
        let mut out = Vec::new();
        // Explicit stack: a deep hierarchy in a hostile file must not overflow the call stack.
        let mut stack: Vec<(usize, Mat4, String)> = Vec::new();
        for (r, p) in self.roots()?.into_iter().rev() {
            stack.push((r, IDENTITY, p));
        }
        while let Some((n, parent, via)) = stack.pop() {
            let path = format!("nodes[{n}]");
            if std::mem::replace(&mut visited[n], true) {
                return Err(bad(
                    via,
                    format!("{path} is reached twice (a cycle, or a node with two parents)"),
                ));
            }
            let node = object(&self.nodes[n], &path)?;
            let world = transform::mul(&parent, &transform::local(node, &path)?);
            if let Some(m) = index(node, "mesh", &path, self.meshes.len(), "mesh")? {
                let node_name = string(node, "name", &path)?.map(str::to_owned);
                out.push(Instance { mesh: m, world, node_name });
            }
            let children = array(node, "children", &path)?;
            for (k, c) in children.iter().enumerate().rev() {
                let p = format!("{path}.children[{k}]");
                stack.push((index_value(c, &p, self.nodes.len(), "node")?, world, p));
            }
        }
        let mut used = vec![false; self.meshes.len()];
        out.iter().for_each(|i| used[i.mesh] = true);
        let unused: Vec<String> =
            (0..self.meshes.len()).filter(|&m| !used[m]).map(|m| format!("meshes[{m}]")).collect();
        if !unused.is_empty() {
            self.warnings.push(format!("not in the scene, not read: {}", unused.join(", ")));
        }
        Ok(out)
    }

    /// The primitives of `meshes[m]` that carry geometry we read (POINTS and position-less
    /// primitives are reported and left out).
    fn primitives(&mut self, m: usize) -> Result<Vec<Prim<'a>>> {
        let mpath = format!("meshes[{m}]");
        let mesh = object(&self.meshes[m], &mpath)?;
        let prims = array(mesh, "primitives", &mpath)?;
        if prims.is_empty() {
            return Err(bad(join(&mpath, "primitives"), "a mesh needs at least one primitive"));
        }
        let mut out = Vec::new();
        for (p, v) in prims.iter().enumerate() {
            let path = format!("{mpath}.primitives[{p}]");
            let obj = object(v, &path)?;
            let mode = uint(obj, "mode", &path)?.unwrap_or(4);
            if mode > 6 {
                return Err(bad(join(&path, "mode"), format!("{mode} is not a primitive mode (0..=6)")));
            }
            if mode == 0 {
                self.warnings.push(format!("{path}: POINTS primitive skipped"));
                continue;
            }
            let apath = join(&path, "attributes");
            let attrs = object(obj.get("attributes").unwrap_or(&Value::Null), &apath)?;
            let n = self.store.accessor_count();
            let Some(position) = index(attrs, "POSITION", &apath, n, "accessor")? else {
                self.warnings.push(format!("{path}: no POSITION attribute, skipped"));
                continue;
            };
            let normal = index(attrs, "NORMAL", &apath, n, "accessor")?;
            let texcoord = index(attrs, "TEXCOORD_0", &apath, n, "accessor")?;
            out.push(Prim { path, obj, mode, position, normal, texcoord });
        }
        Ok(out)
    }

    fn flatten(&mut self, instances: &[Instance]) -> Result<Mesh> {
        // Pass 1 (JSON only): which primitives, and do they all have normals / texcoords?
        let mut per_mesh: HashMap<usize, Vec<Prim<'a>>> = HashMap::new();
        for inst in instances {
            if let std::collections::hash_map::Entry::Vacant(e) = per_mesh.entry(inst.mesh) {
                e.insert(self.primitives(inst.mesh)?);
            }
        }
        let all_prims = || instances.iter().flat_map(|i| per_mesh[&i.mesh].iter());
        let missing = |f: fn(&Prim) -> bool| all_prims().find(|p| !f(p)).map(|p| p.path.clone());
        let keep_normals = match missing(|p| p.normal.is_some()) {
            None => true,
            Some(p) => {
                if all_prims().any(|p| p.normal.is_some()) {
                    self.warnings.push(format!("NORMAL dropped: {p} has none"));
                }
                false
            }
        };
        let keep_uvs = match missing(|p| p.texcoord.is_some()) {
            None => true,
            Some(p) => {
                if all_prims().any(|p| p.texcoord.is_some()) {
                    self.warnings.push(format!("TEXCOORD_0 dropped: {p} has none"));
                }
                false
            }
        };

        // Sizes up front, so the big arrays are allocated once instead of doubling (a 2M-vertex
        // file spent a third of its read time in page faults). Vertex blocks are counted once
        // per distinct block, exactly as pass 2 will create them; both totals are capped by the
        // limits, and every count was checked against the buffer it lives in.
        let (vertices, triangles) = self.sizes(instances, &per_mesh, keep_normals, keep_uvs)?;
        let vertices = vertices.min(self.max_vertices());
        let triangles = triangles.min(self.opts.max_faces);

        // Pass 2: decode and merge.
        let mut out = Out::new(keep_normals, keep_uvs, vertices, triangles);
        let mut blocks: HashMap<BlockKey, Block> = HashMap::new();
        for inst in instances {
            let prims = &per_mesh[&inst.mesh];
            let mesh_name = self.mesh_name(inst)?;
            let triangle_prims = prims.iter().filter(|p| p.mode >= 4).count();
            let flip = transform::det3(&inst.world) < 0.0;
            for (k, prim) in prims.iter().enumerate() {
                let normal = prim.normal.filter(|_| keep_normals);
                let texcoord = prim.texcoord.filter(|_| keep_uvs);
                let key = (inst.world.map(f64::to_bits), prim.position, normal, texcoord);
                let block = match blocks.get(&key) {
                    Some(&b) => b,
                    None => {
                        let b = self.decode_vertices(&mut out, prim, &inst.world, normal, texcoord)?;
                        blocks.insert(key, b);
                        b
                    }
                };
                let indices = self.indices(prim, block)?;
                if prim.mode >= 4 {
                    let (name, synthesized) = match &mesh_name {
                        (n, s) if triangle_prims == 1 => (n.clone(), *s),
                        (n, s) => (format!("{n}/{}", primitive_number(&prim.path, k)), *s),
                    };
                    let group = out.group(name, synthesized);
                    self.triangles(&mut out, prim, &indices, block.base, group, flip)?;
                } else {
                    self.lines(&mut out, prim, &indices, block.base)?;
                }
            }
        }
        if out.degenerate > 0 {
            self.warnings.push(format!("{} degenerate triangles of strips/fans skipped", out.degenerate));
        }
        let mesh = out.finish();
        mesh.check()?;
        Ok(mesh)
    }

    /// Total vertices (distinct blocks) and the triangles of TRIANGLES primitives.
    fn sizes(
        &self,
        instances: &[Instance],
        per_mesh: &HashMap<usize, Vec<Prim<'a>>>,
        keep_normals: bool,
        keep_uvs: bool,
    ) -> Result<(usize, usize)> {
        let mut seen = std::collections::HashSet::new();
        let (mut vertices, mut triangles) = (0usize, 0usize);
        for inst in instances {
            for prim in &per_mesh[&inst.mesh] {
                let key = (
                    inst.world.map(f64::to_bits),
                    prim.position,
                    prim.normal.filter(|_| keep_normals),
                    prim.texcoord.filter(|_| keep_uvs),
                );
                let count = self.store.header(prim.position)?.count;
                if seen.insert(key) {
                    vertices = vertices.saturating_add(count);
                }
                // TRIANGLES only: a strip of degenerate (restart) triangles would otherwise
                // reserve 20 bytes of faces per byte of u8 indices.
                if prim.mode == 4 {
                    let n = match index(
                        prim.obj,
                        "indices",
                        &prim.path,
                        self.store.accessor_count(),
                        "accessor",
                    )? {
                        Some(i) => self.store.header(i)?.count,
                        None => count,
                    };
                    triangles = triangles.saturating_add(n / 3);
                }
            }
        }
        Ok((vertices, triangles))
    }

    /// The group name base for an instance, and whether we made it up.
    fn mesh_name(&self, inst: &Instance) -> Result<(String, bool)> {
        let path = format!("meshes[{}]", inst.mesh);
        let mesh = object(&self.meshes[inst.mesh], &path)?;
        Ok(match (string(mesh, "name", &path)?, &inst.node_name) {
            (Some(n), _) => (n.to_owned(), false),
            (None, Some(n)) => (n.clone(), false),
            (None, None) => (format!("mesh{}", inst.mesh), true),
        })
    }

    fn attribute(&self, i: usize, path: &str, types: &[&str]) -> Result<Header> {
        let h = self.store.header(i)?;
        if !types.contains(&h.type_name.as_str()) {
            return Err(bad(
                path,
                format!("accessors[{i}] is {}, expected {}", h.type_name, types.join(" or ")),
            ));
        }
        Ok(h)
    }

    /// Decodes a primitive's vertex attributes, transformed, onto the end of `out`.
    fn decode_vertices(
        &self,
        out: &mut Out,
        prim: &Prim,
        world: &Mat4,
        normal: Option<usize>,
        texcoord: Option<usize>,
    ) -> Result<Block> {
        let apath = join(&prim.path, "attributes");
        let ppath = join(&apath, "POSITION");
        let ph = self.attribute(prim.position, &ppath, &["VEC3"])?;
        let count = ph.count;
        let total = out.positions.len().checked_add(count).filter(|&t| t <= self.max_vertices());
        if total.is_none() {
            return Err(Error::TooLarge {
                what: "vertices".into(),
                limit: self.max_vertices() as u64,
                actual: (out.positions.len() as u64).saturating_add(count as u64),
            });
        }
        let base = out.positions.len() as u32;
        let raw = self.store.floats(&ph, self.max_vertices())?;
        check_finite(&raw, 3, &ph.path(), &ppath)?;
        for (e, p) in raw.chunks_exact(3).enumerate() {
            let q = transform::apply_point(world, [p[0], p[1], p[2]]);
            if !q.iter().all(|c| c.is_finite()) {
                return Err(invalid(
                    &prim.path,
                    format!("vertex {e} becomes infinite under its node transform"),
                ));
            }
            out.positions.push(q);
        }
        if let Some(i) = normal {
            let npath = join(&apath, "NORMAL");
            let h = self.same_count(self.attribute(i, &npath, &["VEC3"])?, count, &npath)?;
            let raw = self.store.floats(&h, self.max_vertices())?;
            check_finite(&raw, 3, &h.path(), &npath)?;
            let nm = transform::normal_matrix(world);
            if let Some(normals) = out.normals.as_mut() {
                normals.extend(raw.chunks_exact(3).map(|n| transform::apply_normal(&nm, [n[0], n[1], n[2]])));
            }
        }
        if let Some(i) = texcoord {
            let tpath = join(&apath, "TEXCOORD_0");
            let h = self.same_count(self.attribute(i, &tpath, &["VEC2"])?, count, &tpath)?;
            let raw = self.store.floats(&h, self.max_vertices())?;
            check_finite(&raw, 2, &h.path(), &tpath)?;
            if let Some(uvs) = out.uvs.as_mut() {
                // glTF's texture origin is top-left; meshwork keeps OBJ's bottom-left.
                uvs.extend(raw.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]));
            }
        }
        Ok(Block { base, count })
    }

    fn same_count(&self, h: Header, count: usize, path: &str) -> Result<Header> {
        if h.count != count {
            return Err(bad(path, format!("{} has {} elements but POSITION has {count}", h.path(), h.count)));
        }
        Ok(h)
    }

    /// The primitive's vertex indices (local to its block), each checked against the block.
    fn indices(&self, prim: &Prim, block: Block) -> Result<Vec<u32>> {
        let ipath = join(&prim.path, "indices");
        let Some(i) = index(prim.obj, "indices", &prim.path, self.store.accessor_count(), "accessor")? else {
            return Ok((0..block.count as u32).collect());
        };
        let h = self.store.header(i)?;
        if h.type_name != "SCALAR" || !h.component.is_index_type() || h.normalized {
            return Err(bad(
                &ipath,
                format!(
                    "accessors[{i}] is {} {}{}; indices must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT",
                    h.type_name,
                    h.component.name(),
                    if h.normalized { " normalized" } else { "" }
                ),
            ));
        }
        let limit = self.opts.max_faces.saturating_mul(3);
        let indices = self.store.indices(&h, limit)?;
        if let Some((k, &v)) = indices.iter().enumerate().find(|(_, &v)| v as usize >= block.count) {
            return Err(invalid(
                ipath,
                format!("index {k} (accessors[{i}]) is {v}, but the primitive has {} vertices", block.count),
            ));
        }
        Ok(indices)
    }

    fn triangles(
        &mut self,
        out: &mut Out,
        prim: &Prim,
        idx: &[u32],
        base: u32,
        group: u32,
        flip: bool,
    ) -> Result<()> {
        let n = idx.len();
        let tri = |k: usize| -> [u32; 3] {
            match prim.mode {
                4 => [idx[3 * k], idx[3 * k + 1], idx[3 * k + 2]],
                // Strips alternate winding: odd triangles swap their last two vertices (spec 3.7.2.1).
                5 if k.is_multiple_of(2) => [idx[k], idx[k + 1], idx[k + 2]],
                5 => [idx[k], idx[k + 2], idx[k + 1]],
                _ => [idx[k + 1], idx[k + 2], idx[0]],
            }
        };
        let count = match prim.mode {
            4 => {
                if !n.is_multiple_of(3) {
                    self.warnings.push(format!(
                        "{}: {} trailing indices (not a whole triangle) ignored",
                        prim.path,
                        n % 3
                    ));
                }
                n / 3
            }
            _ => n.saturating_sub(2),
        };
        if out.faces.len() + count > self.opts.max_faces {
            return Err(Error::TooLarge {
                what: "faces".into(),
                limit: self.opts.max_faces as u64,
                actual: (out.faces.len() + count) as u64,
            });
        }
        for k in 0..count {
            let [a, mut b, mut c] = tri(k);
            if prim.mode != 4 && (a == b || b == c || a == c) {
                out.degenerate += 1;
                continue;
            }
            if flip {
                std::mem::swap(&mut b, &mut c);
            }
            out.faces.push(&[a + base, b + base, c + base], group);
        }
        Ok(())
    }

    fn lines(&mut self, out: &mut Out, prim: &Prim, idx: &[u32], base: u32) -> Result<()> {
        // Many primitives may reuse one big index accessor: bound the total like faces' indices.
        let limit = self.opts.max_faces.saturating_mul(3);
        out.curve_indices = out.curve_indices.saturating_add(idx.len() + 1);
        if out.curve_indices > limit {
            return Err(Error::TooLarge {
                what: "curve vertices".into(),
                limit: limit as u64,
                actual: out.curve_indices as u64,
            });
        }
        let shifted = idx.iter().map(|&i| i + base);
        match prim.mode {
            1 => {
                if !idx.len().is_multiple_of(2) {
                    self.warnings.push(format!("{}: odd index count, last LINES index ignored", prim.path));
                }
                // Consecutive segments that share an end point are joined into one polyline.
                let mut cur: Vec<u32> = Vec::new();
                for seg in idx.chunks_exact(2) {
                    let (a, b) = (seg[0] + base, seg[1] + base);
                    if cur.last() != Some(&a) {
                        if cur.len() >= 2 {
                            out.curves.push(std::mem::take(&mut cur));
                        }
                        cur = vec![a];
                    }
                    cur.push(b);
                }
                if cur.len() >= 2 {
                    out.curves.push(cur);
                }
            }
            2 | 3 if idx.len() >= 2 => {
                let mut c: Vec<u32> = shifted.collect();
                if prim.mode == 2 {
                    c.push(c[0]);
                }
                out.curves.push(c);
            }
            _ => self
                .warnings
                .push(format!("{}: a line strip/loop needs 2 or more vertices, skipped", prim.path)),
        }
        Ok(())
    }
}

/// The primitive's index in its mesh, from its path (`…primitives[3]` → 3).
fn primitive_number(path: &str, fallback: usize) -> usize {
    path.rsplit('[').next().and_then(|s| s.trim_end_matches(']').parse().ok()).unwrap_or(fallback)
}

fn check_finite(values: &[f64], width: usize, accessor: &str, used_as: &str) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => {
            Err(invalid(accessor, format!("element {} (used as {used_as}) is NaN or infinite", i / width)))
        }
    }
}

/// The mesh under construction.
struct Out {
    positions: Vec<[f64; 3]>,
    normals: Option<Vec<[f64; 3]>>,
    uvs: Option<Vec<[f64; 2]>>,
    faces: Faces,
    curves: Vec<Vec<u32>>,
    names: Vec<String>,
    synthesized: Vec<bool>,
    by_name: HashMap<String, u32>,
    degenerate: usize,
    /// Vertex references in all curves so far (bounded by the face-index limit).
    curve_indices: usize,
}

impl Out {
    fn new(normals: bool, uvs: bool, vertices: usize, triangles: usize) -> Out {
        Out {
            positions: Vec::with_capacity(vertices),
            normals: normals.then(|| Vec::with_capacity(vertices)),
            uvs: uvs.then(|| Vec::with_capacity(vertices)),
            faces: Faces::with_capacity(triangles, triangles * 3),
            curves: Vec::new(),
            names: Vec::new(),
            synthesized: Vec::new(),
            by_name: HashMap::new(),
            degenerate: 0,
            curve_indices: 0,
        }
    }

    /// Group id for `name`; primitives with the same name share a group.
    fn group(&mut self, name: String, synthesized: bool) -> u32 {
        if let Some(&g) = self.by_name.get(&name) {
            return g;
        }
        let g = self.names.len() as u32;
        self.by_name.insert(name.clone(), g);
        self.names.push(name);
        self.synthesized.push(synthesized);
        g
    }

    fn finish(self) -> Mesh {
        // One group whose name we invented carries no information: leave the mesh unnamed, so
        // an unnamed mesh survives a round trip unchanged.
        let groups = if self.names.len() == 1 && self.synthesized[0] { Vec::new() } else { self.names };
        Mesh {
            normals: self.normals.filter(|_| !self.positions.is_empty()),
            uvs: self.uvs.filter(|_| !self.positions.is_empty()),
            positions: self.positions,
            faces: self.faces,
            groups,
            curves: self.curves,
        }
    }
}
