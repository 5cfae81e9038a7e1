use super::*;
use crate::rng::Rng;

/// Brute force with the module's distance and tie order.
fn oracle(points: &[Vec3], q: Vec3, k: usize, skip: Option<usize>) -> Vec<(f32, u32)> {
    let mut all: Vec<(f32, u32)> = points
        .iter()
        .enumerate()
        .filter(|&(i, _)| Some(i) != skip)
        .map(|(i, p)| (dist2(q.to_array(), p.to_array()), i as u32))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    all.truncate(k);
    all
}

fn random_points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng::new(seed);
    (0..n).map(|_| Vec3::new(rng.f32(), rng.f32(), rng.f32() * 0.1)).collect()
}

/// Integer grid points with duplicates: many exact distance ties.
fn tied_points() -> Vec<Vec3> {
    let mut points = Vec::new();
    for i in 0..600u32 {
        let v = (i * 7919) % 343;
        points.push(Vec3::new((v % 7) as f32, ((v / 7) % 7) as f32, (v / 49) as f32));
    }
    points
}

#[test]
fn knn_matches_brute_force() {
    for points in [random_points(3000, 1), tied_points()] {
        let tree = KdTree::new(&points).unwrap();
        let mut rng = Rng::new(9);
        for _ in 0..200 {
            let q = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 8.0 - 1.0;
            for k in [1, 5, 17, 33, 100, 450] {
                let got: Vec<(f32, u32)> = tree.knn(q, k).iter().map(|n| (n.distance_squared, n.index)).collect();
                assert_eq!(got, oracle(&points, q, k, None), "q {q} k {k}");
            }
        }
    }
}

#[test]
fn knn_all_matches_brute_force_and_skips_only_self() {
    for (points, k) in [(random_points(2000, 2), 10), (tied_points(), 10), (random_points(2000, 3), 64)] {
        let all = knn_all(&points, k).unwrap();
        assert_eq!(all.len(), points.len() * k);
        for (i, row) in all.chunks(k).enumerate() {
            let want: Vec<u32> = oracle(&points, points[i], k, Some(i)).iter().map(|x| x.1).collect();
            assert_eq!(row, &want[..], "point {i}");
        }
    }
}

/// Brute force for the single-nearest queries: (distance, index) of the nearest kept point.
fn nearest_oracle(points: &[Vec3], q: Vec3, keep: impl Fn(u32) -> bool) -> Option<(f32, u32)> {
    oracle(points, q, points.len(), None).into_iter().find(|&(_, i)| keep(i)).map(|(d2, i)| (d2.sqrt(), i))
}

#[test]
fn nearest_queries_match_brute_force() {
    for points in [random_points(3000, 4), tied_points()] {
        let tree = KdTree::new(&points).unwrap();
        tree.validate().unwrap();
        let mut rng = Rng::new(10);
        for _ in 0..300 {
            let q = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 8.0 - 1.0;
            let want = nearest_oracle(&points, q, |_| true);
            assert_eq!(tree.nearest(q), want, "q {q}");
            assert_eq!(tree.distance(q), want.unwrap().0);
            let odd = |i: u32| i % 2 == 1;
            assert_eq!(tree.nearest_among(q, odd), nearest_oracle(&points, q, odd), "q {q}");
            let d_odd = nearest_oracle(&points, q, odd).unwrap().0;
            for r in [0.01, 0.3, want.unwrap().0, d_odd, 2.0] {
                let d = want.unwrap().0;
                assert_eq!(tree.any_within(q, r), d <= r, "q {q} r {r}");
                assert_eq!(tree.any_within_among(q, r, odd), d_odd <= r, "q {q} r {r}");
                assert_eq!(tree.distance_within(q, r), if d <= r { d } else { f32::INFINITY }, "q {q} r {r}");
            }
        }
    }
}

#[test]
fn validate_names_each_broken_rule() {
    let points = random_points(500, 5);
    let good = KdTree::new(&points).unwrap();
    good.validate().unwrap();
    let broken = |change: &dyn Fn(&mut KdTree)| {
        let mut tree = good.clone();
        change(&mut tree);
        tree.validate().unwrap_err()
    };
    assert!(broken(&|t| t.entries[1].id = t.entries[0].id).contains("permutation"));
    assert!(broken(&|t| {
        t.splits.pop();
    })
    .contains("splits"));
    assert!(broken(&|t| t.entries.swap(0, 499)).contains("wrong side"));
}

#[test]
fn same_answer_for_any_thread_count() {
    let points = random_points(50_000, 3);
    let run = |threads: usize| crate::Threads::new(threads).unwrap().run(|| knn_all(&points, 8).unwrap());
    assert_eq!(run(1), run(2));
    assert_eq!(run(1), run(3));
}

#[test]
fn small_and_bad_inputs() {
    let empty = KdTree::new(&[]).unwrap();
    assert!(empty.knn(Vec3::ZERO, 3).is_empty());
    assert_eq!((empty.nearest(Vec3::ZERO), empty.distance(Vec3::ZERO)), (None, f32::INFINITY));
    assert!(!empty.any_within(Vec3::ZERO, 1.0));
    empty.validate().unwrap();
    let one = KdTree::new(&[Vec3::ONE]).unwrap();
    assert_eq!(one.knn(Vec3::ZERO, 3).len(), 1);
    assert!(one.knn(Vec3::NAN, 1).is_empty());
    assert!(one.distance(Vec3::NAN).is_nan() && one.distance_within(Vec3::NAN, 1.0).is_nan());
    assert_eq!(one.nearest(Vec3::INFINITY), None);
    assert!(one.knn_all(1).is_err());
    let same = vec![Vec3::splat(2.0); 20];
    let all = knn_all(&same, 3).unwrap();
    assert_eq!(&all[..3], &[1, 2, 3]);
    assert_eq!(&all[3..6], &[0, 2, 3]);
    let err = KdTree::new(&[Vec3::ZERO, Vec3::new(0.0, f32::INFINITY, 0.0)]).unwrap_err();
    assert!(err.to_string().contains("point 1"), "{err}");
    assert!(knn_all(&same, 0).is_err());
}
