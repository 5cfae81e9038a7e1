//! The Markdown report: machine, tables, targets; and its place in `docs/benchmarks.md`.

use crate::common::distance::Distances;
use crate::common::inputs::short_count;
use crate::common::report::{bound, mean_max, ms, percent, seconds, thousands, verdict, Run};
use crate::common::stats::{geometric_mean, max, median, min};
use crate::measure::{reduction, Build, SweepRow};
use crate::memory::Memory;
use std::fmt::Write as _;
use vstree::TreeKind;

/// Targets of issue 2.
const GAIN_TARGET: f64 = 0.18;
const BIG_SECONDS_TARGET: f64 = 2.0;
const BYTES_TARGET: f64 = 150.0;

/// Table 1 row: one input at one bound.
pub struct Row {
    pub input: String,
    pub samples: usize,
    pub bound: f64,
    /// `[octree, vstree]`.
    pub builds: [Build; 2],
    /// Output triangles of the `[octree, vstree]` simplifications (meshes only).
    pub triangles: Option<[usize; 2]>,
    /// Distances of the VS-Tree's simplified mesh to the input (meshes only).
    pub distances: Option<Distances>,
}

impl Row {
    /// 1 − VS-Tree clusters / octree clusters.
    pub fn gain(&self) -> f64 {
        reduction(self.builds[0].stats.leaves, self.builds[1].stats.leaves)
    }

    /// The same gain on partitions (empty cells counted, as pointer-based trees have them).
    pub fn partition_gain(&self) -> f64 {
        reduction(self.builds[0].partitions, self.builds[1].partitions)
    }

    /// VS-Tree build time / octree build time.
    pub fn time_ratio(&self) -> f64 {
        self.builds[1].seconds / self.builds[0].seconds
    }

    pub fn spread_ratio(&self) -> f64 {
        self.builds[1].spread() / self.builds[0].spread()
    }
}

/// One simplification of one input at one bound, by one method.
pub struct Method {
    pub input: String,
    pub bound: f64,
    pub method: String,
    pub triangles: usize,
    /// Median seconds with all threads; for vstree also with one thread.
    pub seconds: f64,
    pub seconds_one_thread: Option<f64>,
    pub note: String,
    pub distances: Distances,
}

/// Where and how the run happened: the common part and this bench's.
pub struct Context {
    pub run: Run,
    pub runs: usize,
    pub big_runs: usize,
    pub cloud_surface: String,
}

/// Everything one run measured.
pub struct Report {
    pub rows: Vec<Row>,
    /// Builds of the largest cloud on one thread (same inputs and bounds as in `rows`).
    pub one_thread: Vec<Row>,
    /// Clusters over a range of bounds (untimed).
    pub sweep: Vec<SweepRow>,
    pub methods: Vec<Method>,
    pub memory: Vec<Memory>,
    pub context: Context,
}

fn kind_name(kind: TreeKind) -> &'static str {
    match kind {
        TreeKind::Octree => "octree",
        TreeKind::VsTree => "VS-Tree",
    }
}

impl Report {
    /// The whole generated block, without the markers.
    pub fn markdown(&self) -> String {
        let c = &self.context;
        let mut md = c.run.header();
        let threads = c.run.threads_text("");
        let _ = writeln!(
            md,
            "- Times are medians of {} runs ({} for inputs of 1M samples or more), octree and \
             VS-Tree builds interleaved; threads: {threads}. Dense clouds are drawn on {}.",
            c.runs, c.big_runs, c.cloud_surface
        );
        c.run.write_notes(&mut md);
        md.push('\n');
        self.targets(&mut md);
        self.table1(&mut md);
        self.scaling(&mut md);
        self.clusters(&mut md);
        self.sweep_table(&mut md);
        self.simplification(&mut md);
        self.memory_table(&mut md);
        md
    }

