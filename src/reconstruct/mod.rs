//! Surface reconstruction from a point cloud (paper §5, POINT_TO_MESH), in stages:
//!
//! 0. the cloud as oriented samples at unit size: isolated points left out, normals estimated
//!    where the cloud has none ([`prepare`], [`crate::normals`]);
//! 1. the samples' noise measured ([`noise`]) and the VS-Tree built allowing for it: the
//!    height-field test and the L2 bound look past the noise, so the T-layer and the quadtrees
//!    stop where the surface's shape, not its noise, is resolved (the L2 bound is the
//!    de-noising control for what the noise does not explain) ([`t_layer`]);
//! 2. the base mesh M0, one vertex per T-node ([`base_mesh`]): an implicit function whose sign
//!    is inside or outside ([`field`]; by default the samples' winding number, [`winding`]) is
//!    polygonised over the tree's octree ([`dual_contour`], the default for a closed output)
//!    or on a grid as fine as the deepest T-node ([`on_grid`]; an open output, and where the
//!    octree's polygonisation is no 2-manifold) and clustered at the T-layer ([`cluster`]);
//! 3. refinement ([`levels`]): split 1-to-4 on PN triangles (with a target distance, only the
//!    regions of M0 whose samples are farther than it, with [`red_green`] transitions between
//!    regions of different levels) and displace by the quadtrees
//!    ([`refine`]); every vertex of M0 and of each level is then projected onto a local
//!    quadratic fit of its nearest samples ([`mls`]; more of them the noisier the cloud), until
//!    the mesh is close enough to the samples or the quadtrees have no detail left. M0 is
//!    remeshed and each level's new vertices relaxed ([`relax`]), and folds are unfolded onto
//!    the samples' fit ([`folds::unfold`]); what unfolding leaves after the last level, mostly
//!    slivers, is collapsed ([`slivers`]);
//! 4. where much of the closed surface has no sample supporting it (an open scan; see
//!    [`Closure`]), only the supported part is kept ([`support`]), and faces past the scan's
//!    border trimmed ([`trim`]).
//!
//! error(M, S), where the paper leaves it open: the root mean square of the distances from the
//! samples (at most [`ERROR_SAMPLES`] of them, evenly spread) to the mesh, over the bounding
//! box's diagonal; the maximum is reported too.

mod adjacency;
mod base_mesh;
mod cluster;
mod dual_contour;
mod field;
mod folds;
mod implicit;
mod leaf_fit;
mod levels;
mod lookup;
mod mls;
mod noise;
mod on_grid;
mod outliers;
mod params;
mod prepare;
mod red_green;
mod refine;
mod regions;
mod relax;
mod slivers;
mod support;
mod t_layer;
mod thicken;
mod trim;
mod winding;

pub use params::{BaseMesh, ReconstructParams, ReconstructStats, RefinementStop};
pub use refine::LevelStats;
pub use support::Closure;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use glam::Vec3;
use std::time::Instant;

/// At most this many samples are measured for error(M, S).
pub const ERROR_SAMPLES: usize = 100_000;
/// Fewer points than this cannot define a surface.
pub const MIN_POINTS: usize = 10;

/// Reconstructs a triangle mesh from a point cloud with (outward) normals.
pub fn reconstruct(
    cloud: &Mesh,
    params: &ReconstructParams,
    progress: &mut Progress,
) -> Result<(Mesh, ReconstructStats)> {
    params.check()?;
    let threads = Threads::new(params.threads)?;
    let mut stats = ReconstructStats::default();
    let start = Instant::now();
    let (samples, scale) =
        prepare::oriented_samples(cloud, params, &threads, &mut stats, &mut progress.stage(0.0, 0.15))?;
    stats.seconds_normals = start.elapsed().as_secs_f64();
    crate::memory::release_freed();

    let t0 = Instant::now();
    let tree = t_layer::tree(&samples, params, &threads, &mut stats, &mut progress.stage(0.15, 0.35))?;
    // The tree holds the samples from here on.
    drop(samples);
    crate::memory::release_freed();
    // Where error(M, S) is measured: in the tree's order, nearby samples one after the other,
    // so the measure finds the same parts of the mesh in cache.
    let measured: Vec<Vec3> = evenly_spread(&tree.samples, ERROR_SAMPLES).iter().map(|s| s.position).collect();
    let t1 = Instant::now();

    progress.report(0.35, "base mesh")?;
    let near = lookup::Lookup::new(&tree, &threads)?;
    let base = base_mesh::build(&near, params, &threads, &mut stats, progress)?;
    let (open, grid_cell) = (base.open, base.grid_cell);
    stats.open = open;
    crate::memory::release_freed();
    let t2 = Instant::now();

    let surface = levels::refine(base, &near, &measured, params, &threads, &mut stats, progress)?;
    let t3 = Instant::now();

    progress.report(0.95, "trimming")?;
    let mut mesh = Mesh {
        positions: surface.positions,
        normals: Some(surface.normals),
        triangles: surface.triangles,
        origin: cloud.origin,
    };
    if open {
        stats.trimmed_triangles = trim::open_output(&mut mesh, &near, params.trim, grid_cell, &threads);
    }
    mesh.positions.iter_mut().for_each(|p| *p /= scale);
    stats.seconds_trim = t3.elapsed().as_secs_f64();
    progress.report(1.0, "done")?;
    stats.output_vertices = mesh.positions.len();
    stats.output_triangles = mesh.triangles.len();
    stats.seconds_tree = (t1 - t0).as_secs_f64();
    stats.seconds_base = (t2 - t1).as_secs_f64();
    stats.seconds_refine = (t3 - t2).as_secs_f64();
    Ok((mesh, stats))
}

/// At most `n` of `points`, evenly spread through the slice.
fn evenly_spread<T: Copy>(points: &[T], n: usize) -> Vec<T> {
    let step = points.len().div_ceil(n.max(1)).max(1);
    points.iter().step_by(step).copied().collect()
}

/// Renumbers the vertices that `triangles` use 0, 1, ... in the order they first appear, and
/// returns the old index of each new one (vertices no triangle uses are left out).
pub(crate) fn renumber_used_vertices(triangles: &mut [[u32; 3]], vertices: usize) -> Vec<usize> {
    let mut index = vec![u32::MAX; vertices];
    let mut kept = Vec::new();
    for v in triangles.iter_mut().flatten() {
        if index[*v as usize] == u32::MAX {
            index[*v as usize] = kept.len() as u32;
            kept.push(*v as usize);
        }
        *v = index[*v as usize];
    }
    kept
}
