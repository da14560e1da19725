//! Issue 24: the `clutchpack` Python package. Builds the wheel (crates/python, maturin),
//! installs it into a fresh virtual environment (tests/python/build_wheel.sh) and runs its
//! pytest suite (crates/python/tests) against this checkout's CLI: `run` and `read` equal
//! the CLI's summary and impacts, a recording cut by kill -9 is refused and then salvaged,
//! bad input raises `ValueError` naming the key, SIGINT stops a 60 s run within a second,
//! and examples/python/fig3.py reproduces `clutchpack sweep` number for number.

use std::path::Path;
use std::process::Command;

#[test]
fn python_package_passes_its_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // the tests' environment (maturin among its packages) made once, by the same call as
    // every other test that needs it: two setup.sh at once would both rebuild it
    let _ = super::python_reader();
    let o = Command::new("bash")
        .arg(root.join("tests/python/build_wheel.sh"))
        .output()
        .expect("bash runs");
    assert!(
        o.status.success(),
        "build_wheel.sh: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let python = String::from_utf8(o.stdout).unwrap().trim().to_string();
    let t = Command::new(&python)
        .args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "crates/python/tests",
        ])
        .current_dir(root)
        .env("CLUTCHPACK_BIN", env!("CARGO_BIN_EXE_clutchpack"))
        .output()
        .expect("pytest runs");
    let out = String::from_utf8_lossy(&t.stdout);
    eprintln!("{out}");
    assert!(
        t.status.success(),
        "pytest failed:\n{out}\n{}",
        String::from_utf8_lossy(&t.stderr)
    );
    assert!(out.contains(" passed"), "{out}");
    assert!(
        !out.contains("skipped"),
        "a Python test was skipped:\n{out}"
    );
}
