//! Simplification of a PLY file larger than memory: out-of-core vertex clustering (Lindstrom
//! 2000) with the VS-Tree as the partition. The file is read three times, front to back, a few
//! MiB at a time, and never held:
//!
//! 1. the faces: a fixed share of the triangles, chosen by a hash of their ordinal, is kept as
//!    vertex indices, to become the tree's samples;
//! 2. the vertices: the box of them all, and the positions those triangles use; the tree is
//!    built on the chosen triangles' centres and normals and fitted to the target's clusters
//!    (its leaves);
//! 3. the vertices, then the faces: each vertex gets the cluster of the sample nearest it (a
//!    leaf's cell may hold vertices of a sheet none of its samples came from, and the nearest
//!    sample is on the vertex's own sheet), and each triangle whose three clusters differ
//!    becomes a triangle of clusters, kept once. Each cluster's point minimises its samples'
//!    quadric, falling where the planes leave it free at the mean of the cluster's vertices.
//!
//! The clustered mesh is then brought to the target by quadric edge collapses, as in memory.
//! What grows with the input is one cluster index per vertex (4 bytes); the rest follows the
//! output's size. The topology is not kept: keeping it needs the whole mesh's edges, so the
//! result is plain clustering's, where sheets closer than a cluster may fuse.

use super::{
    check_target, cluster_with_stats, clusters_for, collapse, collapse_to_target, seed_tree, SimplifyParams,
    SimplifyStats, MAX_ROUNDS,
};
use crate::error::{Error, Result};
use crate::io::ply::{self, Declared, Fail, Sink};
use crate::io::{assemble, Format};
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::quadric::CellStats;
use crate::rng;
use crate::samples::SampleSet;
use crate::simplify::KeepTopology;
use crate::spatial::KdTree;
use crate::tree::{self, NodeKind, VsTree};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashSet;
use std::path::Path;
use std::time::Instant;

/// Samples taken per cluster the target needs (unitless): the tree decides its splits and the
/// clusters their planes from these alone. A one-off probe (Chamfer to the input, 2%) found 4
/// and 8 alike on the 3.2M-triangle bull, and on the 18M-triangle cheese 8 at 0.0209% of the
/// diagonal, 4 at 0.0266%, 16 at 0.0172%; 8 keeps a 200M-triangle file to 1M triangles under
/// 1 GB (`cargo bench --bench simplify -- --models none --stream 200M`, docs/benchmarks.md).
const SAMPLES_PER_CLUSTER: usize = 8;

/// The fewest samples taken (when the input has as many triangles): a small target still gets
/// a tree fitted to its shape rather than to a handful of faces.
const MIN_SAMPLES: usize = 1 << 18;

/// Vertices labelled, or triangles resolved, per parallel batch: large enough to keep both
/// cores busy, small enough to be a few MiB.
const BATCH: usize = 1 << 16;

/// Seed of the hash that chooses the sampled triangles, so that runs are reproducible.
const SAMPLE_SEED: u64 = 0x5eed_5a3b_1e00;

