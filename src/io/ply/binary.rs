//! The body of a binary PLY file. Elements whose properties are all scalars have a fixed
//! stride, so they are decoded straight from the byte slice at precomputed offsets; elements
//! with lists (faces) are read item by item.

use super::header::{Element, Header, Kind};
use super::items::{self, Cursor, Fail, Sink};
use super::plan::{Job, Plan, Role, Target};
use super::scalar::Scalar;
use crate::error::Result;
use crate::io::assemble;
use crate::io::input::Input;
use std::path::Path;

/// Reads the body that starts at byte `start` of `input`, in the given byte order, into `sink`.
pub(crate) fn read(
    input: &mut Input,
    start: usize,
    big_endian: bool,
    header: &Header,
    plan: &Plan,
    sink: &mut impl Sink,
    path: &Path,
) -> Result<()> {
    let mut cursor = Bytes { input, pos: start, big_endian };
    for (element, job) in header.elements.iter().zip(&plan.jobs) {
        if job.target == Target::Faces && !sink.wants_faces() {
            break;
        }
        match fixed_layout(element, job) {
            Some(layout) => read_fixed(&mut cursor, element, &layout, sink, path)?,
            None => items::read_element(&mut cursor, element, job, plan.vertex_count, sink, path)?,
        }
    }
    Ok(())
}

/// Fixed-size items are decoded in blocks of about this many bytes (1 MiB), so that a
/// streaming input holds one block at a time.
const BLOCK: usize = 1 << 20;

/// Where to find the used values inside one fixed-size item.
struct Layout {
    stride: usize,
    /// `(byte offset, type, slot in [x, y, z, nx, ny, nz])` of each used property.
    fields: Vec<(usize, Scalar, usize)>,
    vertices: bool,
}

/// The layout of `element` when none of its properties is a list.
fn fixed_layout(element: &Element, job: &Job) -> Option<Layout> {
    let mut stride = 0usize;
    let mut fields = Vec::new();
    for (property, role) in element.properties.iter().zip(&job.roles) {
        let Kind::Scalar(ty) = property.kind else {
            return None;
        };
        if let Role::Coord(slot) = *role {
            fields.push((stride, ty, slot));
        }
        stride = stride.checked_add(ty.size())?;
    }
    Some(Layout { stride, fields, vertices: job.target == Target::Vertices })
}

/// Decodes (or skips) all items of a fixed-size element, a block of items at a time.
fn read_fixed(cursor: &mut Bytes, element: &Element, layout: &Layout, sink: &mut impl Sink, path: &Path) -> Result<()> {
    if layout.stride == 0 {
        return Ok(());
    }
    let big_endian = cursor.big_endian;
    let start = cursor.pos;
    let decode = layout.vertices && sink.wants_vertices();
    if decode {
        let room = assemble::capacity(element.count, cursor.remaining(), layout.stride);
        sink.reserve_vertices(room).map_err(|fail| items::error(path, None, element, 0, fail))?;
    }
    let per_block = (BLOCK / layout.stride).max(1);
    let mut coords = [0.0f64; 6];
    let mut first = 0;
    while first < element.count {
        let n = per_block.min(element.count - first);
        let Some(block) = cursor.take(n * layout.stride) else {
            let item = cursor.input.end().saturating_sub(start) / layout.stride;
            return Err(items::error(path, None, element, item, Fail::End));
        };
        if decode {
            for (k, bytes) in block.chunks_exact(layout.stride).enumerate() {
                let mut decoded = Ok(());
                for &(offset, ty, slot) in &layout.fields {
                    match bytes.get(offset..).and_then(|b| ty.decode(b, big_endian)) {
                        Some(value) => coords[slot] = value,
                        None => decoded = Err(Fail::End),
                    }
                }
                decoded
                    .and_then(|()| sink.vertex(coords))
                    .map_err(|fail| items::error(path, None, element, first + k, fail))?;
            }
        }
        cursor.release();
        first += n;
    }
    Ok(())
}

/// A position in a binary body.
struct Bytes<'i, 'a> {
    input: &'i mut Input<'a>,
    pos: usize,
    big_endian: bool,
}

impl Bytes<'_, '_> {
    /// The next `n` bytes, or `None` (without moving) if fewer are left.
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        let start = self.pos;
        let end = start.checked_add(n)?;
        if self.input.get(start, n).len() < n {
            return None;
        }
        self.pos = end;
        Some(self.input.get(start, n))
    }
}

impl Cursor for Bytes<'_, '_> {
    #[inline]
    fn number(&mut self, ty: Scalar) -> Result<f64, Fail> {
        let big_endian = self.big_endian;
        let bytes = self.take(ty.size()).ok_or(Fail::End)?;
        ty.decode(bytes, big_endian).ok_or(Fail::End)
    }

    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail> {
        let size = n.checked_mul(ty.size()).ok_or(Fail::End)?;
        self.take(size).map(drop).ok_or(Fail::End)
    }

    fn remaining(&self) -> usize {
        self.input.remaining(self.pos)
    }

    #[inline]
    fn release(&mut self) {
        self.input.release(self.pos);
    }

    fn line(&self) -> Option<usize> {
        None
    }
}
