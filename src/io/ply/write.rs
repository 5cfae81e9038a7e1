//! Writing PLY: `float` positions (`double` for a mesh stored relative to an origin, see
//! [`Mesh::origin`]) and normals, faces as `uchar`-counted index lists.

use crate::io::text::Position;
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use std::io::{self, Write};

/// Writes `mesh` as PLY, binary little-endian or ASCII. The mesh must pass [`Mesh::check`]
/// (missing normals are written as zero rather than panicking).
pub(crate) fn write<W: Write>(out: &mut W, mesh: &Mesh, ascii: bool) -> io::Result<()> {
    write_header(out, mesh, ascii)?;
    let normals = mesh.normals.as_deref();
    let normal = |i: usize| normals.and_then(|n| n.get(i)).copied().unwrap_or(Vec3::ZERO);
    if ascii {
        for i in 0..mesh.positions.len() {
            write!(out, "{}", Position(mesh, i))?;
            if normals.is_some() {
                let n = normal(i);
                write!(out, " {} {} {}", n.x, n.y, n.z)?;
            }
            writeln!(out)?;
        }
        for [a, b, c] in &mesh.triangles {
            writeln!(out, "3 {a} {b} {c}")?;
        }
    } else {
        let absolute = mesh.origin != DVec3::ZERO;
        for (i, p) in mesh.positions.iter().enumerate() {
            if absolute {
                for value in mesh.absolute(i).to_array() {
                    out.write_all(&value.to_le_bytes())?;
                }
            } else {
                out.write_all(&le_bytes(*p))?;
            }
            if normals.is_some() {
                out.write_all(&le_bytes(normal(i)))?;
            }
        }
        for tri in &mesh.triangles {
            let mut face = [3u8; 13];
            for (k, index) in tri.iter().enumerate() {
                face[1 + 4 * k..5 + 4 * k].copy_from_slice(&index.to_le_bytes());
            }
            out.write_all(&face)?;
        }
    }
    Ok(())
}

fn write_header<W: Write>(out: &mut W, mesh: &Mesh, ascii: bool) -> io::Result<()> {
    let format = if ascii { "ascii" } else { "binary_little_endian" };
    writeln!(out, "ply\nformat {format} 1.0\ncomment written by vstree")?;
    writeln!(out, "element vertex {}", mesh.positions.len())?;
    let coordinate = if mesh.origin == DVec3::ZERO { "float" } else { "double" };
    writeln!(out, "property {coordinate} x\nproperty {coordinate} y\nproperty {coordinate} z")?;
    if mesh.normals.is_some() {
        writeln!(out, "property float nx\nproperty float ny\nproperty float nz")?;
    }
    if !mesh.triangles.is_empty() {
        // `int` is what most readers expect; indices past its range need `uint`.
        let index_type = if i32::try_from(mesh.positions.len()).is_ok() { "int" } else { "uint" };
        writeln!(out, "element face {}", mesh.triangles.len())?;
        writeln!(out, "property list uchar {index_type} vertex_indices")?;
    }
    writeln!(out, "end_header")
}

fn le_bytes(v: Vec3) -> [u8; 12] {
    let mut bytes = [0u8; 12];
    for (chunk, value) in bytes.chunks_exact_mut(4).zip(v.to_array()) {
        chunk.copy_from_slice(&value.to_le_bytes());
    }
    bytes
}
