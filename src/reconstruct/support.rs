//! Open or closed: which part of the polygonised surface the samples support.
//!
//! The implicit function is polygonised as a closed surface. Where the cloud is an open scan,
//! part of that surface is the sheet that closes the scan behind it, far from every sample.
//! Measured on the polygonisation, the share of the surface's area that no sample supports
//! tells an open scan (about half of the closed surface is the closing sheet) from a closed
//! object whose scan has holes (a few percent), whatever the shape.

use super::adjacency::Rows;
use crate::mesh::Mesh;
use crate::progress::Threads;
use crate::spatial::KdTree;
use glam::Vec3;
use rayon::prelude::*;

/// A point of the polygonised surface is supported when a sample lies within this many units
/// (grid cells, or sample spacings where those are larger). The polygonisation of a sampled
/// surface stays within one unit of its samples (a grid cell's diagonal is 1.7 cells); two
/// leave room for noise and sampling gaps, and the bound for open output is two
/// sample spacings.
pub(super) const SUPPORT_REACH: f32 = 1.0;

/// A face of the octree's polygonisation is judged supported or not at most this many points
/// along an edge (this squared over the face): a face in the empty space behind a scan can be
/// hundreds of reaches across, and a few hundred points tell its share as well as more.
const MOST_ACROSS: usize = 16;

/// How many points along an edge face `f` of `mesh` is judged at, for points `reach` apart
/// (the `across` of [`supported_faces`]).
pub(super) fn points_across(mesh: &Mesh, f: usize, reach: f32) -> usize {
    let [a, b, c] = mesh.triangles[f].map(|v| mesh.positions[v as usize]);
    let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
    ((longest / reach).ceil() as usize).clamp(1, MOST_ACROSS)
}

/// A cloud is taken to be open when more than this share of the polygonised surface's area
/// is unsupported (far from every sample, or near only samples facing the other way). A
/// hemisphere closed by its disk leaves a third unsupported, the least of any scan from one
/// side (measured 35% on a hemisphere, 55% on bun000); a sphere missing a quarter a quarter;
/// closed objects a few percent (at most 20% on oni's 1,435 points), and those are closed
/// over, as Poisson does.
pub(super) const OPEN_SHARE: f64 = 0.3;

/// Whether the output is open (only the part the samples support) or closed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Closure {
    /// Open when more than [`OPEN_SHARE`] of the closed surface is unsupported by the samples:
    /// an open scan gives an open mesh, a closed object scanned with holes a closed one.
    #[default]
    Auto,
    /// Always the closed surface (holes in the scan are closed over).
    Closed,
    /// Always only the supported part (an open scan, or a closed one with its holes kept).
    Open,
}

/// A point of the polygonised surface is supported only by samples whose normals are within
/// this angle's cosine of its own (60 degrees): where an open scan ends, the closed surface
/// turns back behind it, and the part that has turned by more than that is the closing sheet
/// even where it passes within reach of the border's samples. Normals perturbed by noise
/// (20 degrees) stay well inside it.
pub(super) const SUPPORT_AGREEMENT: f32 = 0.5;

/// How a face of the polygonisation relates to the samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Support {
    /// No sample within reach.
    Far,
    /// Samples within reach, but none whose normal agrees with the face's: the closed
    /// surface has turned back behind the samples' border.
    Turned,
    /// A sample within reach whose normal agrees.
    Supported,
}

