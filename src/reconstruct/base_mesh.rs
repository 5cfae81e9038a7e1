//! Stage 2: the base mesh M0, one vertex per T-node. The implicit function ([`field`]) is
//! polygonised, over the tree's octree ([`BaseMesh::Adaptive`], [`dual_contour`]) or on a
//! uniform grid ([`on_grid`]); faces no sample supports tell an open scan ([`support`]), whose
//! unsupported part is dropped; the rest is clustered at the T-layer ([`cluster`]).

use super::lookup::Lookup;
use super::prepare::keep_unmarked;
use super::{adjacency, cluster, dual_contour, field, on_grid, refine, support, thicken};
use super::{BaseMesh, Closure, ReconstructParams, ReconstructStats};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::topology;
use crate::tree::{NodeKind, VsTree};
use rayon::prelude::*;

/// On an open M0, one vertex stands for a stretch of border at most this many typical T-node
/// sides long (inside, one vertex stands for a T-node): a vertex per T-node along the border
/// too cuts its bends short by as much as the T-node is large, and a flat region's T-node can
/// span half the model. Half a side gave fans of slivers at the border (29% of the angles
/// under 10 degrees on the fandisk view, against 20%), no limit a Chamfer 1.7x larger there.
const BORDER_RUN: f32 = 1.0;

/// How far from the samples, in T-node plane sags, a point of a face over the octree may lie
/// and still be supported: the vertex at either end of a chord across two neighbouring T-nodes
/// lies inside the surface by up to one sag, and the chord, twice a T-node's length, sags four.
const CHORD_SAGS: f32 = 5.0;

/// Over the octree, the band where a closed surface turns behind an open scan's border is a
/// T-node wide rather than a grid cell, and the unsupported share comes out lower than on the
/// grid (a hemisphere's: 0.28 against 0.35, OPEN_SHARE 0.30). A share over the octree above
/// this fraction of OPEN_SHARE is measured again on the grid; closed objects stay well below
/// (rotor_small's creases and capped blind holes, the highest of the corpus's clean 200k
/// clouds, 0.10).
const OCTREE_DOUBT: f64 = 2.0 / 3.0;

/// When the grid measures the open share again, its surface replaces the octree's if its
/// unsupported share is below this fraction of the octree's: a share several times smaller means
/// the octree's cells crossed empty space (cheese: 0.04 against 0.36), while shares this close
/// differ by the two bands only, and the octree's surface is the better one (a box at 20k points:
/// 0.23 on the grid, whose surface has two spurious handles; pinned by
/// `closed_solids_with_sharp_creases_stay_closed`).
const GRID_KEPT_BELOW: f64 = 0.5;

/// Samples in front of a T-node face it when their normals' cosine to its normal is below this
/// (120 degrees): two sheets facing each other across a gap. Curved or noisy samples of the
/// T-node's own sheet turn by less.
const OPPOSED: f32 = -0.5;

/// M0, with what the later stages measure against.
pub(super) struct Base {
    pub surface: refine::Surface,
    /// The output is open: asked for, or an open scan found.
    pub open: bool,
    /// What distances from the samples count in: the polygonisation grid's cell, or the
    /// sample spacing where the samples are sparser than the grid.
    pub unit: f32,
    /// The polygonisation grid's cell (what `trim` counts in).
    pub grid_cell: f32,
}

