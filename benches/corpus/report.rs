//! The Markdown report of the corpus bench: summary lines per method, the rows (vstree and the
//! better screened Poisson of each depth), vstree's stages and memory, and every peer's raw rows.

use crate::child::VstreeRun;
use crate::common::inputs::short_count;
use crate::common::report::{percent, relative, relative_or_dash, secs, thousands, Run};
use crate::common::stats::median;
use crate::inputs::{Variant, TRUTH_SAMPLES};
use crate::measure::{Quality, FOLD_DEGREES};
use crate::{CLOSED_PEERS, OPEN_PEERS};
use std::fmt::Write as _;

/// One input: vstree's reconstruction and the peers'.
pub struct Row {
    pub name: String,
    pub variant: Variant,
    pub points: usize,
    /// A model of the corpus (counted in the genus summary).
    pub corpus: bool,
    pub open: bool,
    pub truth_genus: Option<u32>,
    pub truth_components: usize,
    /// What vstree's child measured and the output's figures, or why it failed.
    pub vstree: Result<(VstreeRun, Quality), String>,
    pub peers: Vec<PeerRow>,
}

/// One peer on one input.
pub struct PeerRow {
    pub method: String,
    /// It was started (it may have failed); false when left out.
    pub ran: bool,
    /// Median time of the reconstruction call; `None` when skipped.
    pub seconds: Option<f64>,
    pub parameters: String,
    /// The output's figures, or why there are none (skipped, unreadable).
    pub quality: Result<Quality, String>,
}

/// Where and how the run happened: the common part and this bench's.
pub struct Context {
    pub run: Run,
    pub peers: bool,
    pub runs: usize,
    pub peer_runs: usize,
}

/// Everything one run measured.
pub struct Report {
    pub rows: Vec<Row>,
    pub context: Context,
}

/// A method as the summary and the tables see it.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Method {
    Vstree,
    /// The better (lower Chamfer) of PyMeshLab's and Open3D's screened Poisson at this depth.
    Poisson(u32),
    Peer(&'static str),
}

impl Method {
    fn name(self) -> String {
        match self {
            Method::Vstree => "vstree".into(),
            Method::Poisson(depth) => format!("Poisson depth {depth}"),
            Method::Peer(m) => peer_name(m).into(),
        }
    }
}

fn peer_name(method: &str) -> &str {
    match method {
        "meshlab-spsr8" => "PyMeshLab screened Poisson, depth 8",
        "meshlab-spsr10" => "PyMeshLab screened Poisson, depth 10",
        "open3d-poisson8" => "Open3D Poisson, depth 8",
        "open3d-poisson10" => "Open3D Poisson, depth 10",
        "open3d-poisson8-trim" => "Open3D Poisson, depth 8, density-trimmed",
        "open3d-poisson10-trim" => "Open3D Poisson, depth 10, density-trimmed",
        other => other,
    }
}

/// What one method gave on one row: seconds, figures, and which peer it was.
struct Entry<'a> {
    seconds: f64,
    quality: &'a Quality,
    method: &'a str,
}

impl Row {
    fn label(&self) -> String {
        format!("{} {} {}", self.name, short_count(self.points), self.variant.name())
    }

    fn peer(&self, method: &str) -> Option<Entry<'_>> {
        let p = self.peers.iter().find(|p| p.method == method)?;
        Some(Entry { seconds: p.seconds?, quality: p.quality.as_ref().ok()?, method: &p.method })
    }

    /// `None` when the method did not run on this row; `Some(None)` when it ran and failed.
    fn entry(&self, method: Method) -> Option<Option<Entry<'_>>> {
        match method {
            Method::Vstree => Some(self.vstree.as_ref().ok().map(|(run, q)| Entry {
                seconds: run.seconds.total,
                quality: q,
                method: "vstree",
            })),
            Method::Poisson(depth) => {
                let [a, b] = [format!("meshlab-spsr{depth}"), format!("open3d-poisson{depth}")];
                let ran = self.peers.iter().any(|p| (p.method == a || p.method == b) && p.ran);
                if !ran {
                    return None;
                }
                let chamfer = |e: &Entry| e.quality.distances.chamfer().unwrap_or(f64::INFINITY);
                let best = [self.peer(&a), self.peer(&b)]
                    .into_iter()
                    .flatten()
                    .min_by(|x, y| chamfer(x).total_cmp(&chamfer(y)).then(x.seconds.total_cmp(&y.seconds)));
                Some(best)
            }
            Method::Peer(m) => {
                let p = self.peers.iter().find(|p| p.method == m && p.ran)?;
                Some(self.peer(m).map(|e| Entry { method: &p.method, ..e }))
            }
        }
    }
}

