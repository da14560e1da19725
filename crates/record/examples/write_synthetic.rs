//! Writes a synthetic two-disc recording (for the independent reader and manual checks).
//!
//! ```text
//! cargo run -p clutchpack_record --example write_synthetic -- OUT.mcap [SAMPLES] [--deterministic] [--wall-s S]
//! ```
//! `--wall-s S` keeps writing (slowly, repeating the stream with growing time) for about S
//! seconds of wall time, to try a SIGKILL mid-run: the recorder flushes at least once per
//! second, so the file stays readable up to the last flush.

use clutchpack_model::Observer;
use clutchpack_record::synthetic::synthetic_run;
use clutchpack_record::{RecordOptions, Recorder};
use std::time::{Duration, Instant};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .first()
        .ok_or("usage: write_synthetic OUT.mcap [SAMPLES] [--deterministic] [--wall-s S]")?;
    let samples: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(2000);
    let deterministic = args.iter().any(|a| a == "--deterministic");
    let wall_s: Option<f64> = args
        .iter()
        .position(|a| a == "--wall-s")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok());
    let dt = 1e-5;
    let run = synthetic_run(samples, dt);
    let options = RecordOptions {
        deterministic,
        per_tooth: true,
        ..Default::default()
    };
    let mut rec = Recorder::create(out, &run.info, &options)?;
    match wall_s {
        None => run.play(&mut rec),
        Some(limit) => {
            let start = Instant::now();
            let mut lap = 0usize;
            while start.elapsed().as_secs_f64() < limit {
                let offset = lap as f64 * samples as f64 * dt;
                for s in &run.samples {
                    let mut s = s.clone();
                    s.t_s += offset;
                    rec.sample(&s);
                    std::thread::sleep(Duration::from_micros(200));
                    if rec.progress(s.t_s) {
                        break;
                    }
                }
                lap += 1;
                eprintln!("lap {lap}: {} messages written", rec.messages());
            }
        }
    }
    let path = rec.finish(None)?;
    println!("{}", path.display());
    Ok(())
}