/// Simplifies the PLY file at `path` to `params.target_faces` triangles without holding it in
/// memory (see the module's documentation). The tree's bound is not used, and samples are
/// always face centres. Refused: other formats, no target, `KeepTopology::On`, and files whose
/// faces come before their vertices.
pub fn simplify_ply_streaming(
    path: &Path,
    params: &SimplifyParams,
    progress: &mut Progress,
) -> Result<(Mesh, SimplifyStats)> {
    let threads = Threads::new(params.threads)?;
    params.check()?;
    refuse(path, params)?;
    let declared = ply::declared(path)?;
    let target = params.target_faces;
    if declared.faces == 0 {
        check_target(0, target)?; // a point cloud
    }
    if !declared.vertices_first {
        return Err(Error::input(format!(
            "{}: its faces come before its vertices, which a stream cannot resolve: simplify it in memory",
            path.display()
        )));
    }
    let t0 = Instant::now();
    let want = clusters_for(target, None, 1.0);
    let budget = (SAMPLES_PER_CLUSTER * want).max(MIN_SAMPLES);
    let chosen = choose_triangles(path, &declared, budget, &mut progress.stage(0.0, 0.3))?;
    check_target(chosen.triangles, target)?;
    let gathered = gather_vertices(path, &declared, &chosen, &mut progress.stage(0.3, 0.45))?;
    let samples = gathered.samples(&chosen.triangles_kept, &chosen.needed);
    let (input_triangles, origin) = (chosen.triangles, gathered.origin);
    drop((chosen, gathered));
    if samples.is_empty() {
        return Err(Error::input("every sampled triangle of the mesh is degenerate (zero area)"));
    }
    let t1 = Instant::now();
    let mut tree = tree::build(&samples, &seed_tree(&params.tree), &threads, &mut progress.stage(0.45, 0.55))?;
    drop(samples);
    crate::memory::release_freed();
    let t2 = Instant::now();
    let mut want = want;
    let mut last_leaves = 0;
    let mut round = 1;
    let (out, out_clusters, stats) = loop {
        let leaves = tree::fit(&mut tree, want, &threads);
        let (clusters, stats) = cluster_with_stats(&tree, &threads);
        let exhausted = leaves < want || leaves <= last_leaves;
        let last_round = exhausted || round == MAX_ROUNDS;
        last_leaves = leaves;
        let labelled =
            label(path, &declared, &tree, origin, &clusters.leaves, &threads, &mut progress.stage(0.55, 0.95))?;
        let (representatives, stats) = centred(&tree, &clusters.leaves, stats, &labelled.vertex_sums);
        let clustered = Mesh::new(representatives.clone(), None, labelled.triangles);
        let identity: Vec<u32> = (0..representatives.len() as u32).collect();
        let (out, out_clusters) = collapse(&clustered, &identity, &representatives, &threads)?;
        if out.triangles.len() >= target || last_round {
            break (out, out_clusters, stats);
        }
        want = clusters_for(target, Some((leaves, out.triangles.len())), 1.0);
        round += 1;
    };
    progress.report(0.95, "collapsing edges to the size")?;
    let mut out = out;
    out.origin = origin;
    let quadrics = out_clusters.iter().map(|&c| stats[c as usize]).collect();
    let out = collapse_to_target(out, quadrics, &tree, target, &threads, &mut progress.stage(0.95, 1.0))?;
    progress.report(1.0, "done")?;
    let stats = SimplifyStats {
        tree: tree.stats(),
        input_vertices: declared.vertices,
        input_triangles,
        output_vertices: out.positions.len(),
        output_triangles: out.triangles.len(),
        seconds_samples: (t1 - t0).as_secs_f64(),
        seconds_tree: (t2 - t1).as_secs_f64(),
        seconds_cluster: t2.elapsed().as_secs_f64(),
        kept_topology: false,
    };
    Ok((out, stats))
}

/// Refuses what a stream cannot do, before the file is read.
fn refuse(path: &Path, params: &SimplifyParams) -> Result<()> {
    if Format::from_path(path) != Some(Format::Ply) {
        return Err(Error::input(format!(
            "{}: only PLY files are streamed; convert it, or simplify it in memory",
            path.display()
        )));
    }
    if params.target_faces == 0 {
        return Err(Error::param(
            "target_faces",
            "0: a streamed simplification needs a target size (the error bound is not used)",
        ));
    }
    if params.keep_topology == KeepTopology::On {
        return Err(Error::param(
            "keep_topology",
            "on: keeping the topology needs the whole mesh in memory; a streamed simplification clusters plainly",
        ));
    }
    Ok(())
}

/// Reports `done` of `total` items every [`BATCH`] items, as a stage's fraction.
fn report(progress: &mut Progress, done: usize, total: usize, stage: &str) -> Result<(), Fail> {
    if done % BATCH != 0 {
        return Ok(());
    }
    progress.report(done as f32 / total.max(1) as f32, stage).map_err(Fail::Stop)
}

/// The error for an allocation of `bytes` for `what` that the system refused.
fn out_of_memory(what: &str, bytes: usize) -> Error {
    Error::TooLarge(format!("not enough memory for {what} ({} MB)", bytes.div_ceil(1 << 20)))
}

