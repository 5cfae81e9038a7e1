//! The cloud's noise level: how far its samples scatter off a smooth surface, estimated from
//! the residual of local quadratic fits. The tree allows for it in its height-field test and
//! its L2 error, so that noise does not look like detail (see
//! [`crate::tree::build_allowing_noise`]), and the fits of the samples' surface average it.

use super::leaf_fit::solve;
use crate::error::Result;
use crate::progress::Threads;
use crate::spatial::KdTree;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The estimate is made on at most this many of the points, evenly spread, so that its cost
/// does not grow with the cloud, and so that the neighbourhoods below reach the same share of
/// the surface whatever the cloud's size.
const NOISE_SUBSAMPLE: usize = 50_000;
/// Local fits made, at points evenly spread through the subsample.
const NOISE_PROBES: usize = 1000;
/// The neighbourhood sizes tried at each probe, smallest first (in points of the subsample):
/// the smallest leaves a quadratic's six coefficients 18 degrees of freedom.
const NOISE_NEIGHBOURS: [usize; 5] = [24, 48, 96, 192, 384];
/// Nearest points searched per probe, of which those on the probe's side make its
/// neighbourhoods: room for the widest with a thin wall's other side among them.
const NOISE_SEARCHED: usize = 2 * 384;
/// A neighbourhood tells the noise once its radius is this many times its fit's residual: a
/// smaller one is a blob inside the noise (its residual is a share of its radius, not the
/// noise), a larger one also holds the shape beyond a quadratic (thin parts, edges, fine
/// detail), so each probe takes the smallest that is wide enough.
const NOISE_WIDTH: f64 = 5.0;
/// Noise reads the same at every width: a probe's estimate is taken where the next wider
/// neighbourhood's residual is at most this many times the narrower one's (the wider one's
/// is the estimate: more degrees of freedom). Where the residual keeps growing with the width,
/// it is the shape's (a crease, a facet's edge, a smooth surface's own curvature), not noise.
const NOISE_PLATEAU: f64 = 1.25;
/// Noise below this share of the sample spacing is not allowed for: the samples do not resolve
/// the surface that finely anyway, and on clean clouds what reads as noise is the shape's (its
/// facets, float rounding on flat parts): up to 0.14 spacings on the corpus's clean clouds at
/// 200k points, against 1.8 and more with 0.25% noise.
const NOISE_FLOOR: f64 = 0.25;
/// A cloud is taken to be noisy when at least this share of its probes show noise; its level
/// is then their median. Noise is everywhere on a noisy cloud, but where the shape varies at
/// the noise's own scale (fine detail, thin parts) a probe sees shape too, and measured noisy
/// clouds show it at 34-95% of their probes. On clean clouds only some probes see something
/// like noise (a coarse mesh's facet pattern, at 12-22% on the corpus), or noise at float
/// precision on flat parts (up to 32%, harmless).
const NOISE_SHOWN: f64 = 0.3;

/// The standard deviation of the points' distance to a smooth surface, in the points' units
/// (0 for points on a plane or a quadric). Each fit takes only the neighbours whose normal
/// faces the same side as its probe's (zero normals count as any side): the two sides of a thin
/// wall would otherwise read as one noisy sheet.
pub(super) fn noise_level(points: &[Vec3], normals: &[Vec3], threads: &Threads) -> Result<f32> {
    let step = spread_step(points.len(), NOISE_SUBSAMPLE);
    let subsample: Vec<Vec3> = points.iter().step_by(step).copied().collect();
    let facing: Vec<Vec3> = normals.iter().step_by(step).copied().collect();
    let near = threads.run(|| KdTree::new(&subsample))?;
    let probe_step = spread_step(subsample.len(), NOISE_PROBES);
    let found: Vec<(Option<f64>, f32)> = threads.run(|| {
        (0..subsample.len())
            .into_par_iter()
            .step_by(probe_step)
            .map(|probe| noise_at(probe, &subsample, &facing, &near))
            .collect()
    });
    let mut levels: Vec<f64> = found.iter().filter_map(|f| f.0).collect();
    if levels.is_empty() || (levels.len() as f64) < NOISE_SHOWN * found.len() as f64 {
        return Ok(0.0);
    }
    levels.sort_by(f64::total_cmp);
    let level = levels[levels.len() / 2];
    // The cloud's spacing: the subsample's, over the square root of its share of the points.
    let mut gaps: Vec<f32> = found.iter().map(|f| f.1).filter(|g| g.is_finite()).collect();
    gaps.sort_by(f32::total_cmp);
    let spacing = f64::from(gaps.get(gaps.len() / 2).copied().unwrap_or(0.0))
        * (subsample.len() as f64 / points.len() as f64).sqrt();
    Ok(if level < NOISE_FLOOR * spacing { 0.0 } else { level as f32 })
}

