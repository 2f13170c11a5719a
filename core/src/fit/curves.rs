//! The curve network: polylines from the curves input, welded into one graph.
//!
//! Polylines may be given as one long strip or as many two-point lines; endpoints that coincide
//! (within `join_tolerance` × the curves' bounding-box diagonal) become one vertex, so crossing
//! curves that share a point form a network. A *feature point* (§2.1) is a vertex where more than
//! two segments meet: it wins correspondence conflicts.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::geometry::{dist, Aabb};
use crate::mesh::{Mesh, Point3};

#[derive(Debug, Clone)]
pub struct CurveNetwork {
    /// Welded curve vertices.
    pub points: Vec<Point3>,
    /// Unique undirected segments (point indices, smaller first).
    pub segments: Vec<[u32; 2]>,
    /// The input polylines as welded point indices (consecutive repeats removed); their order is
    /// kept so the output can carry the same curves.
    pub polylines: Vec<Vec<u32>>,
    /// Number of distinct segments at each point.
    pub degree: Vec<u32>,
    /// Index of the first input polyline that uses each point (for error messages).
    pub curve_of_point: Vec<u32>,
    /// Input vertices merged into another one by the weld.
    pub welded_vertices: usize,
}

impl CurveNetwork {
    /// Builds the network from the polylines of `curves` (`Mesh::curves`). Faces of the curves
    /// input are ignored.
    pub fn from_mesh(curves: &Mesh, join_tolerance: f64) -> Result<Self> {
        if curves.curves.is_empty() {
            return Err(Error::params(
                "curves",
                "the curves input has no polylines (OBJ `l` lines, glTF LINES/LINE_STRIP)",
            ));
        }
        let used: Vec<Point3> =
            curves.curves.iter().flatten().map(|&v| curves.positions[v as usize]).collect();
        let diag = Aabb::of(&used).map(|b| b.diagonal()).unwrap_or(0.0);
        if diag <= 0.0 {
            return Err(Error::params("curves", "all curve vertices are at one point"));
        }
        let tol = join_tolerance.max(0.0) * diag;
        let mut weld = Weld::new(tol.max(diag * 1e-15));
        let mut input_to_point: HashMap<u32, u32> = HashMap::new();
        let mut polylines = Vec::with_capacity(curves.curves.len());
        let mut curve_of_point = Vec::new();
        let mut inputs_seen = 0usize;
        for (ci, c) in curves.curves.iter().enumerate() {
            let mut line: Vec<u32> = Vec::with_capacity(c.len());
            for &v in c {
                let id = match input_to_point.get(&v) {
                    Some(&id) => id,
                    None => {
                        inputs_seen += 1;
                        let id = weld.insert(curves.positions[v as usize]);
                        if id as usize == curve_of_point.len() {
                            curve_of_point.push(ci as u32);
                        }
                        input_to_point.insert(v, id);
                        id
                    }
                };
                if line.last() != Some(&id) {
                    line.push(id);
                }
            }
            if line.len() < 2 {
                return Err(Error::params(
                    "curves",
                    format!("curve {ci} has fewer than two distinct points ({} given)", c.len()),
                ));
            }
            polylines.push(line);
        }
        let points = weld.points;
        let mut seen = HashMap::new();
        let mut segments = Vec::new();
        let mut degree = vec![0u32; points.len()];
        for line in &polylines {
            for w in line.windows(2) {
                let key = [w[0].min(w[1]), w[0].max(w[1])];
                if seen.insert(key, ()).is_none() {
                    segments.push(key);
                    degree[w[0] as usize] += 1;
                    degree[w[1] as usize] += 1;
                }
            }
        }
        let welded_vertices = inputs_seen - points.len();
        Ok(CurveNetwork { points, segments, polylines, degree, curve_of_point, welded_vertices })
    }

    pub fn is_feature(&self, p: u32) -> bool {
        self.degree[p as usize] > 2
    }

    pub fn feature_count(&self) -> usize {
        self.degree.iter().filter(|&&d| d > 2).count()
    }