/// Vertex indices as a set of bits.
struct BitSet(Vec<u64>);

impl BitSet {
    fn new(n: usize) -> Result<BitSet> {
        let mut words = Vec::new();
        words.try_reserve_exact(n.div_ceil(64)).map_err(|_| out_of_memory("a bit per vertex", n / 8))?;
        words.resize(n.div_ceil(64), 0);
        Ok(BitSet(words))
    }

    fn insert(&mut self, i: u32) {
        self.0[i as usize / 64] |= 1 << (i % 64);
    }

    fn contains(&self, i: usize) -> bool {
        self.0[i / 64] >> (i % 64) & 1 == 1
    }

    /// How many members are below each word's first index, to find a member's rank.
    fn ranks(&self) -> Vec<u32> {
        let mut before = 0;
        self.0
            .iter()
            .map(|w| {
                let r = before;
                before += w.count_ones();
                r
            })
            .collect()
    }

    /// The rank of member `i` among the members, given [`BitSet::ranks`].
    fn rank(&self, ranks: &[u32], i: u32) -> usize {
        let word = self.0[i as usize / 64] & ((1u64 << (i % 64)) - 1);
        ranks[i as usize / 64] as usize + word.count_ones() as usize
    }
}

/// Pass 1: the chosen triangles' vertices, and the vertices they use.
struct Chosen {
    triangles_kept: Vec<[u32; 3]>,
    needed: BitSet,
    /// Triangles in the file (its polygons fan-triangulated).
    triangles: usize,
}

struct ChooseTriangles<'p, 'q> {
    chosen: Chosen,
    /// A triangle is chosen when its hash is below this.
    threshold: u64,
    /// The current polygon's triangles (kept to reuse its room).
    fan: Vec<[u32; 3]>,
    polygons: usize,
    total: usize,
    progress: &'p mut Progress<'q>,
}

impl Sink for ChooseTriangles<'_, '_> {
    fn wants_vertices(&self) -> bool {
        false
    }

    fn polygon(&mut self, polygon: &[u32]) -> Result<(), Fail> {
        self.fan.clear();
        assemble::push_fan(polygon, &mut self.fan).map_err(Fail::Bad)?;
        for &tri in &self.fan {
            if rng::stream_seed(SAMPLE_SEED, self.chosen.triangles as u64) < self.threshold {
                tri.iter().for_each(|&v| self.chosen.needed.insert(v));
                self.chosen.triangles_kept.push(tri);
            }
            self.chosen.triangles += 1;
        }
        self.polygons += 1;
        report(self.progress, self.polygons, self.total, "reading the faces")
    }

    fn vertex(&mut self, _: [f64; 6]) -> Result<(), Fail> {
        Ok(())
    }
}

fn choose_triangles(path: &Path, declared: &Declared, budget: usize, progress: &mut Progress) -> Result<Chosen> {
    let share = (budget as f64 / declared.faces as f64).min(1.0);
    let mut sink = ChooseTriangles {
        chosen: Chosen { triangles_kept: Vec::new(), needed: BitSet::new(declared.vertices)?, triangles: 0 },
        threshold: (share * u64::MAX as f64) as u64,
        fan: Vec::new(),
        polygons: 0,
        total: declared.faces,
        progress,
    };
    sink.progress.report(0.0, "reading the faces")?;
    ply::stream(path, &mut sink)?;
    Ok(sink.chosen)
}

/// Pass 2: the box of all vertices, and the positions of those the chosen triangles use, in
/// vertex order.
struct Gathered {
    positions: Vec<DVec3>,
    /// The origin the output is stored relative to, as if the whole mesh were read.
    origin: DVec3,
}

impl Gathered {
    /// The chosen triangles' centres and normals (degenerate ones give none).
    fn samples(&self, triangles: &[[u32; 3]], needed: &BitSet) -> SampleSet {
        let ranks = needed.ranks();
        let mut samples = SampleSet::default();
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| (self.positions[needed.rank(&ranks, v)] - self.origin).as_vec3());
            let n = (b - a).cross(c - a);
            if n.length_squared() > 0.0 {
                samples.positions.push((a + b + c) / 3.0);
                samples.normals.push(n.normalize());
                samples.origin.push(t as u32);
            }
        }
        samples
    }
}

