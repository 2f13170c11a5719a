//! STL reading (ascii and binary) and writing (binary).
//!
//! Binary is recognised by its exact size, 84 + 50·n bytes with n the header's triangle count, and
//! not by a "solid" prefix (binary headers often start with "solid" too). STL stores every
//! triangle's corners separately; reading welds exactly coincident positions (−0 = +0) so that
//! the mesh has connectivity, and says how many corners were merged.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

use rayon::prelude::*;

use super::lex::{self, Tokens};
use super::{Format, Loaded, ReadOptions};
use crate::error::{Error, Location, Result};
use crate::geometry;
use crate::hash::BitsHasher;
use crate::mesh::{Faces, Mesh};

/// True when the length is exactly that of a binary STL with the triangle count in its header.
pub(crate) fn is_binary_size(bytes: &[u8]) -> bool {
    binary_count(bytes).is_some_and(|n| 84 + 50 * n == bytes.len() as u64)
}

fn binary_count(bytes: &[u8]) -> Option<u64> {
    let c = bytes.get(80..84)?;
    Some(u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64)
}

/// True for text that starts with `solid` and has a `facet` or `endsolid` in its first kilobyte,
/// all of it printable ASCII (a binary header may start with "solid" too; its triangles will not be text).
pub(crate) fn looks_ascii(bytes: &[u8]) -> bool {
    let t = &bytes[bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len())..];
    let head = &t[..t.len().min(1024)];
    let head = head.to_ascii_lowercase(); // some exporters write `SOLID`, `FACET NORMAL`
    head.starts_with(b"solid")
        && head.iter().all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace())
        && (memchr::memmem::find(&head, b"facet").is_some()
            || memchr::memmem::find(&head, b"endsolid").is_some())
}

/// Decodes STL bytes.
pub fn read(bytes: &[u8], opts: &ReadOptions) -> Result<Loaded> {
    let ascii = if is_binary_size(bytes) { looks_ascii(bytes) } else { starts_with_solid(bytes) };
    let (soup, groups) =
        if ascii { read_ascii(bytes, opts)? } else { (read_binary(bytes, opts)?, Vec::new()) };
    Ok(weld(soup, groups))
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let t = lex::trim(&bytes[..bytes.len().min(64)]);
    t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"solid")
}

/// Triangles (or polygons, in ascii) with their own corners, before welding.
#[derive(Default)]
struct Soup {
    corners: Vec<[f64; 3]>,
    /// Every coordinate came from an f32 (binary STL): weld on the 12-byte f32 key.
    from_f32: bool,
    /// Corners per facet (3 for binary).
    arity: Vec<u32>,
    groups: Vec<u32>,
}

fn read_binary(bytes: &[u8], opts: &ReadOptions) -> Result<Soup> {
    let Some(n) = binary_count(bytes) else {
        return Err(Error::malformed(
            "stl",
            Location::Byte(bytes.len()),
            format!("{} bytes: too short for a binary STL header (84 bytes) and not ascii STL", bytes.len()),
        ));
    };
    if n > opts.max_faces as u64 {
        return Err(Error::TooLarge { what: "faces".into(), limit: opts.max_faces as u64, actual: n });
    }
    let need = 84 + 50 * n;
    if need != bytes.len() as u64 {
        return Err(Error::malformed(
            "stl",
            Location::Byte(80),
            format!("header declares {n} triangles = {need} bytes, the file has {} bytes", bytes.len()),
        ));
    }
    let n = n as usize; // the size check above bounds n by the file length
    let mut soup =
        Soup { corners: Vec::with_capacity(3 * n), from_f32: true, arity: vec![3; n], groups: vec![0; n] };
    for (t, rec) in bytes[84..].chunks_exact(50).enumerate() {
        for k in 0..3 {
            let at = 12 + 12 * k;
            let mut p = [0.0; 3];
            for (c, v) in p.iter_mut().enumerate() {
                let o = at + 4 * c;
                *v = f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64;
            }
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Error::InvalidMesh {
                    location: Location::Byte(84 + 50 * t + at),
                    message: format!("triangle {t}: coordinate is NaN or infinite"),
                });
            }
            soup.corners.push(p);
        }
    }
    Ok(soup)
}