/// Per face of `mesh`: how the samples of `samples` (normals `normals`, in the same order)
/// support it, within `reach(face)` of the centres of the `across(face)`^2 triangles that
/// cutting each edge in `across(face)` parts makes (1: the face's centre), by a majority of
/// those, and the share of those it is not supported at. A face judged at its centre takes
/// its corners' area-weighted normals (the polygonisation's own faces are often slivers).
pub(super) fn supported_faces(
    mesh: &Mesh,
    samples: &KdTree,
    normals: &[Vec3],
    reach: impl Fn(usize) -> f32 + Sync,
    across: impl Fn(usize) -> usize + Sync,
    threads: &Threads,
) -> Vec<(Support, f32)> {
    let vertex_normals = mesh.area_weighted_normals();
    threads.run(|| {
        mesh.triangles
            .par_iter()
            .enumerate()
            .map(|(f, t)| {
                let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                let across = across(f).max(1);
                // A face judged at several points is large: its own normal says where it faces,
                // where its corners' would blend in the faces around it.
                let own = (b - a).cross(c - a);
                let n = if across > 1 && own.length() > 0.1 * (b - a).length_squared().max((c - a).length_squared()) {
                    own.normalize()
                } else {
                    t.iter().map(|&v| vertex_normals[v as usize]).sum::<Vec3>().normalize_or_zero()
                };
                let reach = reach(f);
                let at = |p: Vec3| {
                    if !samples.any_within(p, reach) {
                        Support::Far
                    } else if samples.any_within_among(p, reach, |i| normals[i as usize].dot(n) > SUPPORT_AGREEMENT) {
                        Support::Supported
                    } else {
                        Support::Turned
                    }
                };
                let mut counts = [0usize; 3];
                for (u, v) in sub_triangle_centres(across) {
                    counts[at(a + u * (b - a) + v * (c - a)) as usize] += 1;
                }
                let [far, turned, supported] = counts;
                let all = far + turned + supported;
                let verdict = if 2 * supported >= all {
                    Support::Supported
                } else if far >= turned {
                    Support::Far
                } else {
                    Support::Turned
                };
                (verdict, (far + turned) as f32 / all as f32)
            })
            .collect()
    })
}

/// The barycentric coordinates (of the second and third corner) of the centres of the n^2
/// triangles that cutting a triangle's edges in `n` parts makes.
fn sub_triangle_centres(n: usize) -> impl Iterator<Item = (f32, f32)> {
    let n_f = n as f32;
    (0..n).flat_map(move |i| {
        (0..n - i).flat_map(move |j| {
            let up = ((i as f32 + 1.0 / 3.0) / n_f, (j as f32 + 1.0 / 3.0) / n_f);
            let down = ((i as f32 + 2.0 / 3.0) / n_f, (j as f32 + 2.0 / 3.0) / n_f);
            std::iter::once(up).chain((i + j + 1 < n).then_some(down))
        })
    })
}

/// The share of `mesh`'s area that `marked` marks: per face, the share of it marked.
pub(super) fn unsupported_share(mesh: &Mesh, marked: &[f32]) -> f64 {
    let (mut all, mut part) = (0.0f64, 0.0f64);
    for (t, &m) in mesh.triangles.iter().zip(marked) {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        let area = f64::from((b - a).cross(c - a).length());
        all += area;
        part += area * f64::from(m);
    }
    if all > 0.0 {
        part / all
    } else {
        0.0
    }
}

/// A connected set of marked faces (faces sharing an edge are connected).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Region {
    pub area: f64,
    /// One of its faces has an edge that no other face of the mesh shares.
    pub touches_border: bool,
}

/// The regions of the faces `marked` true: per face its region (`u32::MAX` for unmarked
/// faces), and the regions.
pub(super) fn regions(mesh: &Mesh, marked: &[bool]) -> (Vec<u32>, Vec<Region>) {
    let faces = Rows::faces(&mesh.triangles, mesh.positions.len());
    // The faces other than `f` on edge a-b.
    let across = |f: usize, a: u32, b: u32| {
        faces.of(a).iter().copied().filter(move |&g| g as usize != f && mesh.triangles[g as usize].contains(&b))
    };
    let mut region = vec![u32::MAX; mesh.triangles.len()];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..mesh.triangles.len() {
        if !marked[start] || region[start] != u32::MAX {
            continue;
        }
        let id = out.len() as u32;
        let mut r = Region::default();
        region[start] = id;
        stack.push(start);
        while let Some(f) = stack.pop() {
            let t = mesh.triangles[f];
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            r.area += 0.5 * f64::from((b - a).cross(c - a).length());
            for k in 0..3 {
                let (u, v) = (t[k], t[(k + 1) % 3]);
                let mut others = across(f, u, v).peekable();
                r.touches_border |= others.peek().is_none();
                for g in others {
                    if marked[g as usize] && region[g as usize] == u32::MAX {
                        region[g as usize] = id;
                        stack.push(g as usize);
                    }
                }
            }
        }
        out.push(r);
    }
    (region, out)
}