/// The base mesh of the samples' tree.
pub(super) fn build(
    near: &Lookup,
    params: &ReconstructParams,
    threads: &Threads,
    stats: &mut ReconstructStats,
    progress: &mut Progress,
) -> Result<Base> {
    let tree = near.tree;
    let grid = on_grid::grid(tree, params.max_grid_depth, near.spacing);
    stats.grid_cells = grid.dims[0] - 5;
    let unit = grid.cell.max(near.spacing);
    let field = field::Field::new(tree, near, params.base_mesh, unit, grid.cell);
    let polygonisation = Polygonisation {
        tree,
        near,
        field: &field,
        kind: params.base_mesh,
        grid: &grid,
        unit,
        sag: plane_sags(tree, threads),
        sample_normals: tree.samples.iter().map(|s| s.normal).collect(),
        smallest_hole: smallest_hole(near),
        why_no_surface: too_sparse_or_unoriented(tree, stats),
        threads,
    };
    // Open asked for; `Auto` first polygonises as for a closed output and, if that finds an
    // open scan, again as for an open one.
    let asked_open = params.closure == Closure::Open || params.trim > 0.0;
    let mut part = polygonisation.run(asked_open, true)?;
    // Where the octree's coarse band along a border leaves it in doubt, the grid's finer one
    // decides. Where the grid's surface has much less area away from the
    // samples, the octree's cells crossed empty space, and the grid's is kept (see
    // GRID_KEPT_BELOW).
    if params.closure == Closure::Auto
        && !asked_open
        && !part.on_grid
        && part.share > OCTREE_DOUBT * support::OPEN_SHARE
    {
        let grid_part = polygonisation.run(false, false)?;
        if grid_part.share < GRID_KEPT_BELOW * part.share {
            part = grid_part;
        } else {
            part.share = grid_part.share;
        }
    }
    stats.unsupported_share = part.share;
    let open = asked_open || support::is_open(params.closure, part.share);
    if open && !asked_open {
        part = polygonisation.run(true, false)?;
    }
    drop(polygonisation);
    progress.report(0.4, "base mesh")?;
    let Polygonised { mut fine, thickened, on_grid, neighbours, labels, unsupported, .. } = part;
    stats.thickened = thickened;
    stats.on_grid = on_grid;
    stats.fine_triangles = fine.triangles.len();
    stats.field_evaluations = field.evaluations();
    let neighbours = if open {
        // An open M0 is made of the supported part only: the closing sheet never joins a
        // T-node's cluster.
        keep_unmarked(&mut fine.triangles, &unsupported);
        // Parts left smaller than the smallest hole are shreds of the closing sheet's edge.
        drop_small_parts(&mut fine, smallest_hole(near));
        adjacency::Rows::neighbours(&fine.triangles, fine.positions.len())
    } else {
        neighbours
    };
    let border_run = BORDER_RUN * 2.0 * near.typical_t_half;
    let mut base = cluster::cluster_at_t_layer(&fine, &labels, &neighbours, grid.cell, border_run);
    // Closed parts of M0 smaller than the smallest hole are shells that clustering flattened
    // (a few T-nodes on a bubble of the implicit function): nothing a T-node can stand for.
    // (An open M0's parts were sorted out on the fine mesh, where a part is not cut short.)
    if !open && drop_small_parts(&mut base.mesh, smallest_hole(near)) {
        base.drop_unused_vertices();
    }
    drop((fine, labels, neighbours));
    if base.mesh.triangles.is_empty() {
        return Err(Error::input(format!(
            "the base mesh is empty: every part of the polygonised surface was smaller than the tree's \
             T-layer can stand for ({})",
            too_sparse_or_unoriented(tree, stats)
        )));
    }
    if !on_grid {
        at_sample_centroids(tree, &mut base);
    }
    stats.base_vertices = base.mesh.positions.len();
    stats.base_triangles = base.mesh.triangles.len();
    let report = topology::analyze(&base.mesh);
    (stats.base_genus, stats.base_boundary_edges) = (report.genus(), report.boundary_edges);
    let surface = refine::Surface {
        normals: base.labels.iter().map(|&t| tree.frames[tree.nodes[t as usize].frame as usize].normal).collect(),
        positions: base.mesh.positions,
        labels: base.labels,
        triangles: base.mesh.triangles,
    };
    Ok(Base { surface, open, unit, grid_cell: grid.cell })
}

/// Parts and holes smaller than this area are below what the T-layer stands for: a square of
/// the typical T-node's side.
fn smallest_hole(near: &Lookup) -> f64 {
    f64::from(2.0 * near.typical_t_half).powi(2)
}

