//! Rate and distortion of simplification to a size (issue 15, points 3 and 4): every triangle
//! mesh in `../shared/data` and its corpus, at 2% and 0.5% of its triangles, simplified by
//! vstree (the VS-Tree's and the octree's plain clustering, and the sized mode that keeps the
//! topology) and by meshoptimizer (`simplify`, `simplify_sloppy`), fast-simplification and
//! PyMeshLab (quadric edge collapse, clustering), run in the same session by
//! `benches/peers.py`. Every output is measured here with the same code: triangles, time of the
//! call alone (median of runs, mesh in memory, in process), Chamfer and Hausdorff distance to
//! the input over its bounding-box diagonal (`vstree::eval::distance`), non-manifold edges, and
//! whether a closed input's genus is kept (`vstree::topology::analyze`). Also error against
//! size over a range of sizes for two models, drawn by `benches/simplify_plot.py` into
//! `docs/images/`. Writes its report into `docs/benchmarks.md` between markers.
//!
//! ```text
//! cargo bench --bench simplify -- [--ratios 0.02,0.005] [--runs N] [--models a,b]
//!     [--data ../shared/data] [--curve igea,camel] [--curve-ratios ...] [--peers a,b]
//!     [--large 1M,3.5M,14M,50M] [--stream 14M,50M,200M] [--meshlab-max 5000000] [--no-write]
//! ```
//!
//! Besides the error against size of the `--curve` models, it draws the time against the
//! input's size of every method at the first ratio over every model (`simplify-time-size.png`).
//!
//! With `--stream`, the `vstree` command also simplifies generated tori of those sizes, and the
//! `--large` inputs' files, streamed and read whole, for time and peak memory (`stream.rs`);
//! `--models none` with no `--large` runs that part alone.

#[path = "../common/mod.rs"]
mod common;
mod large;
mod report;
mod stream;

use common::cli::{list, names, number, shown};
use common::distance::Distances;
use common::report::Clock;
use common::stats::median;
use report::{Context, Report, Row};
use std::path::{Path, PathBuf};
use std::time::Instant;
use vstree::eval::distance::Target;
use vstree::topology::analyze;
use vstree::{io, simplify, KeepTopology, Mesh, MeshSampling, Progress, SampleSet, SimplifyParams, TreeKind};

const USAGE: &str = "\
usage: cargo bench --bench simplify -- [options]
  --ratios A,B        output sizes as fractions of each input's triangles (default 0.02,0.005)
  --runs N            timed runs of every method, the median is shown (default 3)
  --models A,B        only these models (file stems, shared or corpus)
  --data DIR          data directory (default ../shared/data, relative to the project root;
                      its corpus/ folder too)
  --curve A,B         models whose error is measured over a range of sizes and plotted
                      (default igea,camel; or none; a --large size, 14M, names its mesh)
  --curve-ratios A,B  the sizes of the curve (default 0.0025,0.005,0.01,0.02,0.05,0.1)
  --threads N         vstree's worker threads, 0 = all cores (default 0)
  --peers A,B         only these peers (default all: meshopt-simplify, meshopt-sloppy,
                      fast-simplification, meshlab-qec, meshlab-clustering; or none)
  --large A,B         also generated meshes of these sizes (1M, 3.5M, 14M, 50M: corpus meshes split
                      1-to-4 with a little noise, kept under target/bench-simplify/large/;
                      --models naming none of the data's skips those)
  --stream A,B        also stream generated bumpy tori of these sizes (14M, 50M, 200M triangles,
                      kept under target/bench-simplify/stream/) and the --large inputs' files
                      through the vstree command, for time and peak memory
  --meshlab-max N     PyMeshLab's methods only on inputs of at most N triangles (default
                      5000000: above, its clustering's search for the cell size takes minutes
                      per size)
  --no-write          print the report only: do not update docs/benchmarks.md or the plots";

/// The peers `benches/peers.py` runs, in the order the table shows them.
const PEERS: [&str; 5] =
    ["meshopt-simplify", "meshopt-sloppy", "fast-simplification", "meshlab-qec", "meshlab-clustering"];

/// PyMeshLab's methods: its quadric edge collapse is 17-36x slower than meshoptimizer, its
/// clustering's cell size is searched for by bisection, one run per step.
const MESHLAB: [&str; 2] = [PEERS[3], PEERS[4]];

