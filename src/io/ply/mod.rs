//! PLY (Stanford polygon file format) 1.0: ASCII and binary of either byte order.
//!
//! The reader takes positions from the `vertex` element's `x y z`, normals from `nx ny nz`
//! when all three are present, and polygons from the `face` element's `vertex_indices` (or
//! `vertex_index`) list, fan-triangulated. Every other element and property is skipped.
//! Positions and normals must be finite. In ASCII bodies each item is one line (blank lines
//! between items are skipped). Errors name the header or body line (ASCII), or the element
//! item (binary, numbered from 0, e.g. `face 3`).

mod ascii;
mod binary;
mod header;
mod items;
mod plan;
mod scalar;
mod write;

pub(crate) use write::write;

use crate::error::{Error, Result};
use crate::io::input::{self, Input, PREFIX_BYTES};
use crate::mesh::Mesh;
use header::{Encoding, Header};
use items::Parts;
pub(crate) use items::{position, Fail, Sink};
use plan::Plan;
use std::path::Path;

/// Parses a whole PLY file held in memory. `path` is used only in error messages. Bytes after
/// the elements the header declares are ignored.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    read(&mut Input::memory(bytes), 0, path)
}

/// Reads the PLY file that starts at byte `start` of `input`, pulling its header and then
/// the elements the header declares, and nothing after them.
pub(crate) fn read(input: &mut Input, start: usize, path: &Path) -> Result<Mesh> {
    let header = read_header(input, start, path)?;
    let plan = Plan::new(&header, path)?;
    let mut parts = Parts::new(plan.has_normals);
    read_body(input, start, &header, &plan, &mut parts, path)?;
    Ok(parts.into_mesh())
}

/// What a PLY file's header declares, for a reader that streams its body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Declared {
    pub vertices: usize,
    /// Polygons (each fan-triangulated); 0 without a `face` element.
    pub faces: usize,
    /// Whether the `vertex` element comes before the `face` element, as in every writer's files
    /// (the standard's example too); a stream needs it to resolve faces as they come.
    pub vertices_first: bool,
    /// The file's size in bytes.
    pub bytes: u64,
}

/// The header of the PLY file at `path` (a UTF-8 byte order mark before it is skipped).
pub fn declared(path: &Path) -> Result<Declared> {
    let bytes = std::fs::metadata(path).map_err(|e| Error::io(path, e))?.len();
    input::read(path, |input| {
        let start = bom_length(input);
        let header = read_header(input, start, path)?;
        Plan::new(&header, path)?;
        let position = |name: &str| header.elements.iter().position(|e| e.name == name);
        let face = position("face");
        let vertex = position("vertex");
        Ok(Declared {
            vertices: vertex.map_or(0, |i| header.elements[i].count),
            faces: face.map_or(0, |i| header.elements[i].count),
            vertices_first: vertex < face || face.is_none(),
            bytes,
        })
    })
}

/// Streams the body of the PLY file at `path` into `sink`, one pass front to back, holding a
/// few MiB of the file at a time.
pub(crate) fn stream(path: &Path, sink: &mut impl Sink) -> Result<()> {
    input::stream(path, |input| {
        let start = bom_length(input);
        let header = read_header(input, start, path)?;
        let plan = Plan::new(&header, path)?;
        read_body(input, start, &header, &plan, sink, path)
    })
}

fn bom_length(input: &mut Input) -> usize {
    if input.get(0, 3) == b"\xEF\xBB\xBF" {
        3
    } else {
        0
    }
}

/// Reads the body of the PLY file whose header starts at byte `start` of `input` into `sink`.
fn read_body(
    input: &mut Input,
    start: usize,
    header: &Header,
    plan: &Plan,
    sink: &mut impl Sink,
    path: &Path,
) -> Result<()> {
    let body = start + header.body_start;
    match header.encoding {
        Encoding::Ascii => ascii::read(input, body, header.lines + 1, header, plan, sink, path),
        Encoding::BinaryLittleEndian => binary::read(input, body, false, header, plan, sink, path),
        Encoding::BinaryBigEndian => binary::read(input, body, true, header, plan, sink, path),
    }
}

/// The most bytes a PLY header may hold (1 MiB): a header declares its elements and
/// properties in a few hundred bytes, so even thousands of comment lines stay far below, and
/// a longer one is not a header: reading stops there instead of holding it.
const MAX_HEADER: usize = 1 << 20;

/// The header at byte `start` of `input`, pulling twice as much each time it is unfinished,
/// up to [`MAX_HEADER`].
fn read_header(input: &mut Input, start: usize, path: &Path) -> Result<Header> {
    let mut want = PREFIX_BYTES;
    loop {
        let bytes = input.get(start, want);
        let more = bytes.len() == want;
        match header::parse(bytes, more, path) {
            Err(Error::Parse { location, .. }) if more && location == header::UNFINISHED => {
                if want >= MAX_HEADER {
                    let line = 1 + bytes.iter().filter(|&&b| b == b'\n').count();
                    let message = format!(
                        "the header goes on past {} MiB without `end_header`: no PLY header is that long",
                        MAX_HEADER >> 20
                    );
                    return Err(Error::parse(path, format!("line {line}"), message));
                }
                want *= 2;
            }
            result => return result,
        }
    }
}
