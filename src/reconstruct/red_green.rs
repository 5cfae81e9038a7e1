//! Crack-free splitting of some of a mesh's triangles (red-green refinement, as in Bank,
//! Sherman and Weiser 1983): each marked triangle is split 1-to-4 (red); a triangle left with
//! one split edge is halved from that edge's midpoint to its opposite corner (green), one with
//! two or more is split red too. A green pair is temporary: before the next split it is merged
//! back into its parent, whose midpoint then hangs on the edge it shares with the finer
//! triangles, so that refinement never splits a green triangle (which would make ever thinner
//! slivers) and neighbours differ by at most one level. A triangle next to a marked one across
//! half of its hanging edge is split red first, so that no edge ever holds two midpoints.

use rayon::prelude::*;

/// A green pair: `parent` = (a, b, c) halved at `mid`, the midpoint of (b, c), into the
/// triangles (a, b, mid) and (a, mid, c) at `faces` of the split mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Green {
    pub parent: [u32; 3],
    pub mid: u32,
    pub faces: [u32; 2],
}

/// What [`split`] made.
#[derive(Clone, Debug, Default)]
pub(crate) struct Split {
    pub triangles: Vec<[u32; 3]>,
    /// The edges that got a new midpoint vertex: that of `new_edges[k]` is vertex
    /// `vertex_count + k`.
    pub new_edges: Vec<(u32, u32)>,
    /// Per new edge: whether it is a border edge (one triangle).
    pub on_border: Vec<bool>,
    pub greens: Vec<Green>,
    /// Per triangle: the triangle of the input it is part of (for a merged green pair, its
    /// first half).
    pub from: Vec<u32>,
    /// Triangles (after merging the green pairs) split red.
    pub red: usize,
}

/// A triangle of the mesh with its green pairs merged: its corners, and the edge (`k` for the
/// edge from corner k to corner k + 1) that holds a hanging midpoint, with that midpoint.
struct Face {
    corners: [u32; 3],
    hanging: Option<(usize, u32)>,
    /// The input triangle it is (or whose green pair it merges).
    from: u32,
}

fn key(a: u32, b: u32) -> u64 {
    u64::from(a.min(b)) << 32 | u64::from(a.max(b))
}

