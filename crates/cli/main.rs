//! `clutchpack`: the command-line front end. Thin: parses arguments (clap), loads scenes,
//! runs engines, prints tables, writes files. Errors are printed once, with context, and
//! mapped to exit codes: 0 success, 2 bad input (scene, arguments, files), 1 anything else.

/// `println!` that ends the process quietly (exit 0) when stdout is a closed pipe
/// (`clutchpack run | head`), instead of panicking. Any other write error (a full disk, a
/// redirection to `/dev/full`) is reported once on stderr and makes the command fail (exit
/// 1) once it has written its other outputs ([`STDOUT_FAILED`]).
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut o = std::io::stdout().lock();
        if let Err(e) = writeln!(o, $($arg)*).and_then(|()| o.flush()) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
            $crate::stdout_failed(&e);
        }
    }};
}

/// `eprintln!` that ignores a failed write: standard error is where failures are reported,
/// so when it cannot be written (a full disk, `2>/dev/full`, a closed pipe) there is nowhere
/// left to say so, and the command goes on to write its other outputs and exit with its own
/// code rather than panic (exit 101). Shadows the standard macro in every module below.
macro_rules! eprintln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// Set when writing to standard output failed (other than a closed pipe).
static STDOUT_FAILED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Records a failed write to standard output and reports the first one.
fn stdout_failed(e: &std::io::Error) {
    if !STDOUT_FAILED.swap(true, std::sync::atomic::Ordering::SeqCst) {
        eprintln!("error: writing to standard output: {e}");
    }
}

mod bench;
mod bench_frames;
mod check;
mod common;
mod describe;
mod fit;
mod fmu;
mod network;
mod outputs;
mod recording;
mod run;
mod shift_compare;
mod signals;
mod study;
mod sweep;
mod tables;
mod windows_plot;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Wet multi-disc clutch and brake pack simulator: how hard the spline teeth of each friction
/// disc hit the shaft when its speed fluctuates, and how the oil film softens the impacts.
///
/// Start with `clutchpack run` (the paper's case, built in), then `clutchpack sweep` over the
/// oil film thickness. Scene files are TOML with SI keys (see `clutchpack check --keys`).
/// Loads are per tooth in N: negative when the shaft leads, positive when the disc leads.
#[derive(Parser, Debug)]
#[command(name = "clutchpack", version, about, long_about, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run one scene and print the per-disc impact loads.
    Run(run::RunArgs),
    /// Run a scene once per value of one parameter (optionally as ensembles) and fit the
    /// peaks against it (the paper's Fig 3).
    Sweep(sweep::SweepArgs),
    /// Describe a recording (topics, counts, time span, summary); `--serve` streams it to
    /// Foxglove over WebSocket (holding every message in memory).
    Replay(recording::ReplayArgs),
    /// Compare per-disc impact loads across recordings (change against the first).
    Compare(recording::CompareArgs),
    /// Export a recording's topics as CSV files.
    Export(recording::ExportArgs),
    /// Plot a recording's per-disc load histories (PNG or SVG); holds every sample of every
    /// disc in memory (what it draws).
    Plot(recording::PlotArgs),
    /// Measure speed: the paper case per run, the speed-up of a 16-case sweep on 2 threads
    /// over 1, the recording's cost, the shipped whole packs on both engines, and the cost
    /// per disc as staggered packs and brake packs (discs and plates) grow (prints times and
    /// ratios; timing is never a test).
    Bench(bench::BenchArgs),
    /// Studies: many cases of a scene (design factors, random draws, ensembles), sharded over
    /// threads and Slurm or Kubernetes job arrays, merged into Parquet and CSV tables.
    Study(study::StudyArgs),
    /// Fit scene keys to measured series (least squares, Levenberg-Marquardt): fitted
    /// values with standard errors, 95 % intervals and correlations, the residual per
    /// signal, and the fitted scene written beside the input (docs/calibration.md).
    Fit(fit::FitArgs),
    /// Validate scene files: exit 0 if all are valid, 2 with every problem listed if not.
    Check(check::CheckArgs),
    /// Pack a scene into an FMI 2.0 co-simulation FMU (linux64), to put the pack between the
    /// inertias of a driveline model.
    Fmu(fmu::FmuArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(a) => run::run(a),
        Command::Sweep(a) => sweep::sweep(a),
        Command::Check(a) => check::check(a),
        Command::Fit(a) => fit::fit(a),
        Command::Study(a) => study::study(a),
        Command::Bench(a) => bench::bench(a),
        Command::Replay(a) => recording::replay(a),
        Command::Compare(a) => recording::compare(a),
        Command::Export(a) => recording::export(a),
        Command::Plot(a) => recording::plot(a),
        Command::Fmu(a) => fmu::fmu(a),
    };
    match result {
        // a command that could not write its results to stdout did not succeed
        Ok(_) if STDOUT_FAILED.load(std::sync::atomic::Ordering::SeqCst) => ExitCode::from(1),
        Ok(code) => code,
        Err(e) => {
            let bad_input = common::is_bad_input(&e);
            eprintln!("error: {}", error_text(&e));
            if bad_input {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// An error and its causes on one line, `outer: cause: cause`, without repeating a cause whose
/// text the line already holds (an error that prints its source in its own message, as
/// `PartError::Io` does, would otherwise show it twice).
fn error_text(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

#[cfg(test)]
mod tests {
    /// `error: nope: No such file or directory (os error 2): No such file or directory (os
    /// error 2)` was printed for `study merge nope` (issue 25, reproducer 12).
    #[test]
    fn causes_are_printed_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::new(clutchpack_sdk::study::part::PartError::Io {
            path: "nope".into(),
            source: io,
        })
        .context("merging");
        assert_eq!(super::error_text(&e), "merging: nope: no such file");
        let e = anyhow::anyhow!("inner").context("outer");
        assert_eq!(super::error_text(&e), "outer: inner");
    }
}
