//! What [`super::reconstruct`] is asked ([`ReconstructParams`]) and what it reports
//! ([`ReconstructStats`], [`RefinementStop`]).

/// What decides inside and outside for the base mesh.
use super::{refine::LevelStats, support::Closure};
use crate::error::{Error, Result};
use crate::normals::{NormalParams, NormalsReport};
use crate::params;
use crate::tree::{TreeKind, TreeParams, TreeStats};
use std::ffi::CStr;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BaseMesh {
    /// The samples' winding number gives the side everywhere, the distance to the nearest
    /// sample the value. The winding number is a property of the whole cloud, so the topology
    /// does not depend on how large the T-nodes near a thin part or a narrow gap are, and the
    /// distance keeps details down to the sample spacing.
    Winding,
    /// The paper's §5.2: the T-nodes' planes blended by a partition of unity near the samples
    /// (the winding number only decides beyond them). Kept to compare with.
    Paper,
    /// The winding number's side, polygonised over the tree's own octree with the T-nodes as
    /// cells (dual contouring, see `dual_contour`) instead of on a grid as fine as the deepest
    /// T-node: each region at its own T-node's size, the field evaluated at the T-layer's corners.
    /// The default.
    #[default]
    Adaptive,
}

/// Parameters of [`super::reconstruct`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReconstructParams {
    /// The tree: its L2 bound smooths noise (larger = smoother, fewer details); `d_a`/`d_d`
    /// set how deep the T-layer goes, i.e. how dense M0 is where curvature is high.
    pub tree: TreeParams,
    /// Stop refining once error(M, S) (RMS distance over the diagonal) is at most this; each
    /// level then splits only the regions of M0 whose samples are farther (in RMS) from their
    /// triangles than this, so the triangles go where the detail is.
    /// 0 = refine everywhere until the quadtrees have no detail left or `max_levels`.
    pub target_distance: f64,
    /// Most refinement levels (each multiplies the triangle count by 4). 0-12.
    pub max_levels: u32,
    /// A level that displaces fewer than this fraction of its new vertices ends refinement:
    /// the quadtrees have no detail left for further levels. In [0, 1].
    pub min_displaced: f64,
    /// No level is started that would exceed this many triangles.
    pub max_triangles: usize,
    /// The polygonisation grid is as fine as the deepest T-node, but never finer than
    /// 2^`max_grid_depth` cells across. 4-20.
    pub max_grid_depth: u32,
    /// Remove faces farther than this many grid cells from every sample (open scans give
    /// open meshes); 0 keeps the closed surface. Above 0 the input is taken to be open, and
    /// the closing sheet behind it is placed farther back, so that it is trimmed away.
    pub trim: f32,
    /// Open or closed output: by default (`Auto`) open where much of the closed surface is far
    /// from every sample (a scan from one side), closed otherwise (holes closed over); `Open`
    /// keeps only the part of the surface the samples support (a scan's holes too), `Closed`
    /// always closes.
    pub closure: Closure,
    /// How the base mesh's inside and outside are decided.
    pub base_mesh: BaseMesh,
    /// Normals: estimated where the cloud has none (PCA over neighbours, oriented by spanning
    /// tree propagation, turned outward); the cloud's own are kept unless
    /// `normals.reorient_given`.
    pub normals: NormalParams,
    /// Worker threads; 0 = all cores.
    pub threads: usize,
}

impl Default for ReconstructParams {
    fn default() -> Self {
        ReconstructParams {
            tree: TreeParams { error: params::RECONSTRUCT_ERROR.default, ..TreeParams::default() },
            target_distance: params::RECONSTRUCT_TARGET_DISTANCE.default,
            max_levels: params::RECONSTRUCT_MAX_LEVELS.default_u32(),
            min_displaced: params::RECONSTRUCT_MIN_DISPLACED.default,
            max_triangles: params::RECONSTRUCT_MAX_TRIANGLES.default as usize,
            max_grid_depth: params::RECONSTRUCT_MAX_GRID_DEPTH.default_u32(),
            trim: params::RECONSTRUCT_TRIM.default as f32,
            closure: Closure::Auto,
            base_mesh: BaseMesh::default(),
            normals: NormalParams::default(),
            threads: 0,
        }
    }
}

