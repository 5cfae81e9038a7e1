//! The base mesh's implicit function, negative inside: by default the samples' winding number
//! ([`winding`]) says the side and the distance to the nearest sample gives the value
//! ([`BaseMesh::Winding`], [`BaseMesh::Adaptive`]); the paper's blend of the T-nodes' planes
//! ([`implicit`]) is [`BaseMesh::Paper`].

use super::lookup::Lookup;
use super::{implicit, winding, BaseMesh};
use crate::spatial::KdTree;
use crate::tree::VsTree;
use glam::Vec3;
use std::sync::atomic::{AtomicUsize, Ordering};

/// T-node supports in the paper's construction (`BaseMesh::Paper` only): balls of this many
/// times the cube's half diagonal. MPU's α = 0.75 of the full diagonal would be 1.5; wider
/// supports average out the planes of small, noisy T-nodes. Measured on the 24 closed models at
/// 200k clean points (`cargo bench --bench corpus -- --base-mesh paper --sizes 200000 --variants
/// clean --no-synthetic`): genus and components right on 14 with 2.0, 11 with 1.5 (six models
/// gain handles, two lose spurious openings).
const SUPPORT_SCALE: f32 = 2.0;
/// Beyond this many units (see [`Field::new`]) from every sample, the implicit function is
/// pushed away from zero, outward or inward as the winding number says.
const FAR_FROM_SAMPLES: f32 = 1.5;
/// Beyond this many units from every sample, the winding number alone decides inside or
/// outside. Behind an open scan the winding number falls below one half towards the scan's
/// border, which closes the surface into a thin shell (which trimming opens again).
const OUTSIDE_BEYOND: f32 = 4.0;
/// Where the output is open (asked for, or an open scan found), inside is where the winding
/// number exceeds this rather than one half. Behind a scan from one side the winding number
/// stays below one half, so the half threshold closes the scan with a thin shell just behind
/// it, too close to be cut off and ragged where the number wavers around one half; a quarter
/// puts the closing sheet farther back. Measured on the corpus bench's six open inputs (a
/// hemisphere at 10k and 200k points, single views of four meshes), Chamfer to the truth:
/// better on five, by 1.3-2.8x (worse on bear, 0.016% against 0.014% of the diagonal). Pinned by
/// the test `a_scan_from_one_side_leaves_no_sheet_behind_it` (a torus's upper half).
const OPEN_SCAN_INSIDE: f32 = 0.25;
/// The winding number's dipoles are softened over this many sample spacings (see
/// [`winding::WindingNumber::softened`]): within a spacing of the samples the cloud cannot
/// tell the surface from its samples, and an unsoftened sum there swings with the nearest one.
const WINDING_SOFTENING: f32 = 1.0;
/// Where the output may be open, a winding number within this of one half next to the samples
/// is in doubt, and the nearest samples' tangent planes decide the side instead: about 1
/// inside and 0 outside a closed surface, it sinks towards 0 near the border of an open scan.
const WINDING_DOUBT: f32 = 0.25;

/// What decides the value near the samples.
enum Kind<'a> {
    /// The distance to the nearest sample.
    Distance,
    /// The blended T-node planes ([`BaseMesh::Paper`]).
    Planes(implicit::PlaneBlend<'a>),
}

/// The implicit function of one kind of base mesh, counting its evaluations.
pub(super) struct Field<'a> {
    kind: Kind<'a>,
    near: &'a Lookup<'a>,
    winding: winding::WindingNumber<'a>,
    /// Within this distance of the samples, planes (the T-nodes', or near an open scan's
    /// border the samples' own) may decide the side; see [`FAR_FROM_SAMPLES`].
    planes_within: f32,
    /// Beyond this distance from every sample only the winding number's side counts.
    side_only_beyond: f32,
    evaluations: AtomicUsize,
}

impl<'a> Field<'a> {
    /// Distances from the samples count in `unit`s (the polygonisation's grid cell or the
    /// sample spacing, whichever is larger); the planes are blended over `grid_cell`s.
    pub fn new(tree: &'a VsTree, near: &'a Lookup<'a>, kind: BaseMesh, unit: f32, grid_cell: f32) -> Field<'a> {
        // A sparse cloud's leaves are smaller than the surface their few samples stand for: each
        // sample stands for at least a square of the spacing (exactly that on a regular grid).
        let spacing = near.spacing;
        let (softening, min_sample_area) = match kind {
            BaseMesh::Winding | BaseMesh::Adaptive => (WINDING_SOFTENING * spacing, spacing * spacing),
            BaseMesh::Paper => (0.0, 0.0),
        };
        Field {
            kind: match kind {
                BaseMesh::Winding | BaseMesh::Adaptive => Kind::Distance,
                BaseMesh::Paper => Kind::Planes(implicit::PlaneBlend::new(tree, SUPPORT_SCALE, 1.5 * grid_cell)),
            },
            near,
            winding: winding::WindingNumber::new(tree, min_sample_area).softened(softening),
            planes_within: FAR_FROM_SAMPLES * unit,
            side_only_beyond: OUTSIDE_BEYOND * unit.max(near.typical_t_half),
            evaluations: AtomicUsize::new(0),
        }
    }

    /// The points where the function was evaluated so far.
    pub fn evaluations(&self) -> usize {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// The function at `p`, for a closed output or an `open` one.
    pub fn at(&self, p: Vec3, open: bool) -> f32 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let inside_above = if open { OPEN_SCAN_INSIDE } else { 0.5 };
        let index = self.near.index();
        match &self.kind {
            Kind::Distance => {
                let d = index.distance_within(p, self.side_only_beyond).min(self.side_only_beyond);
                let w = self.winding.at(p);
                let inside = if open && d <= self.planes_within && (w - 0.5).abs() < WINDING_DOUBT {
                    // Next to the samples where the winding number is in doubt (an open scan's
                    // falls towards its border, so its level set leaves the samples there), their
                    // own tangent planes tell the side. Not for a closed output: there the level
                    // set may leave an open scan's border, since the scan is closed over anyway,
                    // and the planes of noisy or thin parts would add handles.
                    self.near.fit.plane_side(p) < 0.0
                } else {
                    w > inside_above
                };
                if inside {
                    -d
                } else {
                    d
                }
            }
            Kind::Planes(blend) => self.paper(p, index, blend, inside_above),
        }
    }

    /// The paper's function ([`BaseMesh::Paper`]): within `planes_within` of the samples the
    /// blended T-node planes; farther out the winding number's side, pushed away from zero with
    /// the distance, the planes only allowed to push further that way; beyond
    /// `side_only_beyond` the side alone.
    fn paper(&self, p: Vec3, index: &KdTree, blend: &implicit::PlaneBlend, inside_above: f32) -> f32 {
        if index.any_within(p, self.planes_within) {
            return blend.eval(p);
        }
        let side = if self.winding.at(p) > inside_above { -1.0 } else { 1.0 };
        let d = index.distance_within(p, self.side_only_beyond);
        let blended = if d <= self.side_only_beyond { blend.eval(p) } else { f32::MAX };
        if blended == f32::MAX {
            side * f32::MAX
        } else if side > 0.0 {
            // Otherwise planes that run on past a thin part bulge into the outside, and a bulge
            // that meets another part adds a handle.
            blended.max(0.0) + (d - self.planes_within)
        } else {
            blended.min(0.0) - (d - self.planes_within)
        }
    }
}
