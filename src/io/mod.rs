//! Reading and writing meshes and point clouds: PLY, OBJ, OFF and XYZ/PWN.
//!
//! [`read()`] and [`write()`] pick the format from the file extension (case-insensitive). Each
//! format module also has a `parse(bytes, path)` that reads from memory. Readers never panic
//! on malformed input: they return [`Error::Parse`] naming the file, the place (a line, or an
//! element item such as `face 3` in binary PLY) and what is wrong. Writers replace the target
//! file atomically: it is either left untouched or holds the complete new content.

pub(crate) mod assemble;
mod atomic;
mod cleanup;
mod input;
pub mod obj;
pub mod off;
pub mod ply;
mod text;
pub mod xyz;

pub use cleanup::remove_temporary_files_on_signals;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use input::Input;
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
    /// A UTF-8 byte order mark at the start is skipped (editors on Windows write one).
    pub fn parse(self, bytes: &[u8], path: &Path) -> Result<Mesh> {
        self.read(&mut Input::memory(bytes), path)
    }

    /// Reads a file of this format from `input`, pulling only what the reader needs: a PLY or
    /// OFF file up to the end of the elements it declares, an XYZ file line by line, an OBJ
    /// file whole (tobj takes it whole), and none of them past a bad line or past a byte that
    /// no file of the format holds (NUL in text), so that a file of another kind is refused at
    /// once, with little memory, whatever its size.
    fn read(self, input: &mut Input, path: &Path) -> Result<Mesh> {
        let bom = input.get(0, 3).len() - without_bom(input.get(0, 3)).len();
        let mesh = match self {
            Format::Ply => ply::read(input, bom, path),
            Format::Off => off::read(input, bom, path),
            Format::Xyz => xyz::read(input, bom, path),
            Format::Obj => {
                input::refuse_binary(input.get(0, input::PREFIX_BYTES), path)?;
                obj::parse(&input.text(path)?[bom..], path)
            }
        }?;
        // Valid in the formats, but nothing any stage can work on, nor a mesh the C API can make.
        if mesh.positions.is_empty() {
            return Err(Error::input(format!(
                "{}: no vertices: the file holds neither a mesh nor points",
                path.display()
            )));
        }
        Ok(mesh)
    }
}

fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
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
    input::read(path, |input| format.read(input, path))
}

/// Writes `mesh` to `path` with default options (PLY as binary little-endian).
pub fn write(path: &Path, mesh: &Mesh) -> Result<()> {
    write_with(path, mesh, &WriteOptions::default())
}

/// Writes `mesh` to `path` in the format its extension names, normals included when present
/// (except in OFF, which has none). Point clouds get no faces. The mesh must pass
/// [`Mesh::check`]. The file is replaced atomically: on error it is left as it was.
pub fn write_with(path: &Path, mesh: &Mesh, options: &WriteOptions) -> Result<()> {
    mesh.check()?;
    OutputFile::create(path)?.write(mesh, options)
}

/// An output reserved before the work that makes its content: the format is known, the
/// target is one vstree may replace (a regular file it may write, or a new file; a symbolic
/// link is followed) and its temporary file exists, so a bad output is reported before any
/// work. Dropped without [`OutputFile::write`], it leaves the target as it was.
pub struct OutputFile {
    format: Format,
    reserved: atomic::Reserved,
}

impl OutputFile {
    /// Checks `path` as an output and creates its temporary file next to it.
    pub fn create(path: &Path) -> Result<OutputFile> {
        let format = format_of(path)?;
        Ok(OutputFile { format, reserved: atomic::Reserved::new(path)? })
    }

    /// Writes `mesh` (which must pass [`Mesh::check`]) and puts it in place of the target.
    pub fn write(self, mesh: &Mesh, options: &WriteOptions) -> Result<()> {
        mesh.check()?;
        if mesh.positions.is_empty() {
            // Such a file reads back as an error (see `Format::parse`): never write one.
            return Err(Error::input("the mesh has no vertices: there is nothing to write"));
        }
        let format = self.format;
        self.reserved.fill(|out| match format {
            Format::Ply => ply::write(out, mesh, options.ascii),
            Format::Obj => obj::write(out, mesh),
            Format::Off => off::write(out, mesh),
            Format::Xyz => xyz::write(out, mesh),
        })
    }
}

fn format_of(path: &Path) -> Result<Format> {
    Format::from_path(path).ok_or_else(|| Error::UnsupportedFormat { path: path.to_path_buf() })
}
