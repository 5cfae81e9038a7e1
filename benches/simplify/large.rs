//! Large inputs for the simplification bench, generated, never committed: corpus meshes split
//! 1-to-4 until they reach the size asked for, with a little noise on every vertex (a twentieth
//! of the mean edge, so the split triangles are not coplanar). Written once under
//! `target/bench-simplify/large/` (the peers read files) and read back from there.

use rayon::prelude::*;
use std::path::{Path, PathBuf};
use vstree::{eval::shapes, io, Mesh};

/// The sizes `--large` takes: name, corpus mesh, 1-to-4 splits. The meshes have handles (bull
/// none, cheese 133, couplingdown 9, turbine 11), so keeping the genus is tested at every size.
pub const SIZES: [(&str, &str, u32); 4] =
    [("1M", "turbine", 3), ("3.5M", "bull", 4), ("14M", "cheese", 5), ("50M", "couplingdown", 7)];

/// Noise on every vertex, in mean edge lengths.
const NOISE_EDGES: f32 = 0.05;

/// The mesh of size `name` (one of [`SIZES`]) from the corpus in `data`, and its file: made
/// and written under `dir` when absent.
pub fn mesh(name: &str, data: &Path, dir: &Path) -> Result<(String, PathBuf, Mesh), String> {
    let &(_, model, splits) =
        SIZES.iter().find(|s| s.0 == name).ok_or_else(|| format!("unknown size {name} (one of 1M, 3.5M, 14M, 50M)"))?;
    let label = format!("{model} x{} ({name})", 1u32 << (2 * splits));
    let path = dir.join(format!("{model}-x{}.ply", 1u32 << (2 * splits)));
    if path.exists() {
        let mesh = io::read(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        return Ok((label, path, mesh));
    }
    let source = data.join("corpus").join(format!("{model}.off"));
    let mut mesh = io::read(&source).map_err(|e| format!("{}: {e}", source.display()))?;
    for _ in 0..splits {
        mesh = split(&mesh);
    }
    let edge = mean_edge(&mesh);
    shapes::add_noise(&mut mesh, NOISE_EDGES * edge, 0.0, 1);
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    io::write(&path, &mesh).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok((label, path, mesh))
}

/// Every triangle split into four at its edges' midpoints (shared by the two triangles of an
/// edge, so the mesh stays closed and keeps its genus).
fn split(mesh: &Mesh) -> Mesh {
    let key = |a: u32, b: u32| u64::from(a.min(b)) << 32 | u64::from(a.max(b));
    let mut edges: Vec<u64> =
        mesh.triangles.par_iter().flat_map_iter(|t| (0..3).map(move |k| key(t[k], t[(k + 1) % 3]))).collect();
    edges.par_sort_unstable();
    edges.dedup();
    let n = mesh.positions.len() as u32;
    let mid = |a: u32, b: u32| n + edges.binary_search(&key(a, b)).unwrap_or(0) as u32;
    let mut positions = mesh.positions.clone();
    positions
        .extend(edges.iter().map(|&e| (mesh.positions[(e >> 32) as usize] + mesh.positions[e as u32 as usize]) / 2.0));
    let triangles = mesh
        .triangles
        .par_iter()
        .flat_map_iter(|&[a, b, c]| {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        })
        .collect();
    Mesh::new(positions, None, triangles)
}

/// The mean edge length over the first thousand triangles.
fn mean_edge(mesh: &Mesh) -> f32 {
    let some = &mesh.triangles[..mesh.triangles.len().min(1000)];
    let p = |v: u32| mesh.positions[v as usize];
    let sum: f32 = some.iter().map(|t| (0..3).map(|k| p(t[k]).distance(p(t[(k + 1) % 3]))).sum::<f32>()).sum();
    sum / (3 * some.len()).max(1) as f32
}
