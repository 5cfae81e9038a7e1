//! Surface reconstruction from a point cloud (paper §5, POINT_TO_MESH):
//!
//! 0. estimate normals where the cloud has none ([`crate::normals`]);
//! 1. measure the samples' noise ([`noise`]) and build the VS-Tree of the samples allowing for
//!    it: the height-field test and the L2 bound look past the noise, so the T-layer and the
//!    quadtrees stop where the surface's shape, not its noise, is resolved (the L2 bound is the
//!    de-noising control for what the noise does not explain);
//! 2. an implicit function whose sign is inside or outside: by default the samples' winding
//!    number ([`winding`]) decides the side and the distance to the nearest sample the value
//!    ([`BaseMesh::Winding`]); the paper's blend of the T-nodes' planes ([`implicit`]) is
//!    [`BaseMesh::Paper`]. Polygonise it on a grid as fine as the deepest T-node
//!    ([`crate::polygonise`]), and cluster that mesh at the T-layer into the base mesh M0, one
//!    vertex per T-node ([`base_mesh`]). Where the polygonised surface has handles, parts
//!    thinner than the grid resolves are thickened and the thickened surface is kept if that
//!    removes handles (see `THICKEN_CELLS`);
//! 3. refine: split 1-to-4 on PN triangles and displace by the quadtrees ([`refine`]); every
//!    vertex of M0 and of each level is then projected onto a local quadratic fit of its nearest
//!    samples ([`mls`]; more of them the noisier the cloud, see `fit_neighbours`), which the
//!    quadtree's leaves alone leave off by the curvature; until
//!    the mesh is close enough to the samples or the quadtrees have no detail left. M0 is
//!    remeshed and each level's new vertices relaxed ([`relax`]), and folds are unfolded onto
//!    the samples' fit ([`mls::unfold`]);
//! 4. where much of the closed surface has no sample supporting it (an open scan; see
//!    [`Closure`]), only the supported part is kept, and faces past the scan's border trimmed.
//!
//! error(M, S), where the paper leaves it open: the root mean square of the distances from the
//! samples (at most [`ERROR_SAMPLES`] of them, evenly spread) to the mesh, over the bounding
//! box's diagonal; the maximum is reported too.

mod adjacency;
mod base_mesh;
mod dual_contour;
mod implicit;
mod leaf_fit;
mod mls;
mod noise;
mod outliers;
mod params;
mod refine;
mod relax;
mod support;
mod trim;
mod winding;

pub use params::{BaseMesh, ReconstructParams, ReconstructStats, RefinementStop};
pub use refine::LevelStats;
pub use support::Closure;

