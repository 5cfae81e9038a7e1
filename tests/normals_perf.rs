//! Timings at scale for the k-d tree and normal estimation, on 1M and 5M points sampled on a
//! bumpy sphere. Ignored by default; run with
//! `cargo test --release --test normals_perf -- --ignored --nocapture --test-threads 1`.

use glam::Vec3;
use std::time::Instant;
use vstree::eval::shapes::{bumpy_sphere, sample_surface};
use vstree::normals::{estimate_normals, NormalParams};
use vstree::spatial::KdTree;
use vstree::{Progress, Threads};

const SIZES: [usize; 2] = [1_000_000, 5_000_000];

fn cloud(n: usize) -> Vec<Vec3> {
    sample_surface(&bumpy_sphere(1.0, 0.2, 6.0, 6), n, 7).positions
}

#[test]
#[ignore]
fn knn_timing_1m_5m() {
    for n in SIZES {
        let points = cloud(n);
        for threads in [1, 2] {
            let pool = Threads::new(threads).unwrap();
            let t0 = Instant::now();
            let tree = pool.run(|| KdTree::new(&points).unwrap());
            let t1 = Instant::now();
            let all = pool.run(|| tree.knn_all(10).unwrap());
            let t2 = Instant::now();
            assert_eq!(all.len(), n * 10);
            println!(
                "knn n={n} k=10 threads={threads}: build {:.3} s + queries {:.3} s = {:.3} s",
                (t1 - t0).as_secs_f64(),
                (t2 - t1).as_secs_f64(),
                (t2 - t0).as_secs_f64()
            );
        }
    }
}

#[test]
#[ignore]
fn normals_timing_1m_5m() {
    for n in SIZES {
        let points = cloud(n);
        for threads in [1, 2] {
            // When each stage started, as the progress callback sees it.
            let mut starts: Vec<(String, Instant)> = Vec::new();
            let mut record = |_: f32, stage: &str| {
                if starts.last().is_none_or(|(name, _)| name != stage) {
                    starts.push((stage.to_string(), Instant::now()));
                }
                true
            };
            let params = NormalParams { threads, ..Default::default() };
            let t0 = Instant::now();
            let normals = estimate_normals(&points, &params, &mut Progress::new(&mut record)).unwrap();
            let total = t0.elapsed().as_secs_f64();
            let outward = points.iter().zip(&normals).filter(|(p, n)| p.dot(**n) > 0.0).count();
            println!(
                "normals n={n} k={} threads={threads}: {total:.3} s, {:.3}% outward",
                params.neighbours,
                100.0 * outward as f64 / n as f64
            );
            for pair in starts.windows(2) {
                let secs = (pair[1].1 - pair[0].1).as_secs_f64();
                println!("    {:<28} {secs:.3} s", pair[0].0);
            }
        }
    }
}