    /// Shortest segment length (0 when there is none).
    pub fn min_segment(&self) -> f64 {
        self.segments
            .iter()
            .map(|s| dist(self.points[s[0] as usize], self.points[s[1] as usize]))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Merges points closer than `tol` (hash grid with cell = tol, 27-cell lookup).
struct Weld {
    tol: f64,
    points: Vec<Point3>,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Weld {
    fn new(tol: f64) -> Self {
        Weld { tol, points: Vec::new(), cells: HashMap::new() }
    }

    fn cell(&self, p: Point3) -> [i64; 3] {
        [(p[0] / self.tol).floor() as i64, (p[1] / self.tol).floor() as i64, (p[2] / self.tol).floor() as i64]
    }

    fn insert(&mut self, p: Point3) -> u32 {
        let c = self.cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &i in list {
                            if dist(self.points[i as usize], p) <= self.tol {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let id = self.points.len() as u32;
        self.points.push(p);
        self.cells.entry(c).or_default().push(id);
        id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(points: Vec<Point3>, curves: Vec<Vec<u32>>) -> Mesh {
        Mesh { positions: points, curves, ..Default::default() }
    }

    #[test]
    fn shared_endpoints_join_and_features_are_found() {
        // A plus sign from four two-point lines whose centre is given four times (slightly apart).
        let m = lines(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1e-9, 0.0, 0.0],
                [-1.0, 0.0, 0.0],
                [0.0, 0.0, 1e-9],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0],
                [0.0, -1.0, 0.0],
            ],
            vec![vec![0, 1], vec![2, 3], vec![4, 5], vec![6, 7]],
        );
        let n = CurveNetwork::from_mesh(&m, 1e-6).unwrap();
        assert_eq!(n.points.len(), 5);
        assert_eq!(n.segments.len(), 4);
        assert_eq!(n.feature_count(), 1);
        assert_eq!(n.degree[0], 4);
        assert_eq!(n.welded_vertices, 3);
    }

    #[test]
    fn empty_and_one_point_curves_are_named() {
        let e = CurveNetwork::from_mesh(&lines(vec![[0.0; 3]], vec![]), 1e-6).unwrap_err();
        assert!(matches!(e, Error::InvalidParams { ref field, .. } if field == "curves"), "{e}");
        let e = CurveNetwork::from_mesh(
            &lines(vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![vec![0, 1], vec![1, 1]]),
            1e-6,
        )
        .unwrap_err();
        assert!(e.to_string().contains("curve 1"), "{e}");
    }
}

/// Reads a curve network given as JSON `{"polylines": [[[x, y, z], …], …]}` (issue 5's third curve
/// format besides OBJ `l` and glTF lines). Returns `None` when `bytes` is not such a document, so the
/// caller can fall back to the mesh readers. Each polyline becomes one `Mesh::curves` entry; shared
/// endpoints are joined later, like those of any other curve input.
pub fn polylines_from_json(bytes: &[u8]) -> Option<Result<Mesh>> {
    let text = std::str::from_utf8(bytes).ok()?.trim_start();
    if !text.starts_with('{') || !text.contains("\"polylines\"") {
        return None;
    }
    let doc: serde_json::Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => {
            return Some(Err(Error::malformed(
                "json",
                crate::error::Location::Line(e.line()),
                format!("curve network JSON: {e}"),
            )))
        }
    };
    let lines = doc.get("polylines")?;
    Some(parse_polylines(lines))
}

fn parse_polylines(lines: &serde_json::Value) -> Result<Mesh> {
    use crate::error::Location;
    let at = |path: String, msg: &str| Error::malformed("json", Location::Gltf(path), msg.to_string());
    let lines = lines.as_array().ok_or_else(|| at("polylines".into(), "must be an array of polylines"))?;
    let mut mesh = Mesh::default();
    for (i, line) in lines.iter().enumerate() {
        let points =
            line.as_array().ok_or_else(|| at(format!("polylines[{i}]"), "must be an array of points"))?;
        if points.len() < 2 {
            return Err(at(format!("polylines[{i}]"), "a polyline needs at least 2 points"));
        }
        let mut curve = Vec::with_capacity(points.len());
        for (j, p) in points.iter().enumerate() {
            let xyz = p
                .as_array()
                .filter(|c| c.len() == 3)
                .and_then(|c| Some([c[0].as_f64()?, c[1].as_f64()?, c[2].as_f64()?]))
                .filter(|c| c.iter().all(|v| v.is_finite()))
                .ok_or_else(|| {
                    at(format!("polylines[{i}][{j}]"), "a point is [x, y, z] with finite numbers")
                })?;
            let index = u32::try_from(mesh.positions.len())
                .map_err(|_| at(format!("polylines[{i}]"), "too many points"))?;
            mesh.positions.push(xyz);
            curve.push(index);
        }
        mesh.curves.push(curve);
    }
    if mesh.curves.is_empty() {
        return Err(at("polylines".into(), "no polylines"));
    }
    Ok(mesh)
}

#[cfg(test)]
mod json_tests {
    use super::*;

    #[test]
    fn polylines_json_becomes_curves() {
        let doc = br#"{"polylines": [[[0,0,0],[1,0,0],[1,1,0]], [[1,1,0],[0,1,0.5]]]}"#;
        let m = polylines_from_json(doc).unwrap().unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.curves, vec![vec![0, 1, 2], vec![3, 4]]);
        assert_eq!(m.positions[4], [0.0, 1.0, 0.5]);
        assert_eq!(m.face_count(), 0);
    }

    #[test]
    fn polylines_json_errors_name_the_point() {
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0],[1,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0][1]"), "{e}");
        let e = polylines_from_json(br#"{"polylines": [[[0,0,0]]]}"#).unwrap().unwrap_err();
        assert!(e.to_string().contains("polylines[0]"), "{e}");
        assert!(polylines_from_json(b"v 0 0 0\n").is_none());
        assert!(polylines_from_json(br#"{"asset": {"version": "2.0"}}"#).is_none());
    }
}