/// What a cloud that gives no surface most likely is.
fn too_sparse_or_unoriented(tree: &VsTree, stats: &ReconstructStats) -> String {
    format!(
        "{} points{}: too few or too scattered to sample a surface, or normals that do not face one way",
        tree.samples.len(),
        if stats.normals.estimated > 0 { ", normals estimated" } else { ", normals given" }
    )
}

/// What polygonising the implicit function needs.
struct Polygonisation<'a> {
    tree: &'a VsTree,
    near: &'a Lookup<'a>,
    field: &'a field::Field<'a>,
    kind: BaseMesh,
    grid: &'a crate::polygonise::Grid,
    unit: f32,
    /// Per node, its plane's sag (see [`plane_sags`]).
    sag: Vec<f32>,
    sample_normals: Vec<glam::Vec3>,
    smallest_hole: f64,
    /// What a cloud that gives no surface most likely is.
    why_no_surface: String,
    threads: &'a Threads,
}

/// The implicit function's zero set, polygonised, and what the base mesh needs of it.
struct Polygonised {
    fine: Mesh,
    /// Thickened: see [`thicken`].
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

impl Polygonisation<'_> {
    /// The zero set for a closed or an `open` output.
    fn run(&self, open: bool, octree: bool) -> Result<Polygonised> {
        let (tree, threads) = (self.tree, self.threads);
        // Over the octree for a closed output; where the adaptive polygonisation cannot make a
        // 2-manifold even with its finest leaves (sheets closer than the samples resolve), and
        // for an open one, on the grid: an open output is the supported part of the zero set,
        // cut along faces, and the octree's faces in the empty space behind a scan are as large
        // as the space is, so its border would be as coarse.
        let contour = match self.kind {
            BaseMesh::Adaptive if octree && !open => {
                let facing = |centre: glam::Vec3, radius: f32, t: u32| {
                    let frame = &tree.frames[tree.nodes[t as usize].frame as usize];
                    let index = self.near.index();
                    index.any_within_among(centre, radius, |i| {
                        let s = &tree.samples[i as usize];
                        s.normal.dot(frame.normal) < OPPOSED && frame.height(s.position) > 0.0
                    })
                };
                let at_offset = |lift: &(dyn Fn(glam::Vec3) -> f32 + Sync)| {
                    dual_contour::contour(tree, &|p| self.field.at(p, open) - lift(p), &facing, self.unit, threads)
                        .map(|c| (Mesh::new(c.positions, None, c.triangles), c.labels))
                };
                let thin = (&tree.samples[..], self.near.index(), &self.sample_normals[..]);
                at_offset(&|_| 0.0).map(|plain| {
                    thicken::where_handles(plain, at_offset, thin, self.unit, Some(self.smallest_hole), threads)
                })
            }
            _ => None,
        };
        let on_grid = contour.is_none();
        let (fine, labels, thickened) = match contour {
            // Moved back from the offset, a vertex lies in another leaf than the one it came
            // from: it is labelled where it lies.
            Some(((fine, labels), thickened)) => (fine, (!thickened).then_some(labels), thickened),
            None => {
                let (fine, thickened) = on_grid::polygonise(
                    self.grid,
                    tree,
                    (self.near.index(), &self.sample_normals),
                    self.field,
                    open,
                    threads,
                )?;
                (fine, None, thickened)
            }
        };
        if fine.triangles.is_empty() {
            return Err(Error::input(match self.kind {
                BaseMesh::Winding | BaseMesh::Adaptive => format!(
                    "the points enclose no volume: their winding number stays below one half everywhere \
                     near them ({})",
                    self.why_no_surface
                ),
                BaseMesh::Paper => format!(
                    "the blended T-node planes have no zero crossing near the samples ({})",
                    self.why_no_surface
                ),
            }));
        }
        let neighbours = adjacency::Rows::neighbours(&fine.triangles, fine.positions.len());
        let labels = match labels {
            Some(labels) => cluster::spread_labels(labels, &neighbours),
            None => threads.run(|| cluster::label_vertices(tree, &fine, &neighbours)),
        };
        let reach = support::SUPPORT_REACH * self.unit;
        // A face over the octree joins the vertices of neighbouring T-nodes, each inside the
        // surface by up to its T-node's sag: a chord twice as long sags four times as much.
        let sags = if on_grid { 1.0 } else { CHORD_SAGS };
        let face_reach = |f: usize| {
            let sag = fine.triangles[f]
                .iter()
                .map(|&v| self.sag.get(labels[v as usize] as usize).copied().unwrap_or(0.0))
                .fold(0.0, f32::max);
            reach + sags * sag
        };
        // Its inside is judged at points a reach apart across it, as the grid's small faces are.
        let across = |f: usize| {
            if on_grid {
                return 1;
            }
            support::points_across(&fine, f, face_reach(f))
        };
        let mut support =
            support::supported_faces(&fine, self.near.index(), &self.sample_normals, face_reach, across, threads);
        if !on_grid {
            let agrees = facing_their_t_nodes(tree, &fine, threads);
            for (s, _) in support.iter_mut().zip(&agrees).filter(|(_, &a)| a) {
                *s = (support::Support::Supported, 0.0);
            }
        }
        // Faces that no sample supports: far from all, or near only samples facing the other
        // way (the closing sheet right behind an open scan).
        let unsupported: Vec<bool> = support.iter().map(|&(s, _)| s != support::Support::Supported).collect();
        let kept = support::without_small_regions(&fine, &unsupported, self.smallest_hole);
        // The share counts the part of a supported face that is not supported, and none of a
        // region too small to count.
        let weights: Vec<f32> = (0..kept.len())
            .map(|f| {
                if kept[f] {
                    1.0
                } else if unsupported[f] {
                    0.0
                } else {
                    support[f].1
                }
            })
            .collect();
        let share = support::unsupported_share(&fine, &weights);
        let unsupported = kept;
        Ok(Polygonised { fine, thickened, on_grid, neighbours, labels, unsupported, share })
    }
}

