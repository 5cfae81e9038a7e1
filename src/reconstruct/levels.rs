//! Stage 3: refinement. M0 is snapped onto its T-nodes' patches, projected onto the samples'
//! local fits ([`mls`]) and remeshed ([`relax`]); then level after level is split 1-to-4 on PN
//! triangles and displaced by the quadtrees ([`refine`]), the new vertices relaxed and projected
//! and folds unfolded, until the mesh is close enough to the samples or the quadtrees have no
//! detail left; then the folds left, mostly slivers, are collapsed ([`slivers`]). Without a
//! target distance every triangle is split at every level; with one, only the regions of M0
//! ([`Regions`]) whose samples are still farther from their triangles than the target, so that
//! the triangles go where the detail is, with crack-free transitions
//! ([`red_green`](super::red_green)) between regions that stopped at different levels.

use super::adjacency::Rows;
use super::base_mesh::Base;
use super::cluster::stray_components;
use super::lookup::Lookup;
use super::regions::{Regions, REGION_TRIANGLES};
use super::{folds, mls, refine, relax, slivers, trim, ReconstructParams, ReconstructStats, RefinementStop};
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

/// M0 refined; error(M, S) is measured at `measured`, which also say where to refine.
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
    stats.base_specks = drop_specks(&mut surface, base.unit);
    let gap_of = |s: &mut refine::Surface| Gap::measure(s, measured, threads);
    let mut gap = gap_of(&mut surface);
    stats.base_error = gap.rms / f64::from(tree.diagonal);
    // In the samples' units.
    let target = (params.target_distance * f64::from(tree.diagonal)) as f32;
    stats.stopped = RefinementStop::MaxLevels;
    let mut greens = Vec::new();
    // With a target: M0's regions, and per triangle the region it is part of (a region refines
    // as a whole).
    let mut regions = (target > 0.0).then(|| {
        let grown = Regions::grow(
            surface.triangles.len(),
            &topology::adjacent_face_pairs(&surface.triangles),
            REGION_TRIANGLES,
        );
        let of_triangle = grown.of_triangle.clone();
        (grown, of_triangle)
    });
    let mut measured_now = true;
    // The vertices the last unfolding left folded.
    let mut still_folded = Vec::new();
    for level in 0..params.max_levels {
        if measured_now && gap.rms <= f64::from(target) {
            stats.stopped = RefinementStop::Target;
            break;
        }
        let marked = match &regions {
            Some((regions, region)) => {
                let mut region_far = vec![false; regions.count()];
                for (t, &(count, sum_sq)) in gap.nearest.iter().enumerate() {
                    region_far[region[t] as usize] |= count > 0 && sum_sq > target * target * count as f32;
                }
                fill_gaps(&mut region_far, &regions.neighbours);
                region.iter().map(|&r| region_far[r as usize]).collect()
            }
            None => vec![true; surface.triangles.len()],
        };
        let to_split = marked.iter().filter(|&&far| far).count();
        if to_split == 0 {
            stats.stopped = RefinementStop::Target;
            break;
        }
        if surface.triangles.len() + 3 * to_split > params.max_triangles {
            stats.stopped = RefinementStop::TriangleBudget;
            break;
        }
        progress.report(0.5 + 0.45 * level as f32 / params.max_levels as f32, "refining")?;
        let first_new = surface.positions.len();
        let refined = refiner.refine(&surface, &marked, &greens, threads);
        (surface, greens) = (refined.surface, refined.greens);
        if let Some((_, region)) = &mut regions {
            *region = refined.from.iter().map(|&t| region[t as usize]).collect();
        }
        let border = topology::border_vertices(&surface.triangles, surface.positions.len());
        relax::relax_level(&mut surface, first_new, &border, threads);
        mls::project_vertices(&mut surface, first_new, fit, mls_reach, threads);
        still_folded = folds::unfold(&mut surface, &border, fit, mls_reach, threads);
        stats.levels.push(refined.stats);
        crate::memory::release_freed();
        // Without a target distance only the final error is reported: no need to measure
        // each level (a hierarchy over all the triangles each time).
        measured_now = target > 0.0;
        if measured_now {
            gap = gap_of(&mut surface);
        }
        let level = refined.stats;
        if measured_now && gap.rms <= f64::from(target) {
            stats.stopped = RefinementStop::Target;
            break;
        }
        if (level.displaced as f64) < params.min_displaced * level.new_vertices as f64 {
            stats.stopped = RefinementStop::NoDetail;
            break;
        }
    }
    // What unfolding could not undo: slivers, collapsed. On an open output only near the
    // samples: what lies beyond them is trimmed, and must stay as the trim finds it.
    let kept_part = base.open.then(|| (near.index(), trim::BORDER_TRIM * near.spacing));
    stats.sliver_collapses = slivers::collapse_folds(&mut surface, &still_folded, fit, mls_reach, kept_part, threads);
    if !measured_now || stats.sliver_collapses > 0 {
        gap = gap_of(&mut surface);
    }
    let d = f64::from(tree.diagonal).max(f64::MIN_POSITIVE);
    (stats.final_error, stats.final_max_error) = (gap.rms / d, gap.max / d);
    Ok(surface)
}

