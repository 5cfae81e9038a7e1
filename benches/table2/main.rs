//! Table 2 of the VS-Tree paper redone (reconstruction): for point clouds from
//! `../shared/data` (clean and noisy scans, with and without normals) and dense clouds drawn on
//! igea, vstree's reconstruction time per stage, output size, distances to the input points,
//! mesh quality (valence, angles, topology) and peak memory; and, with `--peers`, PyMeshLab's
//! screened Poisson (depth 8 and 10) and ball pivoting and Open3D's Poisson on the same points
//! with the same normals, measured by the same code. Prints a Markdown report and writes it
//! into `docs/benchmarks.md` between markers.
//!
//! ```text
//! cargo bench --bench table2 -- [--peers] [--runs N] [--big-runs N] [--peer-runs N]
//!     [--big 1000000,5000000] [--models kitten,igea] [--methods meshlab-spsr10]
//!     [--max-peer-points N] [--max-bpa-points N] [--data ../shared/data] [--threads N] [--no-memory] [--no-write]
//! ```

#[path = "../common/mod.rs"]
mod common;
mod inputs;
mod measure;
mod memory;
mod peers;
mod report;

use common::cli::{list, names, number, shown};
use common::report::Clock;
use inputs::{Input, Normals};
use peers::Outcome;
use report::{Context, PeerRow, Report, Row};
use std::path::{Path, PathBuf};
use vstree::normals::{ensure_normals, NormalParams};
use vstree::reconstruct::ReconstructParams;
use vstree::{io, Progress};

const USAGE: &str = "\
usage: cargo bench --bench table2 -- [options]
  --peers               also run the peers (benches/reconstruct_peers.py): PyMeshLab's screened
                        Poisson at depth 8 and 10 and ball pivoting, Open3D's Poisson at depth 10
  --runs N              timed runs of vstree per input (default 3)
  --big-runs N          timed runs of vstree for clouds of 300k points or more (default 2)
  --peer-runs N         timed runs of each peer (default 1)
  --big A,B             sizes of the clouds drawn on igea (default 1000000,5000000; or none)
  --models A,B          only these files of the data directory (stems; or none), default:
                        kitten,ball,armadillo_points_normals,bunny_scans_merged,lion_takanawa,igea
  --methods A,B         only these peers (default: all four; see reconstruct_peers.py --help)
  --max-peer-points N   skip the Poisson peers on clouds with more points (default 2000000)
  --max-bpa-points N    skip ball pivoting on clouds with more points (default 200000)
  --data DIR            data directory (default ../shared/data, relative to the project root)
  --threads N           vstree's worker threads, 0 = all cores (default 0)
  --no-memory           skip the peak-memory measurements (one child per drawn cloud)
  --no-write            print the report only, do not update docs/benchmarks.md";

/// Clouds of this many points or more are reconstructed `--big-runs` times.
pub const BIG_POINTS: usize = 300_000;

/// Command-line options.
pub struct Options {
    peers: bool,
    runs: usize,
    big_runs: usize,
    peer_runs: usize,
    big: Vec<usize>,
    models: Option<Vec<String>>,
    methods: Vec<String>,
    max_peer_points: usize,
    max_bpa_points: usize,
    data: PathBuf,
    threads: usize,
    memory: bool,
    write: bool,
}

