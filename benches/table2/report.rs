//! The Markdown report of Table 2: machine, targets, tables.

use crate::common::inputs::short_count;
use crate::common::report::{percent, relative, relative_or_dash, secs, thousands, verdict, Run};
use crate::common::stats::{max, min};
use crate::inputs::Normals;
use crate::measure::{Quality, Stages, SMALL_ANGLE_DEGREES};
use crate::memory::Memory;
use crate::peers::{self, REFERENCE};
use std::fmt::Write as _;
use vstree::reconstruct::ReconstructStats;

/// Targets of the reconstruction issue.
const SPEEDUP_TARGET: f64 = 10.0;
const CHAMFER_RATIO_TARGET: f64 = 1.5;
/// The speed-up target is for inputs of at least this many points.
const SPEEDUP_MIN_POINTS: usize = 100_000;
/// (points, seconds): clouds of that size reconstructed in under that time.
const SECONDS_TARGETS: [(usize, f64); 2] = [(1_000_000, 3.0), (5_000_000, 15.0)];
const BYTES_TARGET: f64 = 300.0;
const VALENCE6_TARGET: f64 = 0.9;

/// One input: vstree's reconstruction and the peers'.
pub struct Row {
    pub input: String,
    pub points: usize,
    pub normals: Normals,
    pub seconds: Stages,
    pub stats: ReconstructStats,
    pub quality: Quality,
    pub peers: Vec<PeerRow>,
}

impl Row {
    /// The peer run `method`, when it ran and its output could be measured.
    fn peer(&self, method: &str) -> Option<(f64, &Quality)> {
        let p = self.peers.iter().find(|p| p.method == method)?;
        Some((p.seconds?, p.quality.as_ref().ok()?))
    }
}

/// One peer on one input.
pub struct PeerRow {
    pub method: String,
    /// Median time of the reconstruction call; `None` when skipped.
    pub seconds: Option<f64>,
    pub parameters: String,
    /// The output's figures, or why there are none (skipped, unreadable).
    pub quality: Result<Quality, String>,
}

/// Where and how the run happened: the common part and this bench's.
pub struct Context {
    pub run: Run,
    pub runs: usize,
    pub big_runs: usize,
    pub peer_runs: usize,
    pub peers: bool,
    /// The surface the dense clouds were drawn on, when any were.
    pub cloud_surface: Option<String>,
}

/// Everything one run measured.
pub struct Report {
    pub rows: Vec<Row>,
    pub memory: Vec<Memory>,
    pub context: Context,
}

/// `1 run`, `3 runs`.
fn runs_phrase(n: usize) -> String {
    if n == 1 {
        "1 run".into()
    } else {
        format!("{n} runs")
    }
}

/// The method's name as the tables show it.
fn method_name(method: &str) -> &str {
    match method {
        "meshlab-spsr8" => "PyMeshLab screened Poisson, depth 8",
        "meshlab-spsr10" => "PyMeshLab screened Poisson, depth 10",
        "meshlab-bpa" => "PyMeshLab ball pivoting",
        "open3d-poisson10" => "Open3D Poisson, depth 10",
        other => other,
    }
}

impl Report {
    /// The whole generated block, without the markers.
    pub fn markdown(&self) -> String {
        let c = &self.context;
        let mut md = c.run.header();
        let threads = c.run.threads_text("");
        let peers = match (c.peers, c.peer_runs) {
            (false, _) => " Peers not run (`--peers` not given).".to_string(),
            (true, runs) => format!(" Peers: {} each, on the same points with vstree's normals.", runs_phrase(runs)),
        };
        let _ = writeln!(
            md,
            "- vstree: `ReconstructParams::default()` (L2 bound 1e-5), threads: {threads}; times are medians over \
             {} ({} for clouds of {} points or more).{peers}",
            runs_phrase(c.runs),
            runs_phrase(c.big_runs),
            short_count(crate::BIG_POINTS),
        );
        if let Some(surface) = &c.cloud_surface {
            let _ = writeln!(md, "- Dense clouds are drawn on {surface}'s surface, with interpolated normals.");
        }
        c.run.write_notes(&mut md);
        md.push('\n');
        self.targets(&mut md);
        self.table2(&mut md);
        self.stages(&mut md);
        self.memory_table(&mut md);
        md
    }