/// Splits `triangles` (over `vertex_count` vertices) where `marked` says (one flag per
/// triangle), after merging `greens` (the previous split's green pairs) back into their
/// parents (a pair is marked when either half is). A triangle that `halves_well` says would
/// not halve well at its edge k (corner k to k + 1) is split red instead. Orientation is kept.
pub(crate) fn split(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    marked: &[bool],
    greens: &[Green],
    halves_well: impl Fn([u32; 3], usize) -> bool,
) -> Split {
    let mut in_green = vec![false; triangles.len()];
    let mut faces = Vec::with_capacity(triangles.len());
    let mut red = Vec::with_capacity(triangles.len());
    for g in greens {
        in_green[g.faces[0] as usize] = true;
        in_green[g.faces[1] as usize] = true;
        faces.push(Face { corners: g.parent, hanging: Some((1, g.mid)), from: g.faces[0] });
        red.push(marked[g.faces[0] as usize] || marked[g.faces[1] as usize]);
    }
    for (t, &corners) in triangles.iter().enumerate() {
        if !in_green[t] {
            faces.push(Face { corners, hanging: None, from: t as u32 });
            red.push(marked[t]);
        }
    }

    // Edges: (key, 3 * face + k for the face's edge k) sorted, one run per edge; each face's
    // three edges as indices of their runs.
    let mut by_edge: Vec<(u64, u32)> = faces
        .par_iter()
        .enumerate()
        .flat_map_iter(|(f, face)| {
            let c = face.corners;
            (0..3).map(move |k| (key(c[k], c[(k + 1) % 3]), (3 * f + k) as u32))
        })
        .collect();
    by_edge.par_sort_unstable();
    let mut run_start: Vec<u32> = Vec::with_capacity(by_edge.len() / 2 + 1);
    let mut face_edges = vec![[0u32; 3]; faces.len()];
    for (i, &(k, slot)) in by_edge.iter().enumerate() {
        if i == 0 || by_edge[i - 1].0 != k {
            run_start.push(i as u32);
        }
        face_edges[slot as usize / 3][slot as usize % 3] = run_start.len() as u32 - 1;
    }
    run_start.push(by_edge.len() as u32);
    let edge_keys: Vec<u64> = run_start[..run_start.len() - 1].iter().map(|&i| by_edge[i as usize].0).collect();
    // Any edge of the mesh, by its ends (each face's own are in `face_edges`).
    let edge_of = |a: u32, b: u32| edge_keys.binary_search(&key(a, b)).expect("an edge of the mesh");
    let faces_of =
        |e: usize| by_edge[run_start[e] as usize..run_start[e + 1] as usize].iter().map(|x| x.1 as usize / 3);
    // Halves of hanging edges: (key, the face whose edge they halve).
    let mut halves: Vec<(u64, u32)> = Vec::new();
    let mut mid_of_edge: Vec<u32> = vec![u32::MAX; edge_keys.len()];
    let mut split_edges = vec![0u8; faces.len()];
    for (f, face) in faces.iter().enumerate() {
        if let Some((k, m)) = face.hanging {
            let (b, c) = (face.corners[k], face.corners[(k + 1) % 3]);
            halves.push((key(b, m), f as u32));
            halves.push((key(m, c), f as u32));
            mid_of_edge[face_edges[f][k] as usize] = m;
            split_edges[f] = 1;
        }
    }
    halves.sort_unstable();
    let coarser_across = |k: u64| {
        let start = halves.partition_point(|x| x.0 < k);
        halves[start..].iter().take_while(move |x| x.0 == k).map(|x| x.1 as usize)
    };

    // Closure: a split edge splits it in every face that has it; a face with two split edges is
    // split red; a face next to a red one across half of its hanging edge is split red.
    let mut is_split: Vec<bool> = mid_of_edge.iter().map(|&m| m != u32::MAX).collect();
    let mut queue: Vec<usize> = (0..faces.len()).filter(|&f| red[f]).collect();
    while let Some(f) = queue.pop() {
        let c = faces[f].corners;
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            let e = face_edges[f][k] as usize;
            if !is_split[e] {
                is_split[e] = true;
                for g in faces_of(e) {
                    split_edges[g] += 1;
                    let halved_badly = || {
                        let k = (0..3).find(|&k| face_edges[g][k] as usize == e).unwrap_or(0);
                        !halves_well(faces[g].corners, k)
                    };
                    if !red[g] && (split_edges[g] >= 2 || halved_badly()) {
                        red[g] = true;
                        queue.push(g);
                    }
                }
            }
            for g in coarser_across(key(a, b)) {
                if !red[g] {
                    red[g] = true;
                    queue.push(g);
                }
            }
        }
    }

    // New midpoints: one per split edge without a hanging one, in edge order.
    let mut new_edges = Vec::new();
    let mut on_border = Vec::new();
    for e in 0..edge_keys.len() {
        if is_split[e] && mid_of_edge[e] == u32::MAX {
            mid_of_edge[e] = (vertex_count + new_edges.len()) as u32;
            let k = edge_keys[e];
            new_edges.push(((k >> 32) as u32, k as u32));
            on_border.push(faces_of(e).count() == 1 && coarser_across(k).next().is_none());
        }
    }
    let mid_of = |e: usize| is_split[e].then_some(mid_of_edge[e]);
    let mid = |a: u32, b: u32| mid_of(edge_of(a, b));

    let mut out = Split { new_edges, on_border, red: red.iter().filter(|&&r| r).count(), ..Split::default() };
    for (f, face) in faces.iter().enumerate() {
        let c = face.corners;
        if red[f] {
            let m = face_edges[f].map(|e| mid_of(e as usize).expect("a red face's edges are split"));
            out.triangles.push([m[0], m[1], m[2]]);
            for k in 0..3 {
                // The corner child at corner k: (c[k], m[k], m[k - 1]). Where its outer edge is
                // half of the hanging edge and the finer triangle across was split, it is halved.
                let child = [c[k], m[k], m[(k + 2) % 3]];
                let halved = match face.hanging {
                    Some((h, _)) if h == k => mid(c[k], m[k]).map(|x| (0, x)),
                    Some((h, _)) if (h + 1) % 3 == k => mid(m[(k + 2) % 3], c[k]).map(|x| (2, x)),
                    _ => None,
                };
                match halved {
                    Some((edge, x)) => push_green(&mut out, child, edge, x),
                    None => out.triangles.push(child),
                }
            }
        } else if let Some((k, m)) = (0..3).find_map(|k| mid_of(face_edges[f][k] as usize).map(|m| (k, m))) {
            push_green(&mut out, c, k, m);
        } else {
            out.triangles.push(c);
        }
        out.from.resize(out.triangles.len(), face.from);
    }
    out
}

