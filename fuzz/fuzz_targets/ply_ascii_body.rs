//! The PLY reader on ascii bodies behind realistic headers (see ply_header.rs): a mesh or an
//! error whatever the body, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod ply_header;

fuzz_target!(|data: &[u8]| {
    let Some(file) = ply_header::file(data, "ascii") else {
        return;
    };
    if let Ok(mesh) = vstree::io::ply::parse(&file, std::path::Path::new("fuzz.ply")) {
        // What a reader returns is usable: the checks every algorithm relies on do not panic.
        let _ = mesh.check();
    }
});
