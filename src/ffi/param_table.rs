//! The parameter table ([`crate::params`]) for C: hosts build their dialogs from it (labels,
//! defaults, ranges, units, descriptions, choices) instead of keeping copies of their own, and
//! the rules every host needs (a ratio to a face count, a distance to an L2 bound, why a size
//! was missed) are here once.

use super::simplify::vstree_simplify_stats;
use super::{guard, guard_or, non_null, vstree_status, write_out, Failure};
use crate::params::{self, Call, PARAMS};
use std::ffi::{c_char, CStr, CString};
use std::sync::OnceLock;

/// Which call a parameter belongs to: its struct is ::vstree_simplify_params.
pub const VSTREE_CALL_SIMPLIFY: i32 = 0;
/// ::vstree_reconstruct_params.
pub const VSTREE_CALL_RECONSTRUCT: i32 = 1;
/// ::vstree_normal_params.
pub const VSTREE_CALL_NORMALS: i32 = 2;

/// A real number within the range.
pub const VSTREE_PARAM_REAL: i32 = 0;
/// A whole number within the range.
pub const VSTREE_PARAM_INTEGER: i32 = 1;
/// 0 (off) or 1 (on).
pub const VSTREE_PARAM_FLAG: i32 = 2;
/// One of the parameter's choices (vstree_param_choice_get()), by its value.
pub const VSTREE_PARAM_CHOICE: i32 = 3;

// The numbers are the table's own.
const _: () = assert!(
    VSTREE_CALL_SIMPLIFY == Call::Simplify as i32
        && VSTREE_CALL_RECONSTRUCT == Call::Reconstruct as i32
        && VSTREE_CALL_NORMALS == Call::Normals as i32
        && VSTREE_PARAM_REAL == params::Kind::Real as i32
        && VSTREE_PARAM_INTEGER == params::Kind::Integer as i32
        && VSTREE_PARAM_FLAG == params::Kind::Flag as i32
        && VSTREE_PARAM_CHOICE == params::Kind::Choice as i32
);

/// One parameter of a call, as vstree_param_get() gives it. Static: never to be freed, valid
/// as long as the library is loaded. Later versions only add fields at the end, and
/// `struct_size` says how many there are.
#[repr(C)]
pub struct vstree_param_info {
    /// Size of this struct in bytes as the library filled it.
    pub struct_size: u32,
    /// The call: VSTREE_CALL_SIMPLIFY, VSTREE_CALL_RECONSTRUCT or VSTREE_CALL_NORMALS.
    pub call: i32,
    /// VSTREE_PARAM_REAL, VSTREE_PARAM_INTEGER, VSTREE_PARAM_FLAG or VSTREE_PARAM_CHOICE.
    pub kind: i32,
    /// Choices (VSTREE_PARAM_CHOICE), 0 otherwise.
    pub choice_count: u32,
    /// The field's name in the call's struct (and the Python keyword), e.g. "error".
    pub name: *const c_char,
    /// The command line's flag without its dashes ("" where none sets this field alone).
    pub flag: *const c_char,
    /// A short label for a dialog, e.g. "Error bound".
    pub label: *const c_char,
    /// What the value counts in, e.g. "triangles" ("" for a choice or a plain number).
    pub unit: *const c_char,
    /// What the parameter does: one paragraph of English for a tooltip.
    pub help: *const c_char,
    /// The value the call's _default() function sets (a choice's value, a flag's 0 or 1).
    pub default_value: f64,
    /// The range: `min` to `max`, each end included unless `min_open`/`max_open` is 1;
    /// `max` is INFINITY where there is no upper end (a value must still be finite).
    pub min: f64,
    pub max: f64,
    pub min_open: u32,
    pub max_open: u32,
}

