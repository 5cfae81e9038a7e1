//! Peak memory of one piece of work, measured in a child process (the bench run again with a
//! child flag) so nothing else the bench holds counts.
//!
//! The child makes its input, drops everything else, calls [`Probe::start`] (which resets the
//! kernel's peak-RSS counter with `echo 5 > /proc/self/clear_refs`, Linux 4.0+, and notes the
//! resident size: the baseline, i.e. the input plus the program), does the work, and calls
//! [`Probe::report`], which prints the peak resident size (`VmHWM` in `/proc/self/status`).
//! glibc can be told to keep a fixed mmap threshold so that blocks freed before the work (e.g.
//! the mesh a cloud was drawn on) really leave the process.

use std::process::Command;

/// Resident sizes of one measured piece of work.
#[derive(Clone, Copy, Debug)]
pub struct Peak {
    /// Resident bytes just before the work (its input in memory, program, libraries).
    pub baseline: u64,
    /// Peak resident bytes during the work (including the baseline).
    pub peak: u64,
    /// Whether the peak counter could be reset after the input was made; if not, `peak` may
    /// be the peak of making the input instead.
    pub reset: bool,
}

impl Peak {
    /// Peak bytes per item (sample, point), everything included.
    pub fn total_per(&self, items: usize) -> f64 {
        self.peak as f64 / items as f64
    }

    /// Bytes per item the work adds over the baseline.
    pub fn added_per(&self, items: usize) -> f64 {
        self.peak.saturating_sub(self.baseline) as f64 / items as f64
    }

    /// Bytes per item of the baseline.
    pub fn baseline_per(&self, items: usize) -> f64 {
        self.baseline as f64 / items as f64
    }
}

/// A field of `/proc/self/status` in bytes (the file gives kB).
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line[field.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kb * 1024)
}

/// The child's side: the baseline taken once the input is ready.
pub struct Probe {
    baseline: u64,
    reset: bool,
}

impl Probe {
    /// Resets the peak counter and notes the resident size.
    pub fn start() -> Probe {
        let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
        Probe { baseline: status_bytes("VmRSS:").unwrap_or(0), reset }
    }

    /// Prints `memory <baseline> <peak> <reset>` for the parent.
    pub fn report(self) {
        let peak = status_bytes("VmHWM:").unwrap_or(0);
        println!("memory {} {peak} {}", self.baseline, u8::from(self.reset));
    }
}

/// Runs this bench again with `args` (which must make it a child that uses [`Probe`]) and reads
/// its report.
pub fn run_child(args: &[String]) -> Result<Peak, String> {
    run_child_output(args, true).map(|(peak, _)| peak)
}

/// [`run_child`], also returning the child's whole stdout (its other lines). With
/// `fixed_mmap_threshold`, glibc keeps a fixed mmap threshold in the child, so big blocks freed
/// before the work go back to the kernel instead of padding the baseline; without it the child
/// allocates as any program does (for work that is timed too).
pub fn run_child_output(args: &[String], fixed_mmap_threshold: bool) -> Result<(Peak, String), String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut command = Command::new(exe);
    command.args(args);
    if fixed_mmap_threshold {
        command.env("MALLOC_MMAP_THRESHOLD_", "131072");
    }
    let output = command.output().map_err(|e| e.to_string())?;
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    let line = text.lines().find_map(|l| l.strip_prefix("memory ")).ok_or_else(|| {
        format!("no report from the child ({}): {}", output.status, String::from_utf8_lossy(&output.stderr).trim())
    })?;
    let fields: Vec<u64> = line.split_whitespace().filter_map(|f| f.parse().ok()).collect();
    match fields[..] {
        [baseline, peak, reset] if peak > 0 => Ok((Peak { baseline, peak, reset: reset == 1 }, text)),
        _ => Err(format!("unreadable report from the child: {line}")),
    }
}