    fn table1(&self, md: &mut String) {
        md.push_str(
            "### Table 1: build time and clusters at the same L2 bound\n\n\
             Clusters are the leaves, i.e. the non-empty cells. Partitions also count the empty \
             cells that a pointer-based tree allocates (every octree split makes 8 cells, every \
             quadtree split 4). The paper's Table 1 gives its gain \"relative to the final number \
             of partitions\", and its implementation was pointer-based.\n\n\
             | input | samples | L2 bound | octree build (ms) | VS-Tree build (ms) | VS/oct time \
             | octree clusters | VS-Tree clusters | gain | octree partitions | VS-Tree partitions \
             | gain |\n\
             |---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.rows {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} | {} | {} |",
                r.input,
                thousands(r.samples),
                bound(r.bound),
                ms(r.builds[0].seconds),
                ms(r.builds[1].seconds),
                r.time_ratio(),
                thousands(r.builds[0].stats.leaves),
                thousands(r.builds[1].stats.leaves),
                percent(r.gain()),
                thousands(r.builds[0].partitions),
                thousands(r.builds[1].partitions),
                percent(r.partition_gain())
            );
        }
        md.push('\n');
    }

    fn scaling(&self, md: &mut String) {
        if self.one_thread.is_empty() {
            return;
        }
        md.push_str(
            "### Threads: the largest cloud on one thread and on all\n\n\
             | input | L2 bound | octree, 1 thread (ms) | octree, all (ms) | speed-up \
             | VS-Tree, 1 thread (ms) | VS-Tree, all (ms) | speed-up |\n\
             |---|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for one in &self.one_thread {
            let Some(all) = self.rows.iter().find(|r| r.input == one.input && r.bound == one.bound) else {
                continue;
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.2} | {} | {} | {:.2} |",
                one.input,
                bound(one.bound),
                ms(one.builds[0].seconds),
                ms(all.builds[0].seconds),
                one.builds[0].seconds / all.builds[0].seconds,
                ms(one.builds[1].seconds),
                ms(all.builds[1].seconds),
                one.builds[1].seconds / all.builds[1].seconds,
            );
        }
        md.push('\n');
    }

    fn clusters(&self, md: &mut String) {
        md.push_str(
            "### Clusters and simplified output\n\n\
             Spread = variance / mean² of the samples per cluster (the paper: the variance \
             roughly halves). S-leaves = share of the VS-Tree's clusters that are quadtree \
             cells (S-nodes); the others are cubes (V- or T-node leaves), where the \
             height-field test failed or passed only once the bound was met. Output = \
             triangles of the simplified mesh (clouds have none). \
             Distance = VS-Tree output to the input, mean / max relative to the input's \
             bounding-box diagonal, from 200k points on the output's surface to the input's \
             triangles.\n\n\
             | input | L2 bound | octree spread | VS-Tree spread | ratio | T-layer depth \
             | S-leaves | octree output | VS-Tree output | VS-Tree → input |\n\
             |---|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.rows {
            let vs = &r.builds[1].stats;
            let (oct_tris, vs_tris) =
                r.triangles.map_or(("—".into(), "—".into()), |[o, v]| (thousands(o), thousands(v)));
            let _ = writeln!(
                md,
                "| {} | {} | {:.2} | {:.2} | {:.2} | {}–{} | {} | {} | {} | {} |",
                r.input,
                bound(r.bound),
                r.builds[0].spread(),
                r.builds[1].spread(),
                r.spread_ratio(),
                vs.t_depth_min,
                vs.t_depth_max,
                percent(r.builds[1].surface_share()),
                oct_tris,
                vs_tris,
                mean_max(r.distances.and_then(|d| d.out_in)),
            );
        }
        md.push('\n');
    }

    /// The inputs of the bound sweep, in order.
    fn sweep_inputs(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for r in &self.sweep {
            if !names.contains(&r.input) {
                names.push(r.input.clone());
            }
        }
        names
    }

    fn sweep_table(&self, md: &mut String) {
        if self.sweep.is_empty() {
            return;
        }
        md.push_str(
            "### Bound sweep: the gain as the tree deepens\n\n\
             One untimed build of each tree per bound, on samples drawn uniformly on a sphere \
             and on the cloud surface. Cells halve at every level, so each tree's cluster count \
             grows in steps as the bound tightens, and the two trees step at different bounds: \
             the gain at a single bound swings with where the bound falls between steps. \
             S-leaves = share of the VS-Tree's clusters below the T-layer.\n\n\
             | input | L2 bound | octree clusters | VS-Tree clusters | gain | S-leaves \
             | T-layer depth | octree partitions | VS-Tree partitions | gain |\n\
             |---|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n",
        );
        for r in &self.sweep {
            let [oct, vs] = &r.figures;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {}–{} | {} | {} | {} |",
                r.input,
                bound(r.bound),
                thousands(oct.stats.leaves),
                thousands(vs.stats.leaves),
                percent(r.gain()),
                percent(vs.surface_leaves as f64 / vs.stats.leaves.max(1) as f64),
                vs.stats.t_depth_min,
                vs.stats.t_depth_max,
                thousands(oct.partitions),
                thousands(vs.partitions),
                percent(r.partition_gain()),
            );
        }
        md.push('\n');
    }

    fn simplification(&self, md: &mut String) {
        if self.methods.is_empty() {
            return;
        }
        md.push_str(
            "### Simplification side by side with the peers\n\n\
             Peers run at the VS-Tree's output size (PyMeshLab vertex clustering: cell size \
             found by bisection; quadric edge collapse: `targetfacenum`, other parameters at \
             their defaults). Times: vstree's whole `simplify` call (samples, tree, clustering) \
             with all threads and with one; PyMeshLab's filter call (single-threaded). \
             Distances relative to the diagonal, mean / max: output → input from 200k points \
             on the output's surface; input → output from the input's vertices.\n\n\
             | input | L2 bound | method | triangles | time (ms) | output → input \
             | input → output | note |\n\
             |---|--:|---|--:|--:|--:|--:|---|\n",
        );
        for m in &self.methods {
            let time = match m.seconds_one_thread {
                Some(one) => format!("{} (1 thread: {})", ms(m.seconds), ms(one)),
                None => ms(m.seconds),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} |",
                m.input,
                bound(m.bound),
                m.method,
                thousands(m.triangles),
                time,
                mean_max(m.distances.out_in),
                mean_max(m.distances.in_out),
                m.note
            );
        }
        md.push('\n');
    }

    fn memory_table(&self, md: &mut String) {
        if self.memory.is_empty() {
            return;
        }
        md.push_str(
            "### Peak memory of a build\n\n\
             Measured in a child process: resident size once the samples are in memory \
             (baseline), and peak resident size during the build (`VmHWM`, reset after making \
             the samples), per sample.\n\n\
             | tree | samples | L2 bound | baseline (B/sample) | peak, total (B/sample) \
             | peak over baseline (B/sample) |\n\
             |---|--:|--:|--:|--:|--:|\n",
        );
        for m in &self.memory {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.1} | {:.1} | {:.1} |",
                kind_name(m.kind),
                short_count(m.samples),
                bound(m.bound),
                m.baseline_per_sample(),
                m.total_per_sample(),
                m.build_per_sample(),
            );
        }
        if self.memory.iter().any(|m| !m.peak.reset) {
            md.push_str("\nThe peak counter could not be reset: peaks may include making the samples.\n");
        }
        md.push('\n');
    }

    /// The targets, met or missed, with the numbers.
    fn targets(&self, md: &mut String) {
        md.push_str("### Targets (issue 2)\n\n");
        if self.rows.is_empty() {
            md.push_str("No inputs ran.\n\n");
            return;
        }
        let gains: Vec<f64> = self.rows.iter().map(Row::gain).collect();
        let met = gains.iter().filter(|&&g| g >= GAIN_TARGET).count();
        let _ = writeln!(
            md,
            "- VS-Tree ≥ {} fewer clusters than the octree: {}: met on {met} of {} rows; gain \
             min {}, median {}, max {}.",
            percent(GAIN_TARGET),
            verdict(met == gains.len()),
            gains.len(),
            percent(min(&gains)),
            percent(median(&gains)),
            percent(max(&gains)),
        );
        let gains: Vec<f64> = self.rows.iter().map(Row::partition_gain).collect();
        let met = gains.iter().filter(|&&g| g >= GAIN_TARGET).count();
        let _ = writeln!(
            md,
            "  - The same gain on partitions (empty cells counted, see Table 1): met on {met} of {} \
             rows; min {}, median {}, max {}.",
            gains.len(),
            percent(min(&gains)),
            percent(median(&gains)),
            percent(max(&gains)),
        );
        for input in self.sweep_inputs() {
            let rows: Vec<&SweepRow> = self.sweep.iter().filter(|r| r.input == input).collect();
            let gains: Vec<f64> = rows.iter().map(|r| r.gain()).collect();
            let bounds: Vec<f64> = rows.iter().map(|r| r.bound).collect();
            let _ = writeln!(
                md,
                "  - Over {} bounds from {} to {} (bound sweep below), on {input}: gain min {}, \
                 median {}, max {}.",
                gains.len(),
                bound(max(&bounds)),
                bound(min(&bounds)),
                percent(min(&gains)),
                percent(median(&gains)),
                percent(max(&gains)),
            );
        }
        let ratios: Vec<f64> = self.rows.iter().map(Row::time_ratio).collect();
        let faster = ratios.iter().filter(|&&r| r <= 1.0).count();
        let close = ratios.iter().filter(|&&r| r <= 1.05).count();
        let geo = geometric_mean(&ratios);
        let _ = writeln!(
            md,
            "- VS-Tree builds no slower than the octree: {}: met on {faster} of {} rows \
             ({close} within 5%); time ratio VS/oct median {:.2}, geometric mean {geo:.2}, \
             range {:.2}–{:.2}.",
            verdict(faster == ratios.len()),
            ratios.len(),
            median(&ratios),
            min(&ratios),
            max(&ratios),
        );
        let biggest = self.rows.iter().map(|r| r.samples).max().unwrap_or(0);
        if biggest >= 5_000_000 {
            let big: Vec<&Row> = self.rows.iter().filter(|r| r.samples == biggest).collect();
            let worst = big.iter().map(|r| r.builds[1].seconds).fold(0.0, f64::max);
            let list: Vec<String> = big
                .iter()
                .map(|r| {
                    format!(
                        "{} s at {} (octree {} s)",
                        seconds(r.builds[1].seconds),
                        bound(r.bound),
                        seconds(r.builds[0].seconds)
                    )
                })
                .collect();
            let _ = writeln!(
                md,
                "- {} samples build in under {BIG_SECONDS_TARGET} s: {}; VS-Tree {}.",
                short_count(biggest),
                verdict(worst < BIG_SECONDS_TARGET),
                list.join(", ")
            );
        }
        if !self.memory.is_empty() {
            let total = self.memory.iter().map(Memory::total_per_sample).fold(0.0, f64::max);
            let over = self.memory.iter().map(Memory::build_per_sample).fold(0.0, f64::max);
            let _ = writeln!(
                md,
                "- Peak memory under {BYTES_TARGET} B/sample: {} counting everything \
                 ({total:.1} B/sample at worst); the build itself adds at most {over:.1} \
                 B/sample over the samples already in memory.",
                verdict(total < BYTES_TARGET),
            );
        }
        let spreads: Vec<f64> = self.rows.iter().map(Row::spread_ratio).collect();
        let _ = writeln!(
            md,
            "- Cluster-size spread (paper: variance roughly halves): VS-Tree / octree spread \
             median {:.2}, range {:.2}–{:.2}.\n",
            median(&spreads),
            min(&spreads),
            max(&spreads),
        );
    }
}