impl ReconstructParams {
    /// Rejects values outside their documented ranges, naming the parameter.
    pub fn check(&self) -> Result<()> {
        self.tree.check()?;
        // Even when the cloud's own normals are kept: a value outside the range is a mistake.
        self.normals.check()?;
        if self.tree.kind != TreeKind::VsTree {
            return Err(Error::param(
                "tree_kind",
                "octree: reconstruction needs the VS-Tree, whose T-nodes make the base mesh (the octree is \
                 for simplification)",
            ));
        }
        // At these ends of their ranges the height-field test passes only where a cell's samples
        // are all at one point, so the T-layer, and the base mesh made of it, misses the
        // surface. Fine for simplification (the tree is then an octree), not here.
        if self.tree.d_a >= 1.0 {
            return Err(Error::param(
                "d_a",
                format!(
                    "{}: the height-field test (every normal's dot product with the cell's mean normal \
                     above d_a) can never hold, so no cell becomes a T-node and there is no base mesh; \
                     reconstruction needs d_a below 1 (default {})",
                    self.tree.d_a,
                    TreeParams::default().d_a
                ),
            ));
        }
        if self.tree.d_d <= 0.0 {
            return Err(Error::param(
                "d_d",
                format!(
                    "{}: the height-field test (every sample's height over the cell's plane below d_d \
                     times the cell's radius) can never hold, so no cell becomes a T-node and there is no \
                     base mesh; reconstruction needs d_d above 0 (default {:.4})",
                    self.tree.d_d,
                    TreeParams::default().d_d
                ),
            ));
        }
        params::RECONSTRUCT_TARGET_DISTANCE.check(self.target_distance, self.target_distance)?;
        params::RECONSTRUCT_MAX_LEVELS.check(self.max_levels.into(), self.max_levels)?;
        params::RECONSTRUCT_MIN_DISPLACED.check(self.min_displaced, self.min_displaced)?;
        params::RECONSTRUCT_MAX_TRIANGLES.check(self.max_triangles as f64, self.max_triangles)?;
        params::RECONSTRUCT_MAX_GRID_DEPTH.check(self.max_grid_depth.into(), self.max_grid_depth)?;
        params::RECONSTRUCT_TRIM.check(self.trim.into(), self.trim)
    }
}

/// Why the refinement loop ended.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RefinementStop {
    /// error(M, S) reached `target_distance`.
    Target,
    /// A level displaced fewer than `min_displaced` of its new vertices: the quadtrees have
    /// no detail left.
    #[default]
    NoDetail,
    /// `max_levels` levels were done.
    MaxLevels,
    /// The next level would have exceeded `max_triangles`: the target asks for more triangles
    /// than allowed (raise `max_triangles` or the target, or lower the tree's bound).
    TriangleBudget,
}

impl RefinementStop {
    /// Every reason.
    /// cbindgen:ignore
    pub const ALL: [RefinementStop; 4] =
        [RefinementStop::Target, RefinementStop::NoDetail, RefinementStop::MaxLevels, RefinementStop::TriangleBudget];

    /// The reason's name: "target", "no_detail", "max_levels" or "triangle_budget". The CLI
    /// prints it, the C API gives it (vstree_refinement_stopped_str()), and the Python
    /// bindings put it in their statistics.
    pub fn as_str(self) -> &'static str {
        // The names are ASCII, so never "".
        self.as_c_str().to_str().unwrap_or_default()
    }

    /// [`RefinementStop::as_str`] as a static C string, for the C API.
    pub fn as_c_str(self) -> &'static CStr {
        match self {
            RefinementStop::Target => c"target",
            RefinementStop::NoDetail => c"no_detail",
            RefinementStop::MaxLevels => c"max_levels",
            RefinementStop::TriangleBudget => c"triangle_budget",
        }
    }
}

/// What [`super::reconstruct`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReconstructStats {
    /// What was done to the normals.
    pub normals: NormalsReport,
    /// Points left out as isolated: far from the rest for their neighbours' spacing (see
    /// `outliers`).
    pub isolated_points: usize,
    /// The samples' noise level over the bounding box's diagonal: the standard deviation of
    /// their distance to a smooth surface, as local quadratic fits leave it (see `noise`).
    pub noise: f64,
    pub tree: TreeStats,
    /// Cells across the polygonisation grid (a power of two).
    pub grid_cells: u32,
    pub fine_triangles: usize,
    /// Points where the base mesh's implicit function (inside or outside) was evaluated.
    pub field_evaluations: usize,
    /// The polygonisation was thickened (see the `reconstruct` module): the plain one had
    /// handles that vanished once parts thinner than the grid were thickened.
    pub thickened: bool,
    /// The base mesh was polygonised on the uniform grid: asked for, or the adaptive
    /// polygonisation ([`BaseMesh::Adaptive`]) could not make a 2-manifold.
    pub on_grid: bool,
    /// Share of the polygonised closed surface's area no sample supports: farther than the
    /// support's reach from every sample, or near only samples facing the other way (about
    /// half for a scan from one side).
    pub unsupported_share: f64,
    /// The output is the supported part only (see [`Closure`]).
    pub open: bool,
    /// Edges of M0 with one face (0 when M0 is closed).
    pub base_boundary_edges: usize,
    pub base_vertices: usize,
    pub base_triangles: usize,
    /// Genus of M0 when it is a closed manifold.
    pub base_genus: Option<u32>,
    /// Vertices of M0's specks dropped: components its projection squeezed below two sample
    /// spacings.
    pub base_specks: usize,
    pub levels: Vec<LevelStats>,
    /// Why refinement ended.
    pub stopped: RefinementStop,
    /// error(M, S) of M0 and of the final mesh: RMS and max sample-to-mesh distance over the
    /// diagonal.
    pub base_error: f64,
    pub final_error: f64,
    pub final_max_error: f64,
    /// Edges collapsed after the last level to take out folded slivers.
    pub sliver_collapses: usize,
    pub trimmed_triangles: usize,
    pub output_vertices: usize,
    pub output_triangles: usize,
    pub seconds_normals: f64,
    pub seconds_tree: f64,
    pub seconds_base: f64,
    pub seconds_refine: f64,
    pub seconds_trim: f64,
}
