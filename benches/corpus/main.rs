//! Reconstruction on shapes nothing was tuned on: points sampled on the 16 closed meshes of
//! `../shared/data/corpus` and on the closed meshes of `../shared/data`, at each size, with
//! exact normals, without normals and with positions noisy by 0.25% and 0.5% of the diagonal;
//! and synthetic cases with a known answer (an open hemisphere, single-view scans of corpus meshes, a unit sphere at the origin
//! and far from it). Every output, vstree's and with `--peers` screened Poisson's (PyMeshLab
//! and Open3D, depth 8 and 10, on the same points with the same normals), is measured by the
//! same code against the mesh the points came from: genus and components, Chamfer and
//! Hausdorff distance, angles, valence, folds. Prints a Markdown report and writes it into
//! `docs/benchmarks.md` between the `corpus` markers.
//!
//! ```text
//! cargo bench --bench corpus -- [--peers] [--sizes 200000,1000000] [--models bear,igea] [--quick]
//!     [--reduced] [--no-synthetic] [--methods open3d-poisson8] [--runs N] [--peer-runs N]
//!     [--max-peer-points N] [--data ../shared/data] [--threads N] [--base-mesh NAME] [--target-distance X] [--clouds]
//!     [--no-write]
//! ```
//!
//! vstree runs in a child process of its own (see `child`), which gives its peak memory too.

mod child;
#[path = "../common/mod.rs"]
mod common;
mod inputs;
mod measure;
mod report;

use common::cli::{list, names, number, shown};
use common::inputs::short_count;
use common::reconstruction::{run_peers, Outcome};
use common::report::Clock;
use glam::DVec3;
use inputs::{Truth, Variant};
use measure::{quality, Samples};
use report::{Context, PeerRow, Report, Row};
use std::path::{Path, PathBuf};
use vstree::normals::{ensure_normals, NormalParams};
use vstree::reconstruct::{BaseMesh, ReconstructParams};
use vstree::{io, Mesh, Progress};

const USAGE: &str = "\
usage: cargo bench --bench corpus -- [options]
  --peers               also run the peers (benches/reconstruct_peers.py): screened Poisson at depth
                        8 and 10 from PyMeshLab and from Open3D, and on open inputs Open3D's with
                        density trimming
  --sizes A,B           points sampled on each mesh (default 200000,1000000)
  --models A,B          only these meshes (stems; default: the 16 of the corpus and the closed
                        ones of the data directory; or none); single views only of those among them.
                        One 10M row: --models bear --variants clean --sizes 10000000 --no-synthetic
                        (with --peers, also --max-peer-points 10000000)
  --variants A,B        only these samplings of the meshes: clean, nonormals, noisy (0.25% of the
                        diagonal), noisy05 (0.5%) (default: all)
  --quick               20k points, 3 models (bull, femur, triceratops), small synthetic cases
  --reduced             sizes above the smallest only for the corpus's clean variant
  --no-synthetic        skip the hemisphere, single views and spheres
  --methods A,B         only these peers (default: all; see reconstruct_peers.py --help)
  --big-methods A,B     only these peers on clouds larger than the smallest size (default: --methods)
  --runs N              timed runs of vstree per input (default 1)
  --peer-runs N         timed runs of each peer (default 1)
  --max-peer-points N   skip the peers on clouds with more points (default 2000000)
  --data DIR            data directory (default ../shared/data, relative to the project root)
  --threads N           vstree's worker threads, 0 = all cores (default 0)
  --target-distance X   vstree's target distance (a fraction of the diagonal; default: the
                        library's)
  --base-mesh NAME      vstree's base mesh (default: the library's default); an unknown name lists
                        the names
  --clouds              keep each input cloud (target/bench-corpus/<row>-cloud.ply), to rerun
                        a row with the CLI
  --no-write            print the report only, do not update docs/benchmarks.md";

