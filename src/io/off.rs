//! OFF (Object File Format): `OFF`, `NOFF` (normals after each position), `COFF` (colors,
//! ignored) and their combinations. The counts may share the keyword's line; `#` starts a
//! comment; polygons are fan-triangulated and anything after a face's indices (a color) is
//! ignored. Positions and normals must be finite. The writer writes plain `OFF`, which has no
//! normals.

use crate::error::{Error, Result};
use crate::io::input::{Input, Lines};
use crate::io::{assemble, text};
use crate::mesh::Mesh;
use glam::DVec3;
use std::borrow::Cow;
use std::io::{self, Write};
use std::path::Path;

/// Parses a whole OFF file held in memory. `path` is used only in error messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    read(&mut Input::memory(bytes), 0, path)
}

/// Reads the OFF file that starts at byte `start` of `input`, pulling it line by line up to
/// its last declared face: reading stops at the first bad line, and what follows the faces
/// is not read.
pub(crate) fn read(input: &mut Input, start: usize, path: &Path) -> Result<Mesh> {
    let mut lines = Content { lines: Lines::new(start), last: 1, blank: true };
    let at = |n: usize, message: String| Error::parse(path, format!("line {n}"), message);

    let (n, first) = lines.next(input, path, || "file ends before the OFF keyword".into())?;
    let mut words = first.split_whitespace();
    let keyword = words.next().unwrap_or_default();
    let has_normals = parse_keyword(keyword).map_err(|m| at(n, m))?;
    let mut counts: Vec<String> = words.map(str::to_owned).collect();
    let mut counts_line = n;
    if counts.is_empty() {
        let (n, line) = lines.next(input, path, || "file ends before the vertex and face counts".into())?;
        counts = line.split_whitespace().map(str::to_owned).collect();
        counts_line = n;
    }
    let (vertex_count, face_count) = parse_counts(&counts).map_err(|m| at(counts_line, m))?;
    assemble::vertex_count_fits(vertex_count).map_err(|m| Error::TooLarge(format!("{}: {m}", path.display())))?;

    let mut positions = Vec::with_capacity(assemble::capacity(vertex_count, input.remaining(start), 6));
    let mut normals = has_normals.then(|| Vec::with_capacity(positions.capacity()));
    let columns = if has_normals { 6 } else { 3 };
    for i in 0..vertex_count {
        let (n, line) = lines.next(input, path, || format!("file ends after {i} of the {vertex_count} vertices"))?;
        let values = numbers(&line, columns).map_err(|m| at(n, format!("vertex {i}: {m}")))?;
        let p = DVec3::new(values[0], values[1], values[2]);
        positions.push(assemble::finite_position(p).map_err(|m| at(n, format!("vertex {i}: {m}")))?);
        if let Some(normals) = &mut normals {
            let normal = assemble::finite_normal(DVec3::new(values[3], values[4], values[5]).as_vec3());
            normals.push(normal.map_err(|m| at(n, format!("vertex {i}: {m}")))?);
        }
    }

    let mut triangles = Vec::with_capacity(assemble::capacity(face_count, input.remaining(start), 8));
    let mut polygon = Vec::new();
    for i in 0..face_count {
        let (n, line) = lines.next(input, path, || format!("file ends after {i} of the {face_count} faces"))?;
        read_face(&line, vertex_count, &mut polygon)
            .and_then(|()| assemble::push_fan(&polygon, &mut triangles))
            .map_err(|m| at(n, format!("face {i}: {m}")))?;
    }
    Ok(assemble::mesh(positions, normals, triangles))
}

/// The content lines of an OFF input, pulled one at a time: comments removed, blank lines
/// skipped.
struct Content {
    lines: Lines,
    /// The last content line, where an early end is reported.
    last: usize,
    /// Whether every line so far is whitespace only.
    blank: bool,
}

