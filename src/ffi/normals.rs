//! Normal estimation: the parameter struct (whose fields vstree_reconstruct_params repeats),
//! the call, which gives a new mesh handle (handles are immutable), and its report.

use super::mesh::{into_handle, mesh_ref, vstree_mesh};
use super::params::{self, constant_field, flag, threads, Versioned};
use super::progress::{vstree_progress_fn, with_progress};
use super::{guard, non_null, vstree_status, write_out, Failure, FfiResult};
use crate::mesh::Mesh;
use crate::normals::{self, NormalParams, NormalsReport, Orientation, DEFAULT_NEIGHBOURS};
use std::ffi::c_void;
use std::mem::size_of;

/// `orient` value: no orientation; estimated normals keep the arbitrary sign a plane fit gives
/// them, and given normals are left as they are.
pub const VSTREE_ORIENTATION_UNORIENTED: i32 = 0;
/// `orient` value: Hoppe's spanning-tree propagation; in each connected part of the neighbour
/// graph, the normal at the highest point (largest z) points up (+z). For terrain and scans
/// taken from above.
pub const VSTREE_ORIENTATION_PROPAGATE: i32 = 1;
/// `orient` value: propagation, then each connected part keeps the sign most of its given
/// normals already have. For given normals that are mostly right but locally inconsistent.
pub const VSTREE_ORIENTATION_PROPAGATE_MAJORITY: i32 = 2;
/// `orient` value: propagation, then each connected part is turned to face outward (closed
/// shapes of any genus come out outward; an open scan faces its convex side). The default.
pub const VSTREE_ORIENTATION_PROPAGATE_OUTWARD: i32 = 3;

/// Reads an `orient` field.
pub(crate) fn orientation(value: i32) -> FfiResult<Orientation> {
    constant_field(
        "orient",
        value,
        &[
            (VSTREE_ORIENTATION_UNORIENTED, "VSTREE_ORIENTATION_UNORIENTED", Orientation::Unoriented),
            (VSTREE_ORIENTATION_PROPAGATE, "VSTREE_ORIENTATION_PROPAGATE", Orientation::Propagate),
            (
                VSTREE_ORIENTATION_PROPAGATE_MAJORITY,
                "VSTREE_ORIENTATION_PROPAGATE_MAJORITY",
                Orientation::PropagateMajority,
            ),
            (
                VSTREE_ORIENTATION_PROPAGATE_OUTWARD,
                "VSTREE_ORIENTATION_PROPAGATE_OUTWARD",
                Orientation::PropagateOutward,
            ),
        ],
    )
}

/// The C value of an orientation.
pub(crate) fn orientation_value(orient: Orientation) -> i32 {
    match orient {
        Orientation::Unoriented => VSTREE_ORIENTATION_UNORIENTED,
        Orientation::Propagate => VSTREE_ORIENTATION_PROPAGATE,
        Orientation::PropagateMajority => VSTREE_ORIENTATION_PROPAGATE_MAJORITY,
        Orientation::PropagateOutward => VSTREE_ORIENTATION_PROPAGATE_OUTWARD,
    }
}

/// Parameters of vstree_estimate_normals(). Always start from vstree_normal_params_default()
/// and change fields by name: it sets `struct_size`, and fields added in later versions then
/// keep their defaults. Passing NULL means the defaults. The struct has no padding; every field
/// is checked, and an out-of-range one fails the call with VSTREE_STATUS_INVALID_PARAMETER and
/// a message naming it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct vstree_normal_params {
    /// Size of this struct in bytes as the caller knows it; set by the _default() function.
    pub struct_size: u32,
    /// How normals get their signs: a VSTREE_ORIENTATION_* value. Default
    /// VSTREE_ORIENTATION_PROPAGATE_OUTWARD.
    pub orient: i32,
    /// Neighbours per point the plane is fitted to (the point itself not counted), in [3, 256];
    /// default 16. More smooths noise but blurs thin features; time grows about linearly. A
    /// cloud with fewer points uses all its other points.
    pub neighbours: u32,
    /// 0 (default): normals the mesh already has are kept as they are, and only missing (all,
    /// or zero-length) ones are estimated. 1: given normals are re-oriented with `orient` too.
    pub reorient_given: u32,
    /// Worker threads: 0 = all cores (default), else at most 1024. Results do not depend on it.
    pub threads: u32,
}

unsafe impl Versioned for vstree_normal_params {
    const NAME: &'static str = "vstree_normal_params";
    const MIN_SIZE: usize = 20;
    fn defaults() -> Self {
        let d = NormalParams::default();
        vstree_normal_params {
            struct_size: size_of::<Self>() as u32,
            orient: orientation_value(d.orient),
            neighbours: DEFAULT_NEIGHBOURS as u32,
            reorient_given: u32::from(d.reorient_given),
            threads: 0,
        }
    }
}

