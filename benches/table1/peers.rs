//! The peers (PyMeshLab's clustering and quadric edge collapse), run by `benches/peers.py` at
//! the VS-Tree's output size; their outputs are read back so the Rust side measures distances.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// One peer's run at one target size.
#[derive(Clone, Debug)]
pub struct PeerRun {
    /// `meshlab-clustering` or `meshlab-qec`.
    pub method: String,
    pub target: usize,
    pub faces: usize,
    /// Median time of the filter call.
    pub seconds: f64,
    /// The parameter chosen (clustering cell size), for the record.
    pub parameter: String,
    /// The output mesh it wrote.
    pub output: PathBuf,
}

/// Runs the peers on the mesh file `input` for each of `targets` (triangle counts), `runs`
/// timed runs each. The script's progress goes to this process's stderr.
pub fn run(root: &Path, input: &Path, name: &str, targets: &[usize], runs: usize) -> Result<Vec<PeerRun>, String> {
    let mut args: Vec<OsString> = vec!["--input".into(), input.into()];
    args.extend(["--runs".into(), runs.to_string().into(), "--name".into(), name.into()]);
    args.extend(["--out-dir".into(), root.join("target").join("bench-peers").into()]);
    for target in targets {
        args.extend(["--target".into(), target.to_string().into()]);
    }
    let runs: Vec<PeerRun> =
        crate::common::peers::run(root, "peers.py", &args)?.iter().filter_map(|r| parse(r)).collect();
    if runs.is_empty() {
        return Err("benches/peers.py reported no peer".into());
    }
    Ok(runs)
}

/// A `peer <method> <target> <faces> <seconds> <parameter> <path>` record.
fn parse(record: &[String]) -> Option<PeerRun> {
    match record {
        [peer, method, target, faces, seconds, parameter, path] if peer == "peer" => Some(PeerRun {
            method: method.clone(),
            target: target.parse().ok()?,
            faces: faces.parse().ok()?,
            seconds: seconds.parse().ok()?,
            parameter: parameter.clone(),
            output: PathBuf::from(path),
        }),
        _ => None,
    }
}
