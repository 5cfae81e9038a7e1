//! Peak memory of one tree build, measured in a child process (this bench run again with
//! `--memory-child`) so nothing else the bench holds counts.
//!
//! The child makes the samples, drops everything else, resets the kernel's peak-RSS counter
//! (`echo 5 > /proc/self/clear_refs`, Linux 4.0+), notes its resident size (the baseline: the
//! samples plus the program), builds the tree, and reports its peak resident size (`VmHWM` in
//! `/proc/self/status`). glibc is told to keep a fixed mmap threshold so that blocks freed
//! before the build (the mesh the samples were drawn on) really leave the process.

use crate::inputs;
use crate::measure::params;
use std::path::Path;
use std::process::Command;
use vstree::tree::{self, TreeKind};
use vstree::{Progress, Threads};

/// Memory of one build.
#[derive(Clone, Copy, Debug)]
pub struct Memory {
    pub kind: TreeKind,
    pub bound: f64,
    pub samples: usize,
    /// Resident bytes just before the build (samples in memory, program, libraries).
    pub baseline: u64,
    /// Peak resident bytes during the build (including the baseline).
    pub peak: u64,
    /// Whether the peak counter could be reset after the samples were made; if not, `peak`
    /// may be the peak of making the samples instead.
    pub reset: bool,
}

impl Memory {
    /// Peak bytes per sample, everything included.
    pub fn total_per_sample(&self) -> f64 {
        self.peak as f64 / self.samples as f64
    }

    /// Bytes per sample the build adds over the baseline.
    pub fn build_per_sample(&self) -> f64 {
        self.peak.saturating_sub(self.baseline) as f64 / self.samples as f64
    }

    /// Bytes per sample of the baseline.
    pub fn baseline_per_sample(&self) -> f64 {
        self.baseline as f64 / self.samples as f64
    }
}

/// A field of `/proc/self/status` in bytes (the file gives kB).
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line[field.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kb * 1024)
}

/// Runs the child: measures one build and prints `memory <baseline> <peak> <reset>`.
pub fn child(data: &Path, kind: TreeKind, bound: f64, count: usize, threads: usize) {
    let samples = {
        let (_, surface) = inputs::cloud_surface(data);
        inputs::cloud(&surface, count)
    };
    let threads = Threads::new(threads).expect("thread pool");
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let baseline = status_bytes("VmRSS:").unwrap_or(0);
    let tree = tree::build(&samples, &params(kind, bound), &threads, &mut Progress::none()).expect("tree build");
    let peak = status_bytes("VmHWM:").unwrap_or(0);
    std::hint::black_box(&tree);
    println!("memory {baseline} {peak} {}", u8::from(reset));
}

/// Runs a child for one build and reads its report.
pub fn measure(data: &Path, kind: TreeKind, bound: f64, count: usize, threads: usize) -> Result<Memory, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let kind_arg = match kind {
        TreeKind::Octree => "octree",
        TreeKind::VsTree => "vstree",
    };
    let output = Command::new(exe)
        .args(["--memory-child", kind_arg, &bound.to_string(), &count.to_string()])
        .arg("--data")
        .arg(data)
        .args(["--threads", &threads.to_string()])
        // A fixed mmap threshold turns off glibc's dynamic one, so big blocks freed before the
        // build go back to the kernel instead of padding the baseline.
        .env("MALLOC_MMAP_THRESHOLD_", "131072")
        .output()
        .map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&output.stdout);
    let line = text.lines().find_map(|l| l.strip_prefix("memory ")).ok_or_else(|| {
        format!("no report from the child ({}): {}", output.status, String::from_utf8_lossy(&output.stderr).trim())
    })?;
    let fields: Vec<u64> = line.split_whitespace().filter_map(|f| f.parse().ok()).collect();
    match fields[..] {
        [baseline, peak, reset] if peak > 0 => {
            Ok(Memory { kind, bound, samples: count, baseline, peak, reset: reset == 1 })
        }
        _ => Err(format!("unreadable report from the child: {line}")),
    }
}
