//! XYZ / PWN point clouds: one point per line, `x y z` or `x y z nx ny nz`, the same number of
//! columns on every line. Blank lines and lines starting with `#` are skipped. Positions and
//! normals must be finite. A NUL byte is refused at its line.

use crate::error::{Error, Result};
use crate::io::input::{Input, Lines};
use crate::io::{assemble, text};
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use std::io::{self, Write};
use std::path::Path;

/// Parses a whole XYZ/PWN file held in memory. `path` is used only in error messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    read(&mut Input::memory(bytes), 0, path)
}

/// Reads the XYZ/PWN file that starts at byte `start` of `input`, pulling it line by line, so
/// that reading stops at the first bad line.
pub(crate) fn read(input: &mut Input, start: usize, path: &Path) -> Result<Mesh> {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    // Column count and line of the first point, which every other point must match.
    let mut first: Option<(usize, usize)> = None;
    let mut values = Vec::with_capacity(6);
    let mut blank = true;
    let mut lines = Lines::new(start);
    while let Some((n, line)) = lines.next(input, path)? {
        blank &= line.bytes().all(|b| b.is_ascii_whitespace());
        let content = line.trim_start();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let at = |message: String| Error::parse(path, format!("line {n}"), message);
        values.clear();
        for word in content.split_whitespace() {
            values.push(text::number::<f64>(word).map_err(at)?);
        }
        match first {
            None if values.len() == 3 || values.len() == 6 => first = Some((values.len(), n)),
            None => return Err(at(format!("expected 3 or 6 numbers (x y z [nx ny nz]), found {}", values.len()))),
            Some((columns, line)) if columns != values.len() => {
                return Err(at(format!("expected {columns} numbers like line {line}, found {}", values.len())))
            }
            Some(_) => {}
        }
        let p = DVec3::new(values[0], values[1], values[2]);
        let point = positions.len();
        positions.push(assemble::finite_position(p).map_err(|m| at(format!("point {point}: {m}")))?);
        if let [_, _, _, nx, ny, nz] = values[..] {
            let normal = assemble::finite_normal(DVec3::new(nx, ny, nz).as_vec3());
            normals.push(normal.map_err(|m| at(format!("point {point}: {m}")))?);
        }
    }
    if blank {
        return Err(text::empty_file(path));
    }
    assemble::vertex_count_fits(positions.len()).map_err(|m| Error::TooLarge(format!("{}: {m}", path.display())))?;
    let has_normals = first.is_some_and(|(columns, _)| columns == 6);
    Ok(assemble::mesh(positions, has_normals.then_some(normals), Vec::new()))
}

/// Writes the positions (and normals) of `mesh`; triangles are not part of the format.
pub(crate) fn write<W: Write>(out: &mut W, mesh: &Mesh) -> io::Result<()> {
    let normals = mesh.normals.as_deref();
    for i in 0..mesh.positions.len() {
        write!(out, "{}", text::Position(mesh, i))?;
        if let Some(normals) = normals {
            let n = normals.get(i).copied().unwrap_or(Vec3::ZERO);
            write!(out, " {} {} {}", n.x, n.y, n.z)?;
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(s: &str) -> Result<Mesh> {
        parse(s.as_bytes(), Path::new("t.xyz"))
    }

    #[test]
    fn reads_points_with_and_without_normals() {
        let m = parse_str("# header\n\n0 0 0\r\n1 2 3\n").unwrap();
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)]);
        assert!(m.normals.is_none());
        let m = parse_str("0 0 0 0 0 1\n").unwrap();
        assert_eq!(m.normals, Some(vec![Vec3::Z]));
    }

    #[test]
    fn errors_name_the_line() {
        let err = parse_str("0 0 0 0 0 1\n\n1 1 1\n").unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("like line 1"), "{err}");
        let err = parse_str("0 0 0 1\n").unwrap_err().to_string();
        assert!(err.contains("line 1") && err.contains("3 or 6"), "{err}");
        let err = parse_str("0 0 0\n0 zero 0\n").unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("`zero`"), "{err}");
        let err = parse_str("0 0 0\nnan 0 0\n").unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("point 1"), "{err}");
    }
}
