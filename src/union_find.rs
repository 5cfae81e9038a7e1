//! Union-find (disjoint sets) over `0..n`, where every element can also carry a sign relative to
//! the others of its set: plain connectivity (mesh components, vertex fans) ignores the signs,
//! normal orientation uses them to make every normal of a set agree.

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
