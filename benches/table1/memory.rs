//! Peak memory of one tree build, measured in a child process (this bench run again with
//! `--memory-child`; see `common::memory`) so nothing else the bench holds counts.

use crate::common::inputs::cloud_surface;
use crate::common::memory::{run_child, Peak, Probe};
use crate::inputs;
use crate::measure::params;
use std::path::Path;
use vstree::tree::{self, TreeKind};
use vstree::{Progress, Threads};

/// Memory of one build.
#[derive(Clone, Copy, Debug)]
pub struct Memory {
    pub kind: TreeKind,
    pub bound: f64,
    pub samples: usize,
    pub peak: Peak,
}

impl Memory {
    /// Peak bytes per sample, everything included.
    pub fn total_per_sample(&self) -> f64 {
        self.peak.total_per(self.samples)
    }

    /// Bytes per sample the build adds over the baseline.
    pub fn build_per_sample(&self) -> f64 {
        self.peak.added_per(self.samples)
    }

    /// Bytes per sample of the baseline.
    pub fn baseline_per_sample(&self) -> f64 {
        self.peak.baseline_per(self.samples)
    }
}

/// Runs the child: makes the samples, then measures one build.
pub fn child(data: &Path, kind: TreeKind, bound: f64, count: usize, threads: usize) {
    let samples = {
        let (_, surface) = cloud_surface(data);
        inputs::cloud(&surface, count)
    };
    let threads = Threads::new(threads).expect("thread pool");
    let probe = Probe::start();
    let tree = tree::build(&samples, &params(kind, bound), &threads, &mut Progress::none()).expect("tree build");
    std::hint::black_box(&tree);
    probe.report();
}

/// Runs a child for one build and reads its report.
pub fn measure(data: &Path, kind: TreeKind, bound: f64, count: usize, threads: usize) -> Result<Memory, String> {
    let kind_arg = match kind {
        TreeKind::Octree => "octree",
        TreeKind::VsTree => "vstree",
    };
    let args = [
        "--memory-child".to_string(),
        kind_arg.to_string(),
        bound.to_string(),
        count.to_string(),
        "--data".to_string(),
        data.display().to_string(),
        "--threads".to_string(),
        threads.to_string(),
    ];
    let peak = run_child(&args)?;
    Ok(Memory { kind, bound, samples: count, peak })
}
