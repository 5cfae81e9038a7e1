//! The OFF reader never panics, whatever the bytes: it returns a mesh or an error.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = vstree::io::off::parse(data, std::path::Path::new("fuzz.off")) {
        // What a reader returns is usable: the checks every algorithm relies on do not panic.
        let _ = mesh.check();
    }
});
