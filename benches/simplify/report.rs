//! The Markdown report of the simplification bench: the targets of issue 15 with their
//! numbers, a summary per method and size, and the full table per size.

use crate::common::distance::Distances;
use crate::common::folds::FOLD_DEGREES;
use crate::common::report::{ms, percent, relative, thousands, verdict, Run};
use crate::common::stats::{max, median, min};
use crate::{NEW_MODE, REFERENCE};
use std::fmt::Write as _;

/// The target: Chamfer no worse than the reference's, and at least this many times faster.
const SPEED_TARGET: f64 = 5.0;

/// One method's output for one input at one size.
#[derive(Clone, Debug)]
pub struct Row {
    pub input: String,
    pub input_triangles: usize,
    pub ratio: f64,
    pub target: usize,
    pub method: String,
    pub triangles: usize,
    /// Median time of the call (all threads for vstree unless told otherwise).
    pub seconds: f64,
    /// The same on one thread (the new mode only).
    pub seconds_one_thread: Option<f64>,
    pub distances: Distances,
    pub non_manifold_edges: usize,
    /// Edges whose faces turn back onto each other (see `common::folds`).
    pub folds: usize,
    /// For closed manifold inputs: whether the output is closed and manifold with their genus.
    pub genus_kept: Option<bool>,
}

/// Where and how the run happened: the common part and this bench's.
pub struct Context {
    pub run: Run,
    pub runs: usize,
}

pub struct Report {
    pub rows: Vec<Row>,
    /// Rows of the models measured over a range of sizes (plotted).
    pub curve: Vec<Row>,
    pub context: Context,
}

/// The new mode's figures against the reference on one input at one size.
struct Pair {
    input: String,
    chamfer: f64,
    /// Reference time / new mode time.
    speed: f64,
    speed_one_thread: Option<f64>,
    /// Both within 1% (or 2 triangles) of the target.
    equal_size: bool,
}

fn near(count: usize, target: usize) -> bool {
    count.abs_diff(target) as f64 <= (0.01 * target as f64).max(2.0)
}

impl Report {
    fn ratios(&self) -> Vec<f64> {
        let mut ratios: Vec<f64> = Vec::new();
        for r in &self.rows {
            if !ratios.contains(&r.ratio) {
                ratios.push(r.ratio);
            }
        }
        ratios
    }

    fn methods(&self) -> Vec<String> {
        let mut methods: Vec<String> = Vec::new();
        for r in &self.rows {
            if !methods.contains(&r.method) {
                methods.push(r.method.clone());
            }
        }
        methods
    }

