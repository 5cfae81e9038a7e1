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

use crate::error::Result;
use crate::mesh::Mesh;
use header::Encoding;
use plan::Plan;
use std::path::Path;

/// The location of the error for a header that `end_header` does not finish.
pub(crate) const UNFINISHED_HEADER: &str = header::UNFINISHED;

/// Checks the header at the start of `bytes` without reading the body.
pub(crate) fn check_header(bytes: &[u8], path: &Path) -> Result<()> {
    header::parse(bytes, path).map(drop)
}

/// Parses a whole PLY file held in memory. `path` is used only in error messages.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let header = header::parse(bytes, path)?;
    let plan = Plan::new(&header, path)?;
    let body = bytes.get(header.body_start..).unwrap_or_default();
    match header.encoding {
        Encoding::Ascii => ascii::read(body, header.lines + 1, &header, &plan, path),
        Encoding::BinaryLittleEndian => binary::read(body, false, &header, &plan, path),
        Encoding::BinaryBigEndian => binary::read(body, true, &header, &plan, path),
    }
}
