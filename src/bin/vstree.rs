//! `vstree`: the command-line front end. Reads a mesh or point cloud, runs the library, writes
//! the result, and says what it did.

use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use vstree::reconstruct::{reconstruct, BaseMesh, Closure, ReconstructParams, ReconstructStats, RefinementStop};
use vstree::simplify::{simplify, KeepTopology, SimplifyParams, SimplifyStats};
use vstree::tree::{Metric, TreeKind, TreeParams, TreeStats};
use vstree::{io, MeshSampling, Progress, SampleSet, Threads};

/// Prints a line of the report on standard output through [`console::out`]; a failed write
/// returns its error from the enclosing function.
macro_rules! say {
    ($($arg:tt)*) => {
        console::out(format_args!($($arg)*))?
    };
}

/// Prints a line on standard error through [`console::err`].
macro_rules! warn {
    ($($arg:tt)*) => {
        console::err(format_args!($($arg)*))
    };
}

/// The CLI's two streams, written without ever panicking (`println!` panics when a write
/// fails).
mod console {
    use std::io::{ErrorKind, Write};
    use std::sync::atomic::{AtomicBool, Ordering};

    /// Set once the reader of standard output has gone.
    static CLOSED: AtomicBool = AtomicBool::new(false);

    /// Writes a line of the report on standard output. When the reader has gone (a pipe closed
    /// early, as by `| head`), the rest of the report is dropped quietly and the run goes on:
    /// its product is the output file, which is still wanted. Any other failure (a full disk)
    /// is an error naming standard output.
    pub fn out(line: std::fmt::Arguments) -> vstree::Result<()> {
        if closed() {
            return Ok(());
        }
        match writeln!(std::io::stdout().lock(), "{line}") {
            Err(e) if e.kind() == ErrorKind::BrokenPipe => {
                CLOSED.store(true, Ordering::Relaxed);
                Ok(())
            }
            result => result.map_err(stdout_error),
        }
    }

    /// Whether the reader of standard output has gone.
    pub fn closed() -> bool {
        CLOSED.load(Ordering::Relaxed)
    }

    /// A failed write to standard output as the error the user reads.
    pub fn stdout_error(source: std::io::Error) -> vstree::Error {
        vstree::Error::Io { path: "standard output".into(), source }
    }

    /// Writes a line on standard error; a failure is ignored, as there is nowhere left to say it.
    pub fn err(line: std::fmt::Arguments) {
        let _ = writeln!(std::io::stderr().lock(), "{line}");
    }
}

#[derive(Parser)]
#[command(
    name = "vstree",
    version,
    about = "Volume-Surface Trees: clustering simplification and surface reconstruction"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