fn ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}")
    } else {
        "∞ (failed)".into()
    }
}

/// Median and worst (largest, or smallest with `low_is_worst`) of (value, row) pairs.
fn median_worst(values: &[(f64, String)], low_is_worst: bool) -> Option<(f64, f64, &str)> {
    let v: Vec<f64> = values.iter().map(|(x, _)| *x).collect();
    let worst = if low_is_worst {
        values.iter().min_by(|a, b| a.0.total_cmp(&b.0))?
    } else {
        values.iter().max_by(|a, b| a.0.total_cmp(&b.0))?
    };
    Some((median(&v), worst.0, &worst.1))
}

impl Report {
    /// The whole generated block, without the markers.
    pub fn markdown(&self) -> String {
        let c = &self.context;
        let mut md = c.run.header();
        let threads = c.run.threads_text("");
        let peers = if c.peers {
            format!(
                " Peers: {} run{} each, all cores, on the same points with the normals vstree uses.",
                c.peer_runs,
                if c.peer_runs == 1 { "" } else { "s" }
            )
        } else {
            " Peers not run (`--peers` not given).".to_string()
        };
        let _ = writeln!(
            md,
            "- vstree: `ReconstructParams::default()` on every input (open or closed is found, not told); threads: \
             {threads}; {} timed run{} per input.{peers}",
            c.runs,
            if c.runs == 1 { "" } else { "s" }
        );
        c.run.write_notes(&mut md);
        md.push('\n');
        self.summary(&mut md);
        self.rows_table(&mut md);
        self.stages(&mut md);
        self.raw(&mut md);
        md
    }

    /// The rows where a genus is counted: the corpus, clean, at the largest size sampled.
    fn genus_rows(&self) -> (usize, Vec<&Row>) {
        let size = self.rows.iter().filter(|r| r.corpus && r.variant == Variant::Clean).map(|r| r.points).max();
        let size = size.unwrap_or(0);
        (size, self.rows.iter().filter(|r| r.corpus && r.variant == Variant::Clean && r.points == size).collect())
    }

