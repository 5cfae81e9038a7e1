//! The command line's flags and subcommands, and their conversion into library parameters.

use clap::builder::PossibleValue;
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use vstree::params::{self, Param};
use vstree::tree::{Metric, TreeKind, TreeParams};
use vstree::{MeshSampling, Threads};

/// A flag's help from the parameter table: what it does, its range and unit.
fn help(p: &Param) -> String {
    let unit = if p.unit.is_empty() { String::new() } else { format!(", in {}", p.unit) };
    match p.kind {
        params::Kind::Choice | params::Kind::Flag => p.help.to_string(),
        _ => format!("{} ({}{unit}).", p.help.trim_end_matches('.'), p.range_text()),
    }
}

/// The table's default of an integer parameter, as the flag reads it.
fn integer(p: &Param) -> i64 {
    p.default as i64
}

/// Implements [`ValueEnum`] for a flag's enum from the parameter table's choices of `param`:
/// the variants in the choices' order, named and described as the table says.
macro_rules! table_choices {
    ($enum:ident, $param:expr, [$($variant:ident),+ $(,)?]) => {
        impl ValueEnum for $enum {
            fn value_variants<'a>() -> &'a [Self] {
                &[$($enum::$variant),+]
            }
            fn to_possible_value(&self) -> Option<PossibleValue> {
                let choice = $param.choices[*self as usize];
                Some(PossibleValue::new(choice.name).help(choice.help))
            }
        }
    };
}

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
        #[arg(long, value_enum, default_value_t = Sampling::Vertices, help = help(&params::SIMPLIFY_SAMPLING))]
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
        #[arg(long, allow_hyphen_values = true, default_value_t = params::RECONSTRUCT_TARGET_DISTANCE.default,
              help = help(&params::RECONSTRUCT_TARGET_DISTANCE))]
        target: f64,
        #[arg(long, allow_hyphen_values = true, default_value_t = integer(&params::RECONSTRUCT_MAX_LEVELS),
              help = help(&params::RECONSTRUCT_MAX_LEVELS))]
        levels: i64,
        #[arg(long, allow_hyphen_values = true, default_value_t = params::RECONSTRUCT_TRIM.default as f32,
              help = help(&params::RECONSTRUCT_TRIM))]
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
        #[arg(long, value_enum, default_value_t = BaseMeshArg::Adaptive, help = help(&params::RECONSTRUCT_BASE_MESH))]
        base_mesh: BaseMeshArg,
        #[arg(long, help = help(&params::RECONSTRUCT_REORIENT_GIVEN))]
        reorient: bool,
        #[arg(long, allow_hyphen_values = true, default_value_t = integer(&params::RECONSTRUCT_NEIGHBOURS),
              help = help(&params::RECONSTRUCT_NEIGHBOURS))]
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
        #[arg(long, value_enum, default_value_t = Sampling::Vertices, help = help(&params::SIMPLIFY_SAMPLING))]
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
    #[arg(long, value_enum, default_value_t = Kind::Vstree, help = help(&params::SIMPLIFY_TREE_KIND))]
    pub(crate) tree: Kind,
    #[arg(long, value_enum, default_value_t = MetricArg::L2, help = help(&params::SIMPLIFY_METRIC))]
    pub(crate) metric: MetricArg,
    #[arg(long, allow_hyphen_values = true, help = error_help())]
    pub(crate) error: Option<f64>,
    #[arg(long, allow_hyphen_values = true, default_value_t = params::SIMPLIFY_D_A.default as f32,
          help = help(&params::SIMPLIFY_D_A))]
    pub(crate) da: f32,
    #[arg(long, allow_hyphen_values = true, default_value_t = params::SIMPLIFY_D_D.default as f32,
          help = help(&params::SIMPLIFY_D_D))]
    pub(crate) dd: f32,
    #[arg(long, allow_hyphen_values = true, default_value_t = integer(&params::SIMPLIFY_MAX_DEPTH),
          help = help(&params::SIMPLIFY_MAX_DEPTH))]
    pub(crate) max_depth: i64,
    #[arg(long, allow_hyphen_values = true, default_value_t = params::SIMPLIFY_MIN_CELL_SIZE.default,
          help = help(&params::SIMPLIFY_MIN_CELL_SIZE))]
    pub(crate) min_cell_size: f64,
    #[arg(long, allow_hyphen_values = true, default_value_t = integer(&params::SIMPLIFY_THREADS),
          help = help(&params::SIMPLIFY_THREADS))]
    pub(crate) threads: i64,
    /// No progress bar and no report: print nothing but errors (`stats` still prints its
    /// statistics, which are its output).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// `--error`'s help: the L2 bound's row, with reconstruction's default beside simplification's.
