//! Dense clouds drawn on a mesh surface, and how the tables name their sizes.

use glam::Vec3;
use std::path::Path;
use vstree::{eval::shapes, io, Mesh, MeshSampling, SampleSet};

/// Seed of the clouds drawn on a surface: every table draws the same points.
const SEED: u64 = 2006;

/// The surface dense clouds are drawn on: igea (a model of the paper) with smooth vertex
/// normals, or a bumpy sphere when the data directory is absent. Returns its name too.
pub fn cloud_surface(data: &Path) -> (String, Mesh) {
    let igea = data.join("igea.ply");
    if let Ok(mut mesh) = io::read(&igea) {
        if let Ok(samples) = SampleSet::from_mesh(&mesh, MeshSampling::Vertices) {
            // Area-weighted vertex normals, so sampled normals vary smoothly like a scan's.
            let mut normals = vec![Vec3::ZERO; mesh.positions.len()];
            for (&v, &n) in samples.origin.iter().zip(&samples.normals) {
                normals[v as usize] = n;
            }
            mesh.normals = Some(normals);
            return ("igea".into(), mesh);
        }
    }
    ("bumpy sphere".into(), shapes::bumpy_sphere(1.0, 0.2, 6.0, 7))
}

/// `count` points drawn uniformly by area on `surface` (fixed seed), with unit normals
/// interpolated from its vertex normals: a point cloud.
pub fn surface_cloud(surface: &Mesh, count: usize) -> Mesh {
    shapes::sample_surface(surface, count, SEED)
}

/// `1000000` as `1M`, `1500` as `1.5k`.
pub fn short_count(n: usize) -> String {
    match n {
        n if n >= 1_000_000 && n % 1_000_000 == 0 => format!("{}M", n / 1_000_000),
        n if n >= 1_000_000 => format!("{:.1}M", n as f64 / 1e6),
        n if n >= 1_000 && n % 1_000 == 0 => format!("{}k", n / 1_000),
        n => n.to_string(),
    }
}
