//! Stage 1: the samples' noise ([`super::noise`]) and the VS-Tree built allowing for it, so
//! the T-layer is where the surface is a height field at the noise's scale: the base mesh sees
//! no handles in the noise, and no cell is split to chase it.

use super::{noise, ReconstructParams, ReconstructStats};
use crate::error::{shown, Error, Result};
use crate::progress::{Progress, Threads};
use crate::samples::SampleSet;
use crate::tree::{self, TreeParams, VsTree};

/// The VS-Tree of `samples`, or an error naming the parameter that left it without a T-node.
pub(super) fn tree(
    samples: &SampleSet,
    params: &ReconstructParams,
    threads: &Threads,
    stats: &mut ReconstructStats,
    progress: &mut Progress,
) -> Result<VsTree> {
    let noise = noise::noise_level(&samples.positions, &samples.normals, threads)?;
    let tree = tree::build_allowing_noise(samples, &params.tree, noise, threads, progress)?;
    stats.noise = if tree.diagonal > 0.0 { f64::from(noise / tree.diagonal) } else { 0.0 };
    stats.tree = tree.stats();
    if stats.tree.t_nodes == 0 {
        return Err(why_no_t_node(&tree, &params.tree));
    }
    Ok(tree)
}

/// The error for a tree without T-nodes, naming the parameter that stopped it short of the
/// surface: every leaf is then an octree cell, left unsplit because it was at the deepest
/// level, at the smallest cell size, or within the error bound.
fn why_no_t_node(tree: &VsTree, params: &TreeParams) -> Error {
    let leaves = || tree.nodes.iter().filter(|n| n.is_leaf());
    let default = TreeParams::default();
    if leaves().any(|n| u32::from(n.depth) >= params.max_depth) {
        return Error::param(
            "max_depth",
            format!(
                "{}: the tree reached this depth before any cell saw the surface as a height field, so \
                 there is nothing to make the base mesh from; allow a deeper tree (default {})",
                params.max_depth, default.max_depth
            ),
        );
    }
    let smallest = 0.5 * params.min_cell_size * f64::from(tree.diagonal);
    if leaves().any(|n| f64::from(n.half) <= smallest) {
        return Error::param(
            "min_cell_size",
            format!(
                "{}: cells this small are not split, and none of the larger ones saw the surface as a \
                 height field; use a smaller value (default {:e})",
                shown(params.min_cell_size),
                default.min_cell_size
            ),
        );
    }
    Error::param(
        "error",
        format!(
            "{}: the cloud fits this bound in {} octree cell{} too coarse to see the surface as a height \
             field, so there is nothing to make the base mesh from; use a smaller bound (default {:e})",
            shown(params.error),
            leaves().count(),
            if leaves().count() == 1 { "" } else { "s" },
            ReconstructParams::default().tree.error
        ),
    )
}
