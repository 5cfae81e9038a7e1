//! Wavefront OBJ through `tobj`, keeping position indexing (no per-corner vertex splitting).
//!
//! Polygons are fan-triangulated by tobj; points and lines (`p`, `l`) are ignored, as are
//! vertex colours (`v x y z r g b`, on all vertices or some), and an `f` with fewer than three
//! corners is an error, as in the other formats. tobj numbers vertices in order of first use
//! by a face and drops the ones no face uses; a file with no faces is read as a point cloud of
//! all its `v` lines. Normals are kept only when they are per-vertex: as many normals as
//! positions, indexed like them.
//! Positions, and normals when kept, must be finite.
//!
//! tobj reports no line numbers, so when it fails the source is scanned again ([`scan`]) to
//! name the first malformed line; only if none is found is the error located at the file.

mod scan;

use crate::error::{Error, Result};
use crate::io::{assemble, text};
use crate::mesh::Mesh;
use glam::DVec3;
use scan::Data;
use std::io::{self, Write};
use std::panic::{self, AssertUnwindSafe};
use std::path::Path;

/// The location of errors that no line can be found for.
const WHOLE_FILE: &str = "OBJ data";

/// Parses a whole OBJ file held in memory. `path` is used only in error messages; material
/// libraries are not loaded.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    text::reject_blank(bytes, path)?;
    // tobj rejects invalid UTF-8 anywhere, even in comments; numbers are ASCII anyway.
    let source = String::from_utf8_lossy(bytes);
    if let Some((n, problem)) = scan::first_short_face(&source) {
        return Err(Error::parse(path, format!("line {n}"), problem));
    }
    // The update is needed when another crate in the build enables tobj's optional fields.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // tobj can overflow (and so panic, with overflow checks) on absurd relative indices.
    let load = |source: &str| {
        panic::catch_unwind(AssertUnwindSafe(|| {
            tobj::load_obj_buf(&mut source.as_bytes(), &options, |_| Ok(Default::default()))
        }))
    };
    let mut loaded = load(&source);
    // tobj looks colours up by vertex, so colours on some `v` lines only make it fail; they are
    // not used, so the file is read again without them.
    if matches!(loaded, Ok(Err(tobj::LoadError::FaceColorOutOfBounds))) {
        loaded = load(&scan::without_colours(&source));
    }
    let models = match loaded {
        Ok(Ok((models, _materials))) => models,
        Ok(Err(e)) => return Err(rejected(&source, path, e.to_string())),
        Err(_) => return Err(rejected(&source, path, "malformed face indices".into())),
    };
    if models.iter().all(|m| m.mesh.indices.is_empty()) {
        return points(&source, path);
    }
    merge(&models, &source, path)
}

/// The error for a file tobj rejected with `message`: at the first malformed line, or at the
/// whole file if the scan finds none.
fn rejected(source: &str, path: &Path, message: String) -> Error {
    match scan::first_malformed(source) {
        Some((n, problem)) => Error::parse(path, format!("line {n}"), problem),
        None => Error::parse(path, WHOLE_FILE, message),
    }
}

/// The error for a non-finite position or normal in tobj's output: at the `v` or `vn` line it
/// came from (tobj renumbers vertices, so the source is scanned for it), or with `fallback`
/// at the whole file.
fn non_finite(source: &str, path: &Path, data: Data, fallback: String) -> Error {
    match scan::first_non_finite_use(source, data) {
        Some((n, problem)) => Error::parse(path, format!("line {n}"), problem),
        None => Error::parse(path, WHOLE_FILE, fallback),
    }
}

/// Concatenates tobj's models, offsetting each one's indices.
fn merge(models: &[tobj::Model], source: &str, path: &Path) -> Result<Mesh> {
    let mut positions = Vec::new();
    let mut mesh = Mesh { normals: Some(Vec::new()), ..Mesh::default() };
    for model in models {
        let m = &model.mesh;
        let offset = u32::try_from(positions.len())
            .map_err(|_| Error::TooLarge(format!("{}: too many vertices", path.display())))?;
        for p in m.positions.chunks_exact(3) {
            let p = DVec3::new(p[0], p[1], p[2]);
            let vertex = positions.len();
            let p = assemble::finite_position(p)
                .map_err(|e| non_finite(source, path, Data::Position, format!("vertex {vertex} {e}")))?;
            positions.push(p);
        }
        for t in m.indices.chunks_exact(3) {
            let shift = |i: u32| {
                i.checked_add(offset).ok_or_else(|| Error::TooLarge(format!("{}: too many vertices", path.display())))
            };
            mesh.triangles.push([shift(t[0])?, shift(t[1])?, shift(t[2])?]);
        }
        let per_vertex = m.normals.len() == m.positions.len() && m.normal_indices == m.indices;
        match &mut mesh.normals {
            Some(normals) if per_vertex => {
                for n in m.normals.chunks_exact(3) {
                    let vertex = normals.len(); // normals are per vertex, so this is its index
                    let n = assemble::finite_normal(DVec3::new(n[0], n[1], n[2]).as_vec3())
                        .map_err(|e| non_finite(source, path, Data::Normal, format!("vertex {vertex}: {e}")))?;
                    normals.push(n);
                }
            }
            _ => mesh.normals = None,
        }
    }
    Ok(assemble::mesh(positions, mesh.normals, mesh.triangles))
}

