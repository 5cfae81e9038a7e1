//! `vstree`: the command-line front end. Reads a mesh or point cloud, runs the library, writes
//! the result, and says what it did.

use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;
use vstree::reconstruct::{reconstruct, BaseMesh, Closure, ReconstructParams};
use vstree::simplify::{simplify, simplify_ply_streaming, KeepTopology, SimplifyParams, SimplifyStats, SizeMissed};
use vstree::tree::{TreeKind, TreeParams};
use vstree::{io, Progress, SampleSet, Threads};

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

mod args;
mod demo;
mod report;
mod streamed;

use args::{unsigned, BaseMeshArg, Cli, Command, SIMPLIFY_ERROR};
use demo::demo;
use report::{print_reconstruct, print_simplify, print_tree};

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
        "stream" => "--stream",
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
        Command::Simplify {
            input,
            output,
            tree,
            sampling,
            faces,
            ratio,
            keep_topology,
            no_keep_topology,
            stream,
            ascii,
        } => {
            let tree_params = tree.params(SIMPLIFY_ERROR)?;
            tree_params.check()?; // before reading what may be a large file
            let threads = tree.threads()?;
            let size = Size::from_flags(faces, ratio)?;
            let target = reserve_output(&input, &output)?;
            say_threads(threads, tree.quiet);
            let keep_topology = match (keep_topology, no_keep_topology) {
                (true, _) => KeepTopology::On,
                (_, true) => KeepTopology::Off,
                _ => KeepTopology::Auto,
            };
            if let Some(faces) = streamed::decide(stream, &input, &size, keep_topology, tree.quiet)? {
                let params = SimplifyParams {
                    tree: tree_params,
                    sampling: sampling.into(),
                    threads,
                    keep_topology,
                    target_faces: size.faces(faces)?,
                };
                let (out, stats) =
                    with_progress(tree.quiet, |progress| simplify_ply_streaming(&input, &params, progress))?;
                let (_, write_s) = timed(|| target.write(&out, &io::WriteOptions { ascii }))?;
                if !tree.quiet {
                    print_simplify(&input, &output, &stats, 0.0, write_s)?;
                }
                say_size_missed(params.target_faces, &stats);
                return Ok(());
            }
            let (mesh, read_s) = timed(|| read_with_normals(&input, threads, tree.quiet))?;
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
            Size::Ratio(r) => vstree::simplify::faces_for_ratio(r, triangles as u64)?,
        })
    }
}

/// Warns when the output is farther from the size asked for than the library allows for (see
/// [`SizeMissed`]): the topology, or an input with fewer distinct triangles, allowed no closer result.
fn say_size_missed(target: usize, s: &SimplifyStats) {
    if let Some(missed) = SizeMissed::of(target, s.output_triangles, s.kept_topology) {
        let why = match missed {
            SizeMissed::Topology => "fewer would change the topology (genus, borders); --no-keep-topology allows it",
            _ => missed.reason(),
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