use crate::error::{shown, Error, Result};
use crate::mesh::Mesh;
use crate::normals::{self, NormalParams, OrientReport};
use crate::polygonise::{track_surface, Grid, MAX_GRID_POINTS_PER_AXIS};
use crate::progress::{Progress, Threads};
use crate::samples::SampleSet;
use crate::spatial::{KdTree, TriangleBvh};
use crate::topology;
use crate::tree::{self, NodeKind, TreeParams, TreeSample, VsTree};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// At most this many samples are measured for error(M, S).
pub const ERROR_SAMPLES: usize = 100_000;
/// T-node supports in the paper's construction (`BaseMesh::Paper` only): balls of this many
/// times the cube's half diagonal. MPU's α = 0.75 of the full diagonal would be 1.5; wider
/// supports average out the planes of small, noisy T-nodes. Measured on the 24 closed models at
/// 200k clean points (`cargo bench --bench corpus -- --base-mesh paper --sizes 200000 --variants
/// clean --no-synthetic`): genus and components right on 14 with 2.0, 11 with 1.5 (six models
/// gain handles, two lose spurious openings).
const SUPPORT_SCALE: f32 = 2.0;
/// Beyond this many grid cells from every sample, the implicit function is pushed away from
/// zero, outward or inward as the winding number says.
const FAR_FROM_SAMPLES: f32 = 1.5;
/// Beyond this many grid cells from every sample, the winding number alone decides inside or
/// outside. Behind an open scan the winding number falls below one half towards the scan's
/// border, which closes the surface into a thin shell (which trimming opens again).
const OUTSIDE_BEYOND: f32 = 4.0;
/// Where the output is open (asked for, or an open scan found), inside is where the winding
/// number exceeds this rather than one half. Behind a scan from one side the winding number
/// stays below one half, so the half threshold closes the scan with a thin shell just behind
/// it, too close to be cut off and ragged where the number wavers around one half; a quarter
/// puts the closing sheet farther back. Measured on the corpus bench's six open inputs (a
/// hemisphere at 10k and 200k points, single views of four meshes), Chamfer to the truth:
/// better on five, by 1.3-2.8x (worse on bear, 0.016% against 0.014% of the diagonal). Pinned by
/// the test `a_scan_from_one_side_leaves_no_sheet_behind_it` (a torus's upper half).
const OPEN_SCAN_INSIDE: f32 = 0.25;
/// Where the polygonisation has handles, it is made again this many grid cells outside the
/// zero set, and kept if that has fewer handles, with its vertices moved back by as much. The
/// grid's points sample a part thinner than about a cell on one side only, so such a part (a
/// plate thinner than a cell; an ear where overlapping scans disagree by about a cell) comes
/// out perforated, with spurious handles. Offset, the part is thick enough
/// for the grid; moving the vertices back puts the surface where the samples are and cannot
/// change the topology. Gaps narrower than twice the offset close, but they are below what the
/// grid resolves faithfully anyway. Surfaces without handles are never thickened.
const THICKEN_CELLS: f32 = 1.5;
/// An open output's border is cut back to this many sample spacings from the samples (see
/// `trim::border`): the samples cannot place a border more finely than their spacing, and
/// within one spacing of the last samples the cut would wander with each gap between them.
const BORDER_TRIM: f32 = 2.0;
/// On an open M0, one vertex stands for a stretch of border at most this many typical T-node
/// sides long (inside, one vertex stands for a T-node): a vertex per T-node along the border
/// too cuts its bends short by as much as the T-node is large, and a flat region's T-node can
/// span half the model. Half a side gave fans of slivers at the border (29% of the angles
/// under 10 degrees on the fandisk view, against 20%), no limit a Chamfer 1.7x larger there.
const BORDER_RUN: f32 = 1.0;
/// The polygonisation grid has at least 2^this cells across the root cube, however coarse the
/// T-layer: a shape that is a height field over large T-nodes (a hemisphere is one at depth 2)
/// is otherwise polygonised on a grid too coarse to tell its own shape, or where the samples end.
const MIN_GRID_DEPTH: u32 = 6;
/// Extra samples per local fit for each squared noise level per sample spacing (see
/// `fit_neighbours`): a fit then spans about as many noise levels whatever the density. On
/// the corpus's noisy clouds 50, 100 and 200 give median Chamfer ratios to Poisson of 1.26,
/// 1.18 and 1.17 at 0.25% noise and 1.29, 1.30 and 1.36 at 0.5%; more are slower and blur
/// thin parts.
const FIT_NEIGHBOURS_PER_NOISE: f64 = 100.0;
/// The winding number's dipoles are softened over this many sample spacings (see
/// [`winding::WindingNumber::softened`]): within a spacing of the samples the cloud cannot
/// tell the surface from its samples, and an unsoftened sum there swings with the nearest one.
const WINDING_SOFTENING: f32 = 1.0;
/// Where the output may be open, a winding number within this of one half next to the samples
/// is in doubt, and the nearest samples' tangent planes decide the side instead: about 1
/// inside and 0 outside a closed surface, it sinks towards 0 near the border of an open scan.
const WINDING_DOUBT: f32 = 0.25;
/// Given normals whose flux of `p - c` (`c` the centroid) is below this share of its absolute
/// sum point inward, and a reconstruction that may close flips them all. Through a closed surface's
/// outward normals that flux is 3 times its volume (the divergence theorem), so positive
/// whatever the shape: measured +0.7 to +1 on outward clouds, -0.92 on an inward armadillo.
const INWARD_FLUX: f64 = -0.5;
/// Farthest a vertex is moved onto the samples' local fit ([`mls`]), in units (grid cells or
/// sample spacings) or typical T-node half sizes, whichever is larger: M0's vertices start up
/// to a T-node's sag off the surface; a longer move would reach another part of it.
const MLS_REACH: f32 = 2.0;
/// Ring averages of the fine mesh's normals before its vertices are moved back.
const NORMAL_SMOOTHING_PASSES: usize = 2;
/// The polygonisation gives up beyond this many grid cells along the surface.
const MAX_GRID_CELLS: usize = 50_000_000;
/// Fewer points than this cannot define a surface.
pub const MIN_POINTS: usize = 10;

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

