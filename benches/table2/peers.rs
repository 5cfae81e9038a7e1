//! The peers (PyMeshLab's screened Poisson at depth 8 and 10 and ball pivoting, Open3D's
//! Poisson), run by `benches/reconstruct_peers.py` on the cloud with vstree's normals; their
//! outputs are read back so the Rust side measures them like its own.

use crate::common::reconstruction::run_peers;
pub use crate::common::reconstruction::Outcome;
use crate::common::report::thousands;
use std::path::Path;

/// Every peer, in the table's order.
pub const METHODS: [&str; 4] = ["meshlab-spsr8", "meshlab-spsr10", "meshlab-bpa", "open3d-poisson10"];

/// The screened Poisson run the speed and distance targets compare with.
pub const REFERENCE: &str = "meshlab-spsr10";

/// How to run the peers.
pub struct Setup<'a> {
    pub root: &'a Path,
    pub out_dir: &'a Path,
    pub methods: &'a [String],
    pub runs: usize,
    /// Clouds with more points skip the Poisson peers ...
    pub max_peer_points: usize,
    /// ... and these ball pivoting.
    pub max_bpa_points: usize,
}

impl Setup<'_> {
    /// The methods to run on a cloud of `points` points, and the ones left out (with why).
    pub fn split(&self, points: usize) -> (Vec<String>, Vec<Outcome>) {
        let mut run = Vec::new();
        let mut skipped = Vec::new();
        for method in self.methods {
            let (limit, option) = if method == "meshlab-bpa" {
                (self.max_bpa_points, "--max-bpa-points")
            } else {
                (self.max_peer_points, "--max-peer-points")
            };
            if points > limit {
                let reason =
                    format!("skipped: more than {} points (`{option}`), to keep the run short", thousands(limit));
                skipped.push(Outcome::Skipped { method: method.clone(), reason });
            } else {
                run.push(method.clone());
            }
        }
        (run, skipped)
    }
}

/// Runs the peers `methods` on the cloud file `cloud` (with normals). The script's progress
/// goes to this process's stderr.
pub fn run(setup: &Setup, methods: &[String], cloud: &Path, name: &str) -> Result<Vec<Outcome>, String> {
    run_peers(setup.root, setup.out_dir, methods, setup.runs, cloud, name)
}