/// The default parameters, with `struct_size` set. Thread-safe; returns a value (nothing to
/// free).
#[no_mangle]
pub extern "C" fn vstree_normal_params_default() -> vstree_normal_params {
    vstree_normal_params::defaults()
}

/// Reads and checks the caller's parameters (NULL: defaults), naming any bad field.
pub(crate) unsafe fn read_normal_params(pointer: *const vstree_normal_params) -> FfiResult<NormalParams> {
    let p = unsafe { params::read(pointer, "params") }?;
    let normal_params = NormalParams {
        neighbours: p.neighbours as usize,
        orient: orientation(p.orient)?,
        reorient_given: flag("reorient_given", p.reorient_given)?,
        threads: threads(p.threads)?,
    };
    normal_params.check()?;
    Ok(normal_params)
}

/// What vstree_estimate_normals() did. The caller provides it: set `struct_size` to
/// `sizeof(vstree_normals_report)` before the call; on success the library fills as many
/// fields as both it and the caller know and sets `struct_size` to the bytes it filled. Later
/// versions only add fields at the end.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct vstree_normals_report {
    /// In: the size of the caller's struct in bytes. Out: the bytes the library filled.
    pub struct_size: u32,
    /// 1 when an orientation was done (normals estimated with an `orient` other than
    /// VSTREE_ORIENTATION_UNORIENTED, or `reorient_given`), else 0 and the four orientation
    /// counts below are 0.
    pub oriented: u32,
    /// Normals that were estimated: all of them when the mesh had none, the zero-length ones
    /// when only some were, 0 when the given normals were kept or only re-oriented.
    pub estimated: u64,
    /// Neighbours per point actually used (fewer than asked for tiny clouds; 0 when nothing
    /// was estimated or oriented).
    pub neighbours: u64,
    /// Estimated points whose neighbourhood spans no plane (all equal or on a line); they took
    /// the normal of their nearest neighbour that has one.
    pub degenerate: u64,
    /// Connected parts of the neighbour graph, each oriented on its own.
    pub components: u64,
    /// Points in the largest connected part.
    pub largest_component: u64,
    /// Parts the outward test could not decide (no measurable flux): oriented by the +z rule.
    pub undecided_components: u64,
    /// Normals whose sign was changed by the orientation.
    pub flipped: u64,
}

/// The report of a [`NormalsReport`], with `struct_size` the full size.
pub(crate) fn report(r: &NormalsReport) -> vstree_normals_report {
    let o = r.orient.unwrap_or_default();
    vstree_normals_report {
        struct_size: size_of::<vstree_normals_report>() as u32,
        oriented: u32::from(r.orient.is_some()),
        estimated: r.estimated as u64,
        neighbours: r.neighbours as u64,
        degenerate: r.degenerate as u64,
        components: o.components as u64,
        largest_component: o.largest_component as u64,
        undecided_components: o.undecided_components as u64,
        flipped: o.flipped as u64,
    }
}

/// The size of the first published report: the smallest `struct_size` accepted.
const REPORT_MIN_SIZE: usize = 64;

/// Checks a caller's report struct before any work: aligned, and a `struct_size` of at least
/// the first published layout. Returns how many bytes may be written.
unsafe fn report_room(out: *mut vstree_normals_report) -> FfiResult<usize> {
    if (out as usize) % std::mem::align_of::<vstree_normals_report>() != 0 {
        return Err(Failure::argument("out_report", "pointer is misaligned"));
    }
    // SAFETY: non-NULL (checked by the caller) and aligned; the struct begins with a u32.
    let size = unsafe { out.cast::<u32>().read() } as usize;
    if size < REPORT_MIN_SIZE {
        return Err(Failure::argument(
            "out_report->struct_size",
            format!("{size}: set it to sizeof(vstree_normals_report) before the call"),
        ));
    }
    Ok(size.min(size_of::<vstree_normals_report>()))
}

/// Writes the first `room` bytes of `value` at `out`, with `struct_size` = `room`.
unsafe fn write_report(out: *mut vstree_normals_report, mut value: vstree_normals_report, room: usize) {
    value.struct_size = room as u32;
    // SAFETY: `out` has `room` writable bytes (checked by report_room) and `value` has at least
    // as many.
    unsafe {
        std::ptr::copy_nonoverlapping((&value as *const vstree_normals_report).cast::<u8>(), out.cast::<u8>(), room)
    };
}