/// Drops the components of M0 that its projection onto the samples squeezed into a box of two
/// `unit`s (sample spacings or grid cells) a side, or that span fewer than four T-nodes (see
/// [`stray_components`]): bubbles of the implicit function beside the surface, which the
/// projection crumples onto one spot of it. Returns how many vertices were dropped (none where
/// that would leave no face).
fn drop_specks(s: &mut refine::Surface, unit: f32) -> usize {
    let mesh = Mesh::new(std::mem::take(&mut s.positions), None, std::mem::take(&mut s.triangles));
    let neighbours = Rows::neighbours(&mesh.triangles, mesh.positions.len());
    let dropped = stray_components(&mesh, &s.labels, &neighbours, unit);
    (s.positions, s.triangles) = (mesh.positions, mesh.triangles);
    let count = dropped.iter().filter(|&&d| d).count();
    let kept = |t: &[u32; 3]| !t.iter().any(|&v| dropped[v as usize]);
    if count == 0 || !s.triangles.iter().any(kept) {
        return 0;
    }
    s.triangles.retain(kept);
    s.drop_unused_vertices();
    count
}

/// Marks every region that has more than half its `neighbours` (regions that share an edge)
/// marked, until none is left: each boundary between refined and unrefined
/// regions costs irregular vertices (a red-green transition), so a lone region left behind
/// among refined ones is refined with them.
fn fill_gaps(marked: &mut [bool], neighbours: &Rows) {
    let mut count: Vec<usize> =
        (0..marked.len()).map(|r| neighbours.of(r as u32).iter().filter(|&&n| marked[n as usize]).count()).collect();
    let surrounded = |r: usize, count: usize| 2 * count > neighbours.of(r as u32).len();
    let mut queue: Vec<usize> = (0..marked.len()).filter(|&r| !marked[r] && surrounded(r, count[r])).collect();
    while let Some(r) = queue.pop() {
        if marked[r] {
            continue;
        }
        marked[r] = true;
        for &n in neighbours.of(r as u32) {
            let n = n as usize;
            count[n] += 1;
            if !marked[n] && surrounded(n, count[n]) {
                queue.push(n);
            }
        }
    }
}

/// How far a mesh is from the samples: error(M, S) unscaled, and per triangle.
struct Gap {
    /// RMS and largest distance from the measured points to the mesh, in their units.
    rms: f64,
    max: f64,
    /// Per triangle: how many of the points are nearest to it, and their squared distances'
    /// sum. Where each triangle's points are within a distance in the RMS, so are all points.
    nearest: Vec<(u32, f32)>,
}