#[command(args_conflicts_with_subcommands = false)]
enum Command {
    /// Simplify a mesh (or a point cloud) by clustering in a VS-Tree.
    ///
    /// Every leaf of the tree becomes one output vertex, placed where it best fits the samples'
    /// tangent planes; triangles are re-indexed, and those that collapse are dropped. A point
    /// cloud without normals gets them estimated first. The size is set by the error bound
    /// (--error), or exactly by --faces or --ratio. A closed 2-manifold input keeps its
    /// topology unless --no-keep-topology is given.
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
        /// closed and manifold with its genus (and an open one's borders manifold); a cluster
        /// that cannot merge without changing the topology keeps a vertex per piece, so the
        /// output may have more vertices than clusters. The default for closed 2-manifold
        /// inputs; this flag asks for it on any input.
        #[arg(long, conflicts_with = "no_keep_topology")]
        keep_topology: bool,
        /// Plain vertex clustering even for a closed 2-manifold input: faster, but sheets
        /// closer than a cluster may fuse, with non-manifold edges and another genus.
        #[arg(long)]
        no_keep_topology: bool,
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

/// An RMS sample-to-surface distance above this fraction of the diagonal means the surface
/// does not follow the cloud at all: a faithful one is within a sample spacing, well below 1%
/// of the diagonal even for sparse clouds, and the failures seen (a closed blob under an open
/// hemisphere) are at 30%.
const FAR_FROM_SAMPLES: f64 = 0.05;

/// The L2 bound to simplify with, and for `stats`, when `--error` is not given: the
/// library's, as in C, Python, MeshLab and Blender.
const SIMPLIFY_ERROR: f64 = TreeParams::DEFAULT_ERROR;

#[derive(Args, Clone)]
struct TreeArgs {
    /// Hierarchy: the VS-Tree, or a plain octree (the baseline).
    #[arg(long, value_enum, default_value_t = Kind::Vstree)]
    tree: Kind,
    /// Error metric that decides when a cell is split.
    #[arg(long, value_enum, default_value_t = MetricArg::L2)]
    metric: MetricArg,
    /// Error bound per cluster. L2: sum of squared sample-plane distances over the squared
    /// bounding-box diagonal (every sample's tangent plane then passes within sqrt(error) x
    /// diagonal of its cluster's point); l21: mean squared normal deviation (0-4); density:
    /// samples per cluster.
    /// Larger = coarser output (and, to reconstruct, smoother: it is the de-noising control).
    /// Given a size (--faces, --ratio), the bound is no bound and is not used.
    /// [default: 1e-3 to simplify and for stats, 1e-5 to reconstruct; l21: 1e-3; density: 16]
    #[arg(long, allow_hyphen_values = true)]
    error: Option<f64>,
    /// Normal-cone threshold of the height-field test, in [0, 1]: a cell becomes a surface
    /// (2D) node only if every normal's dot product with the mean normal exceeds it. Raise it
    /// for more adaptivity in curved areas.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().d_a)]
    da: f32,
    /// Displacement threshold of the height-field test, in [0, 1]: a cell's height range over
    /// its radius must stay below it. Lower it for more adaptivity in curved areas.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().d_d)]
    dd: f32,
    /// Deepest tree level (1-30).
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().max_depth.into())]
    max_depth: i64,
    /// Cells smaller than this fraction of the bounding-box diagonal are not split, in [0, 1):
    /// guards against duplicate points.
    #[arg(long, allow_hyphen_values = true, default_value_t = TreeParams::default().min_cell_size)]
    min_cell_size: f64,
    /// Worker threads (0 = all cores).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    threads: i64,
    /// No progress bar and no report: print nothing but errors (`stats` still prints its
    /// statistics, which are its output).
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Kind {
    /// Octree far from the surface, quadtrees in its tangent planes near it (the paper's).
    Vstree,
    /// A plain octree with the same metric and bound: the baseline to compare with.
    Octree,
}

