//! The mesh handle: a triangle mesh or a point cloud (no triangles), made from the caller's
//! arrays or read from a file; its arrays are copied out into the caller's buffers.

use super::arrays::{self, copy_out, elements, input};
use super::{guard, guard_or, handle, non_null, vstree_status, write_out, Failure, FfiResult};
use crate::io::{self, assemble, Format, WriteOptions};
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use std::ffi::{c_char, c_void, CStr};
use std::path::{Path, PathBuf};

/// An immutable triangle mesh or point cloud (a mesh with no triangles), with optional
/// per-vertex normals. Opaque: made by vstree_mesh_create(), vstree_mesh_load() or
/// vstree_mesh_load_memory(), freed with vstree_mesh_free(). Results own meshes too
/// (vstree_simplify_result_get_mesh()); those are `const` and freed with their result.
///
/// A handle is never modified after it is made, so several threads may read or process the
/// same mesh at once; freeing it while another thread uses it is not allowed.
pub struct vstree_mesh {
    pub(crate) mesh: Mesh,
}

// Vertices cross the boundary as packed float triples; glam's Vec3 is exactly that.
const _: () = assert!(std::mem::size_of::<Vec3>() == 12 && std::mem::align_of::<Vec3>() == 4);
// Double positions too, as DVec3.
const _: () = assert!(std::mem::size_of::<DVec3>() == 24 && std::mem::align_of::<DVec3>() == 8);

/// `vstree_mesh_save` flag: write PLY as ASCII text instead of binary little-endian.
pub const VSTREE_SAVE_ASCII: u32 = 1;
const KNOWN_SAVE_FLAGS: u32 = VSTREE_SAVE_ASCII;

/// Borrows the mesh behind a handle that must not be NULL.
pub(crate) unsafe fn mesh_ref<'a>(mesh: *const vstree_mesh, argument: &str) -> FfiResult<&'a Mesh> {
    Ok(&unsafe { handle::borrow(mesh, argument) }?.mesh)
}

/// Boxes `mesh` into a new handle for the caller.
pub(crate) fn into_handle(mesh: Mesh) -> *mut vstree_mesh {
    handle::into_raw(vstree_mesh { mesh })
}

/// Copies a flat array of `3 × n` values into `n` triples in one `memcpy`.
fn triples<T: Copy, U: Copy>(flat: &[T], what: &str) -> FfiResult<Vec<U>> {
    const {
        assert!(std::mem::size_of::<U>() == 3 * std::mem::size_of::<T>());
        assert!(std::mem::align_of::<U>() == std::mem::align_of::<T>());
    }
    let n = flat.len() / 3;
    // SAFETY: U is three packed T with T's alignment (checked above at compile time), and
    // `flat` holds at least 3 × n elements.
    let as_triples = unsafe { std::slice::from_raw_parts(flat.as_ptr().cast::<U>(), n) };
    let mut out = arrays::with_capacity(n, what)?;
    out.extend_from_slice(as_triples);
    Ok(out)
}

/// Makes a mesh from the caller's arrays, which are copied (the caller keeps ownership of
/// them and may free them when the call returns). The new handle is written to `*out_mesh`
/// and belongs to the caller, who frees it with vstree_mesh_free().
///
/// - `positions`: 3 × `vertex_count` floats, x y z per vertex, finite and at most 1e18 in
///   magnitude (squares of coordinate differences must fit a float). `vertex_count` must be
///   at least 1 and at most 2^32 - 1. Coordinates far from the origin (georeferenced, say)
///   lose their detail in float: give them as doubles to vstree_mesh_create_f64().
/// - `normals`: NULL, or 3 × `vertex_count` floats, one normal per vertex (any length but
///   zero; they are normalised where used). Point clouds need normals to be simplified.
/// - `triangles`: 3 × `triangle_count` vertex indices (counter-clockwise seen from outside;
///   the winding is kept), each < `vertex_count`; may be NULL when `triangle_count` is 0,
///   which makes a point cloud. `triangle_count` at most 2^32 - 1.
///
/// Fails with VSTREE_STATUS_NULL_POINTER (a needed array or `out_mesh` is NULL),
/// VSTREE_STATUS_TOO_LARGE (a count beyond the limits), VSTREE_STATUS_INVALID_ARGUMENT (an
/// array misaligned for its type), VSTREE_STATUS_INVALID_INPUT (no vertex, a NaN or infinite
/// coordinate or normal, a coordinate beyond 1e18, an index out of range; the message names the first one) or
/// VSTREE_STATUS_OUT_OF_MEMORY. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_create(
    positions: *const f32,
    vertex_count: usize,
    normals: *const f32,
    triangles: *const u32,
    triangle_count: usize,
    out_mesh: *mut *mut vstree_mesh,
) -> vstree_status {
    guard("vstree_mesh_create", || unsafe {
        create(positions, vertex_count, normals, triangles, triangle_count, out_mesh, |p, n, t| {
            Ok(Mesh::new(triples::<f32, Vec3>(p, "positions")?, n, t))
        })
    })
}

