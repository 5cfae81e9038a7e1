//! The tree's invariants and figures, on the real models and on generated shapes.

mod common;

use vstree::eval::shapes;
use vstree::tree::{self, Metric, NodeKind, TreeKind, TreeParams};
use vstree::{MeshSampling, Progress, SampleSet, Threads};

fn build(samples: &SampleSet, params: &TreeParams, threads: usize) -> vstree::VsTree {
    let threads = Threads::new(threads).unwrap();
    tree::build(samples, params, &threads, &mut Progress::none()).unwrap()
}

fn params(kind: TreeKind, error: f64) -> TreeParams {
    TreeParams { kind, error, ..TreeParams::default() }
}

#[test]
fn invariants_hold_on_every_real_model() {
    for (name, mesh) in common::all_models() {
        let samples = common::samples_of(&mesh);
        for kind in [TreeKind::VsTree, TreeKind::Octree] {
            for error in [1e-4, 2e-3] {
                let t = build(&samples, &params(kind, error), 0);
                t.validate().unwrap_or_else(|e| panic!("{name} {kind:?} {error}: {e}"));
                let s = t.stats();
                assert_eq!(s.samples, samples.len());
                assert!(s.leaves >= 1 && s.leaves <= samples.len(), "{name}: {} leaves", s.leaves);
                if kind == TreeKind::Octree {
                    assert_eq!(s.t_nodes + s.s_nodes, 0, "{name}: the octree has T/S nodes");
                } else {
                    assert!(s.t_nodes > 0, "{name}: no T-node at all");
                }
            }
        }
    }
}

#[test]
fn invariants_hold_on_generated_shapes_with_every_metric() {
    let shapes = [shapes::icosphere(1.0, 5), shapes::torus(1.0, 0.3, 96, 48), shapes::double_torus()];
    for mesh in &shapes {
        let samples = SampleSet::from_mesh(mesh, MeshSampling::Vertices).unwrap();
        for (metric, error) in [(Metric::L2, 1e-5), (Metric::L21, 0.01), (Metric::Density, 16.0)] {
            for kind in [TreeKind::VsTree, TreeKind::Octree] {
                let p = TreeParams { kind, metric, error, ..TreeParams::default() };
                let t = build(&samples, &p, 0);
                t.validate().unwrap();
                if metric == Metric::Density {
                    assert!(t.leaves().all(|l| t.nodes[l].count <= 16));
                }
            }
        }
    }
}

#[test]
fn same_tree_with_one_or_two_threads() {
    // Large enough for both the parallel partition and the parallel subtree phase.
    let cloud = shapes::sample_surface(&shapes::torus(1.0, 0.35, 64, 32), 400_000, 7);
    let samples = SampleSet::from_cloud(&cloud).unwrap();
    for kind in [TreeKind::VsTree, TreeKind::Octree] {
        let a = build(&samples, &params(kind, 1e-5), 1);
        let b = build(&samples, &params(kind, 1e-5), 2);
        assert!(a.nodes == b.nodes && a.frames == b.frames && a.samples == b.samples, "{kind:?}: trees differ");
        a.validate().unwrap();
    }
}

/// Points exactly on the unit sphere with their exact normals.
fn unit_sphere_samples(count: usize) -> SampleSet {
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 5), count, 3);
    let positions: Vec<glam::Vec3> = cloud.positions.iter().map(|p| p.normalize()).collect();
    SampleSet { normals: positions.clone(), origin: (0..count as u32).collect(), positions }
}