/// One value of a choice parameter (vstree_param_choice_get()). Static, as
/// ::vstree_param_info.
#[repr(C)]
pub struct vstree_param_choice {
    /// Size of this struct in bytes as the library filled it.
    pub struct_size: u32,
    /// The number the struct's field holds for it.
    pub value: i32,
    /// Its name as the command line and the bindings take it, e.g. "adaptive".
    pub name: *const c_char,
    /// A short label for a dialog.
    pub label: *const c_char,
    /// What it does.
    pub help: *const c_char,
}

/// The table in C form, made once; its strings live as long as the library.
struct CTable {
    params: Vec<vstree_param_info>,
    choices: Vec<Vec<vstree_param_choice>>,
    _strings: Vec<CString>,
}

// SAFETY: the raw pointers point into `_strings`, which is never changed after construction,
// and the structs are only ever read.
unsafe impl Sync for CTable {}
unsafe impl Send for CTable {}

fn table() -> &'static CTable {
    static TABLE: OnceLock<CTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut strings = Vec::new();
        // A CString's buffer does not move when the CString does.
        let mut keep = |text: &str| {
            let owned = CString::new(text).expect("the table's texts hold no NUL byte");
            let pointer = owned.as_ptr();
            strings.push(owned);
            pointer
        };
        let mut params = Vec::new();
        let mut choices = Vec::new();
        for p in PARAMS {
            params.push(vstree_param_info {
                struct_size: std::mem::size_of::<vstree_param_info>() as u32,
                call: p.call as i32,
                kind: p.kind as i32,
                choice_count: p.choices.len() as u32,
                name: keep(p.name),
                flag: keep(p.flag.unwrap_or("")),
                label: keep(p.label),
                unit: keep(p.unit),
                help: keep(p.help),
                default_value: p.default,
                min: p.min,
                max: p.max,
                min_open: p.min_open.into(),
                max_open: p.max_open.into(),
            });
            choices.push(
                p.choices
                    .iter()
                    .map(|c| vstree_param_choice {
                        struct_size: std::mem::size_of::<vstree_param_choice>() as u32,
                        value: c.value,
                        name: keep(c.name),
                        label: keep(c.label),
                        help: keep(c.help),
                    })
                    .collect(),
            );
        }
        CTable { params, choices, _strings: strings }
    })
}

/// How many parameters the table has (every call's together). Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_param_count() -> u32 {
    PARAMS.len() as u32
}

/// Parameter `index` (0 to vstree_param_count() - 1), in each call's struct field order; NULL
/// for an index out of range. Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_param_get(index: u32) -> *const vstree_param_info {
    guard_or(std::ptr::null(), || table().params.get(index as usize).map_or(std::ptr::null(), |p| p as *const _))
}

/// Choice `choice` (0 to `choice_count` - 1) of parameter `index`; NULL when either is out of
/// range. Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_param_choice_get(index: u32, choice: u32) -> *const vstree_param_choice {
    guard_or(std::ptr::null(), || {
        table()
            .choices
            .get(index as usize)
            .and_then(|c| c.get(choice as usize))
            .map_or(std::ptr::null(), |c| c as *const _)
    })
}

/// The index of `call`'s parameter `name` (a field name, e.g. "max_levels"), for
/// vstree_param_get(); -1 when the call has no such parameter or `name` is NULL. Thread-safe.
///
/// `name` must be NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn vstree_param_find(call: i32, name: *const c_char) -> i32 {
    guard_or(-1, || {
        if name.is_null() {
            return -1;
        }
        // SAFETY: the caller gives a NUL-terminated string.
        let Ok(name) = unsafe { CStr::from_ptr(name) }.to_str() else {
            return -1;
        };
        PARAMS.iter().position(|p| p.call as i32 == call && p.name == name).map_or(-1, |i| i as i32)
    })
}