    fn summary(&self, md: &mut String) {
        md.push_str("### Summary\n\n");
        if self.rows.is_empty() {
            md.push_str("No inputs ran.\n\n");
            return;
        }
        let mut methods = vec![Method::Vstree, Method::Poisson(8), Method::Poisson(10)];
        methods.extend(CLOSED_PEERS.iter().chain(&OPEN_PEERS).map(|m| Method::Peer(m)));
        let (genus_size, genus_rows) = self.genus_rows();
        let reference = Method::Poisson(8);
        let _ = writeln!(
            md,
            "Ratios are to Poisson depth 8 on the same row (the better of PyMeshLab's and Open3D's by Chamfer \
             distance): Chamfer and Hausdorff ratio (lower is better; worst = largest), speed = Poisson depth 8's \
             time over the method's (higher is faster; worst = smallest). Genus right: outputs with the true \
             genus on the {} corpus meshes at {} clean. Time per point: slowest row over the median row.\n",
            genus_rows.len(),
            short_count(genus_size)
        );
        for method in methods {
            let rows: Vec<(&Row, Option<Entry>)> =
                self.rows.iter().filter_map(|r| r.entry(method).map(|e| (r, e))).collect();
            if rows.is_empty() {
                continue;
            }
            let mut parts = Vec::new();
            let mut chamfer = Vec::new();
            let mut hausdorff = Vec::new();
            let mut speed = Vec::new();
            if method != reference {
                for (r, e) in &rows {
                    let Some(Some(p)) = r.entry(reference) else { continue };
                    let label = r.label();
                    let (pc, ph) = (p.quality.distances.chamfer(), p.quality.distances.hausdorff());
                    match e {
                        Some(e) => {
                            if let (Some(x), Some(y)) = (e.quality.distances.chamfer(), pc) {
                                chamfer.push((x / y, label.clone()));
                            }
                            if let (Some(x), Some(y)) = (e.quality.distances.hausdorff(), ph) {
                                hausdorff.push((x / y, label.clone()));
                            }
                            speed.push((p.seconds / e.seconds, label));
                        }
                        None => {
                            chamfer.push((f64::INFINITY, label.clone()));
                            hausdorff.push((f64::INFINITY, label));
                        }
                    }
                }
            }
            if let Some((m, w, at)) = median_worst(&chamfer, false) {
                parts.push(format!("Chamfer ratio median {}, worst {} ({at})", ratio(m), ratio(w)));
            }
            if let Some((m, w, at)) = median_worst(&hausdorff, false) {
                parts.push(format!("Hausdorff ratio median {}, worst {} ({at})", ratio(m), ratio(w)));
            }
            let counted: Vec<&Row> = genus_rows.iter().copied().filter(|r| r.entry(method).is_some()).collect();
            if !counted.is_empty() {
                let right = counted
                    .iter()
                    .filter(|r| matches!(r.entry(method), Some(Some(e)) if e.quality.genus_right(r.truth_genus)))
                    .count();
                parts.push(format!("genus right {right} of {}", counted.len()));
            }
            if let Some((m, w, at)) = median_worst(&speed, true) {
                parts.push(format!("speed ratio median {m:.1}×, worst {w:.2}× ({at})"));
            }
            let per_point: Vec<(f64, String)> =
                rows.iter().filter_map(|(r, e)| e.as_ref().map(|e| (e.seconds / r.points as f64, r.label()))).collect();
            if let Some((m, w, at)) = median_worst(&per_point, false) {
                parts.push(format!(
                    "slowest time per point {:.2}× the median ({at}: {:.2} µs against {:.2} µs)",
                    w / m,
                    1e6 * w,
                    1e6 * m
                ));
            }
            if method == Method::Vstree || method == reference {
                let c: Vec<(f64, String)> = rows
                    .iter()
                    .filter_map(|(r, e)| e.as_ref().and_then(|e| e.quality.distances.chamfer()).map(|x| (x, r.label())))
                    .collect();
                if let Some((m, w, at)) = median_worst(&c, false) {
                    parts.push(format!("Chamfer median {}, worst {} ({at})", relative(m), relative(w)));
                }
            }
            let failed = rows.iter().filter(|(_, e)| e.is_none()).count();
            if failed > 0 {
                parts.push(format!("failed on {failed} row{}", if failed == 1 { "" } else { "s" }));
            }
            let _ = writeln!(md, "- **{}** ({} rows): {}.", method.name(), rows.len(), parts.join("; "));
        }
        md.push('\n');
    }