/// vstree's methods: name, tree, whether the topology is kept.
pub const VSTREE: [(&str, TreeKind, KeepTopology); 3] = [
    ("vstree sized, topology kept", TreeKind::VsTree, KeepTopology::On),
    ("vstree VS-Tree clustering", TreeKind::VsTree, KeepTopology::Off),
    ("vstree octree clustering", TreeKind::Octree, KeepTopology::Off),
];

/// The streamed mode's name, measured on the `--large` inputs (their files are PLY).
pub const STREAMED: &str = "vstree streamed (plain)";

/// The new mode, which the targets are about.
pub const NEW_MODE: &str = VSTREE[0].0;
/// The reference of the targets.
pub const REFERENCE: &str = PEERS[0];

struct Options {
    ratios: Vec<f64>,
    runs: usize,
    models: Option<Vec<String>>,
    data: PathBuf,
    curve: Vec<String>,
    curve_ratios: Vec<f64>,
    threads: usize,
    peers: Vec<String>,
    large: Vec<String>,
    stream: Vec<String>,
    meshlab_max: usize,
    write: bool,
}

impl Options {
    fn parse(args: &[String], root: &Path) -> Result<Options, String> {
        let mut o = Options {
            ratios: vec![0.02, 0.005],
            runs: 3,
            models: None,
            data: root.join("../shared/data"),
            curve: names("igea,camel"),
            curve_ratios: vec![0.0025, 0.005, 0.01, 0.02, 0.05, 0.1],
            threads: 0,
            peers: PEERS.iter().map(|p| p.to_string()).collect(),
            large: Vec::new(),
            stream: Vec::new(),
            meshlab_max: 5_000_000,
            write: true,
        };
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = || it.next().ok_or_else(|| format!("{arg} needs a value"));
            match arg.as_str() {
                "--ratios" => o.ratios = list(value()?)?,
                "--runs" => o.runs = number(value()?)?,
                "--models" => o.models = Some(names(value()?)),
                "--data" => o.data = PathBuf::from(value()?),
                "--curve" => {
                    let v = value()?;
                    o.curve = if v == "none" { Vec::new() } else { names(v) };
                }
                "--curve-ratios" => o.curve_ratios = list(value()?)?,
                "--threads" => o.threads = number(value()?)?,
                "--peers" => {
                    let v = value()?;
                    o.peers = if v == "none" { Vec::new() } else { names(v) };
                    if let Some(p) = o.peers.iter().find(|p| !PEERS.contains(&p.as_str())) {
                        return Err(format!("unknown peer {p}\n{USAGE}"));
                    }
                }
                "--large" => o.large = names(value()?),
                "--stream" => o.stream = names(value()?),
                "--meshlab-max" => o.meshlab_max = number(value()?)?,
                "--no-write" => o.write = false,
                other => return Err(format!("unknown option {other}\n{USAGE}")),
            }
        }
        if o.runs == 0 {
            return Err("--runs must be at least 1".into());
        }
        if o.ratios.is_empty() {
            return Err("--ratios needs at least one ratio".into());
        }
        if o.ratios.iter().chain(&o.curve_ratios).any(|&r| !(r > 0.0 && r <= 1.0)) {
            return Err("ratios must be in (0, 1]".into());
        }
        Ok(o)
    }
}

fn main() {
    let args = common::cli::bench_args();
    common::cli::exit_on_help(&args, USAGE);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let options = common::cli::or_exit(Options::parse(&args, &root));
    let command = common::cli::command("simplify", &args);
    let only_stream = options.models.as_deref() == Some(&["none".to_string()][..]) && options.large.is_empty();
    if !only_stream {
        let report = common::cli::or_fail("simplify", run(&options, &root, command.clone()));
        common::report::publish(&root, "simplify", &report.markdown(), options.write);
        if options.write {
            plot(&root, &report, options.ratios[0]);
        }
    }
    if !options.stream.is_empty() {
        let block = common::cli::or_fail("simplify", streamed(&options, &root, command));
        common::report::publish(&root, "simplify-stream", &block, options.write);
    }
}

