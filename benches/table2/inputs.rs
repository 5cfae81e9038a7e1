//! The clouds of Table 2: the paper's kinds of input from `../shared/data` (clean and noisy
//! scans, with and without normals), and dense clouds drawn on igea's surface.

use crate::common::inputs::{cloud_surface, short_count, surface_cloud};
use std::path::Path;
use vstree::{io, Mesh};

/// What the input's normals are, and so what vstree does with them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normals {
    /// Given and oriented outward: kept.
    Given,
    /// Given, but inward or not globally consistent: re-oriented (consistent by propagation,
    /// then outward).
    Reoriented,
    /// None: estimated from 16 neighbours and oriented outward.
    Estimated,
}

impl Normals {
    pub fn describe(self) -> &'static str {
        match self {
            Normals::Given => "given",
            Normals::Reoriented => "given, re-oriented",
            Normals::Estimated => "estimated",
        }
    }
}

/// One input cloud.
pub struct Input {
    /// The file stem, or e.g. `igea 1M` for a cloud drawn on igea.
    pub name: String,
    /// Positions, and normals when the input has them.
    pub cloud: Mesh,
    pub normals: Normals,
}

/// The files of the table, in its order, with what their normals need. `igea.ply` is a mesh:
/// its vertices are used as a cloud without normals.
pub const MODELS: [(&str, Normals); 6] = [
    ("kitten.xyz", Normals::Given),
    ("ball.ply", Normals::Given),
    ("armadillo_points_normals.ply", Normals::Reoriented), // normals point inward
    ("bunny_scans_merged.ply", Normals::Estimated),        // ten raw scans, noisy, overlapping
    ("lion_takanawa.ply", Normals::Reoriented),            // normals not globally oriented
    ("igea.ply", Normals::Estimated),                      // vertices of a mesh
];

/// The stem of a file name.
pub fn stem(file: &str) -> &str {
    file.rsplit_once('.').map_or(file, |(s, _)| s)
}

/// Reads the model `file` of [`MODELS`] from `data` as a cloud; `None` (reported) when it
/// cannot be read.
pub fn model(data: &Path, file: &str, normals: Normals) -> Option<Input> {
    let path = data.join(file);
    let mesh = match io::read(&path) {
        Ok(mesh) => mesh,
        Err(e) => {
            eprintln!("table2: skipping {}: {e}", path.display());
            return None;
        }
    };
    let kept = match normals {
        Normals::Estimated => None,
        Normals::Given | Normals::Reoriented => mesh.normals,
    };
    if normals != Normals::Estimated && kept.is_none() {
        eprintln!("table2: {} has no normals: they will be estimated", path.display());
    }
    let normals = if kept.is_some() { normals } else { Normals::Estimated };
    Some(Input { name: stem(file).to_string(), cloud: Mesh::from_points(mesh.positions, kept), normals })
}

/// `count` points drawn on igea (or on a bumpy sphere without the data directory), with their
/// interpolated normals, as table1 draws them; and the surface's name.
pub fn drawn(data: &Path, count: usize) -> (String, Input) {
    let (surface_name, surface) = cloud_surface(data);
    let input = Input {
        name: format!("{surface_name} {}", short_count(count)),
        cloud: surface_cloud(&surface, count),
        normals: Normals::Given,
    };
    (surface_name, input)
}
