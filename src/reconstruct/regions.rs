//! Where refinement is decided: M0's triangles grouped into compact regions of about
//! [`REGION_TRIANGLES`] each, each refined as a whole (see [`super::levels`]). Inside a region
//! the mesh stays a regular 1-to-4 subdivision (valence 6); where two regions stop at
//! different levels, the red-green transition between them costs a pair of irregular vertices
//! per coarse edge, so the larger the regions, the fewer such vertices for the area, and the
//! coarser the choice of where to stop.

use super::adjacency::Rows;
use std::collections::VecDeque;

/// M0 triangles per region. Measured with a target distance of 2e-4 on the corpus bench's 24
/// clean 200k-point clouds: valence 6 on 95.4% of the vertices at the median row (80.4% at
/// worst) against 96.7% (95.4%) when every triangle is split, with 5% fewer triangles at the
/// median (51% fewer at most) for the same error. Deciding per triangle scatters the
/// transitions: 91% at the median row on an earlier rule, 75-87% on the test shapes.
pub(crate) const REGION_TRIANGLES: usize = 4;

/// Regions of M0's triangles: which region each triangle is in, and which regions share an
/// edge.
pub(crate) struct Regions {
    pub of_triangle: Vec<u32>,
    pub neighbours: Rows,
}

impl Regions {
    /// Grows regions of up to `size` triangles breadth first over the triangles' edge
    /// neighbours (`pairs`, from [`crate::topology::adjacent_face_pairs`]), each from the first
    /// triangle not yet in one: compact patches rather than strips.
    pub fn grow(triangles: usize, pairs: &[[u32; 2]], size: usize) -> Regions {
        let faces = Rows::from_pairs(pairs, triangles);
        let mut of_triangle = vec![u32::MAX; triangles];
        let mut count = 0u32;
        let mut queue = VecDeque::new();
        for seed in 0..triangles {
            if of_triangle[seed] != u32::MAX {
                continue;
            }
            let mut taken = 0;
            queue.clear();
            queue.push_back(seed as u32);
            of_triangle[seed] = count;
            while let Some(t) = queue.pop_front() {
                taken += 1;
                for &n in faces.of(t) {
                    if taken + queue.len() < size && of_triangle[n as usize] == u32::MAX {
                        of_triangle[n as usize] = count;
                        queue.push_back(n);
                    }
                }
            }
            count += 1;
        }
        let mut region_pairs: Vec<[u32; 2]> = pairs
            .iter()
            .map(|&[a, b]| {
                let (x, y) = (of_triangle[a as usize], of_triangle[b as usize]);
                [x.min(y), x.max(y)]
            })
            .filter(|[x, y]| x != y)
            .collect();
        region_pairs.sort_unstable();
        region_pairs.dedup();
        Regions { of_triangle, neighbours: Rows::from_pairs(&region_pairs, count as usize) }
    }

    pub fn count(&self) -> usize {
        self.neighbours.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_cover_every_triangle_with_at_most_size_each_and_know_their_neighbours() {
        // A strip of 20 triangles, each next to the one before.
        let pairs: Vec<[u32; 2]> = (1..20).map(|t| [t - 1, t]).collect();
        let r = Regions::grow(20, &pairs, 8);
        assert_eq!(r.of_triangle, [[0; 8], [1; 8]].concat().into_iter().chain([2; 4]).collect::<Vec<u32>>());
        assert_eq!(r.count(), 3);
        assert_eq!(r.neighbours.of(1), &[0, 2]);
        // One triangle each: the triangles' own adjacency.
        let r = Regions::grow(20, &pairs, 1);
        assert_eq!(r.count(), 20);
        assert_eq!(r.neighbours.of(5), &[4, 6]);
    }
}