struct GatherVertices<'a, 'p, 'q> {
    needed: &'a BitSet,
    positions: Vec<DVec3>,
    min: DVec3,
    max: DVec3,
    count: usize,
    total: usize,
    progress: &'p mut Progress<'q>,
}

impl Sink for GatherVertices<'_, '_, '_> {
    fn wants_faces(&self) -> bool {
        false
    }

    fn vertex(&mut self, c: [f64; 6]) -> Result<(), Fail> {
        let p = ply::position(c)?;
        self.min = self.min.min(p);
        self.max = self.max.max(p);
        if self.needed.contains(self.count) {
            self.positions.push(p);
        }
        self.count += 1;
        report(self.progress, self.count, self.total, "reading the vertices")
    }

    fn polygon(&mut self, _: &[u32]) -> Result<(), Fail> {
        Ok(())
    }
}

fn gather_vertices(path: &Path, declared: &Declared, chosen: &Chosen, progress: &mut Progress) -> Result<Gathered> {
    let needed = chosen.needed.0.iter().map(|w| w.count_ones() as usize).sum();
    let mut positions = Vec::new();
    positions.try_reserve_exact(needed).map_err(|_| out_of_memory("the sampled triangles' vertices", 24 * needed))?;
    let mut sink = GatherVertices {
        needed: &chosen.needed,
        positions,
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
        count: 0,
        total: declared.vertices,
        progress,
    };
    sink.progress.report(0.0, "reading the vertices")?;
    ply::stream(path, &mut sink)?;
    let origin = if sink.count == 0 { DVec3::ZERO } else { assemble::origin_for_box(sink.min, sink.max) };
    Ok(Gathered { positions: sink.positions, origin })
}

/// The clusters' sums with the centroid of their vertices in place of their samples' (positions
/// relative to the tree's root centre), and their representatives from those: the sampled
/// triangles' planes still place each point, and along the directions they leave free (few
/// samples pin few) it falls at the mean of every vertex the cluster took, not of a handful
/// of samples.
fn centred(
    tree: &VsTree,
    leaves: &[u32],
    mut stats: Vec<CellStats>,
    vertex_sums: &[(DVec3, u32)],
) -> (Vec<Vec3>, Vec<CellStats>) {
    let origin = tree.root().center.as_dvec3();
    let representatives = leaves
        .iter()
        .zip(&mut stats)
        .zip(vertex_sums)
        .map(|((&leaf, s), &(sum, count))| {
            if count > 0 && s.count > 0 {
                s.sum_p = sum / f64::from(count) * s.count as f64;
            }
            let node = &tree.nodes[leaf as usize];
            let frame = (node.kind == NodeKind::Surface).then(|| &tree.frames[node.frame as usize]);
            tree::representative(node, frame, s, origin).as_vec3()
        })
        .collect();
    (representatives, stats)
}

/// What pass 3 gives: the triangles of clusters, and each cluster's sum of vertex positions
/// (relative to the tree's root centre) and vertex count.
struct Labelled {
    triangles: Vec<[u32; 3]>,
    vertex_sums: Vec<(DVec3, u32)>,
}

/// Pass 3: the cluster of every vertex, and the triangles of clusters.
struct Label<'a, 'p, 'q> {
    tree: &'a VsTree,
    origin: DVec3,
    threads: &'a Threads,
    labels: Vec<u32>,
    nearest: KdTree,
    /// The cluster of each of the tree's samples, in tree order.
    sample_cluster: Vec<u32>,
    vertex_sums: Vec<(DVec3, u32)>,
    pending_vertices: Vec<Vec3>,
    pending_triangles: Vec<[u32; 3]>,
    seen: HashSet<[u32; 3]>,
    triangles: Vec<[u32; 3]>,
    done: usize,
    total: usize,
    progress: &'p mut Progress<'q>,
}