#[test]
fn a_sphere_switches_to_quadtrees_early_and_needs_fewer_clusters() {
    let samples = unit_sphere_samples(200_000);
    // Bounds well below the T-layer's own error, where the quadtrees do the work. (Near the
    // T-layer both trees stop at similar power-of-two levels and the counts can tie.)
    for error in [3e-6, 1e-5] {
        let vs = build(&samples, &params(TreeKind::VsTree, error), 0).stats();
        let oct = build(&samples, &params(TreeKind::Octree, error), 0).stats();
        eprintln!(
            "sphere {error}: VS-Tree {} clusters (T-layer {}..{}), octree {}",
            vs.leaves, vs.t_depth_min, vs.t_depth_max, oct.leaves
        );
        // Every octant-sized patch of a sphere is a height field: the T-layer sits at depth 2.
        assert_eq!((vs.t_depth_min, vs.t_depth_max), (2, 2));
        assert!(vs.s_nodes > vs.t_nodes);
        assert!(
            (vs.leaves as f64) < 0.8 * oct.leaves as f64,
            "VS-Tree {} vs octree {} clusters",
            vs.leaves,
            oct.leaves
        );
        // More even clusters: a smaller spread of samples per cluster relative to the mean.
        let spread = |s: &vstree::tree::TreeStats| s.leaf_size_variance / s.leaf_size_mean.powi(2);
        eprintln!("  spread: VS-Tree {:.3}, octree {:.3}", spread(&vs), spread(&oct));
        assert!(spread(&vs) < spread(&oct), "clusters are not more even");
    }
}

#[test]
fn fewer_clusters_than_the_octree_on_real_scans() {
    for name in ["bunny_zipper.ply", "igea.ply", "armadillo_43k.obj"] {
        let Some(mesh) = common::load(name) else {
            continue;
        };
        let samples = common::samples_of(&mesh);
        for error in [1e-4, 2e-3] {
            let vs = build(&samples, &params(TreeKind::VsTree, error), 0).stats().leaves;
            let oct = build(&samples, &params(TreeKind::Octree, error), 0).stats().leaves;
            eprintln!("{name} {error}: VS-Tree {vs}, octree {oct} clusters");
            assert!(vs < oct, "{name} at {error}: VS-Tree {vs} >= octree {oct}");
        }
    }
}

#[test]
fn graceful_degradation_to_an_octree() {
    // With d_d = 0 the height-field indicator only holds for cells whose samples coincide, so
    // the VS-Tree has exactly the octree's cells; such single-point cells may be T-leaves.
    let samples = SampleSet::from_mesh(&shapes::torus(1.0, 0.3, 64, 32), MeshSampling::Vertices).unwrap();
    let strict = TreeParams { d_d: 0.0, ..params(TreeKind::VsTree, 1e-4) };
    let a = build(&samples, &strict, 0);
    let b = build(&samples, &params(TreeKind::Octree, 1e-4), 0);
    let cells = |t: &vstree::VsTree| {
        t.nodes.iter().map(|n| (n.start, n.count, n.center, n.half, n.first_child, n.child_count)).collect::<Vec<_>>()
    };
    assert!(cells(&a) == cells(&b), "the VS-Tree's cells differ from the octree's");
    for n in a.nodes.iter().filter(|n| n.kind != NodeKind::Volume) {
        let pts = a.samples_of(n);
        assert!(n.kind == NodeKind::Transition && n.is_leaf() && pts.iter().all(|s| s.position == pts[0].position));
    }
}

/// Mean depth of the T-nodes, weighted by their samples.
fn mean_t_depth(t: &vstree::VsTree) -> f64 {
    let (sum, count) = t
        .nodes
        .iter()
        .filter(|n| n.kind == NodeKind::Transition)
        .fold((0.0, 0.0), |(s, c), n| (s + f64::from(n.depth) * f64::from(n.count), c + f64::from(n.count)));
    sum / count
}

#[test]
fn a_stricter_indicator_pushes_the_t_layer_deeper() {
    let samples = SampleSet::from_mesh(&shapes::bumpy_sphere(1.0, 0.15, 6.0, 6), MeshSampling::Vertices).unwrap();
    let loose = build(&samples, &params(TreeKind::VsTree, 1e-5), 0);
    let strict = TreeParams { d_a: 0.8, d_d: 0.05, ..params(TreeKind::VsTree, 1e-5) };
    let strict = build(&samples, &strict, 0);
    let (l, s) = (loose.stats(), strict.stats());
    eprintln!(
        "T-nodes {} -> {}, mean T depth {:.2} -> {:.2}",
        l.t_nodes,
        s.t_nodes,
        mean_t_depth(&loose),
        mean_t_depth(&strict)
    );
    assert!(mean_t_depth(&strict) > mean_t_depth(&loose) + 0.5);
    assert!(s.t_nodes > l.t_nodes);
}