impl Gap {
    /// The gap between `s` and `points`.
    fn measure(s: &mut refine::Surface, points: &[Vec3], threads: &Threads) -> Gap {
        // The surface's arrays are lent to a mesh for the measure, not copied.
        let mesh = Mesh::new(std::mem::take(&mut s.positions), None, std::mem::take(&mut s.triangles));
        let closest: Vec<Option<(u32, f32)>> = threads.run(|| {
            let bvh = TriangleBvh::new(&mesh);
            points.par_iter().map(|&p| bvh.closest_point(p).map(|c| (c.triangle, c.distance))).collect()
        });
        (s.positions, s.triangles) = (mesh.positions, mesh.triangles);
        // Summed in order, so the figure is the same whatever the thread count.
        let (mut sum_sq, mut max) = (0.0f64, 0.0f64);
        let mut nearest = vec![(0u32, 0.0f32); s.triangles.len()];
        for &(t, d) in closest.iter().flatten() {
            (sum_sq, max) = (sum_sq + f64::from(d) * f64::from(d), max.max(f64::from(d)));
            let n = &mut nearest[t as usize];
            *n = (n.0 + 1, n.1 + d * d);
        }
        Gap { rms: (sum_sq / points.len().max(1) as f64).sqrt(), max, nearest }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_component_squeezed_below_two_units_is_dropped_and_a_small_part_kept() {
        // Three closed components, each vertex its own T-node: the surface (radius 1), a
        // small part 8 units across (kept), and a speck 1.5 units across (dropped), in units of
        // 0.01.
        let unit = 0.01;
        let mut s = refine::Surface::default();
        for (radius, centre) in [(1.0, Vec3::ZERO), (4.0 * unit, Vec3::X * 2.0), (0.75 * unit, Vec3::Y * 2.0)] {
            let sphere = crate::eval::shapes::icosphere(radius, 2);
            let first = s.positions.len() as u32;
            s.triangles.extend(sphere.triangles.iter().map(|t| t.map(|v| v + first)));
            s.normals.extend(sphere.positions.iter().map(|p| p.normalize()));
            s.positions.extend(sphere.positions.iter().map(|&p| p + centre));
        }
        s.labels = (0..s.positions.len() as u32).collect();
        let per_sphere = s.positions.len() / 3;
        assert_eq!(drop_specks(&mut s, unit), per_sphere);
        assert_eq!(s.positions.len(), 2 * per_sphere);
        assert_eq!((s.normals.len(), s.labels.len()), (2 * per_sphere, 2 * per_sphere));
        assert!(s.positions.iter().all(|p| p.y < 1.0), "the speck at y = 2 is gone");
        let report = topology::analyze(&Mesh::new(s.positions.clone(), None, s.triangles.clone()));
        assert!(report.is_watertight());
        assert_eq!(report.components, 2);
    }

    #[test]
    fn a_region_left_behind_among_refined_ones_is_refined_with_them() {
        // Regions in a row 0-1-2-3-4, and 5 beside 1 and 3.
        let pairs = [[0, 1], [1, 2], [2, 3], [3, 4], [5, 1], [5, 3]];
        let rows = Rows::from_pairs(&pairs, 6);
        // 1 has two of its three neighbours marked: it follows. 5 then has one of two, 3 one
        // of three: they do not.
        let mut marked = [true, false, true, false, false, false];
        fill_gaps(&mut marked, &rows);
        assert_eq!(marked, [true, true, true, false, false, false]);
        // 2 and 5 each sit between 1 and 3; 0 and 4 have no other neighbour.
        let mut marked = [false, true, false, true, false, false];
        fill_gaps(&mut marked, &rows);
        assert_eq!(marked, [true; 6]);
        // One marked region among many stays alone.
        let mut marked = [false, false, true, false, false, false];
        fill_gaps(&mut marked, &rows);
        assert_eq!(marked, [false, false, true, false, false, false]);
    }
}