impl Label<'_, '_, '_> {
    /// Labels the pending vertices in parallel, each with the cluster of the sample nearest it.
    fn flush_vertices(&mut self) {
        let (nearest, sample_cluster) = (&self.nearest, &self.sample_cluster);
        let pending = &self.pending_vertices;
        let labels: Vec<u32> = self.threads.run(|| {
            pending.par_iter().map(|&p| nearest.nearest(p).map_or(0, |(_, j)| sample_cluster[j as usize])).collect()
        });
        let centre = self.tree.root().center.as_dvec3();
        for (&p, &label) in pending.iter().zip(&labels) {
            let (sum, count) = &mut self.vertex_sums[label as usize];
            *sum += p.as_dvec3() - centre;
            *count += 1;
        }
        self.labels.extend(labels);
        self.pending_vertices.clear();
    }

    /// Resolves the pending triangles to clusters in parallel, then keeps, in file order, the
    /// first of each triangle of three distinct clusters.
    fn flush_triangles(&mut self) {
        let labels = &self.labels;
        let pending = &self.pending_triangles;
        let resolved: Vec<[u32; 3]> = self.threads.run(|| {
            pending
                .par_iter()
                .filter_map(|t| {
                    let m = t.map(|v| labels[v as usize]);
                    (m[0] != m[1] && m[1] != m[2] && m[0] != m[2]).then_some(m)
                })
                .collect()
        });
        for m in resolved {
            let mut key = m;
            key.sort_unstable();
            if self.seen.insert(key) {
                self.triangles.push(m);
            }
        }
        self.pending_triangles.clear();
    }
}

impl Sink for Label<'_, '_, '_> {
    fn reserve_vertices(&mut self, n: usize) -> Result<(), Fail> {
        self.labels.try_reserve_exact(n).map_err(|_| Fail::Stop(out_of_memory("the cluster of every vertex", 4 * n)))
    }

    fn vertex(&mut self, c: [f64; 6]) -> Result<(), Fail> {
        self.pending_vertices.push((ply::position(c)? - self.origin).as_vec3());
        if self.pending_vertices.len() == BATCH {
            self.flush_vertices();
        }
        self.done += 1;
        report(self.progress, self.done, self.total, "clustering")
    }

    fn polygon(&mut self, polygon: &[u32]) -> Result<(), Fail> {
        if !self.pending_vertices.is_empty() {
            self.flush_vertices();
        }
        assemble::push_fan(polygon, &mut self.pending_triangles).map_err(Fail::Bad)?;
        if self.pending_triangles.len() >= BATCH {
            self.flush_triangles();
        }
        self.done += 1;
        report(self.progress, self.done, self.total, "clustering")
    }
}

/// The triangles of clusters: each vertex in the cluster of the sample nearest it (positions
/// relative to `origin`, the tree's frame), each triangle of three distinct clusters once.
fn label(
    path: &Path,
    declared: &Declared,
    tree: &VsTree,
    origin: DVec3,
    leaves: &[u32],
    threads: &Threads,
    progress: &mut Progress,
) -> Result<Labelled> {
    let positions: Vec<Vec3> = tree.samples.iter().map(|s| s.position).collect();
    let nearest = threads.run(|| KdTree::new(&positions))?;
    let mut sample_cluster = vec![0; tree.samples.len()];
    for (k, &leaf) in leaves.iter().enumerate() {
        sample_cluster[tree.nodes[leaf as usize].range()].fill(k as u32);
    }
    let mut sink = Label {
        tree,
        nearest,
        sample_cluster,
        origin,
        threads,
        labels: Vec::new(),
        vertex_sums: vec![(DVec3::ZERO, 0); leaves.len()],
        pending_vertices: Vec::with_capacity(BATCH),
        pending_triangles: Vec::with_capacity(BATCH + 64),
        seen: HashSet::new(),
        triangles: Vec::new(),
        done: 0,
        total: declared.vertices + declared.faces,
        progress,
    };
    sink.progress.report(0.0, "clustering")?;
    ply::stream(path, &mut sink)?;
    if !sink.pending_vertices.is_empty() {
        sink.flush_vertices();
    }
    sink.flush_triangles();
    Ok(Labelled { triangles: sink.triangles, vertex_sums: sink.vertex_sums })
}