impl Options {
    fn parse(args: &[String], root: &Path) -> Result<Options, String> {
        let mut o = Options {
            peers: false,
            runs: 3,
            big_runs: 2,
            peer_runs: 1,
            big: vec![1_000_000, 5_000_000],
            models: None,
            methods: peers::METHODS.iter().map(|m| m.to_string()).collect(),
            max_peer_points: 2_000_000,
            max_bpa_points: 200_000,
            data: root.join("../shared/data"),
            threads: 0,
            memory: true,
            write: true,
        };
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = || it.next().ok_or_else(|| format!("{arg} needs a value"));
            match arg.as_str() {
                "--peers" => o.peers = true,
                "--no-memory" => o.memory = false,
                "--no-write" => o.write = false,
                "--runs" => o.runs = number(value()?)?,
                "--big-runs" => o.big_runs = number(value()?)?,
                "--peer-runs" => o.peer_runs = number(value()?)?,
                "--threads" => o.threads = number(value()?)?,
                "--max-peer-points" => o.max_peer_points = number(value()?)?,
                "--max-bpa-points" => o.max_bpa_points = number(value()?)?,
                "--big" => {
                    let v = value()?;
                    o.big = if v == "none" { Vec::new() } else { list(v)? };
                }
                "--models" => {
                    let v = value()?;
                    o.models = Some(if v == "none" { Vec::new() } else { names(v) });
                }
                "--methods" => o.methods = names(value()?),
                "--data" => o.data = PathBuf::from(value()?),
                other => return Err(format!("unknown option {other}\n{USAGE}")),
            }
        }
        if o.runs == 0 || o.big_runs == 0 || o.peer_runs == 0 {
            return Err("run counts must be at least 1".into());
        }
        if let Some(bad) = o.methods.iter().find(|m| !peers::METHODS.contains(&m.as_str())) {
            return Err(format!("unknown peer {bad}: the peers are {}", peers::METHODS.join(", ")));
        }
        if let Some(bad) =
            o.models.iter().flatten().find(|m| !inputs::MODELS.iter().any(|(f, _)| inputs::stem(f) == *m))
        {
            let known: Vec<&str> = inputs::MODELS.iter().map(|(f, _)| inputs::stem(f)).collect();
            return Err(format!("unknown model {bad}: the models are {}", known.join(", ")));
        }
        Ok(o)
    }
}

fn main() {
    let args = common::cli::bench_args();
    common::cli::exit_on_help(&args, USAGE);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    if args.first().map(String::as_str) == Some("--memory-child") {
        memory_child(&args[1..], &root);
        return;
    }
    let options = common::cli::or_exit(Options::parse(&args, &root));
    let report = common::cli::or_fail("table2", run(&options, &root, common::cli::command("table2", &args)));
    common::report::publish(&root, "table2", &report.markdown(), options.write);
}

/// `--memory-child <count> [--data DIR] [--threads N]`.
fn memory_child(args: &[String], root: &Path) {
    let count: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let options = Options::parse(args.get(1..).unwrap_or(&[]), root).expect("child options");
    memory::child(&options.data, count, options.threads);
}

/// The reconstruction parameters of the table: the library's defaults (L2 bound 1e-5), with
/// given normals re-oriented where the input needs it.
pub fn params(input: &Input, threads: usize) -> ReconstructParams {
    let defaults = ReconstructParams::default();
    ReconstructParams {
        normals: NormalParams { reorient_given: input.normals == Normals::Reoriented, ..defaults.normals },
        threads,
        ..defaults
    }
}

/// Runs every measurement and gathers the report.
fn run(o: &Options, root: &Path, command: String) -> Result<Report, String> {
    let clock = Clock::start(command, o.threads);
    let out_dir = root.join("target").join("bench-table2");
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let setup = peers::Setup {
        root,
        out_dir: &out_dir,
        methods: &o.methods,
        runs: o.peer_runs,
        max_peer_points: o.max_peer_points,
        max_bpa_points: o.max_bpa_points,
    };
    let mut rows = Vec::new();
    let mut notes = Vec::new();

    let mut missing = Vec::new();
    for (file, normals) in inputs::MODELS {
        if o.models.as_ref().is_some_and(|only| !only.iter().any(|m| m == inputs::stem(file))) {
            continue;
        }
        match inputs::model(&o.data, file, normals) {
            Some(input) => match measure_input(&input, o, &setup, &mut notes) {
                Ok(row) => rows.push(row),
                Err(e) => notes.push(format!("vstree failed on {e}")),
            },
            None => missing.push(file),
        }
    }
    if !missing.is_empty() {
        notes.push(format!("Not found in `{}`, skipped: {}.", shown(&o.data, root), missing.join(", ")));
    }

    let mut memory = Vec::new();
    let mut surface = None;
    for &count in &o.big {
        let (surface_name, input) = inputs::drawn(&o.data, count);
        surface = Some(surface_name);
        match measure_input(&input, o, &setup, &mut notes) {
            Ok(row) => rows.push(row),
            Err(e) => notes.push(format!("vstree failed on {e}")),
        }
        let name = input.name.clone();
        drop(input);
        if o.memory {
            eprintln!("table2: peak memory, {name}");
            match memory::measure(&o.data, &name, count, o.threads) {
                Ok(m) => memory.push(m),
                Err(e) => notes.push(format!("Memory of {name}: {e}")),
            }
        }
    }

    Ok(Report {
        rows,
        memory,
        context: Context {
            run: clock.run(notes),
            runs: o.runs,
            big_runs: o.big_runs,
            peer_runs: o.peer_runs,
            peers: o.peers,
            cloud_surface: surface,
        },
    })
}

