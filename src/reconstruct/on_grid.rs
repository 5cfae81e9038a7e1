//! The base mesh's implicit function polygonised on a uniform grid as fine as the deepest
//! T-node ([`crate::polygonise`]), thickened where the plain polygonisation has handles.

use super::field::Field;
use super::thicken;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::polygonise::{track_surface, Grid, MAX_GRID_POINTS_PER_AXIS};
use crate::progress::Threads;
use crate::spatial::KdTree;
use crate::tree::{NodeKind, TreeSample, VsTree};
use glam::Vec3;
use rayon::prelude::*;

/// The polygonisation grid has at least 2^this cells across the root cube, however coarse the
/// T-layer: a shape that is a height field over large T-nodes (a hemisphere is one at depth 2)
/// is otherwise polygonised on a grid too coarse to tell its own shape, or where the samples end.
const MIN_GRID_DEPTH: u32 = 6;
/// The polygonisation gives up beyond this many grid cells along the surface.
const MAX_GRID_CELLS: usize = 50_000_000;

/// The grid the base mesh is polygonised on: cells the size of the deepest T-node's cube, but
/// no smaller than the samples' spacing (a finer grid sees nothing more) and at most
/// 2^`max_depth` across the root; two cells of margin around the root cube.
pub(super) fn grid(tree: &VsTree, max_depth: u32, spacing: f32) -> Grid {
    let deepest =
        tree.nodes.iter().filter(|n| n.kind == NodeKind::Transition).map(|n| u32::from(n.depth)).max().unwrap_or(0);
    let root = tree.root();
    let resolvable = if spacing > 0.0 { (2.0 * root.half / spacing).log2().floor().max(1.0) as u32 } else { max_depth };
    let depth =
        deepest.max(MIN_GRID_DEPTH).min(resolvable).clamp(1, max_depth.min(MAX_GRID_POINTS_PER_AXIS.ilog2() - 1));
    let cells = 1u32 << depth;
    let cell = 2.0 * root.half / cells as f32;
    let points = cells + 5;
    Grid { origin: root.center - root.half - 2.0 * cell, cell, dims: [points; 3] }
}

/// The zero set of `field` (for a closed or an `open` output) polygonised on `grid`, tracked
/// from the cells of `tree`'s samples, and whether it was thickened ([`thicken`]).
pub(super) fn polygonise(
    grid: &Grid,
    tree: &VsTree,
    (index, normals): (&KdTree, &[Vec3]),
    field: &Field,
    open: bool,
    threads: &Threads,
) -> Result<(Mesh, bool)> {
    // Polygonised `lift` outside the zero set, from the cells the surface should cross.
    let at_offset = |lift: &(dyn Fn(Vec3) -> f32 + Sync)| {
        let seeds = sample_cells(grid, &tree.samples, lift, threads);
        track_surface(&|p| field.at(p, open) - lift(p), grid, &seeds, MAX_GRID_CELLS, threads)
    };
    // A thickened surface too large for the grid budget is no reason to fail: the plain one
    // stands.
    let ((mesh, ()), thickened) = thicken::where_handles(
        (at_offset(&|_| 0.0)?, ()),
        |lift| at_offset(lift).ok().map(|m| (m, ())),
        (&tree.samples, index, normals),
        grid.cell,
        None,
        threads,
    );
    Ok((mesh, thickened))
}

/// The grid cells that hold the samples moved `lift` (at each) along their normals: where the
/// surface tracking starts (the function is polygonised that far outside the samples).
fn sample_cells(
    grid: &Grid,
    samples: &[TreeSample],
    lift: &(dyn Fn(Vec3) -> f32 + Sync),
    threads: &Threads,
) -> Vec<[u32; 3]> {
    threads.run(|| {
        let mut cells: Vec<[u32; 3]> =
            samples.par_iter().map(|s| grid.cell_of(s.position + lift(s.position) * s.normal)).collect();
        cells.par_sort_unstable();
        cells.dedup();
        cells
    })
}
