//! Gives the shared library a SONAME, `libvstree.so.<ABI>`, so applications and plugins link
//! to the stable name and keep working across compatible upgrades. The ABI number is read from
//! `VSTREE_ABI_VERSION` in src/ffi/version.rs, the one place it is written (tests/c checks the
//! built library's SONAME against the header). Only ELF platforms have SONAMEs; on macOS
//! `bindings/install.sh` sets the install name instead.

use std::fs;

const SOURCE: &str = "src/ffi/version.rs";
const NEEDLE: &str = "pub const VSTREE_ABI_VERSION: u32 = ";

fn abi_version() -> u32 {
    let text = fs::read_to_string(SOURCE).unwrap_or_else(|e| panic!("{SOURCE}: {e}"));
    text.lines()
        .find_map(|line| line.strip_prefix(NEEDLE)?.strip_suffix(';')?.parse().ok())
        .unwrap_or_else(|| panic!("{SOURCE}: no line `{NEEDLE}<number>;`"))
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={SOURCE}");
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let elf = matches!(os.as_str(), "linux" | "android" | "freebsd" | "netbsd" | "openbsd" | "dragonfly" | "illumos");
    if elf {
        let abi = abi_version();
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libvstree.so.{abi}");
    }
}