    fn rows_table(&self, md: &mut String) {
        let _ = write!(
            md,
            "### Rows\n\n\
             Time: the reconstruction call alone (cloud in memory; vstree's in a process of its own, and includes \
             estimating normals where the cloud has none, the peers get those normals for free). Vertices: used by \
             a triangle. Genus and components: the output's, then the truth's. Chamfer = mean of the two mean distances (from \
             200k points on the output's surface to the true mesh's triangles; from {} points on the true mesh \
             to the output's triangles), Hausdorff = the larger of the two maxima; both over the true mesh's \
             bounding-box diagonal. < 10°, < 20°: share of triangles with an angle under that. Valence 6: share \
             of vertices with six neighbours. Folds: edges whose faces' normals differ by more than \
             {FOLD_DEGREES:.0}°. Open inputs: open = the output has boundary edges; far = the largest distance \
             from a face's centroid to the nearest sample, in sample spacings (median nearest-neighbour \
             distance). Poisson depth N: the better by Chamfer of PyMeshLab's and Open3D's (which one in \
             brackets; both in the raw rows below).\n\n\
             | input | variant | points | method | time (s) | vertices | genus | components | Chamfer | Hausdorff \
             | < 10° | < 20° | valence 6 | folds | open | far |\n\
             |---|---|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|\n",
            short_count(TRUTH_SAMPLES),
        );
        for r in &self.rows {
            let mut methods = vec![Method::Vstree, Method::Poisson(8), Method::Poisson(10)];
            if r.open {
                methods.extend(OPEN_PEERS.iter().map(|m| Method::Peer(m)));
            }
            for method in methods {
                match r.entry(method) {
                    None => {}
                    Some(Some(e)) => {
                        let name = match method {
                            Method::Poisson(_) => format!(
                                "{} ({})",
                                method.name(),
                                if e.method.starts_with("meshlab") { "PyMeshLab" } else { "Open3D" }
                            ),
                            _ => method.name(),
                        };
                        quality_row(md, r, &name, e.seconds, e.quality);
                    }
                    Some(None) => {
                        let why = match method {
                            Method::Vstree => r.vstree.as_ref().err().cloned().unwrap_or_default(),
                            _ => "no output".into(),
                        };
                        let _ = writeln!(
                            md,
                            "| {} | {} | {} | {} | — | {} | | | | | | | | | | |",
                            r.name,
                            r.variant.name(),
                            thousands(r.points),
                            method.name(),
                            why.replace('|', "/")
                        );
                    }
                }
            }
        }
        md.push('\n');
    }

