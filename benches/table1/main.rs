//! Table 1 of the VS-Tree paper redone (issue 2, "Speed and scale"): for every mesh in
//! `../shared/data` (vertex samples) and for dense clouds drawn on a mesh surface, the octree's
//! and the VS-Tree's build time and cluster count at the same L2 bounds; cluster-size spread,
//! T-layer depth, simplified output and its distance to the input; peak memory of a big build;
//! and, with `--peers`, PyMeshLab's clustering and quadric edge collapse at the same output
//! size. Prints a Markdown report and writes it into `docs/benchmarks.md` between markers.
//!
//! ```text
//! cargo bench --bench table1 -- [--peers] [--runs N] [--big-runs N] [--big 1000000,5000000]
//!     [--bounds 1e-4,2e-3] [--models igea,horse] [--data ../shared/data] [--threads N]
//!     [--peer-runs N] [--no-memory] [--no-write]
//! ```

#[path = "../common/mod.rs"]
mod common;
mod inputs;
mod measure;
mod memory;
mod peers;
mod report;

use common::cli::{list, names, number, shown};
use common::distance::Distances;
use common::report::Clock;
use inputs::Input;
use measure::KINDS;
use report::{Context, Method, Report, Row};
use std::path::{Path, PathBuf};
use vstree::{Threads, TreeKind};

const USAGE: &str = "\
usage: cargo bench --bench table1 -- [options]
  --peers            also run PyMeshLab's clustering and quadric edge collapse (benches/peers.py)
  --runs N           timed runs per measurement (default 5)
  --big-runs N       timed runs for inputs of 1M samples or more (default 3)
  --big A,B          sizes of the clouds drawn on a surface (default 1000000,5000000; or none)
  --bounds A,B       L2 bounds (default 1e-4,2e-3)
  --models A,B       only these models of the data directory (file stems)
  --data DIR         data directory (default ../shared/data, relative to the project root)
  --threads N        worker threads, 0 = all cores (default 0)
  --peer-runs N      timed runs of each peer (default 3)
  --sweep N          clusters of both trees over a range of bounds, on N samples drawn on a
                     sphere and on the cloud surface (default 1000000; or none)
  --no-memory        skip the peak-memory measurement
  --no-write         print the report only, do not update docs/benchmarks.md";

/// Bounds of the sweep: three decades each side of the table's, in half-decade steps.
const SWEEP_BOUNDS: [f64; 11] = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7];

/// Command-line options.
struct Options {
    peers: bool,
    runs: usize,
    big_runs: usize,
    big: Vec<usize>,
    bounds: Vec<f64>,
    models: Option<Vec<String>>,
    data: PathBuf,
    threads: usize,
    peer_runs: usize,
    sweep: Option<usize>,
    memory: bool,
    write: bool,
}

impl Options {
    fn parse(args: &[String], root: &Path) -> Result<Options, String> {
        let mut o = Options {
            peers: false,
            runs: 5,
            big_runs: 3,
            big: vec![1_000_000, 5_000_000],
            bounds: vec![1e-4, 2e-3],
            models: None,
            data: root.join("../shared/data"),
            threads: 0,
            peer_runs: 3,
            sweep: Some(1_000_000),
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
                "--big" => {
                    let v = value()?;
                    o.big = if v == "none" { Vec::new() } else { list(v)? };
                }
                "--bounds" => o.bounds = list(value()?)?,
                "--sweep" => {
                    let v = value()?;
                    o.sweep = if v == "none" { None } else { Some(number(v)?) };
                }
                "--models" => o.models = Some(names(value()?)),
                "--data" => o.data = PathBuf::from(value()?),
                other => return Err(format!("unknown option {other}\n{USAGE}")),
            }
        }
        if o.runs == 0 || o.big_runs == 0 || o.peer_runs == 0 {
            return Err("run counts must be at least 1".into());
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
    let report = common::cli::or_fail("table1", run(&options, &root, common::cli::command("table1", &args)));
    common::report::publish(&root, "table1", &report.markdown(), options.write);
}

/// `--memory-child <octree|vstree> <bound> <count> [--data DIR] [--threads N]`.
fn memory_child(args: &[String], root: &Path) {
    let kind = match args.first().map(String::as_str) {
        Some("octree") => TreeKind::Octree,
        _ => TreeKind::VsTree,
    };
    let bound: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e-4);
    let count: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5_000_000);
    let options = Options::parse(args.get(3..).unwrap_or(&[]), root).expect("child options");
    memory::child(&options.data, kind, bound, count, options.threads);
}

