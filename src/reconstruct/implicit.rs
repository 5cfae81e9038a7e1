//! The base mesh's implicit function (paper §5.2, "Base mesh reconstruction"): each T-node's
//! plane is a linear signed distance, n·(p − c); the planes are blended by a partition of unity
//! whose compactly supported weights overlap across neighbouring T-nodes, as MPU (Ohtake et al.
//! 2003) blends its local quadrics.
//!
//! Support of a T-node: a ball at its cube's centre with radius `scale` times the cube's half
//! diagonal (MPU's α = 0.75 of the full diagonal is `scale` = 1.5), but never less than
//! `min_radius` (a grid cell or two, so the finest nodes still overlap their neighbours).
//! Weight: (1 − d²/R²)³, smooth and zero at the support's border. Where no support reaches,
//! the point counts as outside.
//!
//! Beyond a thin tip (an ear, a finger) the planes of its two sides blend to zero along the
//! tip's mid-plane, which would grow a flap as far as the supports reach; deep inside a thick
//! part no support reaches. So away from the samples the caller lets the winding number
//! decide the side (see `reconstruct` and `winding`).

use crate::tree::{NodeKind, VsTree, MAX_DEPTH};
use glam::Vec3;

/// The blended signed distance to the T-layer's planes.
pub(crate) struct PlaneBlend<'t> {
    tree: &'t VsTree,
    /// Per node (V and T), the box holding the supports of every T-node at or below it.
    reach_lo: Vec<Vec3>,
    reach_hi: Vec<Vec3>,
    /// Per node, the squared support radius (T-nodes only).
    radius_sq: Vec<f32>,
}

impl<'t> PlaneBlend<'t> {
    pub fn new(tree: &'t VsTree, scale: f32, min_radius: f32) -> PlaneBlend<'t> {
        let n = tree.nodes.len();
        let mut reach_lo = vec![Vec3::splat(f32::MAX); n];
        let mut reach_hi = vec![Vec3::splat(f32::MIN); n];
        let mut radius_sq = vec![0.0; n];
        // Children come after their parents: one backward pass accumulates the boxes.
        for i in (0..n).rev() {
            let node = &tree.nodes[i];
            match node.kind {
                NodeKind::Surface => continue,
                NodeKind::Transition => {
                    let r = (scale * 3f32.sqrt() * node.half).max(min_radius);
                    radius_sq[i] = r * r;
                    reach_lo[i] = node.center - r;
                    reach_hi[i] = node.center + r;
                }
                NodeKind::Volume => {
                    for c in node.children() {
                        reach_lo[i] = reach_lo[i].min(reach_lo[c]);
                        reach_hi[i] = reach_hi[i].max(reach_hi[c]);
                    }
                }
            }
        }
        PlaneBlend { tree, reach_lo, reach_hi, radius_sq }
    }

    /// The signed distance of T-node `t`'s plane at `p` (positive on the normal's side).
    fn plane(&self, t: usize, p: Vec3) -> f32 {
        self.tree.frames[self.tree.nodes[t].frame as usize].height(p)
    }

    /// The blended function at `p`: negative inside, positive outside.
    pub fn eval(&self, p: Vec3) -> f32 {
        let (mut sum, mut weights) = (0.0f32, 0.0f32);
        // Depth-first, at most eight children pushed per level: a fixed stack, no allocation.
        let mut stack = [0u32; 8 * (MAX_DEPTH as usize + 1)];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let i = stack[top] as usize;
            if (p.cmplt(self.reach_lo[i]) | p.cmpgt(self.reach_hi[i])).any() {
                continue;
            }
            let node = &self.tree.nodes[i];
            match node.kind {
                NodeKind::Transition => {
                    let d2 = p.distance_squared(node.center);
                    if d2 < self.radius_sq[i] {
                        let w = (1.0 - d2 / self.radius_sq[i]).powi(3);
                        sum += w * self.plane(i, p);
                        weights += w;
                    }
                }
                NodeKind::Volume => {
                    for c in node.children() {
                        stack[top] = c as u32;
                        top += 1;
                    }
                }
                NodeKind::Surface => {}
            }
        }
        if weights > 0.0 {
            sum / weights
        } else {
            f32::MAX
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::{self, TreeParams};
    use crate::{Progress, SampleSet, Threads};

    #[test]
    fn blended_planes_of_a_sphere_approximate_its_signed_distance() {
        let cloud = crate::eval::shapes::sample_surface(&crate::eval::shapes::icosphere(1.0, 5), 50_000, 1);
        let positions: Vec<Vec3> = cloud.positions.iter().map(|p| p.normalize()).collect();
        let samples = SampleSet { normals: positions.clone(), origin: (0..50_000).collect(), positions };
        let t = tree::build(
            &samples,
            &TreeParams { error: 1e-4, ..Default::default() },
            &Threads::new(0).unwrap(),
            &mut Progress::none(),
        )
        .unwrap();
        let f = PlaneBlend::new(&t, 1.5, 0.05);
        // The T-layer's planes pass through their patches' centroids, which lie below a curved
        // surface by the patch's sag (about 0.05 here): the zero set sits that much inside.
        for p in [Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize(), -Vec3::Z] {
            assert!(f.eval(p).abs() < 0.08, "f({p}) = {}", f.eval(p));
            assert!(f.eval(p * 1.15) > 0.05 && f.eval(p * 0.85) < -0.05, "no sign change across {p}");
        }
        assert!(f.eval(Vec3::splat(5.0)) > 0.0, "outside every support");
    }
}
