//! Reading elements item by item, property by property, from either encoding. This is the
//! general path; binary files take a faster one for elements without lists.

use super::header::{Element, Kind};
use super::plan::{Job, Role, Target};
use super::scalar::Scalar;
use crate::error::{Error, Result};
use crate::io::assemble;
use crate::mesh::Mesh;
use glam::Vec3;
use std::path::Path;

/// Why reading a value failed.
pub(crate) enum Fail {
    /// The data ended.
    End,
    /// The data is malformed; the message says how.
    Bad(String),
}

/// A source of values: tokens of an ASCII body, or bytes of a binary one.
pub(crate) trait Cursor {
    /// Reads a value that becomes an `f32` coordinate.
    fn coord(&mut self, ty: Scalar) -> Result<f32, Fail>;
    /// Reads any other value (counts, indices, skipped values).
    fn number(&mut self, ty: Scalar) -> Result<f64, Fail>;
    /// Skips a whole list.
    fn skip_list(&mut self, count: Scalar, item: Scalar) -> Result<(), Fail> {
        let n = list_length(self.number(count)?)?;
        for _ in 0..n {
            self.number(item)?;
        }
        Ok(())
    }
    /// Bytes not yet read.
    fn remaining(&self) -> usize;
    /// The line of the last value read, for text; `None` for binary.
    fn line(&self) -> Option<usize>;
}

/// Positions, normals and triangles as they are read.
pub(crate) struct Parts {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub triangles: Vec<[u32; 3]>,
    /// The vertex count the header declares; face indices are checked against it.
    pub vertex_count: usize,
}

impl Parts {
    /// Empty parts for a file with `vertex_count` vertices.
    pub(crate) fn new(vertex_count: usize, has_normals: bool) -> Parts {
        Parts { positions: Vec::new(), normals: has_normals.then(Vec::new), triangles: Vec::new(), vertex_count }
    }

    /// Reserves room for `n` more vertices.
    pub(crate) fn reserve_vertices(&mut self, n: usize) {
        self.positions.reserve(n);
        if let Some(normals) = &mut self.normals {
            normals.reserve(n);
        }
    }

    /// Adds one vertex from `[x, y, z, nx, ny, nz]`.
    #[inline]
    pub(crate) fn push_vertex(&mut self, c: [f32; 6]) -> Result<(), String> {
        let p = assemble::finite_position(Vec3::new(c[0], c[1], c[2]))?;
        self.positions.push(p);
        if let Some(normals) = &mut self.normals {
            normals.push(Vec3::new(c[3], c[4], c[5]));
        }
        Ok(())
    }

    /// The finished mesh.
    pub(crate) fn into_mesh(self) -> Mesh {
        Mesh { positions: self.positions, normals: self.normals, triangles: self.triangles }
    }
}

/// A list length read as a number.
pub(crate) fn list_length(value: f64) -> Result<usize, Fail> {
    if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
        Ok(value as usize)
    } else {
        Err(Fail::Bad(format!("invalid list length {value}")))
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
        (Fail::End, line) => Error::parse(
            path,
            line.map_or(subject.clone(), |n| format!("line {n}")),
            format!("file ends in {subject} of {}", element.count),
        ),
        (Fail::Bad(message), Some(n)) => Error::parse(path, format!("line {n}"), format!("{subject}: {message}")),
        (Fail::Bad(message), None) => Error::parse(path, subject, message),
    }
}

/// Reads all items of `element`, adding what `job` asks for to `parts`.
pub(crate) fn read_element<C: Cursor>(
    cursor: &mut C,
    element: &Element,
    job: &Job,
    parts: &mut Parts,
    path: &Path,
) -> Result<()> {
    if element.properties.is_empty() {
        return Ok(()); // nothing is stored, however many items there are
    }
    let min_bytes = 2 * element.properties.len();
    let room = assemble::capacity(element.count, cursor.remaining(), min_bytes);
    match job.target {
        Target::Vertices => parts.reserve_vertices(room),
        Target::Faces => parts.triangles.reserve(room),
        Target::Nothing => {}
    }
    let mut coords = [0.0f32; 6];
    let mut polygon = Vec::new();
    for item in 0..element.count {
        read_item(cursor, element, job, parts.vertex_count, &mut coords, &mut polygon)
            .and_then(|()| match job.target {
                Target::Vertices => parts.push_vertex(coords).map_err(Fail::Bad),
                Target::Faces => assemble::push_fan(&polygon, &mut parts.triangles).map_err(Fail::Bad),
                Target::Nothing => Ok(()),
            })
            .map_err(|fail| error(path, cursor.line(), element, item, fail))?;
    }
    Ok(())
}

/// Reads one item's properties into `coords` and `polygon`.
fn read_item<C: Cursor>(
    cursor: &mut C,
    element: &Element,
    job: &Job,
    vertex_count: usize,
    coords: &mut [f32; 6],
    polygon: &mut Vec<u32>,
) -> Result<(), Fail> {
    polygon.clear();
    for (property, role) in element.properties.iter().zip(&job.roles) {
        match (property.kind, *role) {
            (Kind::Scalar(ty), Role::Coord(slot)) => {
                if let Some(c) = coords.get_mut(slot) {
                    *c = cursor.coord(ty)?;
                }
            }
            (Kind::Scalar(ty), _) => {
                cursor.number(ty)?;
            }
            (Kind::List { count, item }, Role::Indices) => {
                let n = list_length(cursor.number(count)?)?;
                for _ in 0..n {
                    polygon.push(index(cursor.number(item)?, vertex_count)?);
                }
            }
            (Kind::List { count, item }, _) => cursor.skip_list(count, item)?,
        }
    }
    Ok(())
}