#[derive(Clone, Copy, ValueEnum)]
enum MetricArg {
    /// Quadric error: how far the cluster's point is from its samples' tangent planes.
    L2,
    /// Normal deviation: how much the cluster's normals differ from their mean.
    L21,
    /// Sample count: at most `--error` samples per cluster (cheap, for huge inputs).
    Density,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum BaseMeshArg {
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
enum Sampling {
    /// One sample per vertex (normal: area-weighted face normals).
    Vertices,
    /// One sample per face, at its centre.
    Faces,
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
    fn params(&self, l2_error: f64) -> vstree::Result<TreeParams> {
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
    fn threads(&self) -> vstree::Result<usize> {
        unsigned("threads", self.threads, format_args!("from 0 (all cores) to {}", Threads::MAX))
    }
}

/// An integer flag's value in the library's unsigned type. The flags are read as signed
/// numbers so that a negative value is not taken for a flag; it never reaches the library's
/// range check (nor does one too large for the type), so it is refused here with the flag's
/// `range`, in the library's words.
fn unsigned<T: TryFrom<i64>>(name: &'static str, value: i64, range: std::fmt::Arguments) -> vstree::Result<T> {
    T::try_from(value)
        .map_err(|_| vstree::Error::InvalidParameter { name, message: format!("{value}: must be {range}") })
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return parse_failure(&e),
    };
    // Ctrl-C or a kill while an output is pending must not leave its hidden temporary file.
    io::remove_temporary_files_on_signals();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            warn!("vstree: error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// Prints what the argument parser says (help and version on standard output, usage errors on
/// standard error) and gives its exit code; help or version that cannot be written is an
/// error, as any report is (a closed pipe is not).
fn parse_failure(e: &clap::Error) -> ExitCode {
    match e.print() {
        Err(failure) if !e.use_stderr() && failure.kind() != std::io::ErrorKind::BrokenPipe => {
            warn!("vstree: error: {}", console::stdout_error(failure));
            ExitCode::FAILURE
        }
        _ => ExitCode::from(e.exit_code().clamp(0, 255) as u8),
    }
}

/// The error as the user should read it: parameters named by their command-line flags.
fn message(e: &vstree::Error) -> String {
    let vstree::Error::InvalidParameter { name, message } = e else {
        return e.to_string();
    };
    let flag = match *name {
        "error" => "--error",
        "tree_kind" => "--tree",
        "d_a" => "--da",
        "d_d" => "--dd",
        "max_depth" => "--max-depth",
        "min_cell_size" => "--min-cell-size",
        "threads" => "--threads",
        "target_faces" => "--faces",
        "ratio" => "--ratio",
        "target_distance" => "--target",
        "max_levels" => "--levels",
        "trim" => "--trim",
        "k" | "neighbours" => "--neighbours",
        _ => return e.to_string(),
    };
    format!("{flag}: {message}")
}

/// Reserves the output before any work is done: refused when vstree cannot write it (format,
/// folder, permissions, not a regular file) or when it is the input itself (the input is never
/// overwritten, even by a successful run).
fn reserve_output(input: &Path, output: &Path) -> vstree::Result<io::OutputFile> {
    if same_file(input, output) {
        return Err(vstree::Error::InvalidInput(format!(
            "the output {} is the input file: write the result to another file",
            output.display()
        )));
    }
    io::OutputFile::create(output)
}

/// Whether both paths name one existing file (through links too).
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        x.dev() == y.dev() && x.ino() == y.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (x, y);
        std::fs::canonicalize(a).ok() == std::fs::canonicalize(b).ok()
    }
}

/// Reads `path`; a point cloud without normals (or with some zero) gets them estimated, since
/// simplification and the tree need them (reconstruction estimates its own).
fn read_with_normals(path: &Path, threads: usize, quiet: bool) -> vstree::Result<vstree::Mesh> {
    let mut mesh = io::read(path)?;
    if mesh.is_point_cloud() {
        // Leaves complete normals as they are; estimates missing or zero ones.
        let params = vstree::normals::NormalParams { threads, ..Default::default() };
        let report = with_progress(quiet, |p| vstree::normals::ensure_normals(&mut mesh, &params, p))?;
        if !quiet && report.estimated > 0 {
            say!("normals: {} estimated from {} neighbours", report.estimated, report.neighbours);
        }
    }
    Ok(mesh)
}

fn run(command: Command) -> vstree::Result<()> {
    match command {
        Command::Simplify { input, output, tree, sampling, faces, ratio, keep_topology, no_keep_topology, ascii } => {
            let tree_params = tree.params(SIMPLIFY_ERROR)?;
            tree_params.check()?; // before reading what may be a large file
            let threads = tree.threads()?;
            let size = Size::from_flags(faces, ratio)?;
            let target = reserve_output(&input, &output)?;
            say_threads(threads, tree.quiet);
            let (mesh, read_s) = timed(|| read_with_normals(&input, threads, tree.quiet))?;
            let keep_topology = match (keep_topology, no_keep_topology) {
                (true, _) => KeepTopology::On,
                (_, true) => KeepTopology::Off,
                _ => KeepTopology::Auto,
            };
            let params = SimplifyParams {
                tree: tree_params,
                sampling: sampling.into(),
                threads,
                keep_topology,
                target_faces: size.faces(mesh.triangles.len())?,
            };
            let (out, stats) = with_progress(tree.quiet, |progress| simplify(&mesh, &params, progress))?;
            let (_, write_s) = timed(|| target.write(&out, &io::WriteOptions { ascii }))?;
            if !tree.quiet {
                print_simplify(&input, &output, &stats, read_s, write_s)?;
            }
            say_size_missed(params.target_faces, &stats);
            Ok(())
        }
        Command::Reconstruct {
            input,
            output,
            tree,
            target,
            levels,
            trim,
            open,
            closed,
            detect_open: _,
            base_mesh,
            reorient,
            neighbours,
            ascii,
        } => {
            let neighbours = unsigned(
                "neighbours",
                neighbours,
                format_args!("from {} to {}", vstree::normals::MIN_NEIGHBOURS, vstree::normals::MAX_NEIGHBOURS),
            )?;
            let normals = vstree::normals::NormalParams { neighbours, reorient_given: reorient, ..Default::default() };
            let threads = tree.threads()?;
            let params = ReconstructParams {
                normals,
                tree: tree.params(ReconstructParams::default().tree.error)?,
                target_distance: target,
                // The range ReconstructParams::check words.
                max_levels: unsigned("max_levels", levels, format_args!("from 0 to 12"))?,
                trim,
                closure: match (open, closed) {
                    (true, _) => Closure::Open,
                    (_, true) => Closure::Closed,
                    _ => Closure::Auto,
                },
                base_mesh: match base_mesh {
                    BaseMeshArg::Winding => BaseMesh::Winding,
                    BaseMeshArg::Paper => BaseMesh::Paper,
                    BaseMeshArg::Adaptive => BaseMesh::Adaptive,
                },
                threads,
                ..ReconstructParams::default()
            };
            params.check()?;
            let target = reserve_output(&input, &output)?;
            say_threads(threads, tree.quiet);
            let (mut cloud, read_s) = timed(|| io::read(&input))?;
            cloud.triangles.clear();
            let (out, stats) = with_progress(tree.quiet, |progress| reconstruct(&cloud, &params, progress))?;
            let (_, write_s) = timed(|| target.write(&out, &io::WriteOptions { ascii }))?;
            if !tree.quiet {
                print_reconstruct(&input, &output, cloud.positions.len(), &stats, read_s, write_s)?;
            }
            Ok(())
        }
        Command::Demo { out } => demo(&out),
        Command::Stats { input, tree, sampling, compare } => {
            let tree_params = tree.params(SIMPLIFY_ERROR)?;
            tree_params.check()?;
            let threads = tree.threads()?;
            say_threads(threads, tree.quiet);
            let mesh = read_with_normals(&input, threads, tree.quiet)?;
            let samples = if mesh.is_point_cloud() {
                SampleSet::from_cloud(&mesh)?
            } else {
                SampleSet::from_mesh(&mesh, sampling.into())?
            };
            let threads = Threads::new(threads)?;
            let mut kinds = vec![tree_params];
            if compare {
                let other = if kinds[0].kind == TreeKind::VsTree { TreeKind::Octree } else { TreeKind::VsTree };
                kinds.push(TreeParams { kind: other, ..kinds[0] });
            }
            say!("{}: {} samples", input.display(), samples.len());
            let mut leaves = Vec::new();
            for params in kinds {
                if console::closed() {
                    return Ok(()); // the statistics are the output, and nobody reads them
                }
                let (built, seconds) = timed(|| {
                    with_progress(tree.quiet, |progress| vstree::tree::build(&samples, &params, &threads, progress))
                })?;
                let stats = built.stats();
                say!("{:?}: built in {:.3} s", params.kind, seconds);
                print_tree(&stats)?;
                leaves.push(stats.leaves);
            }
            if let [first, second] = leaves[..] {
                say!("clusters: {first} vs {second} ({:+.1}%)", 100.0 * (first as f64 / second as f64 - 1.0));
            }
            Ok(())
        }
    }
}

/// The size `simplify` is asked for.
enum Size {
    /// The error bound decides.
    Bound,
    Faces(usize),
    /// A fraction of the input's triangles, in (0, 1].
    Ratio(f64),
}

impl Size {
    /// Checks `--faces` and `--ratio` (at most one is given) before the input is read.
    fn from_flags(faces: Option<i64>, ratio: Option<f64>) -> vstree::Result<Size> {
        let bad = |name, message: String| Err(vstree::Error::InvalidParameter { name, message });
        match (faces, ratio) {
            (Some(n), _) if n < 0 => {
                bad("target_faces", format!("{n}: must be a triangle count >= 1 (0 = use --error)"))
            }
            (Some(0), _) | (None, None) => Ok(Size::Bound),
            (Some(n), _) => Ok(Size::Faces(usize::try_from(n).unwrap_or(usize::MAX))),
            (None, Some(r)) if !(r > 0.0 && r <= 1.0) => {
                bad("ratio", format!("{r}: must be in (0, 1], a fraction of the input's triangles"))
            }
            (None, Some(r)) => Ok(Size::Ratio(r)),
        }
    }

    /// The `target_faces` for an input of `triangles` triangles; a ratio of a point cloud's
    /// (none) is refused, naming `--ratio` (a count is refused by the library).
    fn faces(&self, triangles: usize) -> vstree::Result<usize> {
        Ok(match *self {
            Size::Bound => 0,
            Size::Faces(n) => n,
            Size::Ratio(r) if triangles == 0 => {
                return Err(vstree::Error::InvalidParameter {
                    name: "ratio",
                    message: format!(
                        "{r}: the input is a point cloud, with no triangles to take a fraction of: a ratio needs a mesh (use --error)"
                    ),
                })
            }
            Size::Ratio(r) => ((r * triangles as f64).round() as usize).max(1),
        })
    }
}

/// Warns when the output is farther from the size asked for than 1% (or 2 triangles): the
/// topology, or an input with fewer distinct triangles, allowed no closer result.
fn say_size_missed(target: usize, s: &SimplifyStats) {
    let slack = (target / 100).max(2);
    if target > 0 && s.output_triangles.abs_diff(target) > slack {
        let why = if s.output_triangles > target && s.kept_topology {
            "fewer would change the topology (genus, borders); --no-keep-topology allows it"
        } else if s.output_triangles > target {
            "no further edge can collapse without folding the surface or pinching it"
        } else {
            "the input has no more distinct clusters to give"
        };
        warn!("vstree: warning: {} triangles instead of the {target} asked for: {why}", s.output_triangles);
    }
}

/// Says when `--threads` asks for more threads than the machine has cores (they would only
/// take turns), since the library then uses one per core.
fn say_threads(requested: usize, quiet: bool) {
    if requested > Threads::MAX {
        return; // refused with an error as the work starts
    }
    let used = Threads::count_for(requested);
    if !quiet && requested > used {
        warn!("vstree: --threads {requested}: this machine runs {used} at once; using {used}");
    }
}

fn timed<T>(f: impl FnOnce() -> vstree::Result<T>) -> vstree::Result<(T, f64)> {
    let start = Instant::now();
    let value = f()?;
    Ok((value, start.elapsed().as_secs_f64()))
}

/// Runs `f` with a progress bar on stderr (drawn only when stderr is a terminal).
fn with_progress<T>(quiet: bool, f: impl FnOnce(&mut Progress) -> vstree::Result<T>) -> vstree::Result<T> {
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg:20} [{bar:40}] {percent:>3}% {elapsed}").expect("static template"),
    );
    let mut callback = |fraction: f32, stage: &str| {
        bar.set_message(stage.to_string());
        bar.set_position((fraction * 1000.0) as u64);
        true
    };
    let result = f(&mut Progress::new(&mut callback));
    bar.finish_and_clear();
    result
}