fn ascii_err(line: usize, msg: impl Into<String>) -> Error {
    Error::malformed("stl", Location::Line(line), msg)
}

/// Ascii STL, line by line: `solid name`, then per facet `facet normal …`, `outer loop`, ≥ 3
/// `vertex x y z`, `endloop`, `endfacet`; `endsolid`. Several solids become named groups.
fn read_ascii(bytes: &[u8], opts: &ReadOptions) -> Result<(Soup, Vec<String>)> {
    let mut soup = Soup::default();
    let mut groups: Vec<String> = Vec::new();
    let mut in_facet = 0usize; // corners seen in the current facet, +1 once `facet` is open
    let mut in_solid = false;
    let mut last = 0;
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let n = i + 1;
        let mut t = Tokens::new(line);
        // Keywords are matched case-insensitively: some exporters write `FACET NORMAL`.
        let key = t.next().map(|k| k.to_ascii_lowercase());
        if key.is_some() {
            last = n; // the last line with content, where a truncated file "ends"
        }
        match key.as_deref() {
            None => {}
            Some(b"solid") if !in_solid => {
                in_solid = true;
                groups.push(String::from_utf8_lossy(t.rest()).into_owned());
            }
            Some(b"endsolid") if in_solid && in_facet == 0 => in_solid = false,
            Some(b"facet") if in_solid && in_facet == 0 => in_facet = 1,
            Some(b"outer" | b"endloop") if in_facet > 0 => {}
            Some(b"vertex") if in_facet > 0 => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let tok = t.next().ok_or_else(|| ascii_err(n, "`vertex` needs 3 numbers"))?;
                    *c = lex::parse_f64(tok).ok_or_else(|| {
                        ascii_err(n, format!("`{}` is not a number", String::from_utf8_lossy(tok)))
                    })?;
                }
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(Error::InvalidMesh {
                        location: Location::Line(n),
                        message: "coordinate is NaN or infinite".into(),
                    });
                }
                soup.corners.push(p);
                in_facet += 1;
            }
            Some(b"endfacet") if in_facet > 0 => {
                let k = in_facet - 1;
                if k < 3 {
                    return Err(ascii_err(n, format!("facet has {k} vertices, at least 3 are needed")));
                }
                soup.arity.push(k as u32);
                soup.groups.push(groups.len().saturating_sub(1) as u32);
                if soup.arity.len() > opts.max_faces {
                    let (limit, actual) = (opts.max_faces as u64, soup.arity.len() as u64);
                    return Err(Error::TooLarge { what: "faces".into(), limit, actual });
                }
                in_facet = 0;
            }
            Some(other) => {
                let s = String::from_utf8_lossy(other);
                return Err(ascii_err(n, format!("unexpected `{s}`")));
            }
        }
    }
    if in_facet > 0 || in_solid {
        return Err(ascii_err(last, "file ends inside a facet or solid (truncated?)"));
    }
    if soup.arity.is_empty() {
        return Err(ascii_err(last, "no facets"));
    }
    Ok((soup, groups))
}

/// Exact f32 coordinates as a weld key (-0 mapped to +0), hashed as two words.
#[derive(PartialEq, Eq)]
struct Key32([u32; 3]);

impl Hash for Key32 {
    fn hash<H: Hasher>(&self, h: &mut H) {
        h.write_u64(self.0[0] as u64 | (self.0[1] as u64) << 32);
        h.write_u64(self.0[2] as u64);
    }
}

/// Exact f64 coordinates as a weld key (-0 mapped to +0).
#[derive(PartialEq, Eq)]
struct Key64([u64; 3]);