/// The noise level the neighbourhoods of point `probe` of `points` (with normals `facing`, or
/// none) show, None where they show shape instead or are too few; and the distance from the
/// probe to its nearest other point (infinite when alone).
fn noise_at(probe: usize, points: &[Vec3], facing: &[Vec3], near: &KdTree) -> (Option<f64>, f32) {
    let side = facing.get(probe).copied().unwrap_or(Vec3::ZERO);
    let same_side = |i: usize| facing.get(i).is_none_or(|n| n.dot(side) >= 0.0);
    let (neighbours, distances): (Vec<Vec3>, Vec<f32>) = near
        .knn(points[probe], NOISE_SEARCHED)
        .iter()
        .filter(|n| same_side(n.index as usize))
        .take(NOISE_NEIGHBOURS[NOISE_NEIGHBOURS.len() - 1])
        .map(|n| (points[n.index as usize], n.distance_squared))
        .unzip();
    let gap = distances.iter().find(|&&d| d > 0.0).map_or(f32::INFINITY, |d| d.sqrt());
    (noise_in(&neighbours, &distances), gap)
}

/// The noise level that `neighbours` (nearest first, at squared `distances`) show; None where
/// they show shape instead, or are too few.
fn noise_in(neighbours: &[Vec3], distances: &[f32]) -> Option<f64> {
    let residual = |k: usize| quadratic_fit_residual(&neighbours[..k]);
    // The smallest neighbourhood wide enough decides: noise shows there as a plateau, or the
    // probe sees shape (a wider one would average a crease's or a facet pattern's error into
    // something that looks like noise).
    let (narrow, wider) = NOISE_NEIGHBOURS.windows(2).filter(|w| w[1] <= neighbours.len()).find_map(|w| {
        let narrow = residual(w[0])?;
        (f64::from(distances[w[0] - 1]).sqrt() >= NOISE_WIDTH * narrow).then_some((narrow, w[1]))
    })?;
    let wide = residual(wider)?;
    (wide <= NOISE_PLATEAU * narrow).then_some(wide)
}

/// The step that takes at most `n` of `len` items, evenly spread.
fn spread_step(len: usize, n: usize) -> usize {
    len.div_ceil(n.max(1)).max(1)
}