/// `target_faces` for a `ratio` of `triangles`: round(ratio x triangles), at least 1, at most
/// `triangles`, as every host reads a "keep this fraction" setting. Fails with
/// VSTREE_STATUS_INVALID_PARAMETER when `ratio` is not in (0, 1] or `triangles` is 0 (a point
/// cloud), and when the count does not fit the field.
#[no_mangle]
pub unsafe extern "C" fn vstree_faces_for_ratio(ratio: f64, triangles: u64, out_faces: *mut u32) -> vstree_status {
    guard("vstree_faces_for_ratio", || {
        non_null(out_faces, "out_faces")?;
        let faces = crate::simplify::faces_for_ratio(ratio, triangles).map_err(Failure::from)?;
        let faces = u32::try_from(faces).map_err(|_| Failure::parameter("ratio", "the face count exceeds 2^32 - 1"))?;
        // SAFETY: checked non-NULL.
        unsafe { write_out(out_faces, faces) };
        Ok(())
    })
}

/// The L2 `error` that bounds every sample's tangent plane to within `distance` of its
/// cluster's point, for a model whose bounding-box diagonal is `diagonal`: (distance /
/// diagonal)^2 (the L2 bound sums squared plane distances over the squared diagonal). 0 when
/// either is not a finite number above 0. Thread-safe.
#[no_mangle]
pub extern "C" fn vstree_l2_error_for_distance(distance: f64, diagonal: f64) -> f64 {
    crate::tree::TreeParams::l2_error_for_distance(distance, diagonal)
}

/// Why a simplification to a size gave another size, as a static English sentence, or NULL when
/// its output is within 1% (or 2 triangles) of `target_faces`, or no size was asked. `stats`
/// from vstree_simplify_result_get_stats(); NULL gives NULL.
///
/// `stats` must be NULL or point to a ::vstree_simplify_stats the library filled.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_size_missed(stats: *const vstree_simplify_stats) -> *const c_char {
    guard_or(std::ptr::null(), || {
        if stats.is_null() {
            return std::ptr::null();
        }
        // SAFETY: the caller gives the library's own stats.
        let s = unsafe { &*stats };
        let missed =
            crate::simplify::SizeMissed::of(s.target_faces as usize, s.output_triangles as usize, s.kept_topology != 0);
        missed.map_or(std::ptr::null(), |m| m.reason_c().as_ptr())
    })
}

#[cfg(test)]
mod tests {
    use super::super::normals::{read_normal_params, vstree_normal_params, vstree_normal_params_default};
    use super::super::reconstruct::{
        read_reconstruct_params, vstree_reconstruct_params, vstree_reconstruct_params_default,
    };
    use super::super::simplify::{read_params, vstree_simplify_params, vstree_simplify_params_default};
    use super::super::FfiResult;
    use super::*;
    use crate::params::{Kind, Param};

    /// A C parameter struct's fields by name, as f64.
    trait Fields: Copy {
        fn get(&self, name: &str) -> f64;
        fn set(&mut self, name: &str, value: f64);
        /// The library's reading of the struct (its checks included).
        fn read(&self) -> FfiResult<()>;
        fn defaults() -> Self;
        const C_NAME: &'static str;
        const CALL: Call;
    }

    macro_rules! fields {
        ($s:ident, $call:expr, $defaults:ident, $read:ident, [$($f:ident),+]) => {
            impl Fields for $s {
                fn get(&self, name: &str) -> f64 {
                    match name {
                        $(stringify!($f) => self.$f as f64,)+
                        _ => panic!("{} has no field {name}", stringify!($s)),
                    }
                }
                fn set(&mut self, name: &str, value: f64) {
                    match name {
                        $(stringify!($f) => self.$f = value as _,)+
                        _ => panic!("{} has no field {name}", stringify!($s)),
                    }
                }
                fn read(&self) -> FfiResult<()> {
                    unsafe { $read(self) }.map(|_| ())
                }
                fn defaults() -> Self {
                    $defaults()
                }
                const C_NAME: &'static str = stringify!($s);
                const CALL: Call = $call;
            }
        };
    }

