//! Reordering a node's samples by child cell, and summing each child's samples on the way, so
//! every level of the tree costs one counting pass and one moving pass over its samples.

use super::TreeSample;
use crate::progress::Threads;
use crate::quadric::CellStats;
use glam::DVec3;
use rayon::prelude::*;

/// Slices at least this long are partitioned in parallel (when threads are given).
const PARALLEL_MIN: usize = 1 << 18;
/// Chunk size of the parallel partition: fixed, so the result never depends on thread count.
const CHUNK: usize = 1 << 16;

/// Reorders `samples` so that bucket 0 comes first, then bucket 1, ..., and returns the sums of
/// each bucket's samples (positions taken relative to `origin`); `count` is the bucket size.
pub(super) fn partition<const B: usize>(
    samples: &mut [TreeSample],
    key: impl Fn(&TreeSample) -> usize + Sync + Send,
    origin: DVec3,
    threads: Option<&Threads>,
) -> [CellStats; B] {
    match threads {
        Some(t) if samples.len() >= PARALLEL_MIN => t.run(|| partition_parallel(samples, key, origin)),
        _ => partition_in_place(samples, key, origin),
    }
}

/// In place (American flag sort): a counting pass that also sums, then cycles of swaps.
fn partition_in_place<const B: usize>(
    samples: &mut [TreeSample],
    key: impl Fn(&TreeSample) -> usize,
    origin: DVec3,
) -> [CellStats; B] {
    let mut stats = [CellStats::default(); B];
    for s in samples.iter() {
        stats[key(s)].add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
    }
    let mut next = [0usize; B];
    let mut end = [0usize; B];
    let mut offset = 0usize;
    for b in 0..B {
        next[b] = offset;
        offset += stats[b].count as usize;
        end[b] = offset;
    }
    for b in 0..B {
        while next[b] < end[b] {
            let k = key(&samples[next[b]]);
            if k == b {
                next[b] += 1;
            } else {
                samples.swap(next[b], next[k]);
                next[k] += 1;
            }
        }
    }
    stats
}

/// Stable and chunked: each chunk sorts its samples into per-bucket lists (and sums them), then
/// the lists are copied back bucket by bucket, chunk by chunk.
fn partition_parallel<const B: usize>(
    samples: &mut [TreeSample],
    key: impl Fn(&TreeSample) -> usize + Sync + Send,
    origin: DVec3,
) -> [CellStats; B] {
    let chunks: Vec<([CellStats; B], [Vec<TreeSample>; B])> = samples
        .par_chunks(CHUNK)
        .map(|chunk| {
            let keys: Vec<u8> = chunk.iter().map(|s| key(s) as u8).collect();
            let mut counts = [0usize; B];
            for &k in &keys {
                counts[k as usize] += 1;
            }
            let mut lists: [Vec<TreeSample>; B] = std::array::from_fn(|b| Vec::with_capacity(counts[b]));
            let mut stats = [CellStats::default(); B];
            for (s, &k) in chunk.iter().zip(&keys) {
                stats[k as usize].add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
                lists[k as usize].push(*s);
            }
            (stats, lists)
        })
        .collect();
    let mut stats = [CellStats::default(); B];
    for (chunk_stats, _) in &chunks {
        for (total, part) in stats.iter_mut().zip(chunk_stats) {
            total.merge(part);
        }
    }
    let mut rest = samples;
    let mut copies = Vec::with_capacity(B * chunks.len());
    for b in 0..B {
        for (_, lists) in &chunks {
            let (dst, tail) = std::mem::take(&mut rest).split_at_mut(lists[b].len());
            rest = tail;
            copies.push((dst, &lists[b]));
        }
    }
    copies.into_par_iter().for_each(|(dst, src)| dst.copy_from_slice(src));
    stats
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn samples(n: usize) -> Vec<TreeSample> {
        (0..n)
            .map(|i| {
                let x = ((i * 7919) % 1000) as f32 / 1000.0;
                let y = ((i * 104729) % 997) as f32 / 997.0;
                TreeSample { position: Vec3::new(x, y, 0.5), normal: Vec3::Z, index: i as u32 }
            })
            .collect()
    }

    fn key(s: &TreeSample) -> usize {
        (s.position.x >= 0.5) as usize | ((s.position.y >= 0.5) as usize) << 1
    }

    #[test]
    fn both_partitions_group_by_bucket_with_the_same_counts() {
        let n = PARALLEL_MIN + 1234;
        let mut a = samples(n);
        let mut b = a.clone();
        let sa = partition_in_place::<4>(&mut a, key, DVec3::ZERO);
        let sb = partition_parallel::<4>(&mut b, key, DVec3::ZERO);
        for (x, y) in sa.iter().zip(&sb) {
            assert_eq!(x.count, y.count);
            assert!((x.sum_p - y.sum_p).length() < 1e-6 * x.count as f64);
        }
        for v in [&a, &b] {
            let keys: Vec<usize> = v.iter().map(key).collect();
            assert!(keys.windows(2).all(|w| w[0] <= w[1]), "not grouped by bucket");
            let mut idx: Vec<u32> = v.iter().map(|s| s.index).collect();
            idx.sort_unstable();
            assert!(idx.iter().enumerate().all(|(i, &j)| i as u32 == j), "not a permutation");
        }
        assert_eq!(sa.iter().map(|s| s.count).sum::<u64>(), n as u64);
    }
}