impl Hash for Key64 {
    fn hash<H: Hasher>(&self, h: &mut H) {
        for v in self.0 {
            h.write_u64(v);
        }
    }
}

/// Merges exactly coincident corners into shared vertices (first occurrence order).
fn weld(soup: Soup, groups: Vec<String>) -> Loaded {
    let (positions, index) = if soup.from_f32 {
        weld_by(&soup.corners, |p| Key32(p.map(|c| (c as f32 + 0.0).to_bits())))
    } else {
        weld_by(&soup.corners, |p| Key64(p.map(|c| (c + 0.0).to_bits())))
    };
    let mut faces = Faces::with_capacity(soup.arity.len(), index.len());
    let mut start = 0;
    for (&k, &g) in soup.arity.iter().zip(&soup.groups) {
        faces.push(&index[start..start + k as usize], g);
        start += k as usize;
    }
    let warnings = vec![format!(
        "welded {} facet corners into {} vertices (exactly coincident positions)",
        soup.corners.len(),
        positions.len()
    )];
    let groups = if groups.len() > 1 { groups } else { Vec::new() };
    Loaded { mesh: Mesh { positions, faces, groups, ..Default::default() }, format: Format::Stl, warnings }
}

/// Corners per shard below which welding runs in one table on one thread.
const SHARDED_WELD_MIN: usize = 1 << 16;

fn hash_of<K: Hash>(k: &K) -> u64 {
    let mut h = BitsHasher::default();
    k.hash(&mut h);
    h.finish()
}

/// Positions in first-occurrence order and each corner's vertex id.
///
/// Large inputs are welded in 64 shards chosen by 6 middle bits of the key's hash (the table uses
/// the low bits for buckets and the top 7 for tags, so those stay varied within a shard). Each
/// shard, in parallel, maps every corner to the first corner with the same key; a final pass in
/// corner order numbers those first corners. Small per-shard tables also stay in cache, which
/// matters more than the second core.
fn weld_by<K: Hash + Eq + Send>(
    corners: &[[f64; 3]],
    key: impl Fn(&[f64; 3]) -> K + Sync,
) -> (Vec<[f64; 3]>, Vec<u32>) {
    let n = corners.len();
    let mut first: Vec<u32> = if n < SHARDED_WELD_MIN {
        first_corners(corners, (0..n as u32).collect::<Vec<_>>().as_slice(), &key)
    } else {
        sharded_first_corners(corners, &key)
    };
    // `first[c] <= c`, so numbering in corner order can overwrite `first` in place.
    let mut positions = Vec::with_capacity(n / 6 + 16);
    for c in 0..n {
        let r = first[c] as usize;
        first[c] = if r == c {
            positions.push(corners[c]);
            (positions.len() - 1) as u32
        } else {
            first[r]
        };
    }
    (positions, first)
}

/// For the corners `subset` (ascending), the first corner of `subset` with the same key, indexed
/// like `subset`.
fn first_corners<K: Hash + Eq>(
    corners: &[[f64; 3]],
    subset: &[u32],
    key: &impl Fn(&[f64; 3]) -> K,
) -> Vec<u32> {
    let mut map: HashMap<K, u32, BuildHasherDefault<BitsHasher>> = HashMap::default();
    map.reserve(subset.len() / 6 + 16);
    subset.iter().map(|&c| *map.entry(key(&corners[c as usize])).or_insert(c)).collect()
}

