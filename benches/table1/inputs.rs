//! The benchmark's inputs: every mesh with triangles in the data directory (sampled at its
//! vertices), and dense clouds drawn on a mesh surface.

use crate::common::inputs::surface_cloud;
use std::path::{Path, PathBuf};
use vstree::{io, Mesh, MeshSampling, SampleSet};

/// One input of the table.
pub struct Input {
    /// Short name: the file stem, or e.g. `igea 5M` for a generated cloud.
    pub name: String,
    /// The source file, for meshes read from the data directory.
    pub path: Option<PathBuf>,
    /// The mesh, for inputs with triangles (generated clouds have none).
    pub mesh: Option<Mesh>,
    pub samples: SampleSet,
}

/// Extensions `vstree::io` reads.
const EXTENSIONS: [&str; 5] = ["ply", "obj", "off", "xyz", "pwn"];

/// The meshes (inputs with triangles) in `data`, ordered by sample count, optionally only those
/// whose stem is in `only`. Files that fail to read are reported and skipped.
pub fn models(data: &Path, only: Option<&[String]>) -> Vec<Input> {
    let Ok(entries) = std::fs::read_dir(data) else {
        eprintln!("table1: {} is absent: only generated inputs will run", data.display());
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .filter(|p| only.is_none_or(|names| names.iter().any(|n| *n == stem(p))))
        .collect();
    paths.sort();
    let mut inputs: Vec<Input> = paths.iter().filter_map(|p| model(p)).collect();
    inputs.sort_by_key(|i| i.samples.len());
    inputs
}

fn stem(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The mesh at `path` with its vertex samples, or `None` for point clouds and unreadable files.
fn model(path: &Path) -> Option<Input> {
    let mesh = match io::read(path) {
        Ok(mesh) => mesh,
        Err(e) => {
            eprintln!("table1: skipping {}: {e}", path.display());
            return None;
        }
    };
    if mesh.is_point_cloud() {
        return None;
    }
    let samples = match SampleSet::from_mesh(&mesh, MeshSampling::Vertices) {
        Ok(samples) => samples,
        Err(e) => {
            eprintln!("table1: skipping {}: {e}", path.display());
            return None;
        }
    };
    Some(Input { name: stem(path), path: Some(path.to_path_buf()), mesh: Some(mesh), samples })
}

/// `count` samples drawn uniformly by area on `surface` (fixed seed), with their normals.
pub fn cloud(surface: &Mesh, count: usize) -> SampleSet {
    let cloud = surface_cloud(surface, count);
    // `sample_surface` already gives unit normals: move them instead of copying.
    let normals = cloud.normals.unwrap_or_default();
    SampleSet { origin: (0..cloud.positions.len() as u32).collect(), positions: cloud.positions, normals }
}