/// The peers on every input, and on open inputs only.
pub const CLOSED_PEERS: [&str; 4] = ["meshlab-spsr8", "open3d-poisson8", "meshlab-spsr10", "open3d-poisson10"];
pub const OPEN_PEERS: [&str; 2] = ["open3d-poisson8-trim", "open3d-poisson10-trim"];
/// Points of the synthetic cases: hemispheres, and each single view (before culling) and sphere.
const HEMISPHERES: [usize; 2] = [10_000, 200_000];
const SYNTHETIC: usize = 200_000;
const QUICK_POINTS: usize = 20_000;

/// vstree's base meshes by their `--base-mesh` name, with what the report's notes say of each.
const BASE_MESHES: [(&str, BaseMesh, &str); 3] = [
    ("winding", BaseMesh::Winding, "the samples' winding number and distance, on a grid as fine as the deepest T-node"),
    ("paper", BaseMesh::Paper, "the paper's blended T-node planes near the samples, the winding number beyond"),
    (
        "adaptive",
        BaseMesh::Adaptive,
        "the winding number's side, dual-contoured over the tree's octree (T-nodes as cells)",
    ),
];

/// The base mesh of a `--base-mesh` name.
pub fn base_mesh(name: &str) -> Option<BaseMesh> {
    BASE_MESHES.iter().find(|(n, _, _)| *n == name).map(|&(_, b, _)| b)
}

/// The `--base-mesh` name of a base mesh and what it is.
fn base_mesh_name(base: BaseMesh) -> (&'static str, &'static str) {
    BASE_MESHES.iter().find(|(_, b, _)| *b == base).map_or(("?", "not named in the bench"), |&(n, _, what)| (n, what))
}

/// Command-line options.
pub struct Options {
    peers: bool,
    sizes: Vec<usize>,
    models: Option<Vec<String>>,
    variants: Option<Vec<String>>,
    quick: bool,
    reduced: bool,
    synthetic: bool,
    methods: Vec<String>,
    big_methods: Option<Vec<String>>,
    runs: usize,
    peer_runs: usize,
    max_peer_points: usize,
    data: PathBuf,
    threads: usize,
    write: bool,
    clouds: bool,
    base_mesh: BaseMesh,
    target_distance: f64,
}