/// A file without faces: every `v` line is a point; `vn` lines are its normals when there is
/// exactly one per point, and must then be finite.
fn points(source: &str, path: &Path) -> Result<Mesh> {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    // The first non-finite normal; an error only if the normals are kept.
    let mut bad_normal = None;
    for (n, line) in text::lines(source.as_bytes()) {
        let mut words = line.split_whitespace();
        let is_position = match words.next() {
            Some("v") => true,
            Some("vn") => false,
            _ => continue,
        };
        let at = |m: String| Error::parse(path, format!("line {n}"), m);
        let mut xyz = [0.0f64; 3];
        for c in &mut xyz {
            let word = words.next().ok_or_else(|| at("expected 3 numbers".into()))?;
            *c = text::number(word).map_err(at)?;
        }
        if is_position {
            let vertex = positions.len();
            let p = assemble::finite_position(DVec3::from(xyz)).map_err(|m| at(format!("vertex {vertex} {m}")))?;
            positions.push(p);
        } else {
            let normal = normals.len();
            let xyz = DVec3::from(xyz).as_vec3();
            if let (None, Err(m)) = (&bad_normal, assemble::finite_normal(xyz)) {
                bad_normal = Some(at(format!("normal {normal} {m}")));
            }
            normals.push(xyz);
        }
    }
    let has_normals = !normals.is_empty() && normals.len() == positions.len();
    if let (true, Some(error)) = (has_normals, bad_normal) {
        return Err(error);
    }
    Ok(assemble::mesh(positions, has_normals.then_some(normals), Vec::new()))
}

/// Writes `mesh` as OBJ with 1-based indices; with normals, faces are `f a//a b//b c//c`.
pub(crate) fn write<W: Write>(out: &mut W, mesh: &Mesh) -> io::Result<()> {
    writeln!(out, "# written by vstree")?;
    for i in 0..mesh.positions.len() {
        writeln!(out, "v {}", text::Position(mesh, i))?;
    }
    if let Some(normals) = &mesh.normals {
        for n in normals {
            writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
        }
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| u64::from(i) + 1);
        if mesh.normals.is_some() {
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
        } else {
            writeln!(out, "f {a} {b} {c}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn parse_str(s: &str) -> Result<Mesh> {
        parse(s.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn triangulates_and_keeps_per_vertex_normals() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n\
                   f 1//1 2//2 3//3 4//4\n";
        let m = parse_str(src).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals.as_ref().map(Vec::len), Some(4));
        // One normal shared by all corners is not per-vertex.
        let m = parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n").unwrap();
        assert!(m.normals.is_none());
    }

    #[test]
    fn merges_groups_with_offsets() {
        let src = "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\no b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\n";
        let m = parse_str(src).unwrap();
        assert_eq!(m.positions.len(), 6);
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(m.positions[3], Vec3::Z);
    }

    #[test]
    fn colours_on_some_vertices_are_ignored() {
        let m = parse_str("v 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0 0 0 1\nv 0 1 0\nf 1 2 3\nf 1 3 4\n").unwrap();
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn points_only_is_a_point_cloud() {
        let m = parse_str("v 0 0 0\nv 1 0 0\nvn 0 0 1\nvn 0 0 1\n").unwrap();
        assert!(m.is_point_cloud());
        assert_eq!(m.positions.len(), 2);
        assert!(m.normals.is_some());
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        assert!(parse_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").is_err());
        assert!(parse_str("v 0 x 0\n").is_err());
        assert!(parse_str("v 0 0 0\nvn 0 0 1\nf 1//-4 1//1 1//1\n").is_err());
        assert!(parse_str("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").is_err());
    }
}