/// Like vstree_mesh_create(), with the positions in double precision: 3 × `vertex_count`
/// doubles, x y z per vertex. They are kept as a file's are: a model far from the origin for
/// its size (more than 16 times its extent away, as georeferenced coordinates at 1e6 or 1e8
/// are) is stored in float relative to the centre of its bounding box, so its detail
/// survives, and vstree_mesh_copy_positions_f64() gives the positions back to within float
/// rounding of their distance to that centre; a model nearer the origin is stored as floats.
/// Results made from the mesh carry its origin, and vstree_mesh_save() writes them in double.
/// Since 0.5.0.
///
/// Fails like vstree_mesh_create(); a position is refused when it is NaN, infinite or beyond
/// 1e18 in magnitude (the message names the vertex and its coordinates), and `positions` must
/// be aligned to 8 bytes. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_create_f64(
    positions: *const f64,
    vertex_count: usize,
    normals: *const f32,
    triangles: *const u32,
    triangle_count: usize,
    out_mesh: *mut *mut vstree_mesh,
) -> vstree_status {
    guard("vstree_mesh_create_f64", || unsafe {
        create(positions, vertex_count, normals, triangles, triangle_count, out_mesh, |p, n, t| {
            let read = triples::<f64, DVec3>(p, "positions")?;
            let bad = read.iter().enumerate().find_map(|(i, &v)| assemble::finite_position(v).err().map(|m| (i, m)));
            if let Some((i, message)) = bad {
                return Err(crate::Error::input(format!("vertex {i} {message}")).into());
            }
            Ok(assemble::mesh(read, n, t))
        })
    })
}

/// What vstree_mesh_create() and vstree_mesh_create_f64() share: the counts, the caller's
/// arrays and the mesh's checks. `make` turns the borrowed positions, normals and triangles
/// into the mesh; the new handle goes to `*out_mesh`.
///
/// # Safety
/// The arrays hold the lengths the counts give (see vstree_mesh_create()).
#[allow(clippy::too_many_arguments)]
unsafe fn create<T>(
    positions: *const T,
    vertex_count: usize,
    normals: *const f32,
    triangles: *const u32,
    triangle_count: usize,
    out_mesh: *mut *mut vstree_mesh,
    make: impl FnOnce(&[T], Option<Vec<Vec3>>, Vec<[u32; 3]>) -> FfiResult<Mesh>,
) -> FfiResult {
    non_null(out_mesh, "out_mesh")?;
    let floats = elements(vertex_count, 3, "vertex_count")?;
    let indices = elements(triangle_count, 3, "triangle_count")?;
    if vertex_count == 0 {
        return Err(Failure::new(vstree_status::InvalidInput, "`vertex_count` is 0: a mesh needs at least one vertex"));
    }
    // SAFETY (all three): the caller gives arrays of the documented lengths.
    let positions = unsafe { input(positions, floats, "positions") }?;
    let normals = match normals.is_null() {
        true => None,
        false => Some(unsafe { input(normals, floats, "normals") }?),
    };
    let triangles = unsafe { input(triangles, indices, "triangles") }?;
    let mesh = make(
        positions,
        normals.map(|n| triples::<f32, Vec3>(n, "normals")).transpose()?,
        triples::<u32, [u32; 3]>(triangles, "triangles")?,
    )?;
    mesh.check()?;
    unsafe { write_out(out_mesh, into_handle(mesh)) };
    Ok(())
}

/// A path from a C string: any bytes on Unix, UTF-8 elsewhere.
pub(crate) unsafe fn path_arg(path: *const c_char, argument: &str) -> FfiResult<PathBuf> {
    let pointer = non_null(path, argument)?;
    // SAFETY: non-NULL; the caller gives a NUL-terminated string.
    let bytes = unsafe { CStr::from_ptr(pointer) }.to_bytes();
    if bytes.is_empty() {
        return Err(Failure::argument(argument, "the path is empty"));
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(bytes)))
    }
    #[cfg(not(unix))]
    {
        std::str::from_utf8(bytes)
            .map(PathBuf::from)
            .map_err(|_| Failure::argument(argument, "the path is not valid UTF-8"))
    }
}