impl Options {
    fn parse(args: &[String], root: &Path) -> Result<Options, String> {
        let mut o = Options {
            peers: false,
            sizes: vec![200_000, 1_000_000],
            models: None,
            variants: None,
            quick: false,
            reduced: false,
            synthetic: true,
            methods: CLOSED_PEERS.iter().chain(&OPEN_PEERS).map(|m| m.to_string()).collect(),
            big_methods: None,
            runs: 1,
            peer_runs: 1,
            max_peer_points: 2_000_000,
            data: root.join("../shared/data"),
            threads: 0,
            write: true,
            clouds: false,
            base_mesh: BaseMesh::default(),
            target_distance: ReconstructParams::default().target_distance,
        };
        let mut sizes_given = false;
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = || it.next().ok_or_else(|| format!("{arg} needs a value"));
            match arg.as_str() {
                "--peers" => o.peers = true,
                "--quick" => o.quick = true,
                "--reduced" => o.reduced = true,
                "--no-synthetic" => o.synthetic = false,
                "--no-write" => o.write = false,
                "--clouds" => o.clouds = true,
                "--sizes" => {
                    o.sizes = list(value()?)?;
                    sizes_given = true;
                }
                "--models" => {
                    let v = value()?;
                    o.models = Some(if v == "none" { Vec::new() } else { names(v) });
                }
                "--variants" => o.variants = Some(names(value()?)),
                "--methods" => o.methods = names(value()?),
                "--big-methods" => o.big_methods = Some(names(value()?)),
                "--runs" => o.runs = number(value()?)?,
                "--peer-runs" => o.peer_runs = number(value()?)?,
                "--max-peer-points" => o.max_peer_points = number(value()?)?,
                "--threads" => o.threads = number(value()?)?,
                "--data" => o.data = PathBuf::from(value()?),
                "--target-distance" => o.target_distance = number(value()?)?,
                "--base-mesh" => {
                    let v = value()?;
                    o.base_mesh = base_mesh(v).ok_or_else(|| {
                        let names: Vec<&str> = BASE_MESHES.iter().map(|(n, _, _)| *n).collect();
                        format!("--base-mesh {v}: the base meshes are {}", names.join(", "))
                    })?;
                }
                other => return Err(format!("unknown option {other}\n{USAGE}")),
            }
        }
        if o.quick {
            if !sizes_given {
                o.sizes = vec![QUICK_POINTS];
            }
            if o.models.is_none() {
                o.models = Some(inputs::QUICK_MODELS.iter().map(|m| m.to_string()).collect());
            }
        }
        if o.runs == 0 || o.peer_runs == 0 {
            return Err("run counts must be at least 1".into());
        }
        if o.sizes.is_empty() || o.sizes.contains(&0) {
            return Err("--sizes: give at least one size above 0".into());
        }
        o.sizes.sort_unstable();
        o.sizes.dedup();
        let known: Vec<&str> = CLOSED_PEERS.iter().chain(&OPEN_PEERS).copied().collect();
        if let Some(bad) = o.methods.iter().chain(o.big_methods.iter().flatten()).find(|m| !known.contains(&m.as_str()))
        {
            return Err(format!("unknown peer {bad}: the peers are {}", known.join(", ")));
        }
        if let Some(bad) = o.variants.iter().flatten().find(|v| !Variant::SAMPLED.iter().any(|k| k.file_name() == *v)) {
            return Err(format!("unknown variant {bad}: the variants are clean, nonormals, noisy, noisy05"));
        }
        let models = inputs::models(&o.data);
        if let Some(bad) = o.models.iter().flatten().find(|m| !models.iter().any(|k| k.name == **m)) {
            let known: Vec<&str> = models.iter().map(|k| k.name.as_str()).collect();
            return Err(format!("unknown model {bad}: the models are {}", known.join(", ")));
        }
        Ok(o)
    }

    fn wants(&self, model: &str) -> bool {
        self.models.as_ref().is_none_or(|only| only.iter().any(|m| m == model))
    }

    /// The (size, variant) pairs of a sampled model.
    fn samplings(&self, corpus: bool) -> Vec<(usize, Variant)> {
        let smallest = self.sizes[0];
        let mut out = Vec::new();
        for &size in &self.sizes {
            for variant in Variant::SAMPLED {
                let named = self.variants.as_ref().is_none_or(|v| v.iter().any(|n| n == variant.file_name()));
                if named && (!self.reduced || size == smallest || (corpus && variant == Variant::Clean)) {
                    out.push((size, variant));
                }
            }
        }
        out
    }

    fn hemispheres(&self) -> Vec<usize> {
        if self.quick {
            vec![HEMISPHERES[0], QUICK_POINTS]
        } else {
            HEMISPHERES.to_vec()
        }
    }

    fn synthetic_points(&self) -> usize {
        if self.quick {
            QUICK_POINTS
        } else {
            SYNTHETIC
        }
    }
}

fn main() {
    let args = common::cli::bench_args();
    if args.first().map(String::as_str) == Some("--vstree-child") {
        child::child(&args[1..]);
        return;
    }
    common::cli::exit_on_help(&args, USAGE);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let options = common::cli::or_exit(Options::parse(&args, &root));
    let report = common::cli::or_fail("corpus", run(&options, &root, common::cli::command("corpus", &args)));
    common::report::publish(&root, "corpus", &report.markdown(), options.write);
}

/// One input to reconstruct and what it is measured against.
struct Case<'a> {
    /// The model or shape, e.g. `bear`, `hemisphere`, `bear (view)`, `sphere @1e6`.
    name: String,
    variant: Variant,
    corpus: bool,
    truth: &'a Truth,
    /// As vstree and the peers read it (far from the origin for the offset spheres).
    cloud: Mesh,
    /// Where the truth's origin is in the cloud's coordinates.
    offset: DVec3,
}

impl Case<'_> {
    /// A file name: `bear-200k-clean`.
    fn stem(&self) -> String {
        let variant = self.variant.file_name();
        let name: String =
            self.name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '-' }).collect();
        format!("{name}-{}-{variant}", short_count(self.cloud.positions.len())).replace("--", "-")
    }
}

