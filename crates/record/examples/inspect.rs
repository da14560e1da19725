//! Prints what a recording holds (a stand-in for `clutchpack replay` while the CLI is built).
//!
//! ```text
//! cargo run -p clutchpack_record --example inspect -- FILE.mcap
//! ```
//! Exit code 2 with a one-line reason for a file that cannot be read or is damaged.

use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: inspect FILE.mcap");
        return ExitCode::from(2);
    };
    let t0 = std::time::Instant::now();
    let r = match clutchpack_record::open(&path) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let opened = t0.elapsed();
    print!("{}", r.describe());
    println!("(opened in {:.3} s)", opened.as_secs_f64());
    match r.damage() {
        None => ExitCode::SUCCESS,
        Some(d) => {
            eprintln!("error: {}: {d}", r.path().display());
            ExitCode::from(2)
        }
    }
}