/// Reads a mesh or point cloud from the file at `path` (NUL-terminated; UTF-8, or any bytes on
/// Unix), in the format its extension names: .ply (ASCII or binary), .obj, .off, .xyz or .pwn
/// (points with optional normals). The new handle is written to `*out_mesh`; the caller frees
/// it with vstree_mesh_free().
///
/// Only regular files are read (VSTREE_STATUS_IO for a device, FIFO or directory), and a file
/// whose first bytes are not of its format is refused before the rest is read.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (empty path),
/// VSTREE_STATUS_UNSUPPORTED_FORMAT, VSTREE_STATUS_IO, VSTREE_STATUS_PARSE (the message gives
/// the line or element) or VSTREE_STATUS_INVALID_INPUT (no vertices). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_load(path: *const c_char, out_mesh: *mut *mut vstree_mesh) -> vstree_status {
    guard("vstree_mesh_load", || {
        non_null(out_mesh, "out_mesh")?;
        let path = unsafe { path_arg(path, "path") }?;
        let mesh = io::read(&path)?;
        mesh.check()?;
        unsafe { write_out(out_mesh, into_handle(mesh)) };
        Ok(())
    })
}

/// Parses a mesh or point cloud from `size` bytes at `data` (a whole file held in memory; the
/// caller keeps ownership of it). `name` (NUL-terminated) is a file name whose extension picks
/// the format, such as "scan.ply", or just the extension ("ply"); it is also used in error
/// messages. The new handle is written to `*out_mesh`; the caller frees it with
/// vstree_mesh_free().
///
/// Fails like vstree_mesh_load() (except VSTREE_STATUS_IO); `data` may be NULL only when
/// `size` is 0. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_load_memory(
    data: *const c_void,
    size: usize,
    name: *const c_char,
    out_mesh: *mut *mut vstree_mesh,
) -> vstree_status {
    guard("vstree_mesh_load_memory", || {
        non_null(out_mesh, "out_mesh")?;
        let name = unsafe { path_arg(name, "name") }?;
        // "scan.ply" (or "part.step") names itself; a bare "ply" becomes "memory.ply".
        let name = match name.extension() {
            Some(_) => name,
            None => Path::new("memory").with_extension(&name),
        };
        let format = Format::from_path(&name).ok_or_else(|| crate::Error::UnsupportedFormat { path: name.clone() })?;
        if size > isize::MAX as usize {
            return Err(Failure::new(
                vstree_status::TooLarge,
                format!("`size` is {size}, more than any buffer can hold"),
            ));
        }
        // SAFETY: the caller gives `size` readable bytes at `data`.
        let bytes = unsafe { input(data.cast::<u8>(), size, "data") }?;
        let mesh = format.parse(bytes, &name)?;
        mesh.check()?;
        unsafe { write_out(out_mesh, into_handle(mesh)) };
        Ok(())
    })
}

/// Writes `mesh` to the file at `path` (NUL-terminated), in the format its extension names,
/// with normals when the mesh has them (OFF has none); point clouds are written without
/// faces. `flags`: 0, or VSTREE_SAVE_ASCII for text PLY. The file is replaced atomically: on
/// failure it is left as it was. As `cp` would: a symbolic link is followed to its target, a
/// file the process may not write is refused, and a replaced file keeps its permissions; only
/// regular files are replaced (never a device, FIFO or directory). A mesh far from the origin
/// (see vstree_mesh_copy_positions_f64()) is written with double coordinates. The caller keeps
/// ownership of `mesh`.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (empty path, unknown
/// flag bits), VSTREE_STATUS_UNSUPPORTED_FORMAT or VSTREE_STATUS_IO. Thread-safe (two threads
/// must not write the same path at once).
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_save(mesh: *const vstree_mesh, path: *const c_char, flags: u32) -> vstree_status {
    guard("vstree_mesh_save", || {
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let path = unsafe { path_arg(path, "path") }?;
        if flags & !KNOWN_SAVE_FLAGS != 0 {
            return Err(Failure::argument(
                "flags",
                format!("{flags:#x} has unknown bits (known: VSTREE_SAVE_ASCII = 1)"),
            ));
        }
        let options = WriteOptions { ascii: flags & VSTREE_SAVE_ASCII != 0 };
        io::write_with(&path, mesh, &options)?;
        Ok(())
    })
}

