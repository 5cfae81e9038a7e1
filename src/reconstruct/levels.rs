//! Stage 3: refinement. M0 is snapped onto its T-nodes' patches, projected onto the samples'
//! local fits ([`mls`]) and remeshed ([`relax`]); then level after level is split 1-to-4 on
//! PN triangles and displaced by the quadtrees ([`refine`]), its new vertices relaxed and
//! projected and its folds unfolded, until the mesh is close enough to the samples or the
//! quadtrees have no detail left.

use super::base_mesh::Base;
use super::lookup::Lookup;
use super::{mls, refine, relax, ReconstructParams, ReconstructStats, RefinementStop};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::spatial::TriangleBvh;
use crate::topology;
use glam::Vec3;
use rayon::prelude::*;

/// Farthest a vertex is moved onto the samples' local fit ([`mls`]), in units (grid cells or
/// sample spacings) or typical T-node half sizes, whichever is larger: M0's vertices start up
/// to a T-node's sag off the surface; a longer move would reach another part of it.
const MLS_REACH: f32 = 2.0;

/// M0 refined; error(M, S) is measured at `measured`.
pub(super) fn refine(
    base: Base,
    near: &Lookup,
    measured: &[Vec3],
    params: &ReconstructParams,
    threads: &Threads,
    stats: &mut ReconstructStats,
    progress: &mut Progress,
) -> Result<refine::Surface> {
    let (tree, mut surface) = (near.tree, base.surface);
    let refiner = refine::Refiner::new(tree, threads);
    refiner.snap_base(&mut surface);
    refiner.unfold_base(&mut surface);
    // M0's vertices are off by up to their T-node's sag, later ones by less.
    let mls_reach = MLS_REACH * base.unit.max(near.typical_t_half);
    let fit = &near.fit;
    mls::project_vertices(&mut surface, 0, fit, mls_reach, threads);
    relax::improve(&mut surface, fit, mls_reach, threads);
    let (mut rms, mut max) = sample_error(&mut surface, measured, tree.diagonal, threads);
    stats.base_error = rms;
    stats.stopped = RefinementStop::MaxLevels;
    for level in 0..params.max_levels {
        // M0 itself may be close enough; after a level the check below decides.
        if level == 0 && rms <= params.target_distance {
            stats.stopped = RefinementStop::Target;
            break;
        }
        if 4 * surface.triangles.len() > params.max_triangles {
            stats.stopped = RefinementStop::TriangleBudget;
            break;
        }
        progress.report(0.5 + 0.45 * level as f32 / params.max_levels as f32, "refining")?;
        let first_new = surface.positions.len();
        let (refined, level_stats) = refiner.refine(&surface, threads);
        surface = refined;
        let border = topology::border_vertices(&surface.triangles, surface.positions.len());
        relax::relax_level(&mut surface, first_new, &border, threads);
        mls::project_vertices(&mut surface, first_new, fit, mls_reach, threads);
        mls::unfold(&mut surface, &border, fit, mls_reach, threads);
        stats.levels.push(level_stats);
        crate::memory::release_freed();
        // Without a target distance only the final error is reported: no need to measure
        // each level (a hierarchy over all the triangles each time).
        if params.target_distance > 0.0 {
            (rms, max) = sample_error(&mut surface, measured, tree.diagonal, threads);
        }
        if rms <= params.target_distance {
            stats.stopped = RefinementStop::Target;
            break;
        }
        if (level_stats.displaced as f64) < params.min_displaced * level_stats.new_vertices as f64 {
            stats.stopped = RefinementStop::NoDetail;
            break;
        }
    }
    if params.target_distance <= 0.0 && !stats.levels.is_empty() {
        (rms, max) = sample_error(&mut surface, measured, tree.diagonal, threads);
    }
    (stats.final_error, stats.final_max_error) = (rms, max);
    Ok(surface)
}

/// error(M, S): RMS and max distance from `points` to the surface, over `diagonal`.
fn sample_error(s: &mut refine::Surface, points: &[Vec3], diagonal: f32, threads: &Threads) -> (f64, f64) {
    // The surface's arrays are lent to a mesh for the measure, not copied.
    let mesh = Mesh::new(std::mem::take(&mut s.positions), None, std::mem::take(&mut s.triangles));
    let distances: Vec<f64> = threads.run(|| {
        let bvh = TriangleBvh::new(&mesh);
        points.par_iter().map(|&p| f64::from(bvh.distance(p))).collect()
    });
    (s.positions, s.triangles) = (mesh.positions, mesh.triangles);
    // Summed in order, so the figure is the same whatever the thread count.
    let (sum_sq, max) = distances.iter().fold((0.0, 0.0f64), |(s, m), &d| (s + d * d, m.max(d)));
    let d = f64::from(diagonal).max(f64::MIN_POSITIVE);
    ((sum_sq / points.len().max(1) as f64).sqrt() / d, max / d)
}
