//! Reading and writing meshes and point clouds: PLY, OBJ, OFF and XYZ/PWN.
//!
//! [`read()`] and [`write()`] pick the format from the file extension (case-insensitive). Each
//! format module also has a `parse(bytes, path)` that reads from memory. Readers never panic
//! on malformed input: they return [`Error::Parse`] naming the file, the place (a line, or an
//! element item such as `face 3` in binary PLY) and what is wrong. Writers replace the target
//! file atomically: it is either left untouched or holds the complete new content.

mod assemble;
mod atomic;
pub mod obj;
pub mod off;
pub mod ply;
mod text;
pub mod xyz;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::path::Path;

/// A file format vstree reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
    /// Text points, `x y z [nx ny nz]` per line (`.xyz` and `.pwn`).
    Xyz,
}

impl Format {
    /// The format named by `path`'s extension, ignoring case; `None` for any other extension.
    pub fn from_path(path: &Path) -> Option<Format> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match extension.as_str() {
            "ply" => Format::Ply,
            "obj" => Format::Obj,
            "off" => Format::Off,
            "xyz" | "pwn" => Format::Xyz,
            _ => return None,
        })
    }

    /// Parses a whole file of this format held in memory; `path` is used only in messages.
    pub fn parse(self, bytes: &[u8], path: &Path) -> Result<Mesh> {
        match self {
            Format::Ply => ply::parse(bytes, path),
            Format::Obj => obj::parse(bytes, path),
            Format::Off => off::parse(bytes, path),
            Format::Xyz => xyz::parse(bytes, path),
        }
    }
}

/// How to write a file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Write PLY as ASCII instead of binary little-endian. Other formats are always text.
    pub ascii: bool,
}

/// Reads the mesh or point cloud at `path`, in the format its extension names.
pub fn read(path: &Path) -> Result<Mesh> {
    let format = format_of(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    format.parse(&bytes, path)
}

/// Writes `mesh` to `path` with default options (PLY as binary little-endian).
pub fn write(path: &Path, mesh: &Mesh) -> Result<()> {
    write_with(path, mesh, &WriteOptions::default())
}

/// Writes `mesh` to `path` in the format its extension names, normals included when present
/// (except in OFF, which has none). Point clouds get no faces. The mesh must pass
/// [`Mesh::check`]. The file is replaced atomically: on error it is left as it was.
pub fn write_with(path: &Path, mesh: &Mesh, options: &WriteOptions) -> Result<()> {
    let format = format_of(path)?;
    mesh.check()?;
    atomic::replace(path, |out| match format {
        Format::Ply => ply::write(out, mesh, options.ascii),
        Format::Obj => obj::write(out, mesh),
        Format::Off => off::write(out, mesh),
        Format::Xyz => xyz::write(out, mesh),
    })
}

fn format_of(path: &Path) -> Result<Format> {
    Format::from_path(path).ok_or_else(|| Error::UnsupportedFormat { path: path.to_path_buf() })
}