/// The streaming table: the generated tori and the `--large` inputs' files.
fn streamed(o: &Options, root: &Path, command: String) -> Result<String, String> {
    let clock = Clock::start(command, o.threads);
    let dir = root.join("target").join("bench-simplify");
    let mut inputs = Vec::new();
    for size in &o.large {
        let (name, path, mesh) = large::mesh(size, &o.data, &dir.join("large"))?;
        let faces = ((mesh.triangles.len() as f64 * 0.01).round() as usize).max(1);
        inputs.push(stream::StreamInput { name, path, faces, torus: false });
    }
    for name in &o.stream {
        inputs.push(stream::torus(name, &dir.join("stream"))?);
    }
    let table = stream::report(&inputs, &dir)?;
    Ok(clock.run(Vec::new()).header() + "\n" + &table)
}

/// One input: a triangle mesh read from the data directory.
struct Input {
    name: String,
    /// The `--large` size it was generated at (`14M`), for the others `None`.
    size: Option<String>,
    path: PathBuf,
    mesh: Mesh,
    /// The input's vertices (those triangles use), measured to every output.
    points: Vec<glam::Vec3>,
    diagonal: f32,
    /// The input's genus, when it is closed and manifold.
    genus: Option<u32>,
}

/// The triangle meshes in `data` and `data/corpus`, shared ones first, each group by name.
fn inputs(data: &Path, only: Option<&[String]>) -> Vec<Input> {
    let mut inputs = Vec::new();
    for dir in [data.to_path_buf(), data.join("corpus")] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            eprintln!("simplify: {} is absent", dir.display());
            continue;
        };
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().and_then(|e| e.to_str()).is_some_and(|e| ["ply", "obj", "off"].contains(&e)))
            .collect();
        paths.sort();
        for path in paths {
            let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            if only.is_some_and(|o| !o.contains(&name)) {
                continue;
            }
            let mesh = match io::read(&path) {
                Ok(m) if !m.is_point_cloud() => m,
                Ok(_) => continue,
                Err(e) => {
                    eprintln!("simplify: skipping {}: {e}", path.display());
                    continue;
                }
            };
            inputs.extend(input(name, None, path, mesh));
        }
    }
    inputs
}

/// `mesh`, read from `path`, as an input: `None` if it has no triangle to sample.
fn input(name: String, size: Option<String>, path: PathBuf, mesh: Mesh) -> Option<Input> {
    let samples = SampleSet::from_mesh(&mesh, MeshSampling::Vertices).ok()?;
    let diagonal = vstree::Aabb::of(&samples.positions).map_or(1.0, |b| b.diagonal());
    let genus = analyze(&mesh).genus();
    Some(Input { name, size, path, mesh, points: samples.positions, diagonal, genus })
}

/// The triangle count for `ratio` of `input`'s.
fn target(input: &Input, ratio: f64) -> usize {
    ((input.mesh.triangles.len() as f64 * ratio).round() as usize).max(1)
}

/// One method's output at one size, measured.
fn row(input: &Input, ratio: f64, method: &str, seconds: f64, one_thread: Option<f64>, out: &Mesh) -> Row {
    let distances = if out.triangles.is_empty() {
        Distances::default() // nothing to measure: the row shows dashes
    } else {
        common::distance::between(out, Target::Triangles(&input.mesh), &input.points, input.diagonal)
    };
    let topology = analyze(out);
    let genus_kept = input.genus.map(|g| topology.genus() == Some(g));
    Row {
        input: input.name.clone(),
        input_triangles: input.mesh.triangles.len(),
        ratio,
        target: target(input, ratio),
        method: method.to_string(),
        triangles: topology.faces,
        seconds,
        seconds_one_thread: one_thread,
        distances,
        non_manifold_edges: topology.non_manifold_edges,
        folds: common::folds::folds(out),
        genus_kept,
    }
}

/// vstree's `simplify` to `target` triangles `runs` times: the median time and the output.
fn vstree_run(
    mesh: &Mesh,
    kind: TreeKind,
    keep: KeepTopology,
    target: usize,
    threads: usize,
    runs: usize,
) -> vstree::Result<(f64, Mesh)> {
    let params = SimplifyParams {
        tree: vstree::TreeParams { kind, ..Default::default() },
        keep_topology: keep,
        target_faces: target,
        threads,
        ..Default::default()
    };
    let mut times = Vec::new();
    let mut out = Mesh::default();
    for _ in 0..runs {
        let start = Instant::now();
        let (mesh, _) = simplify(mesh, &params, &mut Progress::none())?;
        times.push(start.elapsed().as_secs_f64());
        out = mesh; // the last output is dropped outside the timed span
    }
    Ok((median(&times), out))
}