/// Per face of a polygonisation over the octree: whether each of its corners lies in a T-node
/// whose normal agrees with the face's (see [`support::SUPPORT_AGREEMENT`]). Such a face joins
/// T-nodes of one sheet and the samples support it, however far its chord cuts across a
/// crease between them (a chord across two flat T-nodes at a right angle leaves their samples
/// by up to half a T-node, far beyond the sags the geometric test allows for).
fn facing_their_t_nodes(tree: &VsTree, fine: &Mesh, threads: &Threads) -> Vec<bool> {
    let at: Vec<Option<u32>> =
        threads.run(|| fine.positions.par_iter().map(|&p| cluster::t_node_at(tree, p)).collect());
    fine.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| fine.positions[v as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            t.iter().all(|&v| {
                at[v as usize].is_some_and(|t| {
                    tree.frames[tree.nodes[t as usize].frame as usize].normal.dot(n) > support::SUPPORT_AGREEMENT
                })
            })
        })
        .collect()
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

/// Moves each M0 vertex that alone stands for its T-node, away from the border, to the centroid
/// of the T-node's samples (its frame's origin). Over the octree a vertex is the mean of the
/// points where the surface crosses its T-node's edges: on a cube as large as a T-node, that
/// mean lies inside a curved or creased surface by up to the cube's sag, where the samples'
/// centroid lies on their plane. A T-node with several vertices keeps them where they are
/// (moving them to one point would fold M0).
fn at_sample_centroids(tree: &VsTree, base: &mut cluster::Clustered) {
    let mut count: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for &t in &base.labels {
        *count.entry(t).or_default() += 1;
    }
    let border = topology::border_vertices(&base.mesh.triangles, base.mesh.positions.len());
    for (v, &t) in base.labels.iter().enumerate() {
        if count[&t] == 1 && !border[v] && t != cluster::UNLABELLED {
            base.mesh.positions[v] = tree.frames[tree.nodes[t as usize].frame as usize].origin;
        }
    }
}
