//! What the reconstruction benches (`benches/table2`, `benches/corpus`) share: vstree's timed
//! reconstructions stage by stage, the smallest angle of a triangle, and the records of the
//! Python peers (`benches/reconstruct_peers.py`), whose outputs are read back so the Rust side
//! measures them like its own.

use crate::common::stats::median;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::Instant;
use vstree::reconstruct::{reconstruct, ReconstructParams, ReconstructStats};
use vstree::{Mesh, Progress};

/// Seconds per stage of a reconstruction (medians over the runs, each stage on its own).
#[derive(Clone, Copy, Debug, Default)]
pub struct Stages {
    pub normals: f64,
    pub tree: f64,
    /// The base mesh M0: implicit function, polygonisation, clustering at the T-layer.
    pub base: f64,
    pub refine: f64,
    /// Removing faces far from the samples (0 unless `ReconstructParams::trim` is set).
    pub trim: f64,
    /// The whole `reconstruct` call, timed outside it.
    pub total: f64,
}

/// vstree's reconstruction of one input.
pub struct Reconstruction {
    pub mesh: Mesh,
    /// The last run's figures (every run gives the same mesh).
    pub stats: ReconstructStats,
    pub seconds: Stages,
}

/// Reconstructs `cloud` `runs` times; the median time of each stage and the last output.
pub fn reconstruction(cloud: &Mesh, params: &ReconstructParams, runs: usize) -> vstree::Result<Reconstruction> {
    let mut times: [Vec<f64>; 6] = Default::default();
    let mut last = None;
    for _ in 0..runs.max(1) {
        // The previous run's output is dropped before the next run, outside its timed span.
        drop(last.take());
        let start = Instant::now();
        let (mesh, stats) = reconstruct(cloud, params, &mut Progress::none())?;
        let total = start.elapsed().as_secs_f64();
        let stages = [
            stats.seconds_normals,
            stats.seconds_tree,
            stats.seconds_base,
            stats.seconds_refine,
            stats.seconds_trim,
            total,
        ];
        for (t, s) in times.iter_mut().zip(stages) {
            t.push(s);
        }
        last = Some((mesh, stats));
    }
    let [normals, tree, base, refine, trim, total] = times.map(|t| median(&t));
    let (mesh, stats) = last.expect("at least one run");
    Ok(Reconstruction { mesh, stats, seconds: Stages { normals, tree, base, refine, trim, total } })
}

/// The smallest angle of a triangle in degrees; 0 for a degenerate one (bad index, repeated
/// vertex, zero-length side).
pub fn smallest_angle(mesh: &Mesh, t: &[u32; 3]) -> f64 {
    let p = &mesh.positions;
    if t.iter().any(|&v| v as usize >= p.len()) {
        return 0.0;
    }
    let [a, b, c] = t.map(|v| p[v as usize].as_dvec3());
    let angle = |o: glam::DVec3, u: glam::DVec3, v: glam::DVec3| {
        let (u, v) = (u - o, v - o);
        let lengths = u.length() * v.length();
        if lengths > 0.0 {
            (u.dot(v) / lengths).clamp(-1.0, 1.0).acos().to_degrees()
        } else {
            0.0
        }
    };
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// What one peer did on one input.
#[derive(Clone, Debug)]
pub enum Outcome {
    Ran {
        method: String,
        /// Median time of the reconstruction call.
        seconds: f64,
        /// Its parameters, for the record.
        parameters: String,
        /// The mesh it wrote.
        output: PathBuf,
    },
    Skipped {
        method: String,
        reason: String,
    },
}

/// Runs `benches/reconstruct_peers.py` from `root` with `methods` on the cloud file `cloud`
/// (with normals), `runs` timed runs each, writing `<out_dir>/<name>-<method>.ply`. The
/// script's progress goes to this process's stderr.
pub fn run_peers(
    root: &Path,
    out_dir: &Path,
    methods: &[String],
    runs: usize,
    cloud: &Path,
    name: &str,
) -> Result<Vec<Outcome>, String> {
    let mut args: Vec<OsString> = vec!["--input".into(), cloud.into(), "--name".into(), name.into()];
    args.extend(["--runs".into(), runs.to_string().into(), "--out-dir".into(), out_dir.into()]);
    args.extend(["--methods".into(), methods.join(",").into()]);
    let records = crate::common::peers::run(root, "reconstruct_peers.py", &args)?;
    Ok(records.iter().filter_map(|r| parse(r)).collect())
}

/// A `peer <method> <seconds> <parameters> <path>` or `skip <method> <reason>` record.
fn parse(record: &[String]) -> Option<Outcome> {
    match record {
        [kind, method, seconds, parameters, path] if kind == "peer" => Some(Outcome::Ran {
            method: method.clone(),
            seconds: seconds.parse().ok()?,
            parameters: parameters.clone(),
            output: PathBuf::from(path),
        }),
        [kind, method, reason] if kind == "skip" => {
            Some(Outcome::Skipped { method: method.clone(), reason: format!("skipped: {reason}") })
        }
        _ => None,
    }
}