impl Content {
    /// The next content line; at the end, an error saying `what` is missing (or that the file
    /// is empty, when it holds nothing but whitespace).
    fn next<'i>(
        &mut self,
        input: &'i mut Input,
        path: &Path,
        what: impl Fn() -> String,
    ) -> Result<(usize, Cow<'i, str>)> {
        while let Some((n, range)) = self.lines.next_range(input, path)? {
            let line = Lines::text(input, range.clone());
            self.blank &= line.bytes().all(|b| b.is_ascii_whitespace());
            if !without_comment(line).trim().is_empty() {
                self.last = n;
                return Ok((n, without_comment(Lines::text(input, range))));
            }
        }
        Err(if self.blank { text::empty_file(path) } else { Error::parse(path, format!("line {}", self.last), what()) })
    }
}

/// `line` up to its first `#`.
fn without_comment(line: Cow<'_, str>) -> Cow<'_, str> {
    match line.find('#') {
        Some(hash) => Cow::Owned(line[..hash].to_owned()),
        None => line,
    }
}

/// Whether the keyword announces normals; `[C][N]OFF` and texture `ST` prefixes are accepted.
fn parse_keyword(keyword: &str) -> Result<bool, String> {
    match keyword.strip_suffix("OFF") {
        Some(prefix) if prefix.chars().all(|c| "STCN".contains(c)) => Ok(prefix.contains('N')),
        _ => Err(format!("expected OFF, NOFF or COFF, found {}", text::quoted(keyword))),
    }
}

/// `vertices faces [edges]`.
fn parse_counts(words: &[String]) -> Result<(usize, usize), String> {
    if words.first().is_some_and(|w| w == "BINARY") {
        return Err("binary OFF is not supported".into());
    }
    match words {
        [v, f, ..] => Ok((text::number(v)?, text::number(f)?)),
        _ => Err("expected the vertex and face counts".into()),
    }
}

/// The first `columns` numbers of a line (the rest, e.g. a color, is ignored).
fn numbers(line: &str, columns: usize) -> Result<Vec<f64>, String> {
    let values = line.split_whitespace().take(columns).map(text::number).collect::<Result<Vec<f64>, _>>()?;
    if values.len() < columns {
        return Err(format!("expected {columns} numbers, found {}", values.len()));
    }
    Ok(values)
}

/// `n i1 ... in [color]` into `polygon`, with checked indices.
fn read_face(line: &str, vertex_count: usize, polygon: &mut Vec<u32>) -> Result<(), String> {
    polygon.clear();
    let mut words = line.split_whitespace();
    let n: usize = text::number(words.next().unwrap_or_default())?;
    for _ in 0..n {
        let word = words.next().ok_or_else(|| format!("announces {n} vertices but lists {}", polygon.len()))?;
        polygon.push(assemble::vertex_index(text::number(word)?, vertex_count)?);
    }
    Ok(())
}

/// Writes `mesh` as plain OFF (normals are not part of plain OFF and are dropped).
pub(crate) fn write<W: Write>(out: &mut W, mesh: &Mesh) -> io::Result<()> {
    writeln!(out, "OFF\n{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
    for i in 0..mesh.positions.len() {
        writeln!(out, "{}", text::Position(mesh, i))?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(out, "3 {a} {b} {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn parse_str(s: &str) -> Result<Mesh> {
        parse(s.as_bytes(), Path::new("t.off"))
    }

    #[test]
    fn reads_variants() {
        let m = parse_str("OFF 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let m = parse_str("# c\nNOFF\n# c\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1 # x\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
        assert_eq!(m.normals.unwrap()[2], Vec3::Z);
        let m = parse_str("COFF\r\n3 1 3\r\n0 0 0 1 1 1 1\r\n1 0 0 1 1 1 1\r\n0 1 0 1 1 1 1\r\n3 0 1 2\r\n").unwrap();
        assert_eq!(m.positions[1], Vec3::X);
        assert!(m.normals.is_none());
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse_str("OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n").unwrap_err().to_string();
        assert!(err.contains("line 4") && err.contains("vertex 1") && err.contains("`x`"), "{err}");
        let err = parse_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap_err().to_string();
        assert!(err.contains("line 6") && err.contains("face 0") && err.contains("vertex 7"), "{err}");
        let err = parse_str("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap_err().to_string();
        assert!(err.contains("file ends after 1 of the 2 faces"), "{err}");
        let err = parse_str("PLY\n").unwrap_err().to_string();
        assert!(err.contains("expected OFF"), "{err}");
    }
}