fn print_tree(s: &TreeStats) -> vstree::Result<()> {
    say!("  nodes: {} (V {}, T {}, S {}), depth {}", s.nodes, s.v_nodes, s.t_nodes, s.s_nodes, s.max_depth);
    if s.t_nodes > 0 {
        say!("  T-layer depth: {}..{}", s.t_depth_min, s.t_depth_max);
    }
    say!(
        "  clusters (leaves): {}, samples per cluster: mean {:.1}, variance {:.1}",
        s.leaves,
        s.leaf_size_mean,
        s.leaf_size_variance
    );
    Ok(())
}

fn print_simplify(input: &Path, output: &Path, s: &SimplifyStats, read_s: f64, write_s: f64) -> vstree::Result<()> {
    say!("{}: {} vertices, {} triangles", input.display(), s.input_vertices, s.input_triangles);
    say!("samples: {}", s.tree.samples);
    print_tree(&s.tree)?;
    say!("{}: {} vertices, {} triangles", output.display(), s.output_vertices, s.output_triangles);
    say!("topology: {}", if s.kept_topology { "kept" } else { "not kept (plain clustering)" });
    say!(
        "time: read {:.3} s, samples {:.3} s, tree {:.3} s, clustering {:.3} s, write {:.3} s",
        read_s,
        s.seconds_samples,
        s.seconds_tree,
        s.seconds_cluster,
        write_s
    );
    Ok(())
}