/// A file name for an input's name (`igea 1M` -> `igea-1M`).
fn file_name(name: &str) -> String {
    name.replace(' ', "-")
}

/// vstree's row of one input and, with `--peers`, the peers' rows.
fn measure_input(input: &Input, o: &Options, setup: &peers::Setup, notes: &mut Vec<String>) -> Result<Row, String> {
    let points = input.cloud.positions.len();
    eprintln!("table2: {} ({points} points, normals {})", input.name, input.normals.describe());
    let params = params(input, o.threads);
    let runs = if points >= BIG_POINTS { o.big_runs } else { o.runs };
    let diagonal = vstree::Aabb::of(&input.cloud.positions).map_or(1.0, |b| b.diagonal());
    let error = |e: vstree::Error| format!("{}: {e}", input.name);

    let rec = measure::reconstruction(&input.cloud, &params, runs).map_err(error)?;
    let quality = measure::quality(&rec.mesh, &input.cloud.positions, diagonal);
    let stem = file_name(&input.name);
    if let Err(e) = io::write(&setup.out_dir.join(format!("{stem}-vstree.ply")), &rec.mesh) {
        eprintln!("table2: cannot write vstree's output: {e}");
    }
    let mut row = Row {
        input: input.name.clone(),
        points,
        normals: input.normals,
        seconds: rec.seconds,
        stats: rec.stats,
        quality,
        peers: Vec::new(),
    };
    drop(rec.mesh);

    let (methods, skipped) = setup.split(points);
    if o.peers {
        row.peers.extend(skipped.into_iter().map(|s| peer_row(s, &[], diagonal)));
    }
    if o.peers && !methods.is_empty() {
        // The peers get the points with the normals vstree uses: its own, estimated or
        // re-oriented with the same parameters (deterministic), written to a PLY file.
        let mut oriented = input.cloud.clone();
        let normal_params = NormalParams { threads: o.threads, ..params.normals };
        ensure_normals(&mut oriented, &normal_params, &mut Progress::none()).map_err(error)?;
        let cloud_path = setup.out_dir.join(format!("{stem}-cloud.ply"));
        io::write(&cloud_path, &oriented).map_err(error)?;
        drop(oriented);
        match peers::run(setup, &methods, &cloud_path, &stem) {
            Ok(outcomes) => {
                for outcome in outcomes {
                    row.peers.push(peer_row(outcome, &input.cloud.positions, diagonal));
                }
            }
            Err(e) => notes.push(format!("Peers on {}: {e}", input.name)),
        }
        // The table's order, whatever order they ran in.
        row.peers.sort_by_key(|p| peers::METHODS.iter().position(|m| *m == p.method));
    }
    Ok(row)
}

/// A peer's row: its output read back and measured.
fn peer_row(outcome: Outcome, points: &[glam::Vec3], diagonal: f32) -> PeerRow {
    match outcome {
        Outcome::Ran { method, seconds, parameters, output } => {
            let quality = match io::read(&output) {
                Ok(mesh) => Ok(measure::quality(&mesh, points, diagonal)),
                Err(e) => Err(format!("cannot read {}: {e}", output.display())),
            };
            PeerRow { method, seconds: Some(seconds), parameters, quality }
        }
        Outcome::Skipped { method, reason } => {
            PeerRow { method, seconds: None, parameters: String::new(), quality: Err(reason) }
        }
    }
}
