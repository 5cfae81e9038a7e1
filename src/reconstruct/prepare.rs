//! Stage 0: the cloud as oriented samples at unit size. Isolated points are left out, normals
//! estimated where the cloud has none, and given normals that all point inward turned out.

use super::support::Closure;
use super::{outliers, params::ReconstructParams, ReconstructStats, MIN_POINTS};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::normals::{self, NormalParams, OrientReport};
use crate::progress::{Progress, Threads};
use crate::samples::SampleSet;
use glam::Vec3;

/// Given normals whose flux of `p - c` (`c` the centroid) is below this share of its absolute
/// sum point inward, and a reconstruction that may close flips them all. Through a closed surface's
/// outward normals that flux is 3 times its volume (the divergence theorem), so positive
/// whatever the shape: measured +0.7 to +1 on outward clouds, -0.92 on an inward armadillo.
const INWARD_FLUX: f64 = -0.5;

/// The oriented samples of `cloud`, scaled by the returned factor (see [`unit_scale`]).
pub(super) fn oriented_samples(
    cloud: &Mesh,
    params: &ReconstructParams,
    threads: &Threads,
    stats: &mut ReconstructStats,
    progress: &mut Progress,
) -> Result<(SampleSet, f32)> {
    if cloud.positions.len() < MIN_POINTS {
        return Err(Error::input(format!("{} points: at least {MIN_POINTS} are needed", cloud.positions.len())));
    }
    crate::mesh::check_positions(&cloud.positions, "point")?;
    normals::refuse_flat(&cloud.positions, threads)?;
    // The work is done at unit size, so that no tolerance depends on the cloud's units: once
    // for the whole cloud, and again without its isolated points.
    let mut scale = unit_scale(&cloud.positions);
    let mut positions: Vec<Vec3> = cloud.positions.iter().map(|&p| p * scale).collect();
    let mut given_normals = cloud.normals.clone();
    let isolated = outliers::isolated_points(&positions, threads)?;
    stats.isolated_points = isolated.iter().filter(|&&i| i).count();
    if stats.isolated_points > 0 {
        keep_unmarked(&mut positions, &isolated);
        given_normals.iter_mut().for_each(|n| keep_unmarked(n, &isolated));
        if positions.len() < MIN_POINTS {
            return Err(Error::input(format!(
                "{} points once {} isolated ones are left out: at least {MIN_POINTS} are needed",
                positions.len(),
                stats.isolated_points
            )));
        }
        let rescale = unit_scale(&positions);
        positions.iter_mut().for_each(|p| *p *= rescale);
        scale *= rescale;
    }
    let mut oriented = Mesh::from_points(positions, given_normals);
    let normal_params = NormalParams { threads: params.threads, ..params.normals };
    stats.normals = normals::ensure_normals(&mut oriented, &normal_params, progress)?;
    let kept_given = stats.normals.estimated == 0 && stats.normals.orient.is_none();
    // Only a closed surface's normals have a flux of a known sign. `Auto` flips too: a closed
    // cloud with inward normals has no inside and fails, while an open scan whose normals
    // all face a common centre (the inside of a bowl) at worst comes out facing the other way.
    if kept_given && params.closure != Closure::Open {
        if let Some(flipped) = turn_inward_normals_out(&mut oriented) {
            let points = oriented.positions.len();
            stats.normals.orient =
                Some(OrientReport { components: 1, largest_component: points, undecided_components: 0, flipped });
        }
    }
    Ok((SampleSet::from_cloud(&oriented)?, scale))
}

/// Keeps the items of `items` whose mark is false, in order.
pub(super) fn keep_unmarked<T>(items: &mut Vec<T>, marks: &[bool]) {
    let mut mark = marks.iter();
    items.retain(|_| !*mark.next().unwrap_or(&false));
}

/// The power of two that brings the bounding box's diagonal of `points` to between 1/√2 and √2.
/// Reconstruction runs on the scaled cloud: tolerances fixed in f32 (a normal too short to
/// trust, a cell too small to split, a squared distance that underflows or loses its digits)
/// would otherwise depend on the units, and a cloud 1e-15 or 1e17 across fails where the same
/// cloud at unit size does not. A power of two scales every f32 exactly, both ways.
fn unit_scale(points: &[Vec3]) -> f32 {
    let diagonal = crate::mesh::Aabb::of(points).map_or(1.0, |b| f64::from(b.diagonal()));
    if !(diagonal.is_finite() && diagonal > 0.0) {
        return 1.0;
    }
    2f32.powi(-(diagonal.log2().round() as i32))
}

/// Flips every normal of `cloud` when together they point inward (see [`INWARD_FLUX`]);
/// returns how many were flipped.
fn turn_inward_normals_out(cloud: &mut Mesh) -> Option<usize> {
    let normals = cloud.normals.as_mut()?;
    let n = cloud.positions.len().max(1) as f64;
    let centroid = cloud.positions.iter().map(|p| p.as_dvec3()).sum::<glam::DVec3>() / n;
    let (flux, absolute) = cloud.positions.iter().zip(normals.iter()).fold((0.0, 0.0), |(f, a), (p, m)| {
        let d = m.as_dvec3().dot(p.as_dvec3() - centroid);
        (f + d, a + d.abs())
    });
    if !(absolute > 0.0 && flux < INWARD_FLUX * absolute) {
        return None;
    }
    normals.iter_mut().for_each(|m| *m = -*m);
    Some(normals.len())
}
