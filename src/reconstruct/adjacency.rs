//! Who is next to whom in a triangle mesh, in two flat arrays (compressed rows): one
//! allocation for the whole mesh, where a `Vec` per vertex costs several times the data on
//! meshes of millions of vertices.

/// Per vertex, the items around it: `items[first[v]..first[v + 1]]`.
pub(crate) struct Rows {
    first: Vec<u32>,
    items: Vec<u32>,
}

impl Rows {
    /// Rows of `count` vertices from the `(vertex, item)` pairs that `visit` hands to its
    /// argument (it is called twice: once to count, once to fill), each row in the order the
    /// pairs come.
    fn build(count: usize, visit: impl Fn(&mut dyn FnMut(u32, u32))) -> Rows {
        let mut first = vec![0u32; count + 1];
        visit(&mut |v, _| first[v as usize + 1] += 1);
        for v in 0..count {
            first[v + 1] += first[v];
        }
        let mut fill = first.clone();
        let mut items = vec![0u32; first[count] as usize];
        visit(&mut |v, item| {
            items[fill[v as usize] as usize] = item;
            fill[v as usize] += 1;
        });
        Rows { first, items }
    }

    /// Each vertex's neighbours along edges, sorted and unique.
    pub fn neighbours(triangles: &[[u32; 3]], vertices: usize) -> Rows {
        let mut rows = Rows::build(vertices, |pair| {
            for t in triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    pair(a, b);
                    pair(b, a);
                }
            }
        });
        rows.sort_and_dedup();
        rows
    }

    /// Each vertex's triangles (indices into `triangles`), sorted and unique.
    pub fn faces(triangles: &[[u32; 3]], vertices: usize) -> Rows {
        let mut rows = Rows::build(vertices, |pair| {
            for (t, tri) in triangles.iter().enumerate() {
                for &v in tri {
                    pair(v, t as u32);
                }
            }
        });
        rows.sort_and_dedup();
        rows
    }

    /// Each of `count` items' partners in `pairs`, both ways.
    pub fn from_pairs(pairs: &[[u32; 2]], count: usize) -> Rows {
        Rows::build(count, |pair| {
            for &[a, b] in pairs {
                pair(a, b);
                pair(b, a);
            }
        })
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.first.len() - 1
    }

    pub fn of(&self, v: u32) -> &[u32] {
        &self.items[self.first[v as usize] as usize..self.first[v as usize + 1] as usize]
    }

    fn sort_and_dedup(&mut self) {
        let mut kept = 0usize;
        let mut start = 0usize;
        for v in 0..self.first.len() - 1 {
            let end = self.first[v + 1] as usize;
            let row = &mut self.items[start..end];
            row.sort_unstable();
            let mut unique = 0;
            for k in 0..row.len() {
                if k == 0 || row[k] != row[k - 1] {
                    row[unique] = row[k];
                    unique += 1;
                }
            }
            self.items.copy_within(start..start + unique, kept);
            self.first[v] = kept as u32;
            kept += unique;
            start = end;
        }
        *self.first.last_mut().expect("one more entry than vertices") = kept as u32;
        self.items.truncate(kept);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_of_a_tetrahedron() {
        let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let n = Rows::neighbours(&triangles, 5);
        for v in 0..4u32 {
            let expected: Vec<u32> = (0..4).filter(|&w| w != v).collect();
            assert_eq!(n.of(v), expected.as_slice());
        }
        assert!(n.of(4).is_empty(), "an unused vertex has no neighbours");
    }
}
