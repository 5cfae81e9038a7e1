//! Shared helpers for the integration tests: the real models in `../shared/data` (skipped with
//! a message when absent, a failure under CI) and the samples of a mesh or cloud.
#![allow(dead_code)]

pub mod ffi;
pub mod scratch;

use std::path::PathBuf;
use vstree::{Mesh, MeshSampling, SampleSet};

/// The real models' folder: `VSTREE_DATA` when set, else `../shared/data`; `None` (after
/// saying so) when it is absent. Where the models are expected (`CI` or `VSTREE_DATA` set), an
/// absent folder fails the test instead, so a run without them cannot pass silently.
pub fn data_dir() -> Option<PathBuf> {
    let named = std::env::var_os("VSTREE_DATA").map(PathBuf::from);
    let expected = named.is_some() || std::env::var_os("CI").is_some();
    let dir = named.unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    if dir.is_dir() {
        Some(dir)
    } else if expected {
        panic!("{} not found, and CI or VSTREE_DATA says the real models must be there", dir.display());
    } else {
        eprintln!("skipping: {} not found", dir.display());
        None
    }
}

/// Loads model `name` from [`data_dir`], or `None` when the folder is absent (and the models are
/// not expected). A model missing from a folder that is there fails the test.
pub fn load(name: &str) -> Option<Mesh> {
    let path = data_dir()?.join(name);
    assert!(path.is_file(), "{} not found", path.display());
    Some(vstree::io::read(&path).unwrap_or_else(|e| panic!("{name}: {e}")))
}

/// Every model in `../shared/data` (empty when the folder is absent).
pub fn all_models() -> Vec<(String, Mesh)> {
    data_dir().map_or_else(Vec::new, |dir| models_in(&dir))
}

/// Every model of a format vstree reads in `dir`, by name.
fn models_in(dir: &std::path::Path) -> Vec<(String, Mesh)> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| vstree::io::Format::from_path(n.as_ref()).is_some())
        .collect();
    names.sort();
    names
        .into_iter()
        .map(|n| {
            let mesh = vstree::io::read(&dir.join(&n)).unwrap_or_else(|e| panic!("{n}: {e}"));
            (n, mesh)
        })
        .collect()
}

/// The samples the library would use: mesh vertices, or the cloud's points with their normals
/// (estimated when the cloud has none).
pub fn samples_of(mesh: &Mesh) -> SampleSet {
    if mesh.is_point_cloud() {
        let mut cloud = mesh.clone();
        // Clouds without normals (raw scans) get them estimated, as `vstree stats` does.
        vstree::normals::ensure_normals(&mut cloud, &Default::default(), &mut vstree::Progress::none()).unwrap();
        SampleSet::from_cloud(&cloud).unwrap()
    } else {
        SampleSet::from_mesh(mesh, MeshSampling::Vertices).unwrap()
    }
}

/// Every mesh of `../shared/data/corpus` (empty when the folder is absent).
pub fn corpus_models() -> Vec<(String, Mesh)> {
    data_dir().map(|d| d.join("corpus")).filter(|d| d.is_dir()).map_or_else(Vec::new, |dir| models_in(&dir))
}