fn error_help() -> String {
    format!(
        "{} To reconstruct: {} [default: {:e} to simplify and for stats, {:e} to reconstruct; l21: {:e}; density: {}]",
        params::SIMPLIFY_ERROR.help,
        params::RECONSTRUCT_ERROR.help,
        params::SIMPLIFY_ERROR.default,
        params::RECONSTRUCT_ERROR.default,
        Metric::L21.default_error(),
        Metric::Density.default_error()
    )
}

/// `--tree`: the choices of the table's `tree_kind`, in their order.
#[derive(Clone, Copy)]
pub(crate) enum Kind {
    Vstree,
    Octree,
}
table_choices!(Kind, params::SIMPLIFY_TREE_KIND, [Vstree, Octree]);

/// `--metric`: the choices of the table's `metric`.
#[derive(Clone, Copy)]
pub(crate) enum MetricArg {
    L2,
    L21,
    Density,
}
table_choices!(MetricArg, params::SIMPLIFY_METRIC, [L2, L21, Density]);

/// `--base-mesh`: the choices of the table's `base_mesh`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum BaseMeshArg {
    Winding,
    Paper,
    Adaptive,
}
table_choices!(BaseMeshArg, params::RECONSTRUCT_BASE_MESH, [Winding, Paper, Adaptive]);

/// `--sampling`: the choices of the table's `sampling`.
#[derive(Clone, Copy)]
pub(crate) enum Sampling {
    Vertices,
    Faces,
}
table_choices!(Sampling, params::SIMPLIFY_SAMPLING, [Vertices, Faces]);

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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use vstree::params::{Call, PARAMS};

    /// Every parameter with a flag is that flag on its subcommand, with the table's help,
    /// default and choices.
    #[test]
    fn the_flags_are_the_parameter_table() {
        let cli = Cli::command();
        let mut checked = 0;
        for (command, call) in [("simplify", Call::Simplify), ("reconstruct", Call::Reconstruct)] {
            let sub = cli.find_subcommand(command).unwrap();
            for p in PARAMS.iter().filter(|p| p.call == call) {
                let Some(flag) = p.flag else { continue };
                let arg = sub
                    .get_arguments()
                    .find(|a| a.get_long() == Some(flag))
                    .unwrap_or_else(|| panic!("{command} has no --{flag} ({})", p.name));
                let shown = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
                let first = p.help.split(['(', '.']).next().unwrap();
                assert!(shown.contains(first), "--{flag}: help {shown:?} is not the table's {:?}", p.help);
                if p.kind == params::Kind::Choice {
                    let names: Vec<String> =
                        arg.get_possible_values().iter().map(|v| v.get_name().to_string()).collect();
                    let table: Vec<&str> = p.choices.iter().map(|c| c.name).collect();
                    assert_eq!(names, table, "--{flag}");
                    let default = arg.get_default_values()[0].to_str().unwrap();
                    assert_eq!(default, p.choices[p.default as usize].name, "--{flag}");
                } else if let Some(default) = arg.get_default_values().first() {
                    let value: f64 = default.to_str().unwrap().parse().unwrap();
                    assert!(
                        (value - p.default).abs() <= 1e-7 * p.default.abs(),
                        "--{flag}: {value} against {}",
                        p.default
                    );
                } else {
                    assert!(
                        p.kind == params::Kind::Flag || flag == "error" || flag == "faces",
                        "--{flag} has no default"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked >= 20, "{checked} flags checked");
    }
}