/// Halves triangle `t` from `m`, the midpoint of its edge `k` (corner k to k + 1), to the
/// opposite corner, and records the pair.
fn push_green(out: &mut Split, t: [u32; 3], k: usize, m: u32) {
    let parent = [t[(k + 2) % 3], t[k], t[(k + 1) % 3]];
    let first = out.triangles.len() as u32;
    out.triangles.push([parent[0], parent[1], m]);
    out.triangles.push([parent[0], m, parent[2]]);
    out.greens.push(Green { parent, mid: m, faces: [first, first + 1] });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology;

    /// A flat grid of n x n squares, two triangles each, over vertices (i, j).
    fn grid(n: u32) -> (Vec<[f32; 2]>, Vec<[u32; 3]>) {
        let positions = (0..=n).flat_map(|j| (0..=n).map(move |i| [i as f32, j as f32])).collect();
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let triangles = (0..n)
            .flat_map(|j| {
                (0..n).flat_map(move |i| {
                    [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
                })
            })
            .collect();
        (positions, triangles)
    }

    /// Positions of the new midpoints appended.
    fn with_midpoints(mut positions: Vec<[f32; 2]>, s: &Split) -> Vec<[f32; 2]> {
        for &(a, b) in &s.new_edges {
            let (p, q) = (positions[a as usize], positions[b as usize]);
            positions.push([(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0]);
        }
        positions
    }

    fn area(p: &[[f32; 2]], t: &[[u32; 3]]) -> Vec<f32> {
        t.iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| p[v as usize]);
                ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / 2.0
            })
            .collect()
    }

    /// Crack-free and oriented over the n x n square: every face keeps a positive area, the
    /// areas add up, no edge has more than two faces and the border edges add up to the
    /// square's perimeter (an edge split on one side only would add a crack's two sides).
    fn assert_conforming(p: &[[f32; 2]], t: &[[u32; 3]], n: u32) {
        let areas = area(p, t);
        assert!(areas.iter().all(|&a| a > 0.0), "a face flipped or degenerate");
        assert!((areas.iter().sum::<f32>() - (n * n) as f32).abs() < 1e-3);
        let border: f32 = topology::edges_and_face_counts(t)
            .iter()
            .map(|&((a, b), faces)| {
                assert!(faces <= 2, "edge ({a}, {b}) has {faces} faces");
                if faces == 1 {
                    let (p, q) = (p[a as usize], p[b as usize]);
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
                } else {
                    0.0
                }
            })
            .sum();
        assert!((border - 4.0 * n as f32).abs() < 1e-3, "border length {border}: a crack");
    }

    #[test]
    fn all_marked_is_the_uniform_1_to_4_split() {
        let (p, t) = grid(3);
        let s = split(&t, p.len(), &vec![true; t.len()], &[], |_, _| true);
        assert_eq!(s.triangles.len(), 4 * t.len());
        assert!(s.greens.is_empty());
        assert_eq!(s.new_edges.len(), topology::edges_and_face_counts(&t).len());
        assert_eq!(s.on_border.iter().filter(|&&b| b).count(), 12);
        assert_conforming(&with_midpoints(p, &s), &s.triangles, 3);
    }

    #[test]
    fn one_marked_triangle_is_closed_by_green_pairs_then_merged_back_before_the_next_split() {
        let (p, t) = grid(4);
        // The middle of the grid: its three neighbours each get one split edge.
        let centre = t.iter().position(|tr| tr[0] == 6).unwrap();
        let mut marked = vec![false; t.len()];
        marked[centre] = true;
        let s = split(&t, p.len(), &marked, &[], |_, _| true);
        assert_eq!(s.red, 1);
        assert_eq!(s.greens.len(), 3);
        assert_eq!(s.new_edges.len(), 3);
        assert_eq!(s.triangles.len(), t.len() - 4 + 4 + 6);
        let p = with_midpoints(p, &s);
        assert_conforming(&p, &s.triangles, 4);

        // Next level: one half of a green pair is marked. The pair is merged back, its parent
        // split red (with the midpoint it had), and the parent's other neighbour turns green:
        // no triangle is ever split from a green half.
        let g = s.greens[0];
        let mut marked = vec![false; s.triangles.len()];
        marked[g.faces[1] as usize] = true;
        let s2 = split(&s.triangles, p.len(), &marked, &s.greens, |_, _| true);
        assert!(s2
            .new_edges
            .iter()
            .all(|&(a, b)| (a, b) != (g.parent[1].min(g.parent[2]), g.parent[1].max(g.parent[2]))));
        // The parent's two other edges are split; the hanging one is not split again.
        assert_eq!(s2.new_edges.len(), 2);
        assert_eq!(s2.red, 1);
        assert_conforming(&with_midpoints(p, &s2), &s2.triangles, 4);
    }

    #[test]
    fn a_triangle_with_two_split_edges_is_split_red() {
        let (p, t) = grid(2);
        // Triangle 1 (the upper half of the square at (0, 0)) shares an edge with triangle 0
        // (that square's lower half) and one with triangle 4 (the lower half of the square
        // above): marking both leaves it two split edges.
        let mut marked = vec![false; t.len()];
        marked[0] = true;
        marked[4] = true;
        let s = split(&t, p.len(), &marked, &[], |_, _| true);
        assert!(s.red >= 3, "{}", s.red);
        assert_conforming(&with_midpoints(p, &s), &s.triangles, 2);
    }

    #[test]
    fn refining_a_corner_again_and_again_stays_crack_free_one_level_apart() {
        // Five rounds, each marking the triangles with a corner at the origin: the mesh
        // grades from fine there to coarse elsewhere without cracks, and no triangle is thinner
        // than a green half of the grid's right triangles (halved across a leg: smallest angle
        // atan(1/3) = 18.4 degrees).
        let (mut p, mut t) = grid(4);
        let mut greens = Vec::new();
        for _ in 0..5 {
            let marked: Vec<bool> = t.iter().map(|tr| tr.iter().any(|&v| p[v as usize] == [0.0, 0.0])).collect();
            let s = split(&t, p.len(), &marked, &greens, |_, _| true);
            p = with_midpoints(p, &s);
            assert_conforming(&p, &s.triangles, 4);
            (t, greens) = (s.triangles, s.greens);
        }
        let smallest = area(&p, &t).into_iter().fold(f32::MAX, f32::min);
        assert!(smallest < 0.5 / 4f32.powi(4), "the corner was refined 5 times: {smallest}");
        for tr in &t {
            let [a, b, c] = tr.map(|v| glam::Vec2::from(p[v as usize]));
            for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b)] {
                let angle = (y - x).angle_to(z - x).abs().to_degrees();
                assert!(angle > 18.4, "angle {angle} in {a} {b} {c}");
            }
        }
        // Far from the corner the grid is as it was.
        assert!(t.iter().any(|tr| tr.map(|v| p[v as usize]) == [[3.0, 3.0], [4.0, 3.0], [4.0, 4.0]]));
    }
}