    fn find(&self, input: &str, ratio: f64, method: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.input == input && r.ratio == ratio && r.method == method)
    }

    /// `method` against the reference on every input at `ratio` where both ran.
    fn pairs(&self, ratio: f64, method: &str) -> Vec<Pair> {
        self.rows
            .iter()
            .filter(|r| r.ratio == ratio && r.method == method)
            .filter_map(|r| {
                let reference = self.find(&r.input, ratio, REFERENCE)?;
                let chamfer = r.distances.chamfer()? / reference.distances.chamfer()?;
                Some(Pair {
                    input: r.input.clone(),
                    chamfer,
                    speed: reference.seconds / r.seconds,
                    speed_one_thread: r.seconds_one_thread.map(|s| reference.seconds / s),
                    equal_size: near(r.triangles, r.target) && near(reference.triangles, r.target),
                })
            })
            .collect()
    }

    pub fn markdown(&self) -> String {
        let c = &self.context;
        let mut md = c.run.header();
        let _ = writeln!(
            md,
            "- Times: {} of the call alone, the mesh already in memory, in process; vstree on {} \
             (the new mode also on one thread), the peers on one. Distances: `vstree::eval::distance`, relative to the \
             input's bounding-box diagonal; Chamfer = mean of the two one-sided mean distances (200k points on the \
             output, the input's vertices), Hausdorff = the larger one-sided maximum.",
            if c.runs == 1 { "one run".to_string() } else { format!("median of {} runs", c.runs) },
            c.run.threads_text(" threads"),
        );
        c.run.write_notes(&mut md);
        md.push('\n');
        self.targets(&mut md);
        self.summary(&mut md);
        for ratio in self.ratios() {
            self.table(&mut md, ratio);
        }
        md
    }

    /// Issue 15's point 3, per size.
    fn targets(&self, md: &mut String) {
        md.push_str("### Targets (issue 15, point 3)\n\n");
        let _ = writeln!(
            md,
            "The new mode (`{NEW_MODE}`: `--faces N`, topology kept) against meshoptimizer `simplify` on \
             every model: Chamfer ratio (new / meshoptimizer, lower is better) and speed ratio (meshoptimizer's \
             time / the new mode's, higher is better). Worst row named.\n"
        );
        for ratio in self.ratios() {
            let pairs = self.pairs(ratio, NEW_MODE);
            if pairs.is_empty() {
                let _ = writeln!(md, "- {}: no pair measured.", percent(ratio));
                continue;
            }
            let chamfers: Vec<f64> = pairs.iter().map(|p| p.chamfer).collect();
            let speeds: Vec<f64> = pairs.iter().map(|p| p.speed).collect();
            let worst_c = pairs.iter().max_by(|a, b| a.chamfer.total_cmp(&b.chamfer)).map(|p| p.input.as_str());
            let worst_s = pairs.iter().min_by(|a, b| a.speed.total_cmp(&b.speed)).map(|p| p.input.as_str());
            let met_c = chamfers.iter().filter(|&&x| x <= 1.0).count();
            let met_s = speeds.iter().filter(|&&x| x >= SPEED_TARGET).count();
            let _ = writeln!(
                md,
                "- **{} of the triangles**, {} models: Chamfer no worse: {}: met on {met_c} of {}; ratio median \
                 {:.2}, worst {:.2} ({}). At least {SPEED_TARGET}x faster: {}: met on {met_s} of {}; speed ratio \
                 median {:.1}, worst {:.1} ({}).",
                percent(ratio),
                pairs.len(),
                verdict(met_c == pairs.len()),
                pairs.len(),
                median(&chamfers),
                max(&chamfers),
                worst_c.unwrap_or("—"),
                verdict(met_s == pairs.len()),
                pairs.len(),
                median(&speeds),
                min(&speeds),
                worst_s.unwrap_or("—"),
            );
            let one: Vec<f64> = pairs.iter().filter_map(|p| p.speed_one_thread).collect();
            if !one.is_empty() {
                let _ =
                    writeln!(md, "  - On one thread: speed ratio median {:.1}, worst {:.1}.", median(&one), min(&one));
            }
            let equal: Vec<f64> = pairs.iter().filter(|p| p.equal_size).map(|p| p.chamfer).collect();
            if equal.len() < pairs.len() {
                let _ = writeln!(
                    md,
                    "  - Where both are within 1% (or 2 triangles) of the size asked ({} of {} models; the others \
                     are held above it by their genus or are too small): Chamfer ratio median {:.2}, worst {:.2}.",
                    equal.len(),
                    pairs.len(),
                    median(&equal),
                    max(&equal),
                );
            }
        }
        md.push('\n');
    }

    /// Every method against the reference, per size.
    fn summary(&self, md: &mut String) {
        let _ = write!(
            md,
            "### Summary per method\n\n\
             Medians over the models of each method's ratio to meshoptimizer `simplify` on the same model \
             (Chamfer and Hausdorff: method / meshoptimizer; speed: meshoptimizer's time / method's); \
             non-manifold: models whose output has a non-manifold edge; folds: edges whose faces turn by \
             more than {FOLD_DEGREES:.0}°, summed over the models; genus kept: closed inputs whose \
             output is closed, manifold and of their genus.\n\n\
             | size | method | Chamfer ratio (median / worst) | Hausdorff ratio (median) | speed ratio (median / worst) \
             | non-manifold | folds | genus kept |\n\
             |--:|---|--:|--:|--:|--:|--:|--:|\n",
        );
        for ratio in self.ratios() {
            for method in self.methods() {
                let rows: Vec<&Row> = self.rows.iter().filter(|r| r.ratio == ratio && r.method == method).collect();
                let pairs = self.pairs(ratio, &method);
                let chamfers: Vec<f64> = pairs.iter().map(|p| p.chamfer).collect();
                let speeds: Vec<f64> = pairs.iter().map(|p| p.speed).collect();
                let hausdorff: Vec<f64> = rows
                    .iter()
                    .filter_map(|r| {
                        let reference = self.find(&r.input, ratio, REFERENCE)?;
                        Some(r.distances.hausdorff()? / reference.distances.hausdorff()?)
                    })
                    .collect();
                let closed: Vec<bool> = rows.iter().filter_map(|r| r.genus_kept).collect();
                let nm = rows.iter().filter(|r| r.non_manifold_edges > 0).count();
                let or_dash = |v: &[f64], f: &dyn Fn(&[f64]) -> f64, digits: usize| {
                    if v.is_empty() {
                        "—".to_string()
                    } else {
                        format!("{:.digits$}", f(v))
                    }
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {} / {} | {} | {} / {} | {} of {} | {} | {} of {} |",
                    percent(ratio),
                    method,
                    or_dash(&chamfers, &median, 2),
                    or_dash(&chamfers, &max, 2),
                    or_dash(&hausdorff, &median, 2),
                    or_dash(&speeds, &median, 1),
                    or_dash(&speeds, &min, 1),
                    nm,
                    rows.len(),
                    thousands(rows.iter().map(|r| r.folds).sum()),
                    closed.iter().filter(|&&k| k).count(),
                    closed.len(),
                );
            }
        }
        md.push('\n');
    }

    fn table(&self, md: &mut String, ratio: f64) {
        let _ = writeln!(
            md,
            "### At {} of the triangles\n\n\
             | model | method | triangles | time (ms) | Chamfer | Hausdorff | non-manifold edges | folds | genus kept |\n\
             |---|---|--:|--:|--:|--:|--:|--:|:-:|",
            percent(ratio)
        );
        let mut last = String::new();
        for r in self.rows.iter().filter(|r| r.ratio == ratio) {
            let model = if r.input == last {
                String::new()
            } else {
                format!("{} ({} → {})", r.input, thousands(r.input_triangles), thousands(r.target))
            };
            last = r.input.clone();
            let time = match r.seconds_one_thread {
                Some(one) => format!("{} (1 thread: {})", ms(r.seconds), ms(one)),
                None => ms(r.seconds),
            };
            let genus = match r.genus_kept {
                Some(true) => "yes",
                Some(false) => "no",
                None => "—",
            };
            let _ = writeln!(
                md,
                "| {model} | {} | {} | {time} | {} | {} | {} | {} | {genus} |",
                r.method,
                thousands(r.triangles),
                r.distances.chamfer().map_or("—".into(), relative),
                r.distances.hausdorff().map_or("—".into(), relative),
                thousands(r.non_manifold_edges),
                thousands(r.folds),
            );
        }
        md.push('\n');
    }
}
