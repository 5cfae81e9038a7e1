use super::*;
use crate::topology::analyze;

#[test]
fn clusters_asked_for_a_target_and_after_a_short_round() {
    assert_eq!((CLUSTERS_PER_TRIANGLE, CLUSTER_MARGIN, MAX_ROUNDS, CLUSTER_FACTOR), (0.5, 1.05, 4, 4.0));
    // Euler's half, 5% more, times the factor.
    assert_eq!(clusters_for(1000, None, 1.0), 525);
    assert_eq!(clusters_for(1000, None, CLUSTER_FACTOR), 2100);
    // A round that gave 900 triangles from 500 clusters: scaled to 1000, 5% more.
    assert_eq!(clusters_for(1000, Some((500, 900)), CLUSTER_FACTOR), 584);
    // Never fewer than one more cluster, and four times as many after a round with none.
    assert_eq!(clusters_for(1000, Some((500, 5000)), CLUSTER_FACTOR), 501);
    assert_eq!(clusters_for(1000, Some((500, 0)), CLUSTER_FACTOR), 2000);
}

#[test]
fn a_sized_run_does_not_depend_on_the_bound() {
    // A size ignores the bound: any bound, even one out of range, gives the same output,
    // with every metric (the tree starts from the metric's seed).
    assert_eq!(SEED_ERROR, 1e-2);
    let mesh = crate::eval::shapes::torus(1.0, 0.3, 96, 48);
    for metric in [Metric::L2, Metric::L21, Metric::Density] {
        let run = |error| {
            let tree = TreeParams { metric, error, ..TreeParams::default() };
            let params = SimplifyParams { tree, target_faces: 600, ..Default::default() };
            simplify(&mesh, &params, &mut Progress::none()).unwrap().0
        };
        let out = run(1e-1);
        for error in [1e-5, 0.5, 0.0, -1.0, f64::NAN] {
            assert_eq!(run(error), out, "{metric:?} at {error}");
        }
        assert!(out.triangles.len().abs_diff(600) <= 2);
    }
}

#[test]
fn collapses_from_more_clusters_follow_a_torus_closer() {
    // What CLUSTER_FACTOR is for: a torus (36,864 triangles) to 300. Cut into as many
    // clusters as the target's vertices, each cell of the tree gives one point, wherever the
    // halving put the cell; cut into CLUSTER_FACTOR times as many, the quadric collapses
    // that take it to the size choose the vertices to remove by what they cost, and the
    // surface stays closer: mean distance 0.0134 against 0.0222 (0.0161 with twice as
    // many, 0.0143 with eight times).
    let torus = crate::eval::shapes::torus(1.0, 0.3, 192, 96);
    let params = SimplifyParams { target_faces: 300, keep_topology: KeepTopology::On, ..Default::default() };
    let threads = Threads::new(1).unwrap();
    let distance = |factor| {
        let (out, _) = simplify_to_size(
            &torus,
            &params,
            Merge::KeepTopology { edge_manifold: true },
            factor,
            &threads,
            &mut Progress::none(),
        )
        .unwrap();
        assert!(out.triangles.len().abs_diff(300) <= 1);
        assert_eq!(analyze(&out).genus(), Some(1));
        let on_output = crate::eval::shapes::sample_surface(&out, 20_000, 1).positions;
        crate::eval::distance::one_sided(&on_output, crate::eval::distance::Target::Triangles(&torus)).mean
    };
    let (one, more) = (distance(1.0), distance(CLUSTER_FACTOR));
    assert!(more < 0.7 * one, "{more} against {one}");
}

#[test]
fn one_round_suffices_on_closed_shapes() {
    // The margin is meant to make the first round give enough triangles: on these shapes,
    // the clustering of the first round's clusters already has the target's count.
    for (mesh, target) in
        [(crate::eval::shapes::icosphere(1.0, 5), 2000), (crate::eval::shapes::torus(1.0, 0.3, 192, 96), 700)]
    {
        let samples = SampleSet::from_mesh(&mesh, MeshSampling::Vertices).unwrap();
        let threads = Threads::new(1).unwrap();
        let mut tree = tree::build(&samples, &TreeParams::default(), &threads, &mut Progress::none()).unwrap();
        tree::fit(&mut tree, clusters_for(target, None, 1.0), &threads);
        let clusters = cluster(&tree, &threads);
        let labels = vertex_labels(&mesh, &samples, &clusters, MeshSampling::Vertices, &tree);
        let (kept, _) =
            collapse_keeping_topology(&mesh, &labels, &clusters.representatives, true, &Threads::new(0).unwrap());
        let (plain, _) = collapse(&mesh, &labels, &clusters.representatives, &threads).unwrap();
        for out in [kept, plain] {
            let n = out.triangles.len();
            assert!(n >= target && n < target * 11 / 10, "{n} triangles for {target}");
        }
    }
}
