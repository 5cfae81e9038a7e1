//! Deciding what each element and property of a PLY file is used for: positions and normals
//! from `vertex`, triangles from `face`, everything else skipped.

use super::header::{Element, Header, Kind};
use crate::error::{Error, Result};
use crate::io::assemble;
use std::path::Path;

/// What one property's values are used for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    Skip,
    /// Slot in `[x, y, z, nx, ny, nz]`.
    Coord(usize),
    /// The face's vertex index list.
    Indices,
}

/// What one element's items become.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    Vertices,
    Faces,
    Nothing,
}

/// The use of one element and of each of its properties.
#[derive(Clone, Debug)]
pub(crate) struct Job {
    pub target: Target,
    pub roles: Vec<Role>,
}

/// The jobs for all elements in header order, plus what the mesh will contain.
#[derive(Clone, Debug)]
pub(crate) struct Plan {
    pub jobs: Vec<Job>,
    pub vertex_count: usize,
    pub has_normals: bool,
}

const COORDS: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];

impl Plan {
    /// Plans the reading of `header`'s elements, rejecting files without usable vertices.
    pub(crate) fn new(header: &Header, path: &Path) -> Result<Plan> {
        let at = |e: &Element, message: String| Error::parse(path, format!("line {}", e.line), message);
        let mut jobs = Vec::with_capacity(header.elements.len());
        let (mut vertex, mut face) = (None, None);
        for element in &header.elements {
            let slot = match element.name.as_str() {
                "vertex" => &mut vertex,
                "face" => &mut face,
                _ => {
                    jobs.push(Job { target: Target::Nothing, roles: vec![Role::Skip; element.properties.len()] });
                    continue;
                }
            };
            if slot.is_some() {
                return Err(at(element, format!("second `{}` element", element.name)));
            }
            *slot = Some(element);
            jobs.push(if element.name == "vertex" {
                vertex_job(element).map_err(|m| at(element, m))?
            } else {
                face_job(element).map_err(|m| at(element, m))?
            });
        }
        let vertex = vertex.ok_or_else(|| Error::parse(path, "header", "no `vertex` element"))?;
        assemble::vertex_count_fits(vertex.count).map_err(|m| Error::TooLarge(format!("{}: {m}", path.display())))?;
        let has_normals = jobs.iter().any(|j| j.roles.contains(&Role::Coord(3)));
        Ok(Plan { jobs, vertex_count: vertex.count, has_normals })
    }
}

/// x, y, z are required scalars; nx, ny, nz are used only when all three are present.
fn vertex_job(element: &Element) -> Result<Job, String> {
    let find = |name: &str| element.properties.iter().position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)));
    let found: Vec<Option<usize>> = COORDS.iter().map(|n| find(n)).collect();
    if let Some(missing) = (0..3).find(|&k| found[k].is_none()) {
        return Err(format!("the vertex element has no scalar `{}` property", COORDS[missing]));
    }
    let used = if found[3..].iter().all(Option::is_some) { 6 } else { 3 };
    let mut roles = vec![Role::Skip; element.properties.len()];
    for (slot, index) in found.iter().enumerate().take(used) {
        if let Some(i) = index {
            roles[*i] = Role::Coord(slot);
        }
    }
    Ok(Job { target: Target::Vertices, roles })
}

/// The first list named `vertex_indices` or `vertex_index` holds the polygon.
fn face_job(element: &Element) -> Result<Job, String> {
    let indices = element
        .properties
        .iter()
        .position(|p| matches!(p.kind, Kind::List { .. }) && (p.name == "vertex_indices" || p.name == "vertex_index"));
    let mut roles = vec![Role::Skip; element.properties.len()];
    match indices {
        Some(i) => roles[i] = Role::Indices,
        None if element.count > 0 => return Err("the face element has no `vertex_indices` list".into()),
        None => {}
    }
    Ok(Job { target: Target::Faces, roles })
}
