//! Reading elements item by item, property by property, from either encoding. This is the
//! general path; binary files take a faster one for elements without lists. In ASCII each
//! item is one line, so the cursor also checks that the line holds exactly the item's values.

use super::header::{Element, Kind};
use super::plan::{Job, Role, Target};
use super::scalar::Scalar;
use crate::error::{Error, Result};
use crate::io::assemble;
#[cfg(doc)]
use crate::io::input::Input;
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use std::path::Path;

/// Why reading a value failed.
pub(crate) enum Fail {
    /// The data ended.
    End,
    /// The data is malformed; the message says how.
    Bad(String),
    /// The item's line (text only) holds `found` values, fewer or more than the item needs.
    /// [`read_element`] turns this into a message with the expected count.
    Count { found: usize },
    /// The sink stopped the reading with this error (the user cancelled, or the file cannot be
    /// streamed as it is laid out); it is passed on as it is.
    Stop(Error),
}

/// A source of values: tokens of an ASCII body, or bytes of a binary one.
pub(crate) trait Cursor {
    /// Reads one value (coordinates, counts, indices, skipped values).
    fn number(&mut self, ty: Scalar) -> Result<f64, Fail>;
    /// Skips `n` values of type `ty` (the items of a list).
    fn skip(&mut self, ty: Scalar, n: usize) -> Result<(), Fail> {
        for _ in 0..n {
            self.number(ty)?;
        }
        Ok(())
    }
    /// Called before each item; a text cursor moves to the item's line.
    fn start_item(&mut self) -> Result<(), Fail> {
        Ok(())
    }
    /// Called after each item; a text cursor checks that nothing is left on its line.
    fn finish_item(&mut self) -> Result<(), Fail> {
        Ok(())
    }
    /// Bytes not yet read.
    fn remaining(&self) -> usize;
    /// Says that what was read so far will not be looked at again (see [`Input::release`]).
    fn release(&mut self);
    /// The line of the current item, for text; `None` for binary.
    fn line(&self) -> Option<usize>;
}

/// What receives the items of a PLY body as they are read: vertices as `[x, y, z, nx, ny,
/// nz]` (normals zero when the file has none) and polygons as checked vertex indices.
pub(crate) trait Sink {
    /// Whether vertices are wanted; when not, they are still checked to be there, not decoded.
    fn wants_vertices(&self) -> bool {
        true
    }
    /// Whether faces are wanted; when not, reading stops at the `face` element.
    fn wants_faces(&self) -> bool {
        true
    }
    /// Room for `n` more vertices (a header's count, bounded by the bytes left); a sink that
    /// holds something per vertex refuses a count it has no memory for.
    fn reserve_vertices(&mut self, _n: usize) -> Result<(), Fail> {
        Ok(())
    }
    /// Room for `n` more polygons.
    fn reserve_polygons(&mut self, _n: usize) {}
    fn vertex(&mut self, c: [f64; 6]) -> Result<(), Fail>;
    fn polygon(&mut self, polygon: &[u32]) -> Result<(), Fail>;
}

/// Positions, normals and triangles as they are read.
pub(crate) struct Parts {
    /// As read, in f64 (see [`assemble::mesh`]).
    pub positions: Vec<DVec3>,
    pub normals: Option<Vec<Vec3>>,
    pub triangles: Vec<[u32; 3]>,
}

impl Parts {
    /// Empty parts, with normals if the file has them.
    pub(crate) fn new(has_normals: bool) -> Parts {
        Parts { positions: Vec::new(), normals: has_normals.then(Vec::new), triangles: Vec::new() }
    }

    /// The finished mesh.
    pub(crate) fn into_mesh(self) -> Mesh {
        assemble::mesh(self.positions, self.normals, self.triangles)
    }
}

impl Sink for Parts {
    fn reserve_vertices(&mut self, n: usize) -> Result<(), Fail> {
        self.positions.reserve(n);
        if let Some(normals) = &mut self.normals {
            normals.reserve(n);
        }
        Ok(())
    }

    fn reserve_polygons(&mut self, n: usize) {
        self.triangles.reserve(n);
    }

    #[inline]
    fn vertex(&mut self, c: [f64; 6]) -> Result<(), Fail> {
        self.positions.push(position(c)?);
        if let Some(normals) = &mut self.normals {
            normals.push(assemble::finite_normal(DVec3::new(c[3], c[4], c[5]).as_vec3()).map_err(Fail::Bad)?);
        }
        Ok(())
    }

    fn polygon(&mut self, polygon: &[u32]) -> Result<(), Fail> {
        assemble::push_fan(polygon, &mut self.triangles).map_err(Fail::Bad)
    }
}

/// The checked position of a vertex read as `[x, y, z, ...]`.
#[inline]
pub(crate) fn position(c: [f64; 6]) -> Result<DVec3, Fail> {
    assemble::finite_position(DVec3::new(c[0], c[1], c[2])).map_err(Fail::Bad)
}

/// A list length read as a number.
fn list_length(value: f64) -> Result<usize, Fail> {
    if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
        Ok(value as usize)
    } else {
        Err(Fail::Bad(format!("invalid list length {value}")))
    }
}

