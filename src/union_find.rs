//! Union-find (disjoint sets) over `0..n`, where every element can also carry a sign relative to
//! the others of its set: plain connectivity (mesh components, vertex fans) ignores the signs,
//! normal orientation uses them to make every normal of a set agree.

use std::sync::atomic::{AtomicU32, Ordering};

/// Union-find (union by rank, path compression) where every element also records whether its
/// sign is opposite to its parent's. Parent and sign share one word, so a step up the tree is
/// one memory access; that limits it to fewer than 2^31 elements.
pub(crate) struct UnionFind {
    /// Parent index in the low 31 bits; the top bit set when the sign is opposite to the
    /// parent's (to the root's after compression).
    link: Vec<u32>,
    rank: Vec<u8>,
}

const FLIP: u32 = 1 << 31;

impl UnionFind {
    /// `n` (at most 2^31) single elements, each its own set.
    pub fn new(n: usize) -> UnionFind {
        assert!(n <= FLIP as usize, "{n} elements: union-find holds at most 2^31");
        UnionFind { link: (0..n as u32).collect(), rank: vec![0; n] }
    }

    /// The root of `x`'s set.
    pub fn find(&mut self, x: u32) -> u32 {
        self.find_signed(x).0
    }

    /// The root of `x`'s set and whether `x`'s sign is opposite to the root's.
    pub fn find_signed(&mut self, x: u32) -> (u32, bool) {
        let (mut root, mut parity) = (x, 0);
        loop {
            let link = self.link[root as usize];
            if link & !FLIP == root {
                break;
            }
            parity ^= link & FLIP;
            root = link & !FLIP;
        }
        // Point every node on the path straight at the root, with its sign relative to it.
        let (mut node, mut to_root) = (x, parity);
        while node != root {
            let link = self.link[node as usize];
            self.link[node as usize] = root | to_root;
            to_root ^= link & FLIP;
            node = link & !FLIP;
        }
        (root, parity != 0)
    }

    /// Joins the sets of `a` and `b`; false when they were already joined.
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        self.union_signed(a, b, false)
    }

    /// Joins the sets of `a` and `b` so that their signs differ exactly when `differ`; false
    /// (and no sign changed) when they were already joined. The root of higher rank stays the
    /// root, `a`'s on equal ranks.
    pub fn union_signed(&mut self, a: u32, b: u32, differ: bool) -> bool {
        let (ra, pa) = self.find_signed(a);
        let (rb, pb) = self.find_signed(b);
        if ra == rb {
            return false;
        }
        let (big, small) = if self.rank[ra as usize] >= self.rank[rb as usize] { (ra, rb) } else { (rb, ra) };
        // sign(a) ^ sign(b) = pa ^ pb ^ (sign of small relative to big) must equal `differ`.
        let flip = if pa ^ pb ^ differ { FLIP } else { 0 };
        self.link[small as usize] = big | flip;
        if self.rank[big as usize] == self.rank[small as usize] {
            self.rank[big as usize] += 1;
        }
        true
    }
}

/// Union-find without signs that many threads join into at once (lock-free: a root is linked
/// by compare-and-swap, paths are halved as they are walked). The sets it ends with do not
/// depend on the order of the joins; which element is a set's root does.
pub(crate) struct SharedUnionFind {
    parent: Vec<AtomicU32>,
}

impl SharedUnionFind {
    /// `n` (below 2^32) single elements.
    pub fn new(n: usize) -> SharedUnionFind {
        assert!(n <= u32::MAX as usize, "{n} elements: union-find holds fewer than 2^32");
        SharedUnionFind { parent: (0..n as u32).map(AtomicU32::new).collect() }
    }

    /// The current root of `x`'s set.
    pub fn find(&self, mut x: u32) -> u32 {
        loop {
            let parent = self.parent[x as usize].load(Ordering::Relaxed);
            if parent == x {
                return x;
            }
            let grandparent = self.parent[parent as usize].load(Ordering::Relaxed);
            if grandparent != parent {
                // Halving: a failed swap only means another thread moved x's link on first.
                let _ =
                    self.parent[x as usize].compare_exchange(parent, grandparent, Ordering::Relaxed, Ordering::Relaxed);
            }
            x = parent;
        }
    }