/// Frees a mesh made by vstree_mesh_create(), vstree_mesh_load() or vstree_mesh_load_memory().
/// NULL is a no-op. Never pass a mesh a result owns (vstree_simplify_result_get_mesh()), nor a
/// mesh another thread is using.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_free(mesh: *mut vstree_mesh) {
    unsafe { handle::free(mesh) }
}

/// The number of vertices (points, for a point cloud); 0 for NULL. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_vertex_count(mesh: *const vstree_mesh) -> usize {
    guard_or(0, || unsafe { mesh_ref(mesh, "mesh") }.map_or(0, |m| m.positions.len()))
}

/// The number of triangles (0 for a point cloud, and for NULL). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_triangle_count(mesh: *const vstree_mesh) -> usize {
    guard_or(0, || unsafe { mesh_ref(mesh, "mesh") }.map_or(0, |m| m.triangles.len()))
}

/// 1 if the mesh has per-vertex normals, 0 if not (or NULL). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_has_normals(mesh: *const vstree_mesh) -> i32 {
    guard_or(0, || unsafe { mesh_ref(mesh, "mesh") }.map_or(0, |m| i32::from(m.normals.is_some())))
}

fn flat(v: &[Vec3]) -> &[f32] {
    // SAFETY: Vec3 is three packed f32 (checked above), so the vector is 3 × len floats.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<f32>(), v.len() * 3) }
}

/// Copies the vertex positions into the caller's buffer `out` of `capacity` floats, which must
/// be at least 3 × vertex count (x y z per vertex). The caller owns `out`.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (misaligned `out`) or
/// VSTREE_STATUS_BUFFER_TOO_SMALL (nothing written). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_copy_positions(
    mesh: *const vstree_mesh,
    out: *mut f32,
    capacity: usize,
) -> vstree_status {
    guard("vstree_mesh_copy_positions", || {
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        if mesh.origin == glam::DVec3::ZERO {
            return unsafe { copy_out(flat(&mesh.positions), out, capacity, "out") };
        }
        let absolute: Vec<Vec3> = (0..mesh.positions.len()).map(|i| mesh.absolute(i).as_vec3()).collect();
        unsafe { copy_out(flat(&absolute), out, capacity, "out") }
    })
}

/// Copies the vertex positions, in double precision, into the caller's buffer `out` of
/// `capacity` doubles (at least 3 × vertex count). A model read from a file far from the
/// origin for its size (georeferenced coordinates, say) is stored relative to an origin of its
/// own; these are its exact absolute positions, where vstree_mesh_copy_positions() rounds them
/// to float. The caller owns `out`. Since 0.1.2.
///
/// Fails like vstree_mesh_copy_positions(). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_copy_positions_f64(
    mesh: *const vstree_mesh,
    out: *mut f64,
    capacity: usize,
) -> vstree_status {
    guard("vstree_mesh_copy_positions_f64", || {
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let absolute: Vec<f64> = (0..mesh.positions.len()).flat_map(|i| mesh.absolute(i).to_array()).collect();
        unsafe { copy_out(&absolute, out, capacity, "out") }
    })
}

/// Copies the per-vertex normals into the caller's buffer `out` of `capacity` floats, which
/// must be at least 3 × vertex count. The caller owns `out`.
///
/// Fails like vstree_mesh_copy_positions(), and with VSTREE_STATUS_INVALID_ARGUMENT when the
/// mesh has no normals (see vstree_mesh_has_normals()). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_copy_normals(
    mesh: *const vstree_mesh,
    out: *mut f32,
    capacity: usize,
) -> vstree_status {
    guard("vstree_mesh_copy_normals", || {
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let normals = mesh
            .normals
            .as_deref()
            .ok_or_else(|| Failure::argument("mesh", "has no normals (see vstree_mesh_has_normals)"))?;
        unsafe { copy_out(flat(normals), out, capacity, "out") }
    })
}

/// Copies the triangles' vertex indices into the caller's buffer `out` of `capacity` uint32
/// values, which must be at least 3 × triangle count. The caller owns `out`. A point cloud has
/// no triangles: nothing is copied and `out` may be NULL.
///
/// Fails like vstree_mesh_copy_positions(). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_mesh_copy_triangles(
    mesh: *const vstree_mesh,
    out: *mut u32,
    capacity: usize,
) -> vstree_status {
    guard("vstree_mesh_copy_triangles", || {
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        // SAFETY: [u32; 3] is three packed u32.
        let indices =
            unsafe { std::slice::from_raw_parts(mesh.triangles.as_ptr().cast::<u32>(), mesh.triangles.len() * 3) };
        unsafe { copy_out(indices, out, capacity, "out") }
    })
}
