//! Command-line helpers: the bench's arguments, and values of options.

use std::path::Path;

/// The arguments after the program name, without the `--bench` that `cargo bench` adds.
pub fn bench_args() -> Vec<String> {
    std::env::args().skip(1).filter(|a| a != "--bench").collect()
}

/// When `args` asks for help (`--help` or `-h`), prints `usage` and exits with code 0.
pub fn exit_on_help(args: &[String], usage: &str) {
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{usage}");
        std::process::exit(0)
    }
}

/// The options `parsed` from the command line, or else its message on stderr and exit code 2.
pub fn or_exit<T>(parsed: Result<T, String>) -> T {
    parsed.unwrap_or_else(|message| {
        eprintln!("{message}");
        std::process::exit(2)
    })
}

/// The bench's `result`, or else `<bench>: <error>` on stderr and exit code 1.
pub fn or_fail<T, E: std::fmt::Display>(bench: &str, result: Result<T, E>) -> T {
    result.unwrap_or_else(|e| {
        eprintln!("{bench}: {e}");
        std::process::exit(1)
    })
}

/// The command line as the report shows it: `cargo bench --bench <name> -- <args>`.
pub fn command(bench: &str, args: &[String]) -> String {
    if args.is_empty() {
        format!("cargo bench --bench {bench}")
    } else {
        format!("cargo bench --bench {bench} -- {}", args.join(" "))
    }
}

pub fn number<T: std::str::FromStr>(s: &str) -> Result<T, String> {
    s.parse().map_err(|_| format!("not a number: {s}"))
}

/// A comma-separated list of numbers.
pub fn list<T: std::str::FromStr>(s: &str) -> Result<Vec<T>, String> {
    s.split(',').map(number).collect()
}

/// A comma-separated list of names.
pub fn names(s: &str) -> Vec<String> {
    s.split(',').map(str::to_string).collect()
}

/// `path` as a document should show it: relative to the project root when possible.
pub fn shown(path: &Path, root: &Path) -> String {
    path.strip_prefix(root).unwrap_or(path).display().to_string()
}
