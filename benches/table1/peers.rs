//! The peers (PyMeshLab's clustering and quadric edge collapse), run by `benches/peers.py` at
//! the VS-Tree's output size; their outputs are read back so the Rust side measures distances.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

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
    let script = root.join("benches").join("peers.py");
    let out_dir = root.join("target").join("bench-peers");
    let mut command = Command::new("python3");
    command
        .arg(&script)
        .arg("--input")
        .arg(input)
        .args(["--runs", &runs.to_string(), "--name", name])
        .arg("--out-dir")
        .arg(&out_dir);
    for target in targets {
        command.args(["--target", &target.to_string()]);
    }
    let output = command
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run python3 {}: {e}", script.display()))?;
    if !output.status.success() {
        return Err(format!("{} failed ({})", script.display(), output.status));
    }
    let runs: Vec<PeerRun> = String::from_utf8_lossy(&output.stdout).lines().filter_map(parse).collect();
    if runs.is_empty() {
        return Err(format!("{} reported nothing", script.display()));
    }
    Ok(runs)
}

/// A `peer <method> <target> <faces> <seconds> <parameter> <path>` line.
fn parse(line: &str) -> Option<PeerRun> {
    let f: Vec<&str> = line.split('\t').collect();
    match f[..] {
        ["peer", method, target, faces, seconds, parameter, path] => Some(PeerRun {
            method: method.to_string(),
            target: target.parse().ok()?,
            faces: faces.parse().ok()?,
            seconds: seconds.parse().ok()?,
            parameter: parameter.to_string(),
            output: PathBuf::from(path),
        }),
        _ => None,
    }
}