    fields!(
        vstree_simplify_params,
        Call::Simplify,
        vstree_simplify_params_default,
        read_params,
        [tree_kind, metric, sampling, error, d_a, d_d, max_depth, threads, min_cell_size, keep_topology, target_faces]
    );
    fields!(
        vstree_reconstruct_params,
        Call::Reconstruct,
        vstree_reconstruct_params_default,
        read_reconstruct_params,
        [
            orient,
            error,
            d_a,
            d_d,
            max_depth,
            max_levels,
            min_cell_size,
            target_distance,
            min_displaced,
            max_triangles,
            max_grid_depth,
            trim,
            neighbours,
            reorient_given,
            threads,
            closure,
            base_mesh
        ]
    );
    fields!(
        vstree_normal_params,
        Call::Normals,
        vstree_normal_params_default,
        read_normal_params,
        [orient, neighbours, reorient_given, threads]
    );

    /// The fields of `typedef struct c_name` in the committed header, in order.
    fn header_fields(c_name: &str) -> Vec<String> {
        let header = include_str!("../../include/vstree.h");
        let start = header.find(&format!("typedef struct {c_name} {{")).unwrap_or_else(|| panic!("no {c_name}"));
        let body = &header[start..start + header[start..].find(&format!("}} {c_name};")).unwrap()];
        body.lines()
            .skip(1)
            .map(str::trim)
            .filter(|l| !l.starts_with('/') && !l.starts_with('*') && l.ends_with(';'))
            .map(|l| l.trim_end_matches(';').rsplit(' ').next().unwrap().to_string())
            .filter(|name| name != "struct_size")
            .collect()
    }