fn print_reconstruct(
    input: &Path,
    output: &Path,
    points: usize,
    s: &ReconstructStats,
    read_s: f64,
    write_s: f64,
) -> vstree::Result<()> {
    say!("{}: {} points", input.display(), points);
    if s.isolated_points > 0 {
        say!("isolated points: {} left out (far from the rest for their neighbours' spacing)", s.isolated_points);
    }
    if s.normals.estimated > 0 {
        say!("normals: {} estimated from {} neighbours", s.normals.estimated, s.normals.neighbours);
    }
    if let Some(o) = &s.normals.orient {
        say!("orientation: {} components, {} flipped", o.components, o.flipped);
    }
    say!("noise: {:.3}% of the diagonal (the tree and the fits look past it)", 100.0 * s.noise);
    print_tree(&s.tree)?;
    let genus = s.base_genus.map_or("not a closed manifold".to_string(), |g| format!("genus {g}"));
    let thickened = if s.thickened { " (thickened: the plain one had handles through thin parts)" } else { "" };
    let polygonised = if s.on_grid {
        format!("grid: {} cells across, {} triangles polygonised{thickened}", s.grid_cells, s.fine_triangles)
    } else {
        format!("octree: {} triangles polygonised over the T-layer", s.fine_triangles)
    };
    say!("{polygonised}, field evaluated at {} points", s.field_evaluations);
    say!("M0: {} vertices, {} triangles, {genus}, error {:.2e}", s.base_vertices, s.base_triangles, s.base_error);
    for (k, level) in s.levels.iter().enumerate() {
        say!(
            "level {}: {} triangles split, {} new vertices, {} displaced by the quadtrees",
            k + 1,
            level.split,
            level.new_vertices,
            level.displaced
        );
    }
    if s.stopped == RefinementStop::TriangleBudget {
        warn!(
            "warning: refinement stopped short of the target: another level would exceed the library's triangle budget"
        );
    }
    say!("refinement stopped: {}", s.stopped.as_str());
    say!("error: RMS {:.2e}, max {:.2e} (sample-to-mesh distance / diagonal)", s.final_error, s.final_max_error);
    let share = 100.0 * s.unsupported_share;
    if s.open {
        say!("open: {share:.0}% of the closed surface is unsupported by the samples; kept: the part they support (--closed closes it)");
    } else {
        say!(
            "closed: {share:.0}% of the closed surface is unsupported by the samples, closed over (--open keeps it open)"
        );
    }
    if s.final_error > FAR_FROM_SAMPLES {
        warn!(
            "warning: the surface is far from the samples (RMS {:.1}% of the diagonal) and does not \
             represent this cloud",
            100.0 * s.final_error
        );
    }
    if s.trimmed_triangles > 0 {
        say!("trimmed: {} triangles far from the samples", s.trimmed_triangles);
    }
    say!("{}: {} vertices, {} triangles", output.display(), s.output_vertices, s.output_triangles);
    say!(
        "time: read {:.3} s, normals {:.3} s, tree {:.3} s, base mesh {:.3} s, refinement {:.3} s, trim {:.3} s, write {:.3} s",
        read_s, s.seconds_normals, s.seconds_tree, s.seconds_base, s.seconds_refine, s.seconds_trim, write_s
    );
    Ok(())
}