/// Everything the run needs besides the options.
struct Bench<'a> {
    o: &'a Options,
    root: &'a Path,
    out_dir: PathBuf,
    clock: Clock,
    rows: Vec<Row>,
    notes: Vec<String>,
    done: usize,
    total: usize,
}

/// Runs every measurement and gathers the report.
fn run(o: &Options, root: &Path, command: String) -> Result<Report, String> {
    let clock = Clock::start(command, o.threads);
    let out_dir = root.join("target").join("bench-corpus");
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let models: Vec<inputs::Model> = inputs::models(&o.data).into_iter().filter(|m| o.wants(&m.name)).collect();
    let views: Vec<&str> =
        if o.synthetic { inputs::SINGLE_VIEWS.iter().copied().filter(|m| o.wants(m)).collect() } else { Vec::new() };
    let synthetic = if o.synthetic { o.hemispheres().len() + 1 + inputs::OFFSETS.len() } else { 0 };
    let total = models.iter().map(|m| o.samplings(m.corpus).len()).sum::<usize>() + views.len() + synthetic;
    let mut bench = Bench { o, root, out_dir, clock, rows: Vec::new(), notes: Vec::new(), done: 0, total };
    let (name, what) = base_mesh_name(o.base_mesh);
    let default = if o.base_mesh == BaseMesh::default() { ", the library's default" } else { "" };
    bench.notes.push(format!("vstree's base mesh: `--base-mesh {name}`{default}: {what}."));
    if o.target_distance != ReconstructParams::default().target_distance {
        bench.notes.push(format!("vstree's target distance: {} of the diagonal.", o.target_distance));
    }

    let mut skipped = Vec::new();
    for model in &models {
        let truth = match inputs::load(model) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("corpus: skipping {}: {e}", model.path.display());
                skipped.push(format!("{} ({e})", shown(&model.path, root)));
                bench.total -= o.samplings(model.corpus).len() + usize::from(views.contains(&model.name.as_str()));
                continue;
            }
        };
        for (size, variant) in o.samplings(model.corpus) {
            let cloud = inputs::sampled(&truth, size, variant);
            let case = Case {
                name: model.name.clone(),
                variant,
                corpus: model.corpus,
                truth: &truth,
                cloud,
                offset: DVec3::ZERO,
            };
            bench.measure(case);
        }
        if views.contains(&model.name.as_str()) {
            let (visible, cloud) = inputs::single_view(&truth, o.synthetic_points());
            let name = format!("{} (view)", model.name);
            bench.measure(Case {
                name,
                variant: Variant::Open,
                corpus: false,
                truth: &visible,
                cloud,
                offset: DVec3::ZERO,
            });
        }
    }
    if !skipped.is_empty() {
        bench.notes.push(format!("Left out: {}.", skipped.join("; ")));
    }
    if o.synthetic {
        for count in o.hemispheres() {
            let (truth, cloud) = inputs::hemisphere(count);
            let name = "hemisphere".to_string();
            bench.measure(Case {
                name,
                variant: Variant::Open,
                corpus: false,
                truth: &truth,
                cloud,
                offset: DVec3::ZERO,
            });
        }
        let (truth, cloud) = inputs::sphere(o.synthetic_points());
        for offset in std::iter::once(0.0).chain(inputs::OFFSETS) {
            let name = if offset == 0.0 { "sphere".to_string() } else { format!("sphere @{offset:e}") };
            let offset = DVec3::splat(offset);
            let path = bench.out_dir.join(format!("sphere-{}.xyz", offset.x));
            match inputs::through_text(&cloud, offset, &path) {
                Ok(read) => bench.measure(Case {
                    name,
                    variant: Variant::Text,
                    corpus: false,
                    truth: &truth,
                    cloud: read,
                    offset,
                }),
                Err(e) => bench.notes.push(format!("{name}: {e}")),
            }
        }
    }
    let context = bench.context(None);
    Ok(Report { rows: bench.rows, context })
}