    fn rows(call: Call) -> Vec<&'static Param> {
        PARAMS.iter().filter(|p| p.call == call).collect()
    }

    /// Values just outside `p`'s range, and values on its ends the range allows.
    fn probes(p: &Param) -> (Vec<f64>, Vec<f64>) {
        if p.kind == Kind::Choice {
            let values = p.choices.iter().map(|c| f64::from(c.value)).collect();
            return (vec![-1.0, p.choices.len() as f64], values);
        }
        let step = |x: f64| if p.kind == Kind::Real { x.abs().max(1.0) * 1e-6 } else { 1.0 };
        let (mut outside, mut inside) = (vec![f64::NAN], vec![]);
        if p.min_open {
            outside.push(p.min);
        } else {
            inside.push(p.min);
        }
        outside.push(p.min - step(p.min));
        if p.max.is_finite() {
            if p.max_open {
                outside.push(p.max);
            } else {
                inside.push(p.max);
            }
            outside.push(p.max + step(p.max));
        } else if p.kind == Kind::Real {
            outside.push(f64::INFINITY);
        }
        (outside, inside)
    }

    fn agrees_with_the_table<S: Fields>() {
        let names: Vec<&str> = rows(S::CALL).iter().map(|p| p.name).collect();
        assert_eq!(names, header_fields(S::C_NAME), "{}: the table's rows are not the struct's fields", S::C_NAME);
        for p in rows(S::CALL) {
            let default = S::defaults().get(p.name);
            let close = (default - p.default).abs() <= 1e-7 * p.default.abs();
            assert!(close, "{}.{}: _default() gives {default}, the table {}", S::C_NAME, p.name, p.default);
            assert!(p.allows(p.default), "{}: the default is outside the range", p.name);
            let (outside, inside) = probes(p);
            // Fields stored in 32 bits cannot hold every probe: skip what the store changed.
            let stored = |v: f64| {
                let mut s = S::defaults();
                s.set(p.name, v);
                let got = s.get(p.name);
                (got == v || got.is_nan() && v.is_nan()).then_some(s)
            };
            for v in inside {
                let s = stored(v).unwrap_or_else(|| panic!("{}: {v} does not fit the field", p.name));
                assert!(s.read().is_ok(), "{}.{} = {v}: refused: {:?}", S::C_NAME, p.name, s.read().err());
            }
            for v in outside {
                let Some(s) = stored(v) else { continue };
                let e = s.read().expect_err(&format!("{}.{} = {v} was accepted", S::C_NAME, p.name));
                assert!(e.message.contains(&format!("`{}`", p.name)), "{}", e.message);
            }
        }
    }

    #[test]
    fn every_field_of_the_c_structs_has_its_default_and_range_from_the_table() {
        agrees_with_the_table::<vstree_simplify_params>();
        agrees_with_the_table::<vstree_reconstruct_params>();
        agrees_with_the_table::<vstree_normal_params>();
        assert_eq!(vstree_param_count() as usize, PARAMS.len());
    }

    /// The doc comment of each field of `typedef struct c_name` in the committed header, joined
    /// into one line.
    fn header_docs(c_name: &str) -> Vec<(String, String)> {
        let header = include_str!("../../include/vstree.h");
        let start = header.find(&format!("typedef struct {c_name} {{")).unwrap();
        let body = &header[start..start + header[start..].find(&format!("}} {c_name};")).unwrap()];
        let (mut docs, mut doc) = (Vec::new(), String::new());
        for line in body.lines().skip(1).map(str::trim) {
            if let Some(text) = line.strip_prefix("* ").or(line.strip_prefix("*")) {
                doc.push(' ');
                doc.push_str(text.trim_end_matches('/'));
            } else if line.ends_with(';') && !line.starts_with('/') {
                let name = line.trim_end_matches(';').rsplit(' ').next().unwrap().to_string();
                docs.push((name, std::mem::take(&mut doc)));
            }
        }
        docs
    }

    /// A number as the header writes one: "1e-5", "20,000,000", "1/6", "2^32 - 1", or a
    /// `#define`d name.
    fn header_number(text: &str) -> Option<f64> {
        let text = text.trim().replace(',', "");
        if let Some((a, b)) = text.split_once('/') {
            return Some(a.parse::<f64>().ok()? / b.parse::<f64>().ok()?);
        }
        if text == "2^32 - 1" {
            return Some(f64::from(u32::MAX));
        }
        if text.starts_with("VSTREE_") {
            let header = include_str!("../../include/vstree.h");
            let at = header.find(&format!("#define {text} "))?;
            return header[at..].lines().next()?.rsplit(' ').next()?.parse().ok();
        }
        text.parse().ok()
    }

    #[test]
    fn the_headers_field_docs_state_the_tables_defaults_and_ranges() {
        let mut stated = (0, 0);
        for c_name in ["vstree_simplify_params", "vstree_reconstruct_params", "vstree_normal_params"] {
            let call = match c_name {
                "vstree_simplify_params" => Call::Simplify,
                "vstree_reconstruct_params" => Call::Reconstruct,
                _ => Call::Normals,
            };
            for (name, doc) in header_docs(c_name) {
                let Some(p) = params::find(call, &name) else { continue };
                // "default X" (a number or a constant's name), where the doc gives one.
                if let Some(at) = doc.to_lowercase().find("default ") {
                    let token: String = doc[at + 8..]
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || "_-+./,^".contains(*c))
                        .collect();
                    if let Some(value) = header_number(token.trim_end_matches(['.', ','])) {
                        assert!(
                            (value - p.default).abs() <= 1e-9 * p.default.abs(),
                            "{c_name}.{name}: the header says default {token}, the table {}",
                            p.default
                        );
                        stated.0 += 1;
                    }
                }
                // "[a, b]" or "[a, b)" where the doc gives a range.
                if let Some(open) = doc.find('[') {
                    let rest = &doc[open + 1..];
                    if let Some(close) = rest.find([']', ')']) {
                        if let Some((a, b)) = rest[..close].split_once(", ") {
                            if let (Some(a), Some(b)) = (header_number(a), header_number(b)) {
                                let max_open = rest.as_bytes()[close] == b')';
                                assert_eq!(
                                    (a, b, max_open),
                                    (p.min, p.max, p.max_open),
                                    "{c_name}.{name}: the header's range"
                                );
                                stated.1 += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(stated.0 >= 15 && stated.1 >= 10, "defaults and ranges stated: {stated:?}");
    }

    #[test]
    fn choices_are_numbered_in_order_and_the_c_enums_agree() {
        use super::super::params::CEnum;
        use super::super::simplify::{vstree_keep_topology, vstree_metric, vstree_sampling, vstree_tree_kind};
        for p in PARAMS.iter().filter(|p| p.kind == Kind::Choice) {
            let values: Vec<i32> = p.choices.iter().map(|c| c.value).collect();
            assert_eq!(values, (0..p.choices.len() as i32).collect::<Vec<_>>(), "{}", p.name);
        }
        let count = |name: &str| params::find(Call::Simplify, name).unwrap().choices.len();
        assert_eq!(count("tree_kind"), vstree_tree_kind::VARIANTS.len());
        assert_eq!(count("metric"), vstree_metric::VARIANTS.len());
        assert_eq!(count("sampling"), vstree_sampling::VARIANTS.len());
        assert_eq!(count("keep_topology"), vstree_keep_topology::VARIANTS.len());
    }

    fn text(p: *const c_char) -> &'static str {
        unsafe { CStr::from_ptr(p) }.to_str().unwrap()
    }

    #[test]
    fn the_c_table_is_the_rust_table() {
        for (i, p) in PARAMS.iter().enumerate() {
            let info = unsafe { &*vstree_param_get(i as u32) };
            assert_eq!(
                (info.call, info.kind, text(info.name), text(info.help)),
                (p.call as i32, p.kind as i32, p.name, p.help)
            );
            assert_eq!((info.default_value, info.min, info.max), (p.default, p.min, p.max));
            let found = unsafe { vstree_param_find(p.call as i32, info.name) };
            assert_eq!(found, i as i32, "{}", p.name);
            for (k, c) in p.choices.iter().enumerate() {
                let choice = unsafe { &*vstree_param_choice_get(i as u32, k as u32) };
                assert_eq!((choice.value, text(choice.name)), (c.value, c.name));
            }
            assert!(vstree_param_choice_get(i as u32, p.choices.len() as u32).is_null());
        }
        assert!(vstree_param_get(PARAMS.len() as u32).is_null());
        assert_eq!(unsafe { vstree_param_find(VSTREE_CALL_NORMALS, c"error".as_ptr()) }, -1);
        assert_eq!(unsafe { vstree_param_find(VSTREE_CALL_SIMPLIFY, std::ptr::null()) }, -1);
    }

    #[test]
    fn host_rules() {
        let mut faces = 0u32;
        assert_eq!(unsafe { vstree_faces_for_ratio(0.1, 1005, &mut faces) }, vstree_status::Ok);
        assert_eq!(faces, 101);
        assert_eq!(unsafe { vstree_faces_for_ratio(1e-9, 10, &mut faces) }, vstree_status::Ok);
        assert_eq!(faces, 1);
        for (ratio, triangles) in [(0.0, 10), (1.5, 10), (f64::NAN, 10), (0.5, 0)] {
            let status = unsafe { vstree_faces_for_ratio(ratio, triangles, &mut faces) };
            assert_eq!(status, vstree_status::InvalidParameter, "{ratio} {triangles}");
        }
        assert_eq!(vstree_l2_error_for_distance(0.03, 3.0), 1e-4);
        assert_eq!(vstree_l2_error_for_distance(-1.0, 3.0), 0.0);
        let mut stats: vstree_simplify_stats = unsafe { std::mem::zeroed() };
        (stats.target_faces, stats.output_triangles, stats.kept_topology) = (1000, 1010, 1);
        assert!(unsafe { vstree_simplify_size_missed(&stats) }.is_null());
        stats.output_triangles = 1100;
        assert!(text(unsafe { vstree_simplify_size_missed(&stats) }).contains("topology"));
        stats.output_triangles = 500;
        assert!(text(unsafe { vstree_simplify_size_missed(&stats) }).contains("clusters"));
        assert!(unsafe { vstree_simplify_size_missed(std::ptr::null()) }.is_null());
    }
}
