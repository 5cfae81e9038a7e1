//! Gives the shared library a SONAME, `libvstree.so.<ABI>`, so applications and plugins link
//! to the stable name and keep working across compatible upgrades. The ABI number is read from
//! `VSTREE_ABI_VERSION` in src/ffi/version.rs, the one place it is written (tests/c checks the
//! built library's SONAME against the header). Only ELF platforms have SONAMEs; on macOS
//! `bindings/install.sh` sets the install name instead.
//!
//! A program linked against `target/<profile>/libvstree.so` asks the loader for the SONAME, so
//! a `libvstree.so.<ABI>` link to it is made there too: such programs then run from the build
//! folder (with `LD_LIBRARY_PATH`) without an install.

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
        link_soname_in_profile_folder(abi);
    }
}

/// Makes `libvstree.so.<abi>` -> `libvstree.so` in the profile folder (`target/release`), which
/// is three levels above OUT_DIR (`target/release/build/vstree-<hash>/out`). The link dangles
/// until the library is linked, a moment later. Failure only means no link: never an error.
fn link_soname_in_profile_folder(abi: u32) {
    #[cfg(unix)]
    {
        let Some(out_dir) = std::env::var_os("OUT_DIR") else { return };
        let Some(profile) = std::path::Path::new(&out_dir).ancestors().nth(3) else { return };
        let link = profile.join(format!("libvstree.so.{abi}"));
        if fs::symlink_metadata(&link).is_err() {
            let _ = std::os::unix::fs::symlink("libvstree.so", &link);
        }
    }
    #[cfg(not(unix))]
    let _ = abi;
}