/// vstree's streamed simplification of the PLY file at `path` to `target` triangles `runs`
/// times: the median time (reading included: it reads as it goes) and the output.
fn streamed_run(path: &Path, target: usize, threads: usize, runs: usize) -> vstree::Result<(f64, Mesh)> {
    let params = SimplifyParams { target_faces: target, threads, ..Default::default() };
    let mut times = Vec::new();
    let mut out = Mesh::default();
    for _ in 0..runs {
        let start = Instant::now();
        let (mesh, _) = vstree::simplify::simplify_ply_streaming(path, &params, &mut Progress::none())?;
        times.push(start.elapsed().as_secs_f64());
        out = mesh;
    }
    Ok((median(&times), out))
}

fn run(o: &Options, root: &Path, command: String) -> Result<Report, String> {
    let clock = Clock::start(command, o.threads);
    let mut rows = Vec::new();
    let mut curve = Vec::new();
    let mut notes = Vec::new();
    let out_dir = root.join("target").join("bench-simplify");
    let mut inputs = inputs(&o.data, o.models.as_deref());
    let first_large = inputs.len();
    for size in &o.large {
        eprintln!("simplify: the {size} input (generated on first use)");
        let (name, path, mesh) = large::mesh(size, &o.data, &out_dir.join("large"))?;
        inputs.extend(input(name, Some(size.clone()), path, mesh));
    }
    if inputs.is_empty() {
        return Err(format!("no triangle mesh in {}", shown(&o.data, root)));
    }
    for (index, input) in inputs.iter().enumerate() {
        let on_curve = o.curve.iter().any(|c| *c == input.name || Some(c) == input.size.as_ref());
        let mut ratios = o.ratios.clone();
        if on_curve {
            ratios.extend(&o.curve_ratios);
        }
        ratios.sort_by(|a, b| b.total_cmp(a));
        ratios.dedup();
        eprintln!("simplify: {} ({} triangles)", input.name, input.mesh.triangles.len());
        let mut measured = Vec::new();
        for &ratio in &ratios {
            let target = target(input, ratio);
            for (k, &(method, kind, keep)) in VSTREE.iter().enumerate() {
                let (seconds, out) = vstree_run(&input.mesh, kind, keep, target, o.threads, o.runs)
                    .map_err(|e| format!("{}: {e}", input.name))?;
                // The new mode on one thread too: the peers run on one.
                let one = if k == 0 && o.threads != 1 {
                    Some(vstree_run(&input.mesh, kind, keep, target, 1, o.runs).map_err(|e| e.to_string())?.0)
                } else {
                    None
                };
                measured.push(row(input, ratio, method, seconds, one, &out));
            }
            if index >= first_large {
                let (seconds, out) =
                    streamed_run(&input.path, target, o.threads, o.runs).map_err(|e| format!("{}: {e}", input.name))?;
                measured.push(row(input, ratio, STREAMED, seconds, None, &out));
            }
        }
        let mut peer_methods = o.peers.clone();
        if input.mesh.triangles.len() > o.meshlab_max && peer_methods.iter().any(|p| MESHLAB.contains(&p.as_str())) {
            peer_methods.retain(|p| !MESHLAB.contains(&p.as_str()));
            notes
                .push(format!("PyMeshLab not run on {} (over --meshlab-max {} triangles).", input.name, o.meshlab_max));
        }
        if !peer_methods.is_empty() {
            let mut targets: Vec<usize> = ratios.iter().map(|&r| target(input, r)).collect();
            targets.dedup();
            match peers(root, &out_dir, input, &targets, &peer_methods, o.runs) {
                Ok(runs) => {
                    for r in runs {
                        let Some(&ratio) = ratios.iter().find(|&&x| target(input, x) == r.target) else { continue };
                        let read = if r.output == Path::new("-") {
                            Ok(Mesh::default())
                        } else {
                            io::read(&root.join(&r.output))
                        };
                        match read {
                            Ok(out) => measured.push(row(input, ratio, &r.method, r.seconds, None, &out)),
                            Err(e) => {
                                notes.push(format!("{} on {}: cannot read its output: {e}", r.method, input.name))
                            }
                        }
                    }
                }
                Err(e) => notes.push(format!("Peers on {}: {e}", input.name)),
            }
        }
        for r in measured {
            if on_curve {
                curve.push(r.clone());
            }
            if o.ratios.contains(&r.ratio) {
                rows.push(r);
            }
        }
    }
    // By size, then model (in reading order), then method (vstree's, then the peers').
    let methods: Vec<&str> = VSTREE.iter().map(|v| v.0).chain([STREAMED]).chain(PEERS).collect();
    let models: Vec<&str> = inputs.iter().map(|i| i.name.as_str()).collect();
    let key = |r: &Row| {
        let at = |v: &[&str], x: &str| v.iter().position(|&y| y == x).unwrap_or(usize::MAX);
        let size = o.ratios.iter().position(|&x| x == r.ratio).unwrap_or(usize::MAX);
        (size, at(&models, &r.input), at(&methods, &r.method))
    };
    rows.sort_by_key(key);
    curve.sort_by(|a, b| (a.input.as_str(), a.method.as_str()).cmp(&(b.input.as_str(), b.method.as_str())));
    Ok(Report { rows, curve, context: Context { run: clock.run(notes), runs: o.runs } })
}

