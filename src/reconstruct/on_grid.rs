//! The base mesh's implicit function polygonised on a uniform grid as fine as the deepest
//! T-node ([`crate::polygonise`]), thickened where the plain polygonisation has handles.

use super::adjacency;
use super::field::Field;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::polygonise::{track_surface, Grid, MAX_GRID_POINTS_PER_AXIS};
use crate::progress::Threads;
use crate::topology;
use crate::tree::{NodeKind, TreeSample, VsTree};
use rayon::prelude::*;

/// The polygonisation grid has at least 2^this cells across the root cube, however coarse the
/// T-layer: a shape that is a height field over large T-nodes (a hemisphere is one at depth 2)
/// is otherwise polygonised on a grid too coarse to tell its own shape, or where the samples end.
const MIN_GRID_DEPTH: u32 = 6;
/// Where the polygonisation has handles, it is made again this many grid cells outside the
/// zero set, and kept if that has fewer handles, with its vertices moved back by as much. The
/// grid's points sample a part thinner than about a cell on one side only, so such a part (a
/// plate thinner than a cell; an ear where overlapping scans disagree by about a cell) comes
/// out perforated, with spurious handles. Offset, the part is thick enough
/// for the grid; moving the vertices back puts the surface where the samples are and cannot
/// change the topology. Gaps narrower than twice the offset close, but they are below what the
/// grid resolves faithfully anyway. Surfaces without handles are never thickened.
const THICKEN_CELLS: f32 = 1.5;
/// Ring averages of the fine mesh's normals before its vertices are moved back.
const NORMAL_SMOOTHING_PASSES: usize = 2;
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
/// from the cells of `tree`'s samples, and whether it was thickened: where it has handles, the
/// thickened one is kept if it has fewer (see [`THICKEN_CELLS`]), its vertices moved back.
pub(super) fn polygonise(
    grid: &Grid,
    tree: &VsTree,
    field: &Field,
    open: bool,
    threads: &Threads,
) -> Result<(Mesh, bool)> {
    // Polygonised `offset` outside the zero set, from the cells the surface should cross.
    let at_offset = |offset: f32| {
        let seeds = sample_cells(grid, &tree.samples, offset, threads);
        track_surface(&|p| field.at(p, open) - offset, grid, &seeds, MAX_GRID_CELLS, threads)
    };
    let fine = at_offset(0.0)?;
    let genus = topology::closed_surface_genus(&fine);
    if genus > 0 {
        // A thickened surface too large for the grid budget is no reason to fail: the plain
        // one stands.
        if let Ok(mut thick) = at_offset(THICKEN_CELLS * grid.cell) {
            if !thick.triangles.is_empty() && topology::closed_surface_genus(&thick) < genus {
                move_inward(&mut thick, THICKEN_CELLS * grid.cell, threads);
                return Ok((thick, true));
            }
        }
    }
    Ok((fine, false))
}

/// Moves every vertex `distance` against its normal: back from the offset the polygonisation
/// was made at onto the implicit function's zero set (near the samples the blended planes are
/// a signed distance). A marching-tetrahedra vertex's own normal is noisy (slivers), so each
/// normal is averaged over its ring first. Only positions change, so the topology stays.
fn move_inward(mesh: &mut Mesh, distance: f32, threads: &Threads) {
    let neighbours = adjacency::Rows::neighbours(&mesh.triangles, mesh.positions.len());
    let mut normals = mesh.area_weighted_normals();
    for _ in 0..NORMAL_SMOOTHING_PASSES {
        normals = threads.run(|| {
            (0..normals.len() as u32)
                .into_par_iter()
                .map(|v| {
                    neighbours
                        .of(v)
                        .iter()
                        .fold(normals[v as usize], |sum, &w| sum + normals[w as usize])
                        .normalize_or_zero()
                })
                .collect()
        });
    }
    threads.run(|| mesh.positions.par_iter_mut().zip(&normals).for_each(|(p, n)| *p -= distance * *n));
}

/// The grid cells that hold the samples moved `offset` along their normals: where the surface
/// tracking starts (the function is polygonised that far outside the samples).
fn sample_cells(grid: &Grid, samples: &[TreeSample], offset: f32, threads: &Threads) -> Vec<[u32; 3]> {
    threads.run(|| {
        let mut cells: Vec<[u32; 3]> =
            samples.par_iter().map(|s| grid.cell_of(s.position + offset * s.normal)).collect();
        cells.par_sort_unstable();
        cells.dedup();
        cells
    })
}