    /// Joins the sets of `a` and `b` (the larger root index is linked under the smaller).
    pub fn union(&self, a: u32, b: u32) {
        let (mut a, mut b) = (a, b);
        loop {
            (a, b) = (self.find(a), self.find(b));
            if a == b {
                return;
            }
            let (low, high) = (a.min(b), a.max(b));
            if self.parent[high as usize].compare_exchange(high, low, Ordering::Relaxed, Ordering::Relaxed).is_ok() {
                return;
            }
        }
    }

    /// Whether `x` is the root of its set (once the joins are over, one element per set is).
    pub fn is_root(&self, x: u32) -> bool {
        self.parent[x as usize].load(Ordering::Relaxed) == x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn signs_are_tracked_relative_to_the_set() {
        let mut sets = UnionFind::new(6);
        assert!(sets.union_signed(0, 1, true));
        assert!(sets.union_signed(2, 3, false));
        assert!(sets.union_signed(1, 2, true));
        assert!(sets.union_signed(4, 3, true));
        assert!(!sets.union_signed(0, 3, false));
        // Signs relative to element 0: 1 flipped, 2 = 1 flipped again, 3 = 2, 4 opposite to 3.
        let sign = |s: &mut UnionFind, x| s.find_signed(x).1 ^ s.find_signed(0).1;
        let signs: Vec<bool> = (0..5).map(|x| sign(&mut sets, x)).collect();
        assert_eq!(signs, [false, true, false, false, true]);
        assert_ne!(sets.find(5), sets.find(0));
    }

    #[test]
    fn shared_joins_from_many_threads_give_the_sets_of_one() {
        use rayon::prelude::*;
        let mut rng = Rng::new(11);
        let n = 20_000u32;
        let pairs: Vec<(u32, u32)> =
            (0..15_000).map(|_| ((rng.next_u64() % n as u64) as u32, (rng.next_u64() % n as u64) as u32)).collect();
        let shared = SharedUnionFind::new(n as usize);
        pairs.par_iter().for_each(|&(a, b)| shared.union(a, b));
        let mut serial = UnionFind::new(n as usize);
        pairs.iter().for_each(|&(a, b)| {
            serial.union(a, b);
        });
        let roots = (0..n).filter(|&x| shared.is_root(x)).count();
        let serial_roots = (0..n).filter(|&x| serial.find(x) == x).count();
        assert_eq!(roots, serial_roots);
        for x in (0..n).step_by(7) {
            let y = (x * 31 + 5) % n;
            assert_eq!(shared.find(x) == shared.find(y), serial.find(x) == serial.find(y), "{x} and {y}");
        }
    }

    /// Random unions against a naive labelling that relabels (and re-signs) a whole set on
    /// every join.
    #[test]
    fn agrees_with_a_naive_labelling() {
        let mut rng = Rng::new(7);
        for case in 0..200 {
            let n = 1 + (rng.next_u64() % 60) as usize;
            let mut sets = UnionFind::new(n);
            let mut label: Vec<usize> = (0..n).collect();
            let mut sign = vec![false; n];
            for _ in 0..(rng.next_u64() % (2 * n as u64 + 1)) {
                let (a, b) = ((rng.next_u64() % n as u64) as usize, (rng.next_u64() % n as u64) as usize);
                let differ = rng.next_u64() & 1 == 1;
                // Half the cases plain, half signed.
                let joined = if case % 2 == 0 {
                    sets.union(a as u32, b as u32)
                } else {
                    sets.union_signed(a as u32, b as u32, differ)
                };
                let differ = differ && case % 2 == 1;
                assert_eq!(joined, label[a] != label[b], "case {case}: union({a}, {b})");
                if joined {
                    let (from, to) = (label[b], label[a]);
                    let turn = sign[a] ^ sign[b] ^ differ;
                    for x in 0..n {
                        if label[x] == from {
                            label[x] = to;
                            sign[x] ^= turn;
                        }
                    }
                }
            }
            for x in 0..n {
                for y in 0..n {
                    let ((rx, px), (ry, py)) = (sets.find_signed(x as u32), sets.find_signed(y as u32));
                    assert_eq!(rx == ry, label[x] == label[y], "case {case}: {x} and {y}");
                    if rx == ry {
                        assert_eq!(px ^ py, sign[x] ^ sign[y], "case {case}: signs of {x} and {y}");
                    }
                }
                if case % 2 == 0 {
                    assert!(!sets.find_signed(x as u32).1, "plain unions never flip a sign");
                }
            }
        }
    }
}