impl Bench<'_> {
    /// The report's context now; `partial` adds a note that the run is not finished.
    fn context(&self, partial: Option<String>) -> Context {
        Context {
            run: self.clock.run(self.notes.iter().cloned().chain(partial).collect()),
            peers: self.o.peers,
            runs: self.o.runs,
            peer_runs: self.o.peer_runs,
        }
    }

    /// The report so far, in `target/bench-corpus/partial.md`, so a run stopped early still
    /// leaves its rows.
    fn checkpoint(&mut self) {
        let note = format!("Partial: {} of {} inputs done.", self.done, self.total);
        let report = Report { rows: std::mem::take(&mut self.rows), context: self.context(Some(note)) };
        if let Err(e) = std::fs::write(self.out_dir.join("partial.md"), report.markdown()) {
            eprintln!("corpus: cannot write the partial report: {e}");
        }
        self.rows = report.rows;
    }

    /// vstree's row of one case and, with `--peers`, the peers'.
    fn measure(&mut self, mut case: Case) {
        self.done += 1;
        let points = case.cloud.positions.len();
        let label = format!("{} {} {}", case.name, short_count(points), case.variant.name());
        eprintln!("corpus: [{}/{}, {:.0} s] {label}: vstree", self.done, self.total, self.clock.elapsed());
        let open = case.truth.open;
        let stem = case.stem();
        let samples = open.then(|| Samples::new(&inputs::local(&case.cloud, case.offset).positions));
        // vstree's child and the peers read the cloud from this file; the bench's copy is
        // dropped so that the cloud is not held twice while they run.
        let cloud_path = self.out_dir.join(format!("{stem}-cloud.ply"));
        let cloud = std::mem::take(&mut case.cloud);
        let needs_normals = cloud.normals.is_none();
        let written = io::write(&cloud_path, &cloud).map_err(|e| format!("cannot write the cloud: {e}"));
        drop(cloud);
        let output = self.out_dir.join(format!("{stem}-vstree.ply"));
        let base_mesh = base_mesh_name(self.o.base_mesh).0;
        let vstree = written
            .and_then(|()| {
                let asked = child::Asked { runs: self.o.runs, threads: self.o.threads, base_mesh, target: self.o.target_distance };
                child::run(&cloud_path, &output, &asked)
            })
            .and_then(|run| {
                let mesh = io::read(&output).map_err(|e| format!("cannot read vstree's output: {e}"))?;
                let q = quality(&inputs::local(&mesh, case.offset), case.truth, samples.as_ref());
                eprintln!(
                    "corpus:   vstree {:.2} s, {:.0} bytes/point, {} vertices, genus {:?} (truth {:?}), Chamfer {:.4}%, {} ({:.1}% unsupported), farthest face {:.1} spacings",
                    run.seconds.total,
                    run.memory.total_per(points),
                    q.vertices,
                    q.genus,
                    case.truth.genus,
                    100.0 * q.distances.chamfer().unwrap_or(f64::NAN),
                    if run.open { "open" } else { "closed" },
                    100.0 * run.unsupported_share,
                    q.farthest_face.unwrap_or(f64::NAN)
                );
                Ok((run, q))
            });
        if let Err(e) = &vstree {
            eprintln!("corpus:   vstree failed: {e}");
        }
        let mut row = Row {
            name: case.name.clone(),
            variant: case.variant,
            points,
            corpus: case.corpus,
            open,
            truth_genus: case.truth.genus,
            truth_components: case.truth.components,
            vstree,
            peers: Vec::new(),
        };
        if self.o.peers {
            self.peers(&case, &cloud_path, needs_normals, &stem, samples.as_ref(), &mut row);
        }
        if !self.o.clouds {
            let _ = std::fs::remove_file(&cloud_path);
        }
        self.rows.push(row);
        self.checkpoint();
    }

    /// The peers on the case's points (in `cloud`) with the normals vstree uses.
    fn peers(
        &mut self,
        case: &Case,
        cloud: &Path,
        needs_normals: bool,
        stem: &str,
        samples: Option<&Samples>,
        row: &mut Row,
    ) {
        let wanted = match &self.o.big_methods {
            Some(big) if row.points > self.o.sizes[0] => big,
            _ => &self.o.methods,
        };
        let methods: Vec<String> = CLOSED_PEERS
            .iter()
            .chain(if case.truth.open { &OPEN_PEERS[..] } else { &[] })
            .filter(|m| wanted.iter().any(|k| k == *m))
            .map(|m| m.to_string())
            .collect();
        if methods.is_empty() {
            return;
        }
        if row.points > self.o.max_peer_points {
            let reason = format!("skipped: more than {} points (`--max-peer-points`)", self.o.max_peer_points);
            row.peers.extend(methods.into_iter().map(|method| PeerRow {
                method,
                ran: false,
                seconds: None,
                parameters: String::new(),
                quality: Err(reason.clone()),
            }));
            return;
        }
        // The normals vstree uses: the given ones, or its own estimate where the cloud has none
        // (deterministic, the same parameters), written to a PLY file (in doubles for a cloud
        // far from the origin) that every peer reads.
        let oriented = self.out_dir.join(format!("{stem}-oriented.ply"));
        let cloud_path = if needs_normals {
            let normal_params = NormalParams { threads: self.o.threads, ..ReconstructParams::default().normals };
            let estimated = io::read(cloud).map_err(|e| e.to_string()).and_then(|mut c| {
                ensure_normals(&mut c, &normal_params, &mut Progress::none()).map_err(|e| e.to_string())?;
                io::write(&oriented, &c).map_err(|e| e.to_string())
            });
            if let Err(e) = estimated {
                self.notes.push(format!("Peers on {} {}: normals: {e}", case.name, case.variant.name()));
                return;
            }
            oriented.as_path()
        } else {
            cloud
        };
        let mut outcomes = run_peers(self.root, &self.out_dir, &methods, self.o.peer_runs, cloud_path, stem);
        if let (Err(e), true) = (&outcomes, methods.len() > 1) {
            // One method may crash the script (a segmentation fault far from the origin): run
            // each on its own, so the others are measured and the crash is a failed row.
            eprintln!("corpus:   {e}: running the peers one by one");
            let mut each = Vec::new();
            for method in &methods {
                match run_peers(
                    self.root,
                    &self.out_dir,
                    std::slice::from_ref(method),
                    self.o.peer_runs,
                    cloud_path,
                    stem,
                ) {
                    Ok(o) => each.extend(o),
                    Err(e) => row.peers.push(PeerRow {
                        method: method.clone(),
                        ran: true,
                        seconds: None,
                        parameters: String::new(),
                        quality: Err(format!("failed: {}", e.rsplit('/').next().unwrap_or(&e))),
                    }),
                }
            }
            outcomes = Ok(each);
        }
        match outcomes {
            Ok(outcomes) => {
                for outcome in outcomes {
                    let peer = peer_row(outcome, case, samples);
                    if let (Some(s), Ok(q)) = (peer.seconds, &peer.quality) {
                        eprintln!(
                            "corpus:   {} {s:.2} s, {} vertices, genus {:?}, Chamfer {:.4}%",
                            peer.method,
                            q.vertices,
                            q.genus,
                            100.0 * q.distances.chamfer().unwrap_or(f64::NAN)
                        );
                    }
                    row.peers.push(peer);
                }
            }
            Err(e) => self.notes.push(format!("Peers on {} {}: {e}", case.name, case.variant.name())),
        }
        row.peers.sort_by_key(|p| CLOSED_PEERS.iter().chain(&OPEN_PEERS).position(|m| *m == p.method));
        if needs_normals {
            let _ = std::fs::remove_file(&oriented);
        }
    }
}

/// A peer's row: its output read back, put in the truth's frame and measured.
fn peer_row(outcome: Outcome, case: &Case, samples: Option<&Samples>) -> PeerRow {
    match outcome {
        Outcome::Ran { method, seconds, parameters, output } => {
            let quality = match io::read(&output) {
                Ok(mesh) => Ok(quality(&inputs::local(&mesh, case.offset), case.truth, samples)),
                Err(e) => Err(format!("cannot read {}: {e}", output.display())),
            };
            PeerRow { method, ran: true, seconds: Some(seconds), parameters, quality }
        }
        Outcome::Skipped { method, reason } => {
            PeerRow { method, ran: false, seconds: None, parameters: String::new(), quality: Err(reason) }
        }
    }
}