/// Runs every measurement and gathers the report.
fn run(o: &Options, root: &Path, command: String) -> vstree::Result<Report> {
    let clock = Clock::start(command, o.threads);
    let threads = Threads::new(o.threads)?;
    let mut rows = Vec::new();
    let mut methods = Vec::new();
    let mut notes = Vec::new();

    let models = inputs::models(&o.data, o.models.as_deref());
    if models.is_empty() {
        notes.push(format!("No model found in `{}`: only generated clouds ran.", shown(&o.data, root)));
    }
    for input in &models {
        eprintln!("table1: {} ({} samples)", input.name, input.samples.len());
        let (mut r, mut m) = mesh_rows(input, o, &threads)?;
        if o.peers {
            match peer_rows(input, &r, o, root) {
                Ok(p) => m.extend(p),
                Err(e) => notes.push(format!("Peers on {}: {e}", input.name)),
            }
        }
        m.sort_by_key(|m| o.bounds.iter().position(|&b| b == m.bound));
        rows.append(&mut r);
        methods.append(&mut m);
    }

    let mut one_thread = Vec::new();
    let (surface_name, surface) = common::inputs::cloud_surface(&o.data);
    let largest = o.big.iter().copied().max();
    for &count in &o.big {
        eprintln!("table1: {count} samples on {surface_name}");
        let input = Input {
            name: format!("{surface_name} {}", common::inputs::short_count(count)),
            path: None,
            mesh: None,
            samples: inputs::cloud(&surface, count),
        };
        let (mut r, _) = mesh_rows(&input, o, &threads)?;
        rows.append(&mut r);
        if Some(count) == largest && o.threads != 1 {
            eprintln!("table1: {count} samples on one thread");
            let single = Threads::new(1)?;
            for &bound in &o.bounds {
                one_thread.push(Row {
                    input: input.name.clone(),
                    samples: count,
                    bound,
                    builds: measure::builds(&input.samples, bound, &single, o.big_runs, false)?,
                    triangles: None,
                    distances: None,
                });
            }
        }
    }
    let mut sweep = Vec::new();
    if let Some(count) = o.sweep {
        let sphere = vstree::eval::shapes::icosphere(1.0, 6);
        for (name, mesh) in [("sphere", &sphere), (surface_name.as_str(), &surface)] {
            let name = format!("{name} {}", common::inputs::short_count(count));
            eprintln!("table1: bound sweep on {name}");
            sweep.extend(measure::sweep(&name, &inputs::cloud(mesh, count), &SWEEP_BOUNDS, &threads)?);
        }
    }
    drop(surface);

    let mut memory = Vec::new();
    if let (true, Some(&count), Some(&bound)) =
        (o.memory, o.big.iter().max(), o.bounds.iter().min_by(|a, b| a.total_cmp(b)))
    {
        for kind in KINDS {
            eprintln!("table1: peak memory, {kind:?}, {count} samples");
            match memory::measure(&o.data, kind, bound, count, o.threads) {
                Ok(m) => memory.push(m),
                Err(e) => notes.push(format!("Memory of the {kind:?} build: {e}")),
            }
        }
    }

    Ok(Report {
        rows,
        one_thread,
        sweep,
        methods,
        memory,
        context: Context { run: clock.run(notes), runs: o.runs, big_runs: o.big_runs, cloud_surface: surface_name },
    })
}

/// Table rows of one input at every bound and, for meshes, its octree and VS-Tree
/// simplifications.
fn mesh_rows(input: &Input, o: &Options, threads: &Threads) -> vstree::Result<(Vec<Row>, Vec<Method>)> {
    let big = input.samples.len() >= 1_000_000;
    let runs = if big { o.big_runs } else { o.runs };
    let diagonal = vstree::Aabb::of(&input.samples.positions).map_or(1.0, |b| b.diagonal());
    let mut rows = Vec::new();
    let mut methods = Vec::new();
    for &bound in &o.bounds {
        let builds = measure::builds(&input.samples, bound, threads, runs, !big)?;
        let mut row = Row {
            input: input.name.clone(),
            samples: input.samples.len(),
            bound,
            builds,
            triangles: None,
            distances: None,
        };
        if let Some(mesh) = &input.mesh {
            let mut triangles = [0; 2];
            for (k, kind) in KINDS.into_iter().enumerate() {
                let out = measure::simplified(mesh, kind, bound, o.threads, runs)?;
                let one = match kind {
                    TreeKind::VsTree => Some(measure::simplified(mesh, kind, bound, 1, runs)?.seconds),
                    TreeKind::Octree => None,
                };
                let d = measure::distances(mesh, &input.samples.positions, diagonal, &out.mesh);
                triangles[k] = out.mesh.triangles.len();
                if kind == TreeKind::VsTree {
                    row.distances = Some(d);
                }
                methods.push(Method {
                    input: input.name.clone(),
                    bound,
                    method: format!("vstree {}", if k == 0 { "octree" } else { "VS-Tree" }),
                    triangles: out.mesh.triangles.len(),
                    seconds: out.seconds,
                    seconds_one_thread: one,
                    note: String::new(),
                    distances: d,
                });
            }
            row.triangles = Some(triangles);
        }
        rows.push(row);
    }
    Ok((rows, methods))
}

/// The peers' rows for one mesh, at the VS-Tree's output size for each bound.
fn peer_rows(input: &Input, rows: &[Row], o: &Options, root: &Path) -> Result<Vec<Method>, String> {
    let (Some(path), Some(mesh)) = (&input.path, &input.mesh) else {
        return Ok(Vec::new());
    };
    let targets: Vec<(f64, usize)> =
        rows.iter().filter_map(|r| r.triangles.map(|[_, vs]| (r.bound, vs))).filter(|&(_, t)| t > 0).collect();
    let mut unique: Vec<usize> = targets.iter().map(|&(_, t)| t).collect();
    unique.sort_unstable();
    unique.dedup();
    let runs = peers::run(root, path, &input.name, &unique, o.peer_runs)?;
    let diagonal = vstree::Aabb::of(&input.samples.positions).map_or(1.0, |b| b.diagonal());
    let mut methods = Vec::new();
    for run in &runs {
        let distances = match vstree::io::read(&root.join(&run.output)) {
            Ok(out) => measure::distances(mesh, &input.samples.positions, diagonal, &out),
            Err(e) => {
                eprintln!("table1: cannot read {}: {e}", run.output.display());
                Distances::default()
            }
        };
        for &(bound, _) in targets.iter().filter(|&&(_, t)| t == run.target) {
            methods.push(Method {
                input: input.name.clone(),
                bound,
                method: run.method.clone(),
                triangles: run.faces,
                seconds: run.seconds,
                seconds_one_thread: None,
                note: run.parameter.clone(),
                distances,
            });
        }
    }
    Ok(methods)
}