    /// The targets, met or missed, with the numbers.
    fn targets(&self, md: &mut String) {
        md.push_str("### Targets\n\n");
        if self.rows.is_empty() {
            md.push_str("No inputs ran.\n\n");
            return;
        }
        self.speed_target(md);
        for (points, limit) in SECONDS_TARGETS {
            if let Some(r) = self.rows.iter().find(|r| r.points == points) {
                let _ = writeln!(
                    md,
                    "- {} points in under {limit} s: {}; {} s ({}).",
                    short_count(points),
                    verdict(r.seconds.total < limit),
                    secs(r.seconds.total),
                    r.input
                );
            }
        }
        if let Some(worst) =
            self.memory.iter().max_by(|a, b| a.peak.total_per(a.points).total_cmp(&b.peak.total_per(b.points)))
        {
            let list: Vec<String> = self
                .memory
                .iter()
                .map(|m| format!("{:.0} B/point on {}", m.peak.total_per(m.points), m.input))
                .collect();
            let _ = writeln!(
                md,
                "- Peak memory under {BYTES_TARGET:.0} B/point: {} counting everything ({}); the reconstruction \
                 adds at most {:.0} B/point over the cloud already in memory.",
                verdict(worst.peak.total_per(worst.points) < BYTES_TARGET),
                list.join(", "),
                self.memory.iter().map(|m| m.peak.added_per(m.points)).fold(0.0, f64::max),
            );
        }
        let shares: Vec<f64> = self.rows.iter().map(|r| r.quality.valence6).collect();
        let met = shares.iter().filter(|&&s| s > VALENCE6_TARGET).count();
        let below: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.quality.valence6 <= VALENCE6_TARGET)
            .map(|r| format!("{} {}", r.input, percent(r.quality.valence6)))
            .collect();
        let _ = writeln!(
            md,
            "- Over {} of vstree's vertices of valence 6: {}: met on {met} of {} inputs; range {}–{}{}.",
            percent(VALENCE6_TARGET),
            verdict(met == shares.len()),
            shares.len(),
            percent(min(&shares)),
            percent(max(&shares)),
            if below.is_empty() { String::new() } else { format!(" (not met: {})", below.join(", ")) }
        );
        md.push('\n');
    }

    /// The speed-up against screened Poisson at depth 10, at a comparable Chamfer distance.
    fn speed_target(&self, md: &mut String) {
        let eligible: Vec<&Row> = self.rows.iter().filter(|r| r.points >= SPEEDUP_MIN_POINTS).collect();
        let title = format!(
            "At least {SPEEDUP_TARGET:.0}× faster than screened Poisson at depth 10 on every input of {} points or \
             more, at a Chamfer distance no worse than {CHAMFER_RATIO_TARGET}× Poisson's",
            short_count(SPEEDUP_MIN_POINTS)
        );
        let compared: Vec<(&Row, f64, &Quality)> =
            eligible.iter().filter_map(|r| r.peer(REFERENCE).map(|(s, q)| (*r, s, q))).collect();
        if compared.is_empty() {
            let why = if eligible.is_empty() {
                format!("no input of {} points or more ran", short_count(SPEEDUP_MIN_POINTS))
            } else if !self.context.peers {
                "the peers did not run (no `--peers`)".to_string()
            } else {
                "screened Poisson at depth 10 ran on none of these inputs".to_string()
            };
            let _ = writeln!(md, "- {title}: not evaluated: {why}.");
            return;
        }
        let mut parts = Vec::new();
        let mut met = 0;
        for (r, poisson_seconds, poisson) in &compared {
            let speedup = poisson_seconds / r.seconds.total;
            let ratio = match (r.quality.distances.chamfer(), poisson.distances.chamfer()) {
                (Some(ours), Some(theirs)) if theirs > 0.0 => ours / theirs,
                _ => f64::INFINITY,
            };
            let ok = speedup >= SPEEDUP_TARGET && ratio <= CHAMFER_RATIO_TARGET;
            met += usize::from(ok);
            parts.push(format!(
                "{} {speedup:.1}× ({} s vs {} s), Chamfer {ratio:.2}× ({} vs {}){}",
                r.input,
                secs(r.seconds.total),
                secs(*poisson_seconds),
                relative_or_dash(r.quality.distances.chamfer()),
                relative_or_dash(poisson.distances.chamfer()),
                if ok { "" } else { " ✗" }
            ));
        }
        let missing: Vec<&str> =
            eligible.iter().filter(|r| r.peer(REFERENCE).is_none()).map(|r| r.input.as_str()).collect();
        let _ = writeln!(
            md,
            "- {title}: {}: met on {met} of the {} inputs where Poisson ran{}: {}.",
            match (met == compared.len(), missing.is_empty()) {
                (false, _) => verdict(false),
                (true, true) => verdict(true),
                (true, false) => "**met where measured**",
            },
            compared.len(),
            if missing.is_empty() {
                String::new()
            } else {
                format!(" (not evaluated on {}: no Poisson run)", missing.join(", "))
            },
            parts.join("; ")
        );
    }

    fn table2(&self, md: &mut String) {
        let _ = write!(
            md,
            "### Table 2: reconstruction by every method\n\n\
             Time: the reconstruction call alone (cloud in memory; vstree's includes estimating or re-orienting \
             normals where the input needs it, the peers get those normals for free). Vertices: used by a \
             triangle. Chamfer = mean of the two mean distances (output → input points, from 200k points on \
             the output's surface; input points → output's triangles); Hausdorff = the larger of the two \
             maxima; both relative to the input's bounding-box diagonal. Valence 6: share of vertices with six \
             neighbours. Angles: share of triangles with an angle under {SMALL_ANGLE_DEGREES:.0}°. Watertight: \
             closed, manifold, consistently oriented (else the count of boundary edges).\n\n\
             | input | points | method | time (s) | vertices | triangles | Chamfer | Hausdorff | valence 6 \
             | angles < {SMALL_ANGLE_DEGREES:.0}° | watertight | genus | components |\n\
             |---|--:|---|--:|--:|--:|--:|--:|--:|--:|---|--:|--:|\n"
        );
        for r in &self.rows {
            quality_row(md, &r.input, r.points, "vstree", r.seconds.total, &r.quality);
            for p in &r.peers {
                match (&p.quality, p.seconds) {
                    (Ok(q), Some(s)) => quality_row(md, &r.input, r.points, method_name(&p.method), s, q),
                    (Err(why), seconds) => {
                        let _ = writeln!(
                            md,
                            "| {} | {} | {} | {} | {} | | | | | | | | |",
                            r.input,
                            thousands(r.points),
                            method_name(&p.method),
                            seconds.map_or("—".into(), secs),
                            why.replace('|', "/")
                        );
                    }
                    (Ok(_), None) => {}
                }
            }
        }
        let parameters: Vec<String> = peers::METHODS
            .iter()
            .filter_map(|m| {
                let p = self.rows.iter().flat_map(|r| &r.peers).find(|p| p.method == *m && !p.parameters.is_empty())?;
                Some(format!("{}: {}", method_name(m), p.parameters))
            })
            .collect();
        if !parameters.is_empty() {
            let _ = writeln!(md, "\nPeer parameters (others at their defaults): {}.", parameters.join("; "));
        }
        md.push('\n');
    }

    fn stages(&self, md: &mut String) {
        md.push_str(
            "### vstree stage by stage\n\n\
             Medians per stage (each on its own; total = the whole call). Normals: kept as given, re-oriented \
             (consistent by propagation, then outward), or estimated from 16 neighbours. M0: the base mesh \
             (blended T-node planes polygonised and clustered at the T-layer), its size and genus. Levels: \
             1-to-4 refinements done. Error: vstree's own measure, RMS / max distance from up to 100k samples \
             to the output over the diagonal.\n\n\
             | input | points | normals | normals (s) | tree (s) | M0 (s) | refine (s) | total (s) | tree nodes \
             | M0 vertices / triangles | M0 genus | levels | error RMS / max |\n\
             |---|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.rows {
            let s = &r.stats;
            let normals = match (r.normals, s.normals.orient) {
                (Normals::Given, _) => "given".to_string(),
                (n, Some(o)) if o.flipped > 0 => format!("{}, {} flipped", n.describe(), thousands(o.flipped)),
                (n, _) => n.describe().to_string(),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {normals} | {} | {} | {} | {} | {} | {} | {} / {} | {} | {} | {} / {} |",
                r.input,
                thousands(r.points),
                secs(r.seconds.normals),
                secs(r.seconds.tree),
                secs(r.seconds.base),
                secs(r.seconds.refine),
                secs(r.seconds.total),
                thousands(s.tree.nodes),
                thousands(s.base_vertices),
                thousands(s.base_triangles),
                s.base_genus.map_or("—".into(), |g| g.to_string()),
                s.levels.len(),
                relative(s.final_error),
                relative(s.final_max_error),
            );
        }
        md.push('\n');
    }

    fn memory_table(&self, md: &mut String) {
        if self.memory.is_empty() {
            return;
        }
        md.push_str(
            "### Peak memory of a reconstruction\n\n\
             Measured in a child process: resident size once the cloud (positions and normals) is in memory \
             (baseline), and peak resident size during `reconstruct` (`VmHWM`, reset after making the cloud), \
             per input point.\n\n\
             | input | points | baseline (B/point) | peak, total (B/point) | peak over baseline (B/point) \
             | peak (MiB) |\n\
             |---|--:|--:|--:|--:|--:|\n",
        );
        for m in &self.memory {
            let _ = writeln!(
                md,
                "| {} | {} | {:.1} | {:.1} | {:.1} | {:.0} |",
                m.input,
                thousands(m.points),
                m.peak.baseline_per(m.points),
                m.peak.total_per(m.points),
                m.peak.added_per(m.points),
                m.peak.peak as f64 / 1024.0 / 1024.0,
            );
        }
        if self.memory.iter().any(|m| !m.peak.reset) {
            md.push_str("\nThe peak counter could not be reset: peaks may include making the cloud.\n");
        }
        md.push('\n');
    }
}

/// One method's line of Table 2.
fn quality_row(md: &mut String, input: &str, points: usize, method: &str, seconds: f64, q: &Quality) {
    let watertight = if q.watertight {
        "yes".to_string()
    } else if q.boundary_edges > 0 {
        format!("no ({} boundary edges)", thousands(q.boundary_edges))
    } else {
        "no (non-manifold)".to_string()
    };
    let _ = writeln!(
        md,
        "| {input} | {} | {method} | {} | {} | {} | {} | {} | {} | {} | {watertight} | {} | {} |",
        thousands(points),
        secs(seconds),
        thousands(q.vertices),
        thousands(q.triangles),
        relative_or_dash(q.distances.chamfer()),
        relative_or_dash(q.distances.hausdorff()),
        percent(q.valence6),
        percent(q.small_angles),
        q.genus.map_or("—".into(), |g| g.to_string()),
        thousands(q.components),
    );
}
