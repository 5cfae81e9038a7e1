//! The OBJ reader returns a mesh or an error whatever the bytes; no panic escapes it.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod tolerate_tobj;

fuzz_target!(init: tolerate_tobj::install(), |data: &[u8]| {
    if let Ok(mesh) = vstree::io::obj::parse(data, std::path::Path::new("fuzz.obj")) {
        // What a reader returns is usable: the checks every algorithm relies on do not panic.
        let _ = mesh.check();
    }
});
