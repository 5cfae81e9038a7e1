//! The tree's samples as the stages after the tree look them up, and the lengths their
//! tolerances count in.

use super::mls;
use crate::error::Result;
use crate::progress::Threads;
use crate::spatial::KdTree;
use crate::tree::{NodeKind, VsTree};
use glam::Vec3;

/// Extra samples per local fit for each squared noise level per sample spacing (see
/// `fit_neighbours`): a fit then spans about as many noise levels whatever the density. On
/// the corpus's noisy clouds 50, 100 and 200 give median Chamfer ratios to Poisson of 1.26,
/// 1.18 and 1.17 at 0.25% noise and 1.29, 1.30 and 1.36 at 0.5%; more are slower and blur
/// thin parts.
const FIT_NEIGHBOURS_PER_NOISE: f64 = 100.0;

/// The samples of a tree, indexed, with local fits of their surface.
pub(super) struct Lookup<'t> {
    pub tree: &'t VsTree,
    /// Local fits of the samples' surface; its index holds the samples in the tree's order,
    /// which keeps neighbours together in memory.
    pub fit: mls::SampleSurface<'t>,
    /// The typical distance between neighbouring samples.
    pub spacing: f32,
    /// The median T-node's half side: a T-node's plane strays from its samples by up to its
    /// patch's sag, so caps on distances to the samples leave room for the typical T-node too.
    pub typical_t_half: f32,
}

impl<'t> Lookup<'t> {
    pub fn new(tree: &'t VsTree, threads: &Threads) -> Result<Lookup<'t>> {
        let fit = mls::SampleSurface::new(&tree.samples, threads)?;
        let tree_order: Vec<Vec3> = tree.samples.iter().map(|s| s.position).collect();
        let spacing = sample_spacing(fit.index(), &tree_order);
        let fit = fit.with_neighbours(fit_neighbours(tree.noise, spacing), threads)?;
        let typical_t_half =
            median(tree.nodes.iter().filter(|n| n.kind == NodeKind::Transition).map(|n| n.half).collect());
        Ok(Lookup { tree, fit, spacing, typical_t_half })
    }

    /// The samples' positions, indexed.
    pub fn index(&self) -> &KdTree {
        self.fit.index()
    }
}

/// Samples per local fit of the samples' surface: [`mls::NEIGHBOURS`] on a clean cloud, and
/// more as the noise grows against the spacing, so that a fit averages it away (a fit's noise
/// shrinks as the square root of its samples).
fn fit_neighbours(noise: f32, spacing: f32) -> usize {
    let ratio = if spacing > 0.0 { f64::from(noise / spacing) } else { 0.0 };
    mls::NEIGHBOURS + (FIT_NEIGHBOURS_PER_NOISE * ratio * ratio).min(1e6) as usize
}

/// The median of `values` (0 when empty).
fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(0.0)
}

/// The typical distance between neighbouring samples: the median, over up to 2,000 of the odd
/// points, of the distance to the nearest even point at another place (`near` holds `points`;
/// duplicate points would make it 0).
fn sample_spacing(near: &KdTree, points: &[Vec3]) -> f32 {
    let odd: Vec<Vec3> = points.iter().skip(1).step_by(2).copied().collect();
    median(
        super::evenly_spread(&odd, 2000)
            .iter()
            .filter_map(|&p| near.nearest_among(p, |i| i % 2 == 0 && points[i as usize] != p).map(|(d, _)| d))
            .filter(|d| d.is_finite())
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_points_do_not_make_the_spacing_zero() {
        // A 0.01 grid, every point twice and next to its copy (as the tree orders them): each
        // odd point's nearest even one was its copy (a bull of 20k points, each twice, came
        // out with genus 47 on a grid finer than its samples).
        let points: Vec<Vec3> = (0..100 * 100)
            .flat_map(|k| {
                let p = Vec3::new((k % 100) as f32 * 0.01, (k / 100) as f32 * 0.01, 0.0);
                [p, p]
            })
            .collect();
        let near = KdTree::new(&points).unwrap();
        assert!((sample_spacing(&near, &points) - 0.01).abs() < 1e-6, "{}", sample_spacing(&near, &points));
    }
}