/// The RMS residual of the least-squares height field h = a u² + b uv + c v² + d u + e v + f
/// over the points' own best plane (u, v along it, h across), corrected for the six fitted
/// coefficients. None when there are too few points to leave a residual.
fn quadratic_fit_residual(points: &[Vec3]) -> Option<f64> {
    const TERMS: usize = 6;
    if points.len() <= 2 * TERMS {
        return None;
    }
    let centroid = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / points.len() as f64;
    let mut covariance = crate::linalg::Sym3::default();
    for p in points {
        covariance.add(&crate::linalg::Sym3::outer(p.as_dvec3() - centroid));
    }
    let (_, [u, v, n]) = covariance.eigen();
    // Coordinates scaled by the neighbourhood's size keep the normal equations well conditioned.
    let size = points.iter().map(|p| (p.as_dvec3() - centroid).length()).fold(0.0, f64::max);
    if size == 0.0 {
        return Some(0.0);
    }
    let local = |p: &Vec3| {
        let d = (p.as_dvec3() - centroid) / size;
        (d.dot(u), d.dot(v), d.dot(n))
    };
    let terms = |x: f64, y: f64| [x * x, x * y, y * y, x, y, 1.0];
    let mut normal_matrix = [[0.0f64; TERMS]; TERMS];
    let mut rhs = [0.0f64; TERMS];
    for p in points {
        let (x, y, h) = local(p);
        let t = terms(x, y);
        for i in 0..TERMS {
            rhs[i] += t[i] * h;
            for j in 0..TERMS {
                normal_matrix[i][j] += t[i] * t[j];
            }
        }
    }
    let coefficients = solve(normal_matrix, rhs)?;
    let squared: f64 = points
        .iter()
        .map(|p| {
            let (x, y, h) = local(p);
            let fitted: f64 = terms(x, y).iter().zip(&coefficients).map(|(t, c)| t * c).sum();
            (h - fitted).powi(2)
        })
        .sum();
    Some((squared / (points.len() - TERMS) as f64).sqrt() * size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes::{add_noise, icosphere, sample_surface, torus};

    fn level(cloud: &crate::mesh::Mesh) -> f32 {
        noise_level(&cloud.positions, cloud.normals.as_deref().unwrap_or(&[]), &Threads::new(2).unwrap()).unwrap()
    }

    /// Gaussian noise of a known deviation on curved surfaces (a sphere, a torus whose tube is a
    /// tenth of its size) is found within 15%, at 20k and 200k points; the same surfaces
    /// without noise read as nearly noiseless.
    #[test]
    fn the_noise_level_is_found_on_curved_surfaces() {
        for (surface, sigma) in [(icosphere(1.0, 6), 0.01f32), (torus(1.0, 0.2, 256, 64), 0.005)] {
            for count in [20_000, 200_000] {
                let clean = sample_surface(&surface, count, 7);
                let quiet = level(&clean);
                assert!(quiet < 0.1 * sigma, "{count} clean points: {quiet}");
                let mut noisy = clean.clone();
                add_noise(&mut noisy, sigma, 0.0, 3);
                let found = level(&noisy);
                assert!((found / sigma - 1.0).abs() < 0.15, "{count} points, noise {sigma}: found {found}");
            }
        }
    }

    /// A coarse polyhedron (an icosphere of 320 faces) sampled densely is flat facets meeting
    /// at creases: shape that a wide fit would take for noise of a few percent of its radius,
    /// but which shows as noise at only a few probes, so it reads as noiseless. With 1% noise
    /// added, that is found.
    #[test]
    fn a_facet_pattern_is_not_noise() {
        let faceted = sample_surface(&icosphere(1.0, 2), 200_000, 5);
        let found = level(&faceted);
        assert!(found < 1e-4, "facets read as noise {found}");
        let mut noisy = faceted.clone();
        add_noise(&mut noisy, 0.01, 0.0, 6);
        let found = level(&noisy);
        assert!((found / 0.01 - 1.0).abs() < 0.15, "noise 0.01 on facets: found {found}");
    }

    /// A quadratic over its own best plane (symmetric, so that plane is z = const) is fitted
    /// exactly; too few points leave no residual.
    #[test]
    fn a_quadratic_has_no_residual() {
        let points: Vec<Vec3> = (0..100)
            .map(|i| {
                let (x, y) = ((i % 10) as f32 * 0.1 - 0.45, (i / 10) as f32 * 0.1 - 0.45);
                Vec3::new(x, y, 0.3 * x * x - 0.2 * y * y)
            })
            .collect();
        let residual = quadratic_fit_residual(&points).unwrap();
        assert!(residual < 1e-6, "{residual}");
        assert_eq!(quadratic_fit_residual(&points[..12]), None);
    }
}