/// Reconstructs a triangle mesh from a point cloud with (outward) normals.
pub fn reconstruct(
    cloud: &Mesh,
    params: &ReconstructParams,
    progress: &mut Progress,
) -> Result<(Mesh, ReconstructStats)> {
    params.check()?;
    if cloud.positions.len() < MIN_POINTS {
        return Err(Error::input(format!("{} points: at least {MIN_POINTS} are needed", cloud.positions.len())));
    }
    let threads = Threads::new(params.threads)?;
    crate::mesh::check_positions(&cloud.positions, "point")?;
    normals::refuse_flat(&cloud.positions, &threads)?;
    let mut stats = ReconstructStats::default();
    let start = Instant::now();
    // The work is done at unit size, so that no tolerance depends on the cloud's units: once
    // for the whole cloud, and again without its isolated points.
    let mut scale = unit_scale(&cloud.positions);
    let mut positions: Vec<Vec3> = cloud.positions.iter().map(|&p| p * scale).collect();
    let mut given_normals = cloud.normals.clone();
    let isolated = outliers::isolated_points(&positions, &threads)?;
    stats.isolated_points = isolated.iter().filter(|&&i| i).count();
    if stats.isolated_points > 0 {
        keep_unmarked(&mut positions, &isolated);
        given_normals.iter_mut().for_each(|n| keep_unmarked(n, &isolated));
        if positions.len() < MIN_POINTS {
            return Err(Error::input(format!(
                "{} points once {} isolated ones are left out: at least {MIN_POINTS} are needed",
                positions.len(),
                stats.isolated_points
            )));
        }
        let rescale = unit_scale(&positions);
        positions.iter_mut().for_each(|p| *p *= rescale);
        scale *= rescale;
    }
    let mut oriented = Mesh::from_points(positions, given_normals);
    let normal_params = NormalParams { threads: params.threads, ..params.normals };
    stats.normals = normals::ensure_normals(&mut oriented, &normal_params, &mut progress.stage(0.0, 0.15))?;
    let kept_given = stats.normals.estimated == 0 && stats.normals.orient.is_none();
    // Only a closed surface's normals have a flux of a known sign. `Auto` flips too: a closed
    // cloud with inward normals has no inside and fails, while an open scan whose normals
    // all face a common centre (the inside of a bowl) at worst comes out facing the other way.
    if kept_given && params.closure != Closure::Open {
        if let Some(flipped) = turn_inward_normals_out(&mut oriented) {
            let points = oriented.positions.len();
            stats.normals.orient =
                Some(OrientReport { components: 1, largest_component: points, undecided_components: 0, flipped });
        }
    }
    let samples = SampleSet::from_cloud(&oriented)?;
    drop(oriented);
    stats.seconds_normals = start.elapsed().as_secs_f64();

    let t0 = Instant::now();
    // The tree allows for the noise, so the T-layer is where the surface is a height field at
    // the noise's scale (the base mesh sees no handles in it) and no cell is split to chase it.
    let noise = noise::noise_level(&samples.positions, &samples.normals, &threads)?;
    let tree = tree::build_allowing_noise(&samples, &params.tree, noise, &threads, &mut progress.stage(0.15, 0.35))?;
    stats.noise = if tree.diagonal > 0.0 { f64::from(noise / tree.diagonal) } else { 0.0 };
    stats.tree = tree.stats();
    if stats.tree.t_nodes == 0 {
        return Err(why_no_t_node(&tree, &params.tree));
    }
    let t1 = Instant::now();

    progress.report(0.35, "base mesh")?;
    // The tree's order keeps neighbours together in memory, which makes the build faster.
    // Where error(M, S) is measured; the tree holds the samples from here on.
    let measured = evenly_spread(&samples.positions, ERROR_SAMPLES);
    drop(samples);
    let tree_order: Vec<Vec3> = tree.samples.iter().map(|s| s.position).collect();
    let sample_index = threads.run(|| KdTree::new(&tree_order))?;
    let spacing = sample_spacing(&sample_index, &tree_order);
    let grid = polygonisation_grid(&tree, params.max_grid_depth, spacing);
    stats.grid_cells = grid.dims[0] - 5;
    drop(tree_order);
    // Distances from the samples count in grid cells, or in sample spacings where the samples
    // are sparser than the grid.
    let distance_unit = grid.cell.max(spacing);
    // A T-node's plane strays from its samples by up to its patch's sag, so the cap on the
    // distance to the samples must leave room for the typical T-node too.
    let typical_t_half = median(tree.nodes.iter().filter(|n| n.kind == NodeKind::Transition).map(|n| n.half).collect());
    // Beyond this distance from every sample only the winding number's side counts.
    let side_only_beyond = OUTSIDE_BEYOND * distance_unit.max(typical_t_half);
    // A sparse cloud's leaves are smaller than the surface their few samples stand for: each
    // sample stands for at least a square of the spacing (exactly that on a regular grid).
    let (softening, min_sample_area) = match params.base_mesh {
        BaseMesh::Winding | BaseMesh::Adaptive => (WINDING_SOFTENING * spacing, spacing * spacing),
        BaseMesh::Paper => (0.0, 0.0),
    };
    let winding = winding::WindingNumber::new(&tree, min_sample_area).softened(softening);
    let onto_samples = mls::SampleSurface::new(&tree.samples, fit_neighbours(noise, spacing), &threads)?;
    let blend = implicit::PlaneBlend::new(&tree, SUPPORT_SCALE, 1.5 * grid.cell);
    // Within this distance of the samples, planes (the T-nodes', or near an open scan's
    // border the samples' own) may decide the side; see FAR_FROM_SAMPLES.
    let planes_within = FAR_FROM_SAMPLES * distance_unit;
    // Open asked for; `Auto` first polygonises as for a closed output and, if that finds an
    // open scan, again as for an open one.
    let asked_open = params.closure == Closure::Open || params.trim > 0.0;
    let evaluations = AtomicUsize::new(0);
    let f = |p: Vec3, open: bool| {
        evaluations.fetch_add(1, Ordering::Relaxed);
        let inside_above = if open { OPEN_SCAN_INSIDE } else { 0.5 };
        match params.base_mesh {
            BaseMesh::Winding | BaseMesh::Adaptive => {
                let d = sample_index.distance_within(p, side_only_beyond).min(side_only_beyond);
                let w = winding.at(p);
                let inside = if open && d <= planes_within && (w - 0.5).abs() < WINDING_DOUBT {
                    // Next to the samples where the winding number is in doubt (an open scan's
                    // falls towards its border, so its level set leaves the samples there), their
                    // own tangent planes tell the side. Not for a closed output: there the level
                    // set may leave an open scan's border, since the scan is closed over anyway,
                    // and the planes of noisy or thin parts would add handles.
                    onto_samples.plane_side(p) < 0.0
                } else {
                    w > inside_above
                };
                if inside {
                    -d
                } else {
                    d
                }
            }
            BaseMesh::Paper => {
                paper_function(p, &sample_index, &blend, &winding, inside_above, planes_within, side_only_beyond)
            }
        }
    };
    // Polygonised `offset` outside the zero set, from the cells the surface should cross.
    let polygonise = |offset: f32, open: bool| {
        let seeds = sample_cells(&grid, &tree.samples, offset, &threads);
        track_surface(&|p| f(p, open) - offset, &grid, &seeds, MAX_GRID_CELLS, &threads)
    };
    // What a cloud that gives no surface most likely is.
    let too_sparse_or_unoriented = format!(
        "{} points{}: too few or too scattered to sample a surface, or normals that do not face one way",
        tree.samples.len(),
        if stats.normals.estimated > 0 { ", normals estimated" } else { ", normals given" }
    );
    let sag = plane_sags(&tree, &threads);
    let sample_normals: Vec<Vec3> = tree.samples.iter().map(|s| s.normal).collect();
    let smallest_hole = f64::from(2.0 * typical_t_half).powi(2);
    let polygonised = |open: bool| -> Result<Polygonised> {
        // Where the adaptive polygonisation cannot make a 2-manifold even with its finest
        // leaves (sheets closer than the samples resolve), the grid's is used.
        let contour = match params.base_mesh {
            BaseMesh::Adaptive => dual_contour::contour(&tree, &|p| f(p, open), distance_unit, &threads),
            _ => None,
        };
        let on_grid = contour.is_none();
        let (mut fine, labels, thickened) = match contour {
            Some(c) => (Mesh::new(c.positions, None, c.triangles), Some(c.labels), false),
            None => {
                let (fine, thickened) = polygonise_on_grid(&|cells| polygonise(cells * grid.cell, open))?;
                (fine, None, thickened)
            }
        };
        if fine.triangles.is_empty() {
            return Err(Error::input(match params.base_mesh {
                BaseMesh::Winding | BaseMesh::Adaptive => format!(
                    "the points enclose no volume: their winding number stays below one half everywhere \
                     near them ({})",
                    too_sparse_or_unoriented
                ),
                BaseMesh::Paper => format!(
                    "the blended T-node planes have no zero crossing near the samples ({})",
                    too_sparse_or_unoriented
                ),
            }));
        }
        let neighbours = adjacency::Rows::neighbours(&fine.triangles, fine.positions.len());
        if thickened {
            move_inward(&mut fine, &neighbours, THICKEN_CELLS * grid.cell, &threads);
        }
        let labels = match labels {
            Some(labels) => base_mesh::spread_labels(labels, &neighbours),
            None => threads.run(|| base_mesh::label_vertices(&tree, &fine, &neighbours)),
        };
        let reach = support::SUPPORT_REACH * distance_unit;
        // A face of the adaptive polygonisation spans whole T-nodes, so its centre is as far
        // from the surface as a chord of that length sags: up to half its longest edge.
        let chord = |f: usize| {
            let [a, b, c] = fine.triangles[f].map(|v| fine.positions[v as usize]);
            0.5 * a.distance(b).max(b.distance(c)).max(c.distance(a))
        };
        let face_reach = |f: usize| {
            let sag = sag.get(labels[fine.triangles[f][0] as usize] as usize).copied().unwrap_or(0.0);
            reach + sag + if params.base_mesh == BaseMesh::Adaptive { chord(f) } else { 0.0 }
        };
        let support = support::supported_faces(&fine, &sample_index, &sample_normals, face_reach, &threads);
        // Faces that no sample supports: far from all, or near only samples facing the other
        // way (the closing sheet right behind an open scan).
        let unsupported: Vec<bool> = support.iter().map(|&s| s != support::Support::Supported).collect();
        let unsupported = support::without_small_regions(&fine, &unsupported, smallest_hole);
        let share = support::unsupported_share(&fine, &unsupported);
        Ok(Polygonised { fine, thickened, on_grid, neighbours, labels, unsupported, share })
    };
    let mut part = polygonised(asked_open)?;
    stats.unsupported_share = part.share;
    stats.open = asked_open || support::is_open(params.closure, part.share);
    if stats.open && !asked_open {
        part = polygonised(true)?;
    }
    drop((sample_normals, sag));
    progress.report(0.4, "base mesh")?;
    let Polygonised { mut fine, thickened, on_grid, neighbours, labels, unsupported, .. } = part;
    stats.thickened = thickened;
    stats.on_grid = on_grid;
    stats.fine_triangles = fine.triangles.len();
    stats.field_evaluations = evaluations.load(Ordering::Relaxed);
    let neighbours = if stats.open {
        // An open M0 is made of the supported part only: the closing sheet never joins a
        // T-node's cluster.
        keep_unmarked(&mut fine.triangles, &unsupported);
        // Parts left smaller than the smallest hole are shreds of the closing sheet's edge.
        drop_small_parts(&mut fine, smallest_hole);
        adjacency::Rows::neighbours(&fine.triangles, fine.positions.len())
    } else {
        neighbours
    };
    let border_run = BORDER_RUN * 2.0 * typical_t_half;
    let mut base = base_mesh::cluster_at_t_layer(&fine, &labels, &neighbours, grid.cell, border_run);
    // Closed parts of M0 smaller than the smallest hole are shells that clustering flattened
    // (a few T-nodes on a bubble of the implicit function): nothing a T-node can stand for.
    // (An open M0's parts were sorted out on the fine mesh, where a part is not cut short.)
    if !stats.open && drop_small_parts(&mut base.mesh, smallest_hole) {
        base.drop_unused_vertices();
    }
    drop((fine, labels, neighbours));
    if base.mesh.triangles.is_empty() {
        return Err(Error::input(format!(
            "the base mesh is empty: every part of the polygonised surface was smaller than the tree's \
             T-layer can stand for ({})",
            too_sparse_or_unoriented
        )));
    }
    stats.base_vertices = base.mesh.positions.len();
    stats.base_triangles = base.mesh.triangles.len();
    let base_report = topology::analyze(&base.mesh);
    (stats.base_genus, stats.base_boundary_edges) = (base_report.genus(), base_report.boundary_edges);
    let mut surface = refine::Surface {
        normals: base.labels.iter().map(|&t| tree.frames[tree.nodes[t as usize].frame as usize].normal).collect(),
        positions: base.mesh.positions,
        labels: base.labels,
        triangles: base.mesh.triangles,
    };
    let t2 = Instant::now();

    let refiner = refine::Refiner::new(&tree, &threads);
    refiner.snap_base(&mut surface);
    refiner.unfold_base(&mut surface);
    // M0's vertices are off by up to their T-node's sag, later ones by less.
    let mls_reach = MLS_REACH * distance_unit.max(typical_t_half);
    mls::project_vertices(&mut surface, 0, &onto_samples, mls_reach, &threads);
    relax::improve(&mut surface, &onto_samples, mls_reach, &threads);
    let (mut rms, mut max) = sample_error(&mut surface, &measured, tree.diagonal, &threads);
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
        let (refined, level_stats) = refiner.refine(&surface, &threads);
        surface = refined;
        let border = topology::border_vertices(&surface.triangles, surface.positions.len());
        relax::relax_level(&mut surface, first_new, &border, &threads);
        mls::project_vertices(&mut surface, first_new, &onto_samples, mls_reach, &threads);
        mls::unfold(&mut surface, &border, &onto_samples, mls_reach, &threads);
        stats.levels.push(level_stats);
        // Without a target distance only the final error is reported: no need to measure
        // each level (a hierarchy over all the triangles each time).
        if params.target_distance > 0.0 {
            (rms, max) = sample_error(&mut surface, &measured, tree.diagonal, &threads);
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
        (rms, max) = sample_error(&mut surface, &measured, tree.diagonal, &threads);
    }
    (stats.final_error, stats.final_max_error) = (rms, max);
    let t3 = Instant::now();

    progress.report(0.95, "trimming")?;
    let mut mesh = Mesh {
        positions: surface.positions,
        normals: Some(surface.normals),
        triangles: surface.triangles,
        origin: cloud.origin,
    };
    if stats.open {
        // An explicit `trim` removes every face farther than it. Otherwise the border is cut
        // back to BORDER_TRIM sample spacings past the last samples (see `trim::border`).
        stats.trimmed_triangles = if params.trim > 0.0 {
            trim::far_faces(&mut mesh, &sample_index, params.trim * grid.cell, &threads)
        } else {
            trim::border(&mut mesh, &sample_index, BORDER_TRIM * spacing, &threads)
        };
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

/// Keeps the items of `items` whose mark is false, in order.
fn keep_unmarked<T>(items: &mut Vec<T>, marks: &[bool]) {
    let mut mark = marks.iter();
    items.retain(|_| !*mark.next().unwrap_or(&false));
}

/// The power of two that brings the bounding box's diagonal of `points` to between 1/√2 and √2.
/// Reconstruction runs on the scaled cloud: tolerances fixed in f32 (a normal too short to
/// trust, a cell too small to split, a squared distance that underflows or loses its digits)
/// would otherwise depend on the units, and a cloud 1e-15 or 1e17 across fails where the same
/// cloud at unit size does not. A power of two scales every f32 exactly, both ways.
fn unit_scale(points: &[Vec3]) -> f32 {
    let diagonal = crate::mesh::Aabb::of(points).map_or(1.0, |b| f64::from(b.diagonal()));
    if !(diagonal.is_finite() && diagonal > 0.0) {
        return 1.0;
    }
    2f32.powi(-(diagonal.log2().round() as i32))
}

/// The implicit function's zero set, polygonised, and what the base mesh needs of it.
struct Polygonised {
    fine: Mesh,
    /// Thickened: see `THICKEN_CELLS`.
    thickened: bool,
    /// Made on the uniform grid rather than over the tree's octree.
    on_grid: bool,
    neighbours: adjacency::Rows,
    /// The T-node each vertex is clustered into.
    labels: Vec<u32>,
    /// Faces no sample supports, and their share of the area.
    unsupported: Vec<bool>,
    share: f64,
}

/// Removes the connected parts of `mesh` whose area is below `smallest`; whether any went.
fn drop_small_parts(mesh: &mut Mesh, smallest: f64) -> bool {
    let (part, parts) = support::regions(mesh, &vec![true; mesh.triangles.len()]);
    if parts.iter().all(|p| p.area >= smallest) {
        return false;
    }
    let mut p = part.iter();
    mesh.triangles.retain(|_| p.next().is_some_and(|&r| parts[r as usize].area >= smallest));
    true
}

/// The paper's implicit function ([`BaseMesh::Paper`]): within `planes_within` of the samples the
/// blended T-node planes; farther out the winding number's side, pushed away from zero with the
/// distance, the planes only allowed to push further that way; beyond `side_only_beyond` the side alone.
fn paper_function(
    p: Vec3,
    sample_index: &KdTree,
    blend: &implicit::PlaneBlend,
    winding: &winding::WindingNumber,
    inside_above: f32,
    planes_within: f32,
    side_only_beyond: f32,
) -> f32 {
    if sample_index.any_within(p, planes_within) {
        return blend.eval(p);
    }
    let side = if winding.at(p) > inside_above { -1.0 } else { 1.0 };
    let d = sample_index.distance_within(p, side_only_beyond);
    let blended = if d <= side_only_beyond { blend.eval(p) } else { f32::MAX };
    if blended == f32::MAX {
        side * f32::MAX
    } else if side > 0.0 {
        // Otherwise planes that run on past a thin part bulge into the outside, and a bulge
        // that meets another part adds a handle.
        blended.max(0.0) + (d - planes_within)
    } else {
        blended.min(0.0) - (d - planes_within)
    }
}

/// Flips every normal of `cloud` when together they point inward (see [`INWARD_FLUX`]);
/// returns how many were flipped.
fn turn_inward_normals_out(cloud: &mut Mesh) -> Option<usize> {
    let normals = cloud.normals.as_mut()?;
    let n = cloud.positions.len().max(1) as f64;
    let centroid = cloud.positions.iter().map(|p| p.as_dvec3()).sum::<glam::DVec3>() / n;
    let (flux, absolute) = cloud.positions.iter().zip(normals.iter()).fold((0.0, 0.0), |(f, a), (p, m)| {
        let d = m.as_dvec3().dot(p.as_dvec3() - centroid);
        (f + d, a + d.abs())
    });
    if !(absolute > 0.0 && flux < INWARD_FLUX * absolute) {
        return None;
    }
    normals.iter_mut().for_each(|m| *m = -*m);
    Some(normals.len())
}

/// The grid the base mesh is polygonised on: cells the size of the deepest T-node's cube, but
/// no smaller than the samples' spacing (a finer grid sees nothing more) and at most
/// 2^`max_depth` across the root; two cells of margin around the root cube.
fn polygonisation_grid(tree: &VsTree, max_depth: u32, spacing: f32) -> Grid {
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

/// The grid polygonisation (`polygonise(offset)` makes it `offset` grid cells outside the zero set), and
/// whether it was thickened: where it has handles, the thickened one is kept if it has fewer
/// (see `THICKEN_CELLS`; the caller moves its vertices back).
fn polygonise_on_grid(polygonise: &dyn Fn(f32) -> Result<Mesh>) -> Result<(Mesh, bool)> {
    let fine = polygonise(0.0)?;
    let genus = topology::closed_surface_genus(&fine);
    if genus > 0 {
        // A thickened surface too large for the grid budget is no reason to fail: the plain
        // one stands.
        if let Ok(thick) = polygonise(THICKEN_CELLS) {
            if !thick.triangles.is_empty() && topology::closed_surface_genus(&thick) < genus {
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
fn move_inward(mesh: &mut Mesh, neighbours: &adjacency::Rows, distance: f32, threads: &Threads) {
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

/// Per node, for T-nodes: the largest distance from one of its samples to its plane (0 for
/// other nodes, and for a label no T-node has).
fn plane_sags(tree: &VsTree, threads: &Threads) -> Vec<f32> {
    threads.run(|| {
        tree.nodes
            .par_iter()
            .map(|node| {
                if node.kind != NodeKind::Transition {
                    return 0.0;
                }
                let frame = &tree.frames[node.frame as usize];
                tree.samples_of(node).iter().map(|s| frame.height(s.position).abs()).fold(0.0, f32::max)
            })
            .collect()
    })
}

/// The median of `values` (0 when empty).
fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
}

/// The typical distance between neighbouring samples: the median, over up to 2,000 of the odd
/// points, of the distance to the nearest even point at another place (`near` holds `points`;
/// duplicate points would make it 0).
fn sample_spacing(near: &KdTree, points: &[Vec3]) -> f32 {
    let odd: Vec<Vec3> = points.iter().skip(1).step_by(2).copied().collect();
    median(
        evenly_spread(&odd, 2000)
            .iter()
            .filter_map(|&p| near.nearest_among(p, |i| i % 2 == 0 && points[i as usize] != p).map(|(d, _)| d))
            .filter(|d| d.is_finite())
            .collect(),
    )
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

/// Samples per local fit of the samples' surface: [`mls::NEIGHBOURS`] on a clean cloud, and
/// more as the noise grows against the spacing, so that a fit averages it away (a fit's noise
/// shrinks as the square root of its samples).
fn fit_neighbours(noise: f32, spacing: f32) -> usize {
    let ratio = if spacing > 0.0 { f64::from(noise / spacing) } else { 0.0 };
    mls::NEIGHBOURS + (FIT_NEIGHBOURS_PER_NOISE * ratio * ratio).min(1e6) as usize
}

/// At most `n` of `points`, evenly spread through the slice.
fn evenly_spread(points: &[Vec3], n: usize) -> Vec<Vec3> {
    let step = points.len().div_ceil(n.max(1)).max(1);
    points.iter().step_by(step).copied().collect()
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

/// Renumbers the vertices that `triangles` use 0, 1, ... in the order they first appear, and
/// returns the old index of each new one (vertices no triangle uses are left out).
pub(super) fn renumber_used_vertices(triangles: &mut [[u32; 3]], vertices: usize) -> Vec<usize> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_points_do_not_make_the_spacing_zero() {
        // A 0.01 grid, every point twice and next to its copy (as the tree orders them): each
        // odd point's nearest even one was its copy (a bull of 20k points, each twice, came
        // out with genus 47 on a grid finer than its samples).
        let points: Vec<Vec3> = (0..100 * 100)
            .flat_map(|k| {
                let p = Vec3::new((k % 100) as f32 * 0.01, (k / 100) as f32 * 0.01, 0.0);
                [p, p]
            })
            .collect();
        let near = KdTree::new(&points).unwrap();
        assert!((sample_spacing(&near, &points) - 0.01).abs() < 1e-6, "{}", sample_spacing(&near, &points));
    }
}