#[test]
fn locate_finds_the_leaf_of_every_sample() {
    let samples = SampleSet::from_mesh(&shapes::torus(1.0, 0.3, 64, 32), MeshSampling::Vertices).unwrap();
    let t = build(&samples, &params(TreeKind::VsTree, 1e-5), 0);
    for leaf in t.leaves() {
        for s in t.samples_of(&t.nodes[leaf]) {
            assert_eq!(t.locate(s.position), Some(leaf));
        }
    }
    assert_eq!(t.locate(glam::Vec3::splat(100.0)), None);
}

/// A valid tree to break, with a T-layer and quadtrees below it.
fn sphere_tree() -> vstree::VsTree {
    let t = build(&unit_sphere_samples(20_000), &params(TreeKind::VsTree, 1e-5), 0);
    t.validate().unwrap();
    assert!(t.stats().s_nodes > 0);
    t
}

/// Breaks a copy of a valid tree with `corrupt` and checks that `validate` names the fault.
fn fails_with(corrupt: impl Fn(&mut vstree::VsTree), expected: &str) {
    let mut t = sphere_tree();
    corrupt(&mut t);
    let e = t.validate().expect_err("a broken tree passed validate()");
    assert!(e.contains(expected), "expected {expected:?} in {e:?}");
}

#[test]
fn validate_finds_every_kind_of_fault() {
    let first_leaf = |t: &vstree::VsTree| t.leaves().next().unwrap();
    let first_of = |t: &vstree::VsTree, kind| t.nodes.iter().position(|n| n.kind == kind && !n.is_leaf()).unwrap();
    // A sample listed twice (and another missing).
    fails_with(|t| t.samples[1].index = t.samples[0].index, "repeated");
    // A sample moved out of its leaf's cell.
    fails_with(
        |t| {
            let leaf = first_leaf(t);
            let start = t.nodes[leaf].start as usize;
            t.samples[start].position += glam::Vec3::splat(0.5);
        },
        "outside",
    );
    // A frame that is not orthonormal.
    fails_with(|t| t.frames[0].u *= 2.0, "not orthonormal");
    // A volume cell below a T-node (the 3D/2D boundary crossed twice).
    fails_with(
        |t| {
            let c = t.nodes[first_of(t, NodeKind::Transition)].first_child as usize;
            t.nodes[c].kind = NodeKind::Volume;
            t.nodes[c].frame = vstree::tree::NO_FRAME;
        },
        "Volume child",
    );
    // A child cell larger than its parent.
    fails_with(
        |t| {
            let c = t.nodes[first_of(t, NodeKind::Volume)].first_child as usize;
            t.nodes[c].half *= 4.0;
        },
        "sub-cell",
    );
    // Children whose sample ranges do not tile their parent's.
    fails_with(
        |t| {
            let c = t.nodes[first_of(t, NodeKind::Surface)].first_child as usize;
            t.nodes[c].count -= 1;
        },
        "start",
    );
}

#[test]
fn the_tree_does_not_depend_on_units() {
    // Bounds are relative to the diagonal, so the same shape in metres or micrometres, here or
    // far from the origin, gives the same clusters (up to the rounding of 32-bit coordinates).
    let base = unit_sphere_samples(50_000);
    let counts: Vec<(f32, usize)> = [1e-9f32, 1e-3, 1.0, 1e4, 1e9]
        .iter()
        .map(|&scale| {
            let mut s = base.clone();
            for p in &mut s.positions {
                *p = *p * scale + glam::Vec3::new(3.0, -2.0, 1.0) * scale;
            }
            let t = build(&s, &params(TreeKind::VsTree, 1e-5), 0);
            t.validate().unwrap();
            (scale, t.stats().leaves)
        })
        .collect();
    let unit = counts[2].1 as f64;
    for (scale, leaves) in &counts {
        assert!((*leaves as f64 / unit - 1.0).abs() < 0.01, "scale {scale}: {leaves} clusters, {unit} at scale 1");
    }
}
