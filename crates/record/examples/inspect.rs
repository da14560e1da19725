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
    let i = r.info();
    println!(
        "{path}: {} bytes, {} messages, t = {:?} .. {:?} s, opened in {:.3} s",
        r.file_bytes(),
        i.messages,
        i.start_s,
        i.end_s,
        opened.as_secs_f64()
    );
    for t in &i.topics {
        println!(
            "  {:<28} {:<28} {:>9} messages",
            t.topic, t.schema_name, t.messages
        );
    }
    for (name, m) in &i.metadata {
        println!("  metadata {name}: {} keys", m.len());
    }
    if let Some(s) = r.summary() {
        for d in &s.discs {
            println!(
                "  summary {}: max+ {} N, max- {} N, p99 {} N, {} impacts",
                d.name, d.max_positive_n, d.max_negative_n, d.p99_abs_n, d.impacts
            );
        }
    }
    let t1 = std::time::Instant::now();
    let h = r.load_histories();
    println!(
        "  load histories of {} discs ({} samples) in {:.3} s",
        h.len(),
        h.first().map_or(0, |h| h.t_s.len()),
        t1.elapsed().as_secs_f64()
    );
    match r.damage() {
        None => ExitCode::SUCCESS,
        Some(d) => {
            eprintln!("error: {}: {d}", r.path().display());
            ExitCode::from(2)
        }
    }
}
