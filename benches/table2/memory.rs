//! Peak memory of one reconstruction, measured in a child process (this bench run again with
//! `--memory-child`; see `common::memory`) so nothing else the bench holds counts.

use crate::common::memory::{run_child, Peak, Probe};
use crate::inputs;
use std::path::Path;
use vstree::reconstruct::reconstruct;
use vstree::Progress;

/// Memory of one reconstruction.
#[derive(Clone, Debug)]
pub struct Memory {
    pub input: String,
    pub points: usize,
    pub peak: Peak,
}

/// Runs the child: draws the cloud (the surface it was drawn on is dropped), then measures
/// one reconstruction with the bench's parameters.
pub fn child(data: &Path, count: usize, threads: usize) {
    let (_, input) = inputs::drawn(data, count);
    let params = crate::params(&input, threads);
    let probe = Probe::start();
    let out = reconstruct(&input.cloud, &params, &mut Progress::none()).expect("reconstruction");
    std::hint::black_box(&out);
    probe.report();
}

/// Runs a child for one reconstruction of `count` points drawn on igea (the input `name`) and
/// reads its report.
pub fn measure(data: &Path, name: &str, count: usize, threads: usize) -> Result<Memory, String> {
    let args = [
        "--memory-child".to_string(),
        count.to_string(),
        "--data".to_string(),
        data.display().to_string(),
        "--threads".to_string(),
        threads.to_string(),
    ];
    let peak = run_child(&args)?;
    Ok(Memory { input: name.to_string(), points: count, peak })
}