fn sharded_first_corners<K: Hash + Eq + Send>(
    corners: &[[f64; 3]],
    key: &(impl Fn(&[f64; 3]) -> K + Sync),
) -> Vec<u32> {
    const SHARDS: usize = 64;
    let shard: Vec<u8> =
        corners.par_iter().map(|p| ((hash_of(&key(p)) >> 32) as usize % SHARDS) as u8).collect();
    // Corners grouped by shard, ascending within each (a counting sort).
    let mut start = [0usize; SHARDS + 1];
    for &s in &shard {
        start[s as usize + 1] += 1;
    }
    for s in 0..SHARDS {
        start[s + 1] += start[s];
    }
    let mut order = vec![0u32; corners.len()];
    let mut fill = start;
    for (c, &s) in shard.iter().enumerate() {
        order[fill[s as usize]] = c as u32;
        fill[s as usize] += 1;
    }
    drop(shard);
    let per_shard: Vec<Vec<u32>> = (0..SHARDS)
        .into_par_iter()
        .map(|s| first_corners(corners, &order[start[s]..start[s + 1]], key))
        .collect();
    let mut first = vec![0u32; corners.len()];
    for (s, reps) in per_shard.iter().enumerate() {
        for (&c, &r) in order[start[s]..start[s + 1]].iter().zip(reps) {
            first[c as usize] = r;
        }
    }
    first
}

/// Encodes `mesh` as binary STL: polygons are fan-triangulated (STL holds only triangles),
/// coordinates become f32, normals are computed per triangle, groups and curves are not kept.
pub fn write(mesh: &Mesh) -> Result<Vec<u8>> {
    mesh.check()?;
    let ntri: usize = (0..mesh.faces.len()).map(|i| mesh.faces.arity(i).saturating_sub(2)).sum();
    let ntri32 = u32::try_from(ntri).map_err(|_| Error::TooLarge {
        what: "STL triangles".into(),
        limit: u32::MAX as u64,
        actual: ntri as u64,
    })?;
    let mut out = Vec::with_capacity(84 + 50 * ntri);
    // The header must not start with "solid" (some readers take that as ascii).
    let mut header = [b' '; 80];
    let text = b"binary STL written by meshwork; polygons fan-triangulated";
    header[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&header);
    out.extend_from_slice(&ntri32.to_le_bytes());
    for idx in mesh.faces.triangles() {
        // A coordinate beyond f32's range would be written as infinity, a file no reader accepts.
        for i in idx {
            if let Some(&c) = mesh.positions[i as usize].iter().find(|c| !(**c as f32).is_finite()) {
                return Err(Error::InvalidMesh {
                    location: Location::Vertex(i as usize),
                    message: format!(
                        "coordinate {c:e} is beyond binary STL's f32 range (±{:e}); write OBJ, PLY or OFF \
                         to keep it, or rescale the mesh",
                        f32::MAX
                    ),
                });
            }
        }
        let tri = idx.map(|i| mesh.positions[i as usize]);
        let n = geometry::normalize(geometry::triangle_cross(tri[0], tri[1], tri[2]));
        for v in std::iter::once(n).chain(tri) {
            for c in v {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sharded weld against a plain std HashMap weld, on enough corners to shard, with values
    /// whose low mantissa bits are zero and with -0.0 next to +0.0.
    #[test]
    fn sharded_weld_matches_a_plain_weld() {
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let distinct: Vec<[f64; 3]> = (0..30_000)
            .map(|i| [(i % 50) as f64 * 0.5, (i / 50 % 30) as f64 * 0.25, (i / 1500) as f64])
            .collect();
        let mut corners: Vec<[f64; 3]> = (0..200_000).map(|_| distinct[next() % distinct.len()]).collect();
        corners[7] = [-0.0, 0.0, 0.0];
        corners[8] = [0.0, -0.0, 0.0];
        assert!(corners.len() >= SHARDED_WELD_MIN);
        let (pos, idx) = weld_by(&corners, |p| Key64(p.map(|c| (c + 0.0).to_bits())));

        let mut map = std::collections::HashMap::new();
        let mut want_pos = Vec::new();
        let want_idx: Vec<u32> = corners
            .iter()
            .map(|p| {
                let k = p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
                *map.entry(k).or_insert_with(|| {
                    want_pos.push(*p);
                    want_pos.len() as u32 - 1
                })
            })
            .collect();
        assert_eq!(idx, want_idx);
        assert_eq!(pos, want_pos);
    }
}