/// `unsupported` with every region of it smaller than `min_area` turned supported: the base
/// mesh cannot show a hole smaller than its own faces (a T-node), and collapsing keeps every
/// hole, so a speck of unsupported faces (a sliver whose normal strays, a gap in the samples)
/// would otherwise become a hole the size of a base-mesh face.
pub(super) fn without_small_regions(mesh: &Mesh, unsupported: &[bool], min_area: f64) -> Vec<bool> {
    let (region, regions) = regions(mesh, unsupported);
    region.iter().map(|&r| r != u32::MAX && regions[r as usize].area >= min_area).collect()
}

/// Whether the output is open, given the unsupported share of the closed surface.
pub(super) fn is_open(closure: Closure, unsupported_share: f64) -> bool {
    match closure {
        Closure::Auto => unsupported_share > OPEN_SHARE,
        Closure::Closed => false,
        Closure::Open => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes::icosphere;

    #[test]
    fn a_sphere_sampled_on_one_half_is_half_unsupported() {
        let sphere = icosphere(1.0, 4);
        let upper: Vec<Vec3> = sphere.positions.iter().copied().filter(|p| p.z > 0.0).collect();
        let threads = Threads::new(1).unwrap();
        let support = supported_faces(&sphere, &KdTree::new(&upper).unwrap(), &upper, |_| 0.05, |_| 1, &threads);
        let unsupported: Vec<f32> = support.iter().map(|&(s, _)| f32::from(u8::from(s == Support::Far))).collect();
        let share = unsupported_share(&sphere, &unsupported);
        assert!((share - 0.5).abs() < 0.05, "{share}");
        assert!(is_open(Closure::Auto, share));
        assert!(!is_open(Closure::Closed, share));
    }

    #[test]
    fn a_sphere_with_a_small_hole_stays_closed() {
        // A cap of 5% of the area unsampled (z > 0.9): a hole, closed over.
        let sphere = icosphere(1.0, 4);
        let kept: Vec<Vec3> = sphere.positions.iter().copied().filter(|p| p.z <= 0.9).collect();
        let threads = Threads::new(1).unwrap();
        let support = supported_faces(&sphere, &KdTree::new(&kept).unwrap(), &kept, |_| 0.05, |_| 1, &threads);
        let unsupported: Vec<f32> = support.iter().map(|&(s, _)| f32::from(u8::from(s == Support::Far))).collect();
        let share = unsupported_share(&sphere, &unsupported);
        assert!(share > 0.02 && share < 0.08, "{share}");
        assert!(!is_open(Closure::Auto, share));
        assert!(is_open(Closure::Open, share));
    }

    #[test]
    fn a_sphere_missing_a_quarter_stays_closed_and_missing_half_opens() {
        // Caps of 25% and 50% of the area unsampled (z > 0.5, z > 0): a closed object scanned
        // from most sides, closed over; a scan from one side, opened (see OPEN_SHARE).
        let sphere = icosphere(1.0, 4);
        let threads = Threads::new(1).unwrap();
        for (top, open) in [(0.5, false), (0.0, true)] {
            let kept: Vec<Vec3> = sphere.positions.iter().copied().filter(|p| p.z <= top).collect();
            let support = supported_faces(&sphere, &KdTree::new(&kept).unwrap(), &kept, |_| 0.05, |_| 1, &threads);
            let unsupported: Vec<f32> =
                support.iter().map(|&(s, _)| f32::from(u8::from(s != Support::Supported))).collect();
            let share = unsupported_share(&sphere, &unsupported);
            assert_eq!(is_open(Closure::default(), share), open, "{share} unsupported");
        }
    }

    #[test]
    fn faces_turned_from_their_samples_are_told_apart() {
        // The samples of the upper half, with normals pointing down: near, but turned.
        let sphere = icosphere(1.0, 3);
        let upper: Vec<Vec3> = sphere.positions.iter().copied().filter(|p| p.z > 0.0).collect();
        let down: Vec<Vec3> = upper.iter().map(|_| -Vec3::Z).collect();
        let threads = Threads::new(1).unwrap();
        let support = supported_faces(&sphere, &KdTree::new(&upper).unwrap(), &down, |_| 0.2, |_| 1, &threads);
        let centre = |t: &[u32; 3]| t.iter().map(|&v| sphere.positions[v as usize]).sum::<Vec3>() / 3.0;
        for (t, (s, _)) in sphere.triangles.iter().zip(&support) {
            let z = centre(t).z;
            if z > 0.1 {
                assert_eq!(*s, Support::Turned, "z {z}");
            } else if z < -0.25 {
                assert_eq!(*s, Support::Far, "z {z}");
            }
        }
    }

    #[test]
    fn specks_smaller_than_the_bound_are_closed_over() {
        // Two unsupported regions: a cap of 5% of the area and one face elsewhere.
        let sphere = icosphere(1.0, 4);
        let centre = |t: &[u32; 3]| t.iter().map(|&v| sphere.positions[v as usize]).sum::<Vec3>() / 3.0;
        let speck = sphere.triangles.iter().position(|t| centre(t).z < -0.9).unwrap();
        let unsupported: Vec<bool> =
            sphere.triangles.iter().enumerate().map(|(f, t)| centre(t).z > 0.9 || f == speck).collect();
        let (_, regions) = regions(&sphere, &unsupported);
        assert_eq!(regions.len(), 2);
        assert!(regions.iter().all(|r| !r.touches_border), "a closed mesh has no border");
        let kept = without_small_regions(&sphere, &unsupported, 0.1);
        assert!(!kept[speck]);
        assert_eq!(kept.iter().filter(|&&k| k).count(), unsupported.iter().filter(|&&u| u).count() - 1);
    }

    #[test]
    fn regions_see_the_border() {
        let sphere = icosphere(1.0, 3);
        let upper: Vec<[u32; 3]> = sphere
            .triangles
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&v| sphere.positions[v as usize].z > -1e-6))
            .collect();
        let dome = Mesh::new(sphere.positions.clone(), None, upper);
        let near_pole: Vec<bool> =
            dome.triangles.iter().map(|t| t.iter().all(|&v| dome.positions[v as usize].z > 0.8)).collect();
        let near_rim: Vec<bool> =
            dome.triangles.iter().map(|t| t.iter().any(|&v| dome.positions[v as usize].z < 0.1)).collect();
        assert!(!regions(&dome, &near_pole).1[0].touches_border);
        assert!(regions(&dome, &near_rim).1.iter().all(|r| r.touches_border));
    }

    #[test]
    fn a_large_face_is_judged_across_its_area() {
        // One triangle over a square of samples of which only the half x < 0 is sampled: its
        // centre (x = 0.33) sees no sample; 8 x 8 points across it see the half it covers.
        let samples: Vec<Vec3> = (0..200 * 200)
            .map(|i| Vec3::new(-2.0 + 0.01 * (i % 200) as f32, -1.0 + 0.01 * (i / 200) as f32, 0.0))
            .filter(|p| p.x < 0.0)
            .collect();
        let normals = vec![Vec3::Z; samples.len()];
        let face = Mesh::new(
            vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)],
            None,
            vec![[0, 1, 2]],
        );
        let index = KdTree::new(&samples).unwrap();
        let threads = Threads::new(1).unwrap();
        let at_centre = supported_faces(&face, &index, &normals, |_| 0.05, |_| 1, &threads)[0];
        assert_eq!(at_centre, (Support::Far, 1.0));
        let (verdict, unsupported) = supported_faces(&face, &index, &normals, |_| 0.05, |_| 8, &threads)[0];
        // The triangle's part at x < 0 is a quarter of it.
        assert!(verdict == Support::Far && (unsupported - 0.75).abs() < 0.1, "{verdict:?} {unsupported}");
        assert_eq!(sub_triangle_centres(8).count(), 64);
        assert!(sub_triangle_centres(8).all(|(u, v)| u > 0.0 && v > 0.0 && u + v < 1.0));
    }
}