/// The `demo` job: both algorithms on generated shapes whose answers are known.
fn demo(out: &Path) -> vstree::Result<()> {
    use vstree::{eval::shapes, topology};
    if out.exists() && !out.is_dir() {
        let e = std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "exists and is not a folder: name a folder for --out",
        );
        return Err(vstree::Error::Io { path: out.to_path_buf(), source: e });
    }
    std::fs::create_dir_all(out).map_err(|e| vstree::Error::Io { path: out.to_path_buf(), source: e })?;
    say!("== simplification: a bumpy sphere, VS-Tree against octree at the same L2 bound (1e-5)");
    let mesh = shapes::bumpy_sphere(1.0, 0.08, 5.0, 8);
    let input = out.join("demo-sphere.ply");
    io::write(&input, &mesh)?;
    say!("{}: {} vertices, {} triangles", input.display(), mesh.positions.len(), mesh.triangles.len());
    for (kind, name) in [(TreeKind::VsTree, "vstree"), (TreeKind::Octree, "octree")] {
        let params =
            SimplifyParams { tree: TreeParams { kind, error: 1e-5, ..TreeParams::default() }, ..Default::default() };
        let (simplified, stats) = with_progress(false, |p| simplify(&mesh, &params, p))?;
        let path = out.join(format!("demo-sphere-{name}.ply"));
        io::write(&path, &simplified)?;
        say!(
            "{:7} {} clusters -> {}: {} triangles in {:.3} s",
            name,
            stats.tree.leaves,
            path.display(),
            stats.output_triangles,
            stats.seconds_samples + stats.seconds_tree + stats.seconds_cluster
        );
    }

    say!("\n== reconstruction: 200k noisy points on a genus-3 pretzel");
    let mut cloud = shapes::sample_surface(&shapes::genus_n_pretzel(3), 200_000, 1);
    shapes::add_noise(&mut cloud, 0.002, 0.05, 2);
    let input = out.join("demo-pretzel-points.ply");
    io::write(&input, &cloud)?;
    let (mesh, stats) = with_progress(false, |p| reconstruct(&cloud, &ReconstructParams::default(), p))?;
    let output = out.join("demo-pretzel-reconstructed.ply");
    io::write(&output, &mesh)?;
    print_reconstruct(&input, &output, cloud.positions.len(), &stats, 0.0, 0.0)?;
    let report = topology::analyze(&mesh);
    say!("result: watertight {}, genus {:?} (the shape has genus 3)", report.is_watertight(), report.genus());
    Ok(())
}
