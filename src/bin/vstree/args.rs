//! The command line's flags and subcommands, and their conversion into library parameters.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use vstree::reconstruct::ReconstructParams;
use vstree::tree::{Metric, TreeKind, TreeParams};
use vstree::{MeshSampling, Threads};

#[derive(Parser)]
#[command(
    name = "vstree",
    version,
    about = "Volume-Surface Trees: clustering simplification and surface reconstruction"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
#[command(args_conflicts_with_subcommands = false)]
pub(crate) enum Command {
    /// Simplify a mesh (or a point cloud) by clustering in a VS-Tree.
    ///
    /// Every leaf of the tree becomes one output vertex, placed where it best fits the samples'
    /// tangent planes; triangles are re-indexed, and those that collapse are dropped. A point
    /// cloud without normals gets them estimated first. The size is set by the error bound
    /// (--error), or exactly by --faces or --ratio. An edge-manifold input (no edge in
    /// more than two triangles: closed or with borders, as most scans are) keeps its topology
    /// unless --no-keep-topology is given.
    ///
    /// A run that would keep nothing of the shape is an error naming the flag that made the tree
    /// that coarse (--error, --max-depth or --min-cell-size): a mesh whose every triangle
    /// collapses, or a cloud whose every point collapses into one. A flat cloud (3 points are
    /// one) is within any L2 or l21 bound of one plane: simplify it with --metric density,
    /// which splits by sample count (--error 1 keeps every point).
    Simplify {
        /// Input file: .ply, .obj, .off, .xyz or .pwn.
        input: PathBuf,
        /// Output file (format from the extension). Written atomically: never left half-done.
        output: PathBuf,
        #[command(flatten)]
        tree: TreeArgs,
        /// Which mesh elements become samples.
        #[arg(long, value_enum, default_value_t = Sampling::Vertices)]
        sampling: Sampling,
        /// Triangles wanted (instead of --error): the tree is grown or cut, splitting the
        /// cluster with the largest error first, and quadric edge collapses bring the mesh to
        /// this count (within one triangle). Below what the topology allows (a closed surface
        /// of genus g needs more than 4 g triangles, a tetrahedron's 4 at least) the output is
        /// the smallest mesh reachable, and a warning says so. 0 = use the error bound.
        #[arg(long, allow_hyphen_values = true, conflicts_with_all = ["ratio", "error"])]
        faces: Option<i64>,
        /// Fraction of the input's triangles wanted, in (0, 1] (instead of --error): 0.1 keeps
        /// 10%, rounded, at least 1 triangle; then as --faces.
        #[arg(long, allow_hyphen_values = true, conflicts_with = "error")]
        ratio: Option<f64>,
        /// Keep the topology: clusters merge by edge collapses that keep a closed 2-manifold
        /// closed and manifold with its genus (and an open one's borders manifold, its holes
        /// open); a cluster that cannot merge without changing the topology keeps a vertex per
        /// piece, so the output may have more vertices than clusters. The default for
        /// edge-manifold inputs; this flag asks for it on any input.
        #[arg(long, conflicts_with = "no_keep_topology")]
        keep_topology: bool,
        /// Plain vertex clustering even for an edge-manifold input: faster, but sheets
        /// closer than a cluster may fuse, with non-manifold edges and another genus.
        #[arg(long)]
        no_keep_topology: bool,
        /// Read a PLY file in passes instead of holding it, for meshes larger than memory:
        /// memory follows the output's size plus 4 bytes per input vertex. The file is read
        /// three times; the tree is built from a sample of its triangles (face centres,
        /// whatever --sampling says), and the clustering is plain: the topology is not kept
        /// (sheets closer than a cluster may fuse). Needs --faces or --ratio (with --ratio,
        /// the faces the header declares are counted). auto = when the file is larger than
        /// an eighth of the memory available and the other conditions hold.
        #[arg(long, value_enum, default_value_t = Stream::Auto)]
        stream: Stream,
        /// Write PLY as text instead of binary.
        #[arg(long)]
        ascii: bool,
    },
    /// Reconstruct a triangle mesh from a point cloud with normals (paper section 5).
    ///
    /// The T-layer of the tree gives a coarse closed base mesh of the right genus; it is then
    /// refined (1-to-4 on curved PN triangles) and its new vertices pulled onto the samples by
    /// the quadtrees, until the mesh is close enough or the tree has no detail left.
    Reconstruct {
        /// Input point cloud with normals: .ply, .xyz, .pwn (or a mesh: its vertices are used).
        input: PathBuf,
        /// Output mesh (format from the extension). Written atomically.
        output: PathBuf,
        #[command(flatten)]
        tree: TreeArgs,
        /// Stop refining once the RMS distance from the samples to the mesh is at most this
        /// fraction of the bounding-box diagonal, splitting only the regions whose samples are
        /// farther than this (0 = refine everywhere while the tree has detail left).
        #[arg(long, allow_hyphen_values = true, default_value_t = ReconstructParams::default().target_distance)]
        target: f64,
        /// Most refinement levels (each one multiplies the triangles by 4).
        #[arg(long, allow_hyphen_values = true, default_value_t = ReconstructParams::default().max_levels.into())]
        levels: i64,
        /// Remove every face farther than this many grid cells from every sample, and make the
        /// output open (0 = no such trimming: open scans are found and cut at their border
        /// without it).
        #[arg(long, allow_hyphen_values = true, default_value_t = ReconstructParams::default().trim)]
        trim: f32,
        /// Keep only the part of the surface that the samples support, whatever its share: a
        /// scan's holes stay open too. By default the output is open only where much of the
        /// closed surface (30%) is unsupported by the samples, as behind a scan from one side.
        #[arg(long, conflicts_with = "closed")]
        open: bool,
        /// Always close the surface, over holes and the back of an open scan.
        #[arg(long)]
        closed: bool,
        /// Accepted for scripts written for 0.2, where open output was not the default: it
        /// is now.
        #[arg(long, hide = true)]
        detect_open: bool,
        /// What decides the base mesh's inside and outside.
        #[arg(long, value_enum, default_value_t = BaseMeshArg::Adaptive)]
        base_mesh: BaseMeshArg,
        /// Re-orient the normals the cloud already has (consistent by spanning-tree
        /// propagation, then facing outward). Clouds without normals always get them estimated.
        #[arg(long)]
        reorient: bool,
        /// Neighbours used to estimate normals (3-256).
        #[arg(long, allow_hyphen_values = true, default_value_t = vstree::normals::DEFAULT_NEIGHBOURS as i64)]
        neighbours: i64,
        /// Write PLY as text instead of binary.
        #[arg(long)]
        ascii: bool,
    },
    /// Run both jobs on a generated sample, no input needed: a bumpy sphere of 1.3M triangles is
    /// simplified (VS-Tree and octree side by side), and a noisy 200k-point cloud drawn on a
    /// genus-3 shape is reconstructed. Everything is written to the output folder.
    Demo {
        /// Folder for the sample inputs and the results (created if missing).
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Build the tree and print its statistics, without writing anything.
    Stats {
        /// Input file: .ply, .obj, .off, .xyz or .pwn.
        input: PathBuf,
        #[command(flatten)]
        tree: TreeArgs,
        /// Which mesh elements become samples.
        #[arg(long, value_enum, default_value_t = Sampling::Vertices)]
        sampling: Sampling,
        /// Also build the other kind of tree (octree or VS-Tree) and compare cluster counts.
        #[arg(long)]
        compare: bool,
    },
}

/// The L2 bound to simplify with, and for `stats`, when `--error` is not given: the
/// library's, as in C, Python, MeshLab and Blender.
pub(crate) const SIMPLIFY_ERROR: f64 = TreeParams::DEFAULT_ERROR;

#[derive(Args, Clone)]
pub(crate) struct TreeArgs {
    /// Hierarchy: the VS-Tree, or a plain octree (the baseline).
    #[arg(long, value_enum, default_value_t = Kind::Vstree)]
    pub(crate) tree: Kind,
    /// Error metric that decides when a cell is split.
    #[arg(long, value_enum, default_value_t = MetricArg::L2)]
    pub(crate) metric: MetricArg,
    /// Error bound per cluster. L2: sum of squared sample-plane distances over the squared
    /// bounding-box diagonal (every sample's tangent plane then passes within sqrt(error) x
    /// diagonal of its cluster's point); l21: mean squared normal deviation (0-4); density:
    /// samples per cluster.
    /// Larger = coarser output (and, to reconstruct, smoother: it is the de-noising control).
    /// Given a size (--faces, --ratio), the bound is no bound and is not used.
    /// [default: 1e-3 to simplify and for stats, 1e-5 to reconstruct; l21: 1e-3; density: 16]
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) error: Option<f64>,
    /// Normal-cone threshold of the height-field test, in [0, 1]: a cell becomes a surface
    /// (2D) node only if every normal's dot product with the mean normal exceeds it. Raise it
    /// for more adaptivity in curved areas.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().d_a)]
    pub(crate) da: f32,
    /// Displacement threshold of the height-field test, in [0, 1]: a cell's height range over
    /// its radius must stay below it. Lower it for more adaptivity in curved areas.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().d_d)]
    pub(crate) dd: f32,
    /// Deepest tree level (1-30).
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().max_depth.into())]
    pub(crate) max_depth: i64,
    /// Cells smaller than this fraction of the bounding-box diagonal are not split, in [0, 1):
    /// guards against duplicate points.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().min_cell_size)]
    pub(crate) min_cell_size: f64,
    /// Worker threads (0 = all cores).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    pub(crate) threads: i64,
    /// No progress bar and no report: print nothing but errors (`stats` still prints its
    /// statistics, which are its output).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Kind {
    /// Octree far from the surface, quadtrees in its tangent planes near it (the paper's).
    Vstree,
    /// A plain octree with the same metric and bound: the baseline to compare with.
    Octree,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum MetricArg {
    /// Quadric error: how far the cluster's point is from its samples' tangent planes.
    L2,
    /// Normal deviation: how much the cluster's normals differ from their mean.
    L21,
    /// Sample count: at most `--error` samples per cluster (cheap, for huge inputs).
    Density,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum BaseMeshArg {
    /// The points' winding number says inside or outside, the distance to the nearest point how
    /// far, polygonised on a grid as fine as the smallest T-node (the default before 0.7.0).
    Winding,
    /// The paper's construction: the T-nodes' planes blended near the points (to compare with).
    Paper,
    /// The winding number's side, polygonised over the tree's octree, each region at its own
    /// T-node's size (the field evaluated at the T-layer's corners, not on a fine grid; an open
    /// output is made on the grid). The default.
    Adaptive,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Sampling {
    /// One sample per vertex (normal: area-weighted face normals).
    Vertices,
    /// One sample per face, at its centre.
    Faces,
}

/// Whether `simplify` streams its input (see its `--stream`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Stream {
    Auto,
    On,
    Off,
}

impl From<Sampling> for MeshSampling {
    fn from(s: Sampling) -> MeshSampling {
        match s {
            Sampling::Vertices => MeshSampling::Vertices,
            Sampling::Faces => MeshSampling::FaceCenters,
        }
    }
}

impl TreeArgs {
    /// The tree's parameters; without `--error`, the L2 metric's bound is `l2_error` (the
    /// command's) and the other metrics' their own, in their units.
    pub(crate) fn params(&self, l2_error: f64) -> vstree::Result<TreeParams> {
        let metric = match self.metric {
            MetricArg::L2 => Metric::L2,
            MetricArg::L21 => Metric::L21,
            MetricArg::Density => Metric::Density,
        };
        let default_error = if metric == Metric::L2 { l2_error } else { metric.default_error() };
        Ok(TreeParams {
            kind: match self.tree {
                Kind::Vstree => TreeKind::VsTree,
                Kind::Octree => TreeKind::Octree,
            },
            metric,
            error: self.error.unwrap_or(default_error),
            d_a: self.da,
            d_d: self.dd,
            max_depth: unsigned("max_depth", self.max_depth, format_args!("from 1 to {}", vstree::tree::MAX_DEPTH))?,
            min_cell_size: self.min_cell_size,
        })
    }

    /// `--threads`, checked for sign (the library checks the rest).
    pub(crate) fn threads(&self) -> vstree::Result<usize> {
        unsigned("threads", self.threads, format_args!("from 0 (all cores) to {}", Threads::MAX))
    }
}

/// An integer flag's value in the library's unsigned type. The flags are read as signed
/// numbers so that a negative value is not taken for a flag; it never reaches the library's
/// range check (nor does one too large for the type), so it is refused here with the flag's
/// `range`, in the library's words.
pub(crate) fn unsigned<T: TryFrom<i64>>(
    name: &'static str,
    value: i64,
    range: std::fmt::Arguments,
) -> vstree::Result<T> {
    T::try_from(value)
        .map_err(|_| vstree::Error::InvalidParameter { name, message: format!("{value}: must be {range}") })
}