/// One peer's run at one size, as `benches/peers.py` reports it.
struct PeerRun {
    method: String,
    target: usize,
    seconds: f64,
    output: PathBuf,
}

/// Runs every peer on `input` at each of `targets`.
fn peers(
    root: &Path,
    out_dir: &Path,
    input: &Input,
    targets: &[usize],
    methods: &[String],
    runs: usize,
) -> Result<Vec<PeerRun>, String> {
    let mut args: Vec<std::ffi::OsString> = vec!["--input".into(), input.path.clone().into()];
    args.extend(["--runs".into(), runs.to_string().into(), "--name".into(), input.name.clone().into()]);
    args.extend(["--out-dir".into(), out_dir.into(), "--methods".into(), methods.join(",").into()]);
    for t in targets {
        args.extend(["--target".into(), t.to_string().into()]);
    }
    let records = common::peers::run(root, "peers.py", &args)?;
    Ok(records
        .iter()
        .filter_map(|r| match r.as_slice() {
            [peer, method, target, _faces, seconds, _parameter, path] if peer == "peer" => Some(PeerRun {
                method: method.clone(),
                target: target.parse().ok()?,
                seconds: seconds.parse().ok()?,
                output: PathBuf::from(path),
            }),
            _ => None,
        })
        .collect())
}

/// Writes the curve's rows to `target/bench-simplify/curve.tsv` and every model's times at the
/// first ratio to `times.tsv` beside it, and has `benches/simplify_plot.py` draw one PNG of
/// error against size per curve model and one of time against input size into `docs/images/`.
fn plot(root: &Path, report: &Report, first_ratio: f64) {
    let dir = root.join("target").join("bench-simplify");
    let mut curve = String::from("model\tmethod\tratio\ttriangles\tchamfer\thausdorff\tseconds\n");
    for r in &report.curve {
        let d: Distances = r.distances;
        curve.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\t{}\t{}\n",
            r.input,
            r.method,
            r.ratio,
            r.triangles,
            d.chamfer().unwrap_or(f64::NAN),
            d.hausdorff().unwrap_or(f64::NAN),
            r.seconds
        ));
    }
    let mut times = String::from("model\tmethod\tratio\tinput_triangles\tseconds\n");
    for r in report.rows.iter().filter(|r| r.ratio == first_ratio) {
        let (model, n, ratio) = (&r.input, r.input_triangles, r.ratio);
        times.push_str(&format!("{model}\t{}\t{ratio}\t{n}\t{}\n", r.method, r.seconds));
        if let Some(one) = r.seconds_one_thread {
            times.push_str(&format!("{model}\t{} (1 thread)\t{ratio}\t{n}\t{one}\n", r.method));
        }
    }
    let (curve_path, times_path) = (dir.join("curve.tsv"), dir.join("times.tsv"));
    let written = std::fs::create_dir_all(&dir)
        .and_then(|()| std::fs::write(&curve_path, curve))
        .and_then(|()| std::fs::write(&times_path, times));
    if let Err(e) = written {
        eprintln!("simplify: cannot write under {}: {e}", dir.display());
        return;
    }
    let args: Vec<std::ffi::OsString> =
        vec![curve_path.into(), times_path.into(), root.join("docs").join("images").into()];
    match common::peers::run(root, "simplify_plot.py", &args) {
        Ok(records) => {
            for r in records {
                eprintln!("simplify: wrote {}", r.join(" "));
            }
        }
        Err(e) => eprintln!("simplify: no plot: {e}"),
    }
}