    fn stages(&self, md: &mut String) {
        md.push_str(
            "### vstree stage by stage\n\n\
             T-nodes: the tree's T-layer (`stats.tree.t_nodes`); field evaluations: points where the base mesh's \
             implicit function was evaluated (`stats.field_evaluations`). Seconds per stage from `ReconstructStats` \
             (normals: kept or estimated; M0: the base mesh; trim: only on open inputs), the whole call, M0's share \
             of it, the time per input point, and the refinement levels done. Memory, in bytes per input point: \
             peak = the largest resident size (`VmHWM`) of the process that ran the call, which holds only the \
             program and the cloud (read from PLY) besides; call = that peak less the resident size just before \
             the call (what the call itself added). Speed: Open3D's Poisson depth 8 time over vstree's whole \
             call on the same row.\n\n",
        );
        self.stage_summary(md);
        md.push_str(
            "| input | variant | points | T-nodes | field evaluations | normals | tree | M0 | refine | trim | total \
             | M0 share | µs/point | peak B/point | call B/point | levels |\n\
             |---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.rows {
            let Ok((run, _)) = &r.vstree else { continue };
            let (s, m) = (&run.seconds, &run.memory);
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} | {} | {} |",
                r.name,
                r.variant.name(),
                thousands(r.points),
                thousands(run.t_nodes),
                thousands(run.field_evaluations),
                secs(s.normals),
                secs(s.tree),
                secs(s.base),
                secs(s.refine),
                secs(s.trim),
                secs(s.total),
                percent(s.base / s.total),
                1e6 * s.total / r.points as f64,
                thousands(m.total_per(r.points).round() as usize),
                thousands(m.added_per(r.points).round() as usize),
                run.levels,
            );
        }
        let unreset = self.rows.iter().filter(|r| matches!(&r.vstree, Ok((run, _)) if !run.memory.reset)).count();
        if unreset > 0 {
            let _ = writeln!(
                md,
                "\nOn {unreset} rows the peak counter could not be reset after reading the cloud: their peak may be \
                 the reading's."
            );
        }
        md.push('\n');
    }

    /// The stage table's summary: M0's share, the peak memory, and the speed against Open3D's
    /// Poisson depth 8, each at the median and the worst row.
    fn stage_summary(&self, md: &mut String) {
        let mut share = Vec::new();
        let mut bytes = Vec::new();
        let mut speed = Vec::new();
        for r in &self.rows {
            let Ok((run, _)) = &r.vstree else { continue };
            share.push((run.seconds.base / run.seconds.total, r.label()));
            bytes.push((run.memory.total_per(r.points), r.label()));
            if let Some(p) = r.peer("open3d-poisson8") {
                speed.push((p.seconds / run.seconds.total, r.label()));
            }
        }
        let mut parts = Vec::new();
        if let Some((m, w, at)) = median_worst(&share, false) {
            parts.push(format!("M0 share median {}, worst {} ({at})", percent(m), percent(w)));
        }
        if let Some((m, w, at)) = median_worst(&bytes, false) {
            let b = |x: f64| thousands(x.round() as usize);
            parts.push(format!("peak memory median {} B/point, worst {} B/point ({at})", b(m), b(w)));
        }
        match median_worst(&speed, true) {
            Some((m, w, at)) => parts.push(format!(
                "speed against Open3D Poisson depth 8 median {m:.2}×, worst {w:.2}× ({at}; {} rows)",
                speed.len()
            )),
            None => parts.push("no Open3D Poisson depth 8 rows to compare the speed with".into()),
        }
        if !share.is_empty() {
            let _ = writeln!(md, "**Summary** ({} rows): {}.\n", share.len(), parts.join("; "));
        }
    }

    fn raw(&self, md: &mut String) {
        if !self.rows.iter().any(|r| !r.peers.is_empty()) {
            return;
        }
        md.push_str(
            "### Every peer run\n\n\
             | input | variant | points | method | time (s) | vertices | genus | components | Chamfer | Hausdorff \
             | < 10° | < 20° | valence 6 | folds | open | far |\n\
             |---|---|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|\n",
        );
        let mut parameters: Vec<String> = Vec::new();
        for r in &self.rows {
            for p in &r.peers {
                match (&p.quality, p.seconds) {
                    (Ok(q), Some(s)) => quality_row(md, r, peer_name(&p.method), s, q),
                    (Err(why), seconds) => {
                        let _ = writeln!(
                            md,
                            "| {} | {} | {} | {} | {} | {} | | | | | | | | | | |",
                            r.name,
                            r.variant.name(),
                            thousands(r.points),
                            peer_name(&p.method),
                            seconds.map_or("—".into(), secs),
                            why.replace('|', "/")
                        );
                    }
                    (Ok(_), None) => {}
                }
                let line = format!("{}: {}", peer_name(&p.method), p.parameters);
                if !p.parameters.is_empty() && !parameters.contains(&line) {
                    parameters.push(line);
                }
            }
        }
        if !parameters.is_empty() {
            let _ = writeln!(md, "\nPeer parameters (others at their defaults): {}.", parameters.join("; "));
        }
        md.push('\n');
    }
}

/// One method's line of the tables.
fn quality_row(md: &mut String, r: &Row, method: &str, seconds: f64, q: &Quality) {
    let genus = q.genus.map_or("—".into(), |g| g.to_string());
    let truth_genus = r.truth_genus.map_or("open".into(), |g| g.to_string());
    let mark = if r.truth_genus.is_some() && !q.genus_right(r.truth_genus) { " ✗" } else { "" };
    let (open, far) = if r.open {
        (if q.is_open() { "yes" } else { "no" }.to_string(), q.farthest_face.map_or("—".into(), |f| format!("{f:.1}")))
    } else {
        (String::new(), String::new())
    };
    let _ = writeln!(
        md,
        "| {} | {} | {} | {method} | {} | {} | {genus} / {truth_genus}{mark} | {} / {} | {} | {} | {} | {} | {} | {} | {open} | {far} |",
        r.name,
        r.variant.name(),
        thousands(r.points),
        secs(seconds),
        thousands(q.vertices),
        thousands(q.components),
        thousands(r.truth_components),
        relative_or_dash(q.distances.chamfer()),
        relative_or_dash(q.distances.hausdorff()),
        percent(q.under10),
        percent(q.under20),
        percent(q.valence6),
        thousands(q.folds),
    );
}