/// Estimates and orients normals: gives a copy of `mesh` (its positions and triangles) whose
/// normals are the given ones where kept and estimated ones where missing. Triangles are
/// ignored by the estimation: the vertices are treated as a point cloud (a plane fitted to each
/// point's `params->neighbours` nearest neighbours, then signs chosen by `params->orient`).
///
/// - A mesh without normals, or whose normals are all zero: every normal is estimated.
/// - A mesh with normals: they are kept (then the copy is equal to `mesh`), or re-oriented
///   when `params->reorient_given` is 1; zero-length ones are estimated and take the sign of
///   their neighbours.
///
/// Estimated and re-oriented normals are unit length. Mesh handles are immutable, so `mesh` is
/// never changed: on success a new mesh is written to `*out_mesh` and belongs to the caller,
/// who frees it with vstree_mesh_free() (and may free `mesh` at once). `out_report` may be
/// NULL; if not, set its `struct_size` first (see ::vstree_normals_report); it is written on
/// success only. `params` NULL means the defaults. `progress` (may be NULL) is called with
/// `user_data` from the calling thread; returning 0 from it cancels.
///
/// Fails with VSTREE_STATUS_NULL_POINTER (`mesh`, `out_mesh`), VSTREE_STATUS_INVALID_ARGUMENT
/// (bad `params->struct_size` or `out_report->struct_size`), VSTREE_STATUS_INVALID_PARAMETER,
/// VSTREE_STATUS_INVALID_INPUT (fewer than 3 points, all points equal or on one line),
/// VSTREE_STATUS_OUT_OF_MEMORY or VSTREE_STATUS_CANCELLED; nothing is written then.
/// Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_estimate_normals(
    mesh: *const vstree_mesh,
    params: *const vstree_normal_params,
    progress: vstree_progress_fn,
    user_data: *mut c_void,
    out_mesh: *mut *mut vstree_mesh,
    out_report: *mut vstree_normals_report,
) -> vstree_status {
    guard("vstree_estimate_normals", || {
        non_null(out_mesh, "out_mesh")?;
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let params = unsafe { read_normal_params(params) }?;
        let room = match out_report.is_null() {
            true => 0,
            false => unsafe { report_room(out_report) }?,
        };
        let mut copy = Mesh {
            positions: copy_of(&mesh.positions, "positions")?,
            normals: mesh.normals.as_ref().map(|n| copy_of(n, "normals")).transpose()?,
            triangles: copy_of(&mesh.triangles, "triangles")?,
            origin: mesh.origin,
        };
        let r = with_progress(progress, user_data, |p| normals::ensure_normals(&mut copy, &params, p))?;
        if room > 0 {
            unsafe { write_report(out_report, report(&r), room) };
        }
        unsafe { write_out(out_mesh, into_handle(copy)) };
        Ok(())
    })
}

/// A copy of `data`, OUT_OF_MEMORY instead of an abort when it cannot be allocated.
fn copy_of<T: Copy>(data: &[T], what: &str) -> FfiResult<Vec<T>> {
    let mut out = super::arrays::with_capacity(data.len(), what)?;
    out.extend_from_slice(data);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::offset_of;

    #[test]
    fn layouts_have_no_padding() {
        assert_eq!(size_of::<vstree_normal_params>(), 20);
        assert_eq!(offset_of!(vstree_normal_params, threads), 16);
        assert_eq!(size_of::<vstree_normals_report>(), 8 + 7 * 8);
        assert_eq!(offset_of!(vstree_normals_report, estimated), 8);
        assert_eq!(size_of::<vstree_normals_report>(), REPORT_MIN_SIZE);
    }

    #[test]
    fn every_field_is_checked_by_name() {
        type Spoil = fn(&mut vstree_normal_params);
        let cases: [(&str, Spoil); 6] = [
            ("orient", |p| p.orient = 4),
            ("orient", |p| p.orient = -1),
            ("neighbours", |p| p.neighbours = 2),
            ("neighbours", |p| p.neighbours = 257),
            ("reorient_given", |p| p.reorient_given = 2),
            ("threads", |p| p.threads = 1025),
        ];
        for (field, spoil) in cases {
            let mut p = vstree_normal_params_default();
            spoil(&mut p);
            let e = unsafe { read_normal_params(&p) }.unwrap_err();
            assert_eq!(e.status, vstree_status::InvalidParameter, "{field}");
            assert!(e.message.contains(&format!("`{field}`")), "{}", e.message);
        }
        assert_eq!(unsafe { read_normal_params(std::ptr::null()) }.unwrap(), NormalParams::default());
    }
}