/// How many values one item needs, as far as is known while reading it: one per scalar, and
/// one (the length) plus the length per list. Lists not read yet count only their length.
#[derive(Clone, Copy)]
struct Expected {
    values: usize,
    unread_lists: usize,
}

impl Expected {
    fn new(element: &Element) -> Expected {
        let lists = element.properties.iter().filter(|p| matches!(p.kind, Kind::List { .. })).count();
        Expected { values: element.properties.len(), unread_lists: lists }
    }

    /// Records a list of length `n`.
    fn list(&mut self, n: usize) {
        self.values = self.values.saturating_add(n);
        self.unread_lists = self.unread_lists.saturating_sub(1);
    }

    /// Replaces a [`Fail::Count`] by a message saying how many values were expected.
    fn explain(self, fail: Fail) -> Fail {
        match fail {
            Fail::Count { found } => {
                let at_least = if self.unread_lists > 0 { "at least " } else { "" };
                let plural = if self.values == 1 { "" } else { "s" };
                Fail::Bad(format!("expected {at_least}{} value{plural}, found {found}", self.values))
            }
            other => other,
        }
    }
}

/// A vertex index read as a number, checked against the vertex count.
fn index(value: f64, vertex_count: usize) -> Result<u32, Fail> {
    if value.fract() != 0.0 || !value.is_finite() {
        return Err(Fail::Bad(format!("vertex index {value} is not an integer")));
    }
    assemble::vertex_index(value as i64, vertex_count).map_err(Fail::Bad)
}

/// The error for item `item` of `element`: located by line for text, by item for binary.
pub(crate) fn error(path: &Path, line: Option<usize>, element: &Element, item: usize, fail: Fail) -> Error {
    let subject = format!("{} {item}", element.name);
    match (fail, line) {
        (Fail::Stop(error), _) => error,
        (Fail::End, line) => Error::parse(
            path,
            line.map_or(subject.clone(), |n| format!("line {n}")),
            format!("file ends after {item} of the {} `{}` elements", element.count, element.name),
        ),
        (Fail::Bad(message), Some(n)) => Error::parse(path, format!("line {n}"), format!("{subject}: {message}")),
        (Fail::Bad(message), None) => Error::parse(path, subject, message),
        // read_element explains counts; this is a fallback that names the count alone.
        (Fail::Count { found }, line) => Error::parse(
            path,
            line.map_or(subject.clone(), |n| format!("line {n}")),
            format!("{subject}: {found} values do not match the element's properties"),
        ),
    }
}

/// Reads all items of `element`, giving what `job` asks for to `sink`.
pub(crate) fn read_element<C: Cursor>(
    cursor: &mut C,
    element: &Element,
    job: &Job,
    vertex_count: usize,
    sink: &mut impl Sink,
    path: &Path,
) -> Result<()> {
    if element.properties.is_empty() {
        return Ok(()); // nothing is stored, however many items there are
    }
    let min_bytes = 2 * element.properties.len();
    let room = assemble::capacity(element.count, cursor.remaining(), min_bytes);
    let wanted = match job.target {
        Target::Vertices if sink.wants_vertices() => {
            sink.reserve_vertices(room).map_err(|fail| error(path, cursor.line(), element, 0, fail))?;
            Target::Vertices
        }
        Target::Faces => {
            sink.reserve_polygons(room);
            Target::Faces
        }
        _ => Target::Nothing,
    };
    let mut coords = [0.0f64; 6];
    let mut polygon = Vec::new();
    let fresh = Expected::new(element);
    for item in 0..element.count {
        let mut expected = fresh;
        cursor
            .start_item()
            .and_then(|()| read_item(cursor, element, job, vertex_count, &mut coords, &mut polygon, &mut expected))
            .and_then(|()| cursor.finish_item())
            .and_then(|()| match wanted {
                Target::Vertices => sink.vertex(coords),
                Target::Faces => sink.polygon(&polygon),
                Target::Nothing => Ok(()),
            })
            .map_err(|fail| error(path, cursor.line(), element, item, expected.explain(fail)))?;
        cursor.release();
    }
    Ok(())
}

/// Reads one item's properties into `coords` and `polygon`, counting list lengths into
/// `expected` as they are read.
fn read_item<C: Cursor>(
    cursor: &mut C,
    element: &Element,
    job: &Job,
    vertex_count: usize,
    coords: &mut [f64; 6],
    polygon: &mut Vec<u32>,
    expected: &mut Expected,
) -> Result<(), Fail> {
    polygon.clear();
    for (property, role) in element.properties.iter().zip(&job.roles) {
        match (property.kind, *role) {
            (Kind::Scalar(ty), Role::Coord(slot)) => {
                if let Some(c) = coords.get_mut(slot) {
                    *c = cursor.number(ty)?;
                }
            }
            (Kind::Scalar(ty), _) => {
                cursor.number(ty)?;
            }
            (Kind::List { count, item }, role) => {
                let n = list_length(cursor.number(count)?)?;
                expected.list(n);
                if role == Role::Indices {
                    for _ in 0..n {
                        polygon.push(index(cursor.number(item)?, vertex_count)?);
                    }
                } else {
                    cursor.skip(item, n)?;
                }
            }
        }
    }
    Ok(())
}
