//! Reading recordings: `replay`, `compare`, `export`, `plot`.
//!
//! Every command reads the whole file it is given, streaming: the reader holds one chunk at a
//! time and reads the file again for each pass over its messages, so `replay` (the text
//! description) and `export --csv` take memory that does not grow with the recording; `plot`
//! and `compare` keep what they draw or rank (`plot` every sample of every disc, `compare`
//! the impacts). A damaged file (truncated by a killed run, corrupted) is an error (exit 2)
//! that says what was read and what was not, unless `--salvage` is given: then the command
//! works on the messages recovered and warns. A file that changes under a command (removed,
//! shortened) is an error too, never a partial result.

use crate::common::BadInput;
use crate::outputs::Output;
use anyhow::{Context, Result};
use clutchpack_sdk::analysis::{disc_stats, DiscStats};
use clutchpack_sdk::record::RecordingReader;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Opens a recording; a damaged one is bad input unless `salvage`.
pub fn open_recording(path: &Path, salvage: bool) -> Result<RecordingReader> {
    let (reader, warning) =
        clutchpack_sdk::open_recording(path, salvage).map_err(|e| BadInput(e.to_string()))?;
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    Ok(reader)
}

/// `Err` (bad input naming the file) if a pass over the recording's messages could not read
/// the file again (it changed since it was opened).
pub fn reread_ok(reader: &RecordingReader) -> Result<()> {
    match reader.reread_error() {
        None => Ok(()),
        Some(e) => Err(BadInput(e.to_string()).into()),
    }
}

/// Per-disc statistics of a recording, from its impact events (the same definitions as
/// `clutchpack run`).
pub fn recording_stats(reader: &RecordingReader) -> Vec<DiscStats> {
    disc_stats(&reader.disc_names(), &reader.impacts())
}

/// Arguments of `clutchpack replay`.
#[derive(clap::Args, Debug)]
pub struct ReplayArgs {
    /// The recording (.mcap).
    pub file: PathBuf,
    /// Work on the messages of a damaged file (killed run) instead of failing.
    #[arg(long)]
    pub salvage: bool,
    /// Stream the recording over the Foxglove WebSocket protocol on 127.0.0.1, with
    /// playback control, so that Foxglove can watch it live (open connection
    /// ws://127.0.0.1:PORT).
    #[arg(long)]
    pub serve: bool,
    /// Port of `--serve` (0 picks a free one).
    #[arg(long, default_value_t = 8765)]
    pub port: u16,
    /// Playback speed of `--serve` as a factor of simulated time (impacts last ~70 us: slow
    /// motion helps).
    #[arg(long, default_value_t = 0.01)]
    pub speed: f32,
    /// With `--serve`: wait for the viewer's play button instead of playing as soon as a
    /// viewer subscribes.
    #[arg(long)]
    pub paused: bool,
}

pub fn replay(a: ReplayArgs) -> Result<ExitCode> {
    let reader = open_recording(&a.file, a.salvage)?;
    let text = crate::describe::describe(&reader);
    reread_ok(&reader)?;
    out!("{}", text.trim_end());
    if a.serve {
        serve(&reader, a.port, a.speed, a.paused)?;
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(feature = "serve")]
fn serve(reader: &RecordingReader, port: u16, speed: f32, paused: bool) -> Result<()> {
    let stop = crate::signals::flag();
    let opts = clutchpack_sdk::record::ServeOptions {
        port,
        speed,
        autoplay: !paused,
        ..Default::default()
    };
    clutchpack_sdk::record::serve(reader, &opts, &stop, |p| {
        eprintln!(
            "serving on ws://127.0.0.1:{p}: in Foxglove, Open connection > Foxglove WebSocket; Ctrl-C to stop"
        )
    })
    .map_err(|e| anyhow::anyhow!("serving the recording: {e}"))?;
    Ok(())
}

#[cfg(not(feature = "serve"))]
fn serve(_reader: &RecordingReader, _port: u16, _speed: f32, _paused: bool) -> Result<()> {
    Err(
        BadInput("this build has no WebSocket server: rebuild with `--features serve`".into())
            .into(),
    )
}

/// Output formats of `compare`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CompareFormat {
    Table,
    Markdown,
    Csv,
    Json,
}

/// Arguments of `clutchpack compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// Recordings to compare; changes are reported against the first.
    #[arg(required = true, num_args = 2..)]
    pub files: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = CompareFormat::Table)]
    pub format: CompareFormat,
    /// Grouped bar chart of the peaks per disc and run (PNG or SVG; an existing FILE is
    /// replaced).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Use the recovered messages of damaged files.
    #[arg(long)]
    pub salvage: bool,
}

/// One (run, disc) row of `compare`.
#[derive(Debug, Serialize)]
pub struct CompareRow {
    pub run: String,
    pub disc: String,
    pub max_positive_n: f64,
    pub max_negative_n: f64,
    pub p99_abs_n: f64,
    pub impacts: usize,
    /// Change of max_positive_n against the first run's same disc, per cent.
    pub max_positive_change_pct: Option<f64>,
    /// Change of |max_negative_n| against the first run's same disc, per cent.
    pub max_negative_change_pct: Option<f64>,
    /// Change of p99_abs_n against the first run's same disc, per cent.
    pub p99_abs_change_pct: Option<f64>,
    /// Life of the disc's teeth at the run's duty in h, from the recording's stored summary
    /// (`None`: unlimited, or not stored).
    pub life_h: Option<f64>,
    /// Whether the recording stored the disc's fatigue (older recordings did not).
    pub fatigue_stored: bool,
    /// Change of the life against the first run's same disc, per cent (`None` when either
    /// life is unlimited or not stored).
    pub life_change_pct: Option<f64>,
}

fn pct(new: f64, old: f64) -> Option<f64> {
    (old.abs() > 0.0).then(|| (new.abs() - old.abs()) / old.abs() * 100.0)
}

/// Stored fatigue of each disc of a recording, by name.
type Lives = Vec<(String, Option<clutchpack_sdk::record::FatigueSummary>)>;

/// Builds the comparison rows of runs (name, stats, stored fatigue), the first being the
/// baseline.
pub fn compare_rows(runs: &[(String, Vec<DiscStats>, Lives)]) -> Vec<CompareRow> {
    let base = &runs[0].1;
    let base_lives = &runs[0].2;
    let life_of =
        |lives: &Lives, name: &str| lives.iter().find(|(n, _)| n == name).and_then(|(_, f)| *f);
    let mut rows = Vec::new();
    for (run, stats, lives) in runs {
        for s in stats {
            let f = life_of(lives, &s.name);
            let bf = life_of(base_lives, &s.name);
            let b = base.iter().find(|b| b.name == s.name);
            rows.push(CompareRow {
                run: run.clone(),
                disc: s.name.clone(),
                max_positive_n: s.max_positive_n,
                max_negative_n: s.max_negative_n,
                p99_abs_n: s.p99_abs_n,
                impacts: s.impacts,
                max_positive_change_pct: b.and_then(|b| pct(s.max_positive_n, b.max_positive_n)),
                max_negative_change_pct: b.and_then(|b| pct(s.max_negative_n, b.max_negative_n)),
                p99_abs_change_pct: b.and_then(|b| pct(s.p99_abs_n, b.p99_abs_n)),
                life_h: f.and_then(|f| f.life_h),
                fatigue_stored: f.is_some(),
                life_change_pct: match (f.and_then(|f| f.life_h), bf.and_then(|f| f.life_h)) {
                    (Some(new), Some(old)) => pct(new, old),
                    _ => None,
                },
            });
        }
    }
    rows
}

fn fmt_pct(p: Option<f64>) -> String {
    p.map(|p| format!("{p:+.1} %"))
        .unwrap_or_else(|| "-".into())
}

pub fn compare(a: CompareArgs) -> Result<ExitCode> {
    if let Some(r) = crate::study::compare_hook(&a.files) {
        return r; // two study folders: ensembles compared with confidence intervals
    }
    if let Some(p) = &a.plot {
        let inputs: Vec<&Path> = a.files.iter().map(PathBuf::as_path).collect();
        crate::outputs::check_outputs(&[Output::figure("--plot", p)], &inputs)?;
    }
    let mut runs = Vec::new();
    let mut networks = Vec::new();
    for f in &a.files {
        let reader = open_recording(f, a.salvage)?;
        if reader
            .info()
            .metadata(clutchpack_sdk::record::META_NETWORK)
            .is_some()
        {
            networks.push((f.display().to_string(), network_clutches(f, &reader)?));
            continue;
        }
        let stats = recording_stats(&reader);
        reread_ok(&reader)?;
        if stats.is_empty() {
            // say so rather than leaving the run out silently
            eprintln!(
                "warning: {}: no disc was recovered; the run has no rows below",
                f.display()
            );
        }
        let lives: Lives = reader
            .summary()
            .map(|s| {
                s.discs
                    .iter()
                    .enumerate()
                    .map(|(i, d)| (d.name.clone(), s.fatigue_of(i).copied()))
                    .collect()
            })
            .unwrap_or_default();
        runs.push((f.display().to_string(), stats, lives));
    }
    match (runs.is_empty(), networks.is_empty()) {
        (true, false) => return compare_networks(&a, &networks),
        (false, false) => {
            return Err(BadInput(format!(
                "{}: a network recording among pack recordings: compare packs with packs \
                 (their discs) or networks with networks (their clutches)",
                networks[0].0
            ))
            .into())
        }
        _ => {}
    }
    // after reading: a bad file's error stays the only line
    eprintln!("{}", crate::study::ONE_SAMPLE_NOTE);
    let rows = compare_rows(&runs);
    let header = [
        "run",
        "disc",
        "max + [N]",
        "change",
        "max - [N]",
        "change",
        "p99 abs [N]",
        "change",
        "impacts",
        "life [h]",
        "change",
    ];
    let life = |r: &CompareRow| match (r.fatigue_stored, r.life_h) {
        (false, _) => "-".to_string(),
        (true, h) => clutchpack_sdk::analysis::fatigue::format_life_h(h),
    };
    let cells: Vec<[String; 11]> = rows
        .iter()
        .map(|r| {
            [
                r.run.clone(),
                r.disc.clone(),
                format!("{:.1}", r.max_positive_n),
                fmt_pct(r.max_positive_change_pct),
                format!("{:.1}", r.max_negative_n),
                fmt_pct(r.max_negative_change_pct),
                format!("{:.1}", r.p99_abs_n),
                fmt_pct(r.p99_abs_change_pct),
                r.impacts.to_string(),
                life(r),
                fmt_pct(r.life_change_pct),
            ]
        })
        .collect();
    match a.format {
        CompareFormat::Json => out!("{}", serde_json::to_string_pretty(&rows)?),
        CompareFormat::Csv => {
            out!("run,disc,max_positive_n,max_positive_change_pct,max_negative_n,max_negative_change_pct,p99_abs_n,p99_abs_change_pct,impacts,life_h,life_change_pct");
            for r in &rows {
                let o = |p: Option<f64>| p.map(|p| p.to_string()).unwrap_or_default();
                out!(
                    "{},{},{},{},{},{},{},{},{},{},{}",
                    r.run,
                    r.disc,
                    r.max_positive_n,
                    o(r.max_positive_change_pct),
                    r.max_negative_n,
                    o(r.max_negative_change_pct),
                    r.p99_abs_n,
                    o(r.p99_abs_change_pct),
                    r.impacts,
                    o(r.life_h),
                    o(r.life_change_pct)
                );
            }
        }
        CompareFormat::Markdown => {
            out!("| {} |", header.join(" | "));
            out!("|{}", "---|".repeat(header.len()));
            for c in &cells {
                out!("| {} |", c.join(" | "));
            }
        }
        CompareFormat::Table => {
            let mut w = header.map(|h| h.len());
            for c in &cells {
                for (i, x) in c.iter().enumerate() {
                    w[i] = w[i].max(x.len());
                }
            }
            let line = |c: &[String]| {
                c.iter()
                    .enumerate()
                    .map(|(i, x)| {
                        if i < 2 {
                            format!("{x:<w$}", w = w[i])
                        } else {
                            format!("{x:>w$}", w = w[i])
                        }
                    })
                    .collect::<Vec<_>>()
                    .join("  ")
            };
            out!("{}", line(&header.map(String::from)));
            out!(
                "{}",
                "-".repeat(w.iter().sum::<usize>() + 2 * (w.len() - 1))
            );
            for c in &cells {
                out!("{}", line(c));
            }
            out!("changes are of the magnitudes against the first run, per cent; life: of the teeth at the run's duty (stored in the recording; - if not stored)");
        }
    }
    if let Some(path) = &a.plot {
        let mut discs: Vec<String> = Vec::new();
        for (_, s, _) in &runs {
            for d in s {
                if !discs.contains(&d.name) {
                    discs.push(d.name.clone());
                }
            }
        }
        let values: Vec<Vec<(f64, f64)>> = runs
            .iter()
            .map(|(_, s, _)| {
                discs
                    .iter()
                    .map(|d| {
                        s.iter()
                            .find(|x| &x.name == d)
                            .map(|x| (x.max_positive_n, x.max_negative_n))
                            .unwrap_or((0.0, 0.0))
                    })
                    .collect()
            })
            .collect();
        let names: Vec<String> = runs.iter().map(|(n, _, _)| n.clone()).collect();
        crate::outputs::write_with(path, |tmp| {
            clutchpack_sdk::analysis::plot_compare(tmp, &names, &discs, &values)
                .with_context(|| format!("plotting {}", path.display()))
        })?;
    }
    Ok(ExitCode::SUCCESS)
}

/// A network run's clutches (lumped and resolved packs) and its packs' discs and plates.
type NetworkRun = (
    Vec<clutchpack_sdk::analysis::ClutchRun>,
    Vec<clutchpack_sdk::analysis::PackBodyRun>,
    Vec<serde_json::Value>,
);

/// The clutches (lumped and resolved packs) and the packs' bodies of a network recording,
/// from its attached summary (the run's `--summary-json`). A recording of a run that did not
/// finish (killed; read with `--salvage`) has none: its packs' bodies from the impacts it
/// holds (with the contacts still open where it ends), its clutches left out (their heat is
/// the summary's), said on stderr; with no impact either, bad input.
fn network_clutches(f: &Path, reader: &RecordingReader) -> Result<NetworkRun> {
    let Some(summary) = reader
        .info()
        .attachments
        .iter()
        .find(|x| x.name == clutchpack_sdk::record::SUMMARY_ATTACHMENT)
        .and_then(|x| serde_json::from_slice::<serde_json::Value>(&x.data).ok())
    else {
        let net = clutchpack_sdk::record::read_network(reader)
            .transpose()
            .map_err(|e| BadInput(format!("{}: {e}", f.display())))?;
        let bodies = net.as_ref().map_or_else(Vec::new, |n| {
            clutchpack_sdk::analysis::PackBodyRun::from_impacts(&n.couplings, &n.impacts)
        });
        let Some(net) = net.filter(|_| !bodies.is_empty()) else {
            return Err(BadInput(format!(
                "{}: a network recording without its summary (the run did not finish) and \
                 without a pack's impact: nothing to compare",
                f.display()
            ))
            .into());
        };
        eprintln!(
            "note: {}: no summary (the run did not finish): its packs' bodies from the {} \
             impacts it holds ({} contacts still open where it ends, closed there); its \
             clutches are not compared",
            f.display(),
            net.impacts.len(),
            net.open_contacts
        );
        return Ok((Vec::new(), bodies, Vec::new()));
    };
    let couplings = summary["couplings"].as_array().cloned().unwrap_or_default();
    let bodies = couplings
        .iter()
        .filter(|c| c["kind"] == "pack")
        .flat_map(|c| {
            let pack = c["name"].as_str().unwrap_or("?").to_string();
            c["pack_bodies"]
                .as_array()
                .cloned()
                .unwrap_or_default()
                .into_iter()
                .map(move |b| clutchpack_sdk::analysis::PackBodyRun {
                    name: format!("{pack}/{}", b["name"].as_str().unwrap_or("?")),
                    impacts: b["impacts"].as_u64().unwrap_or(0),
                    peak_abs_n: b["largest_peak_n"].as_f64().unwrap_or(0.0).abs(),
                })
        })
        .collect();
    let clutches = couplings
        .iter()
        .filter(|c| c["kind"] == "clutch" || c["kind"] == "one_way_clutch" || c["kind"] == "pack")
        .map(|c| {
            let num = |k: &str| c[k].as_f64().unwrap_or(0.0);
            clutchpack_sdk::analysis::ClutchRun {
                name: c["name"].as_str().unwrap_or("?").to_string(),
                heat_j: num("heat_j"),
                first_lock_s: c["lock_times_s"]
                    .as_array()
                    .and_then(|l| l.first())
                    .and_then(serde_json::Value::as_f64),
                max_abs_torque_n_m: num("min_torque_n_m").abs().max(num("max_torque_n_m").abs()),
            }
        })
        .collect();
    let shifts = summary["shifts"].as_array().cloned().unwrap_or_default();
    Ok((clutches, bodies, shifts))
}

/// `compare` of network recordings: per run and clutch (lumped or a resolved pack) its heat,
/// first lock and largest torque against the first run's, and which clutch of which run takes
/// the most heat; per run and pack body its impacts and largest peak, and which one is hit
/// hardest. JSON: `{"clutches": [...], "pack_bodies": [...]}`.
fn compare_networks(a: &CompareArgs, networks: &[(String, NetworkRun)]) -> Result<ExitCode> {
    use clutchpack_sdk::analysis::{
        clutch_compare_rows, clutch_compare_table, hardest_hit, hottest_clutch,
        largest_peak_change, pack_body_compare_rows, pack_body_compare_table, TableFormat,
    };
    if a.plot.is_some() {
        return Err(BadInput(
            "--plot: the bar chart of discs' peaks is for pack recordings; `clutchpack plot` \
             draws each network run's speeds and torques"
                .into(),
        )
        .into());
    }
    let clutches: Vec<_> = networks
        .iter()
        .map(|(run, (c, _, _))| (run.clone(), c.clone()))
        .collect();
    let bodies: Vec<_> = networks
        .iter()
        .map(|(run, (_, b, _))| (run.clone(), b.clone()))
        .collect();
    let shifts: Vec<_> = networks
        .iter()
        .map(|(run, (_, _, s))| (run.clone(), s.clone()))
        .collect();
    let rows = clutch_compare_rows(&clutches);
    let body_rows = pack_body_compare_rows(&bodies);
    let format = match a.format {
        CompareFormat::Json => {
            let both =
                serde_json::json!({ "clutches": rows, "pack_bodies": body_rows, "shifts": shifts });
            out!("{}", serde_json::to_string_pretty(&both)?);
            return Ok(ExitCode::SUCCESS);
        }
        CompareFormat::Csv => TableFormat::Csv,
        CompareFormat::Markdown => TableFormat::Markdown,
        CompareFormat::Table => TableFormat::Text,
    };
    if !rows.is_empty() {
        // none when every run was cut short (no summary: its clutches are not compared)
        out!("{}", clutch_compare_table(&rows, format).trim_end());
    }
    if !body_rows.is_empty() {
        out!("{}", pack_body_compare_table(&body_rows, format).trim_end());
    }
    if format == TableFormat::Text {
        for line in crate::shift_compare::lines(&shifts) {
            out!("{line}");
        }
        out!("changes against the first run, per cent; shift: the first lock's, s");
        if let Some(h) = hottest_clutch(&rows) {
            out!(
                "the clutch that takes the most heat: {} in {} ({:.1} J{})",
                h.clutch,
                h.run,
                h.heat_j,
                h.heat_change_pct
                    .filter(|p| p.abs() > 0.0)
                    .map_or(String::new(), |p| format!(
                        ", {p:+.1} % against the first run"
                    ))
            );
        }
        if let Some(h) = hardest_hit(&body_rows).filter(|h| h.impacts > 0) {
            out!(
                "the pack body hit hardest: {} in {} ({:.3} N per tooth{})",
                h.body,
                h.run,
                h.peak_abs_n,
                h.peak_change_pct
                    .filter(|p| p.abs() > 0.0)
                    .map_or(String::new(), |p| format!(
                        ", {p:+.1} % against the first run"
                    ))
            );
        }
        if let Some(c) = largest_peak_change(&body_rows) {
            out!(
                "the largest change of a pack body's peak: {} in {} ({:+.1} %, {:.3} N per tooth)",
                c.body,
                c.run,
                c.peak_change_pct.unwrap_or(0.0),
                c.peak_abs_n
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Arguments of `clutchpack export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// The recording (.mcap).
    pub file: PathBuf,
    /// Folder for the CSV files (one per topic; created if needed; existing files of the
    /// same names are replaced, each written whole).
    #[arg(long, value_name = "DIR", required = true)]
    pub csv: PathBuf,
    /// Use the recovered messages of a damaged file.
    #[arg(long)]
    pub salvage: bool,
}

pub fn export(a: ExportArgs) -> Result<ExitCode> {
    if a.csv.exists() && !a.csv.is_dir() {
        return Err(BadInput(format!("--csv {}: is not a folder", a.csv.display())).into());
    }
    // SIGINT, SIGTERM and SIGHUP stop the export between files: those written are complete
    let stop = crate::signals::flag();
    let reader = open_recording(&a.file, a.salvage)?;
    let written =
        clutchpack_sdk::record::export_csv_until(&reader, &a.csv, &stop).map_err(|e| match e {
            // the input was fine: writing the CSV failed (a full disk, a lost folder): exit 1
            e @ clutchpack_sdk::record::ReadError::Export { .. } => anyhow::Error::from(e),
            e => BadInput(e.to_string()).into(),
        })?;
    for p in &written {
        out!("{}", p.display());
    }
    if stop.load(std::sync::atomic::Ordering::SeqCst) {
        eprintln!(
            "interrupted ({}): {} files written",
            crate::signals::received_name(),
            written.len()
        );
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// Arguments of `clutchpack plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    /// The recording (.mcap).
    pub file: PathBuf,
    /// The figure (PNG or SVG by extension; an existing FIG is replaced).
    #[arg(short = 'o', long = "out", value_name = "FIG", required = true)]
    pub out: PathBuf,
    /// Use the recovered messages of a damaged file.
    #[arg(long)]
    pub salvage: bool,
    /// Draw the fatigue figure instead of the load history: the exceedance spectra of the
    /// contact peaks of all discs (impacts per hour above each load, log-log) and, for discs
    /// with recorded per-tooth loads, the damage of each tooth around the disc (polar).
    #[arg(long)]
    pub spectrum: bool,
}

fn plot_spectrum(reader: &RecordingReader, a: &PlotArgs) -> Result<ExitCode> {
    let clutchpack_sdk::RecordedFatigue {
        names,
        histories,
        fatigue,
        duration_s: duration,
        warning,
    } = clutchpack_sdk::RecordedFatigue::of(reader);
    if let Some(w) = warning {
        eprintln!("warning: {w}");
    }
    reread_ok(reader)?;
    let spectra: Vec<(String, Vec<(f64, f64)>)> = names
        .iter()
        .zip(&histories)
        .map(|(n, h)| {
            (
                n.clone(),
                clutchpack_sdk::analysis::cycles::exceedance_spectrum(&h.lumped.peaks, duration),
            )
        })
        .collect();
    let teeth: Vec<(String, Vec<f64>)> = fatigue
        .iter()
        .filter_map(|d| d.teeth.as_ref().map(|t| (d.name.clone(), t.damage.clone())))
        .collect();
    let scene = reader
        .info()
        .metadata("clutchpack.run")
        .and_then(|m| m.get("scene_name").cloned())
        .unwrap_or_else(|| a.file.display().to_string());
    clutchpack_sdk::analysis::fatigue_plot::plot_spectrum(
        &a.out,
        &format!("{scene}: tooth load spectra and damage"),
        &spectra,
        &teeth,
    )
    .with_context(|| format!("plotting {}", a.out.display()))?;
    out!("{}", a.out.display());
    Ok(ExitCode::SUCCESS)
}

pub fn plot(a: PlotArgs) -> Result<ExitCode> {
    crate::outputs::check_outputs(&[Output::figure("--out", &a.out)], &[a.file.as_path()])?;
    let reader = open_recording(&a.file, a.salvage)?;
    if let Some(net) = clutchpack_sdk::record::read_network(&reader) {
        let net = net.map_err(|e| BadInput(format!("{}: {e}", a.file.display())))?;
        reread_ok(&reader)?;
        return crate::network::plot_recording(&reader, &net, &a.file, &a.out, a.spectrum);
    }
    if a.spectrum {
        return plot_spectrum(&reader, &a);
    }
    let (names, mut histories): (Vec<String>, Vec<Vec<(f64, f64)>>) = reader
        .load_histories()
        .into_iter()
        .map(|h| (h.name, h.t_s.into_iter().zip(h.load_n).collect()))
        .unzip();
    clutchpack_sdk::merge_peaks(&mut histories, &reader.impacts());
    reread_ok(&reader)?;
    let series: Vec<(String, Vec<(f64, f64)>)> = names.into_iter().zip(histories).collect();
    let scene = reader
        .info()
        .metadata("clutchpack.run")
        .and_then(|m| m.get("scene_name").cloned())
        .unwrap_or_else(|| a.file.display().to_string());
    let title = format!("{scene}: per-tooth load");
    crate::outputs::write_with(&a.out, |tmp| {
        clutchpack_sdk::analysis::plot_load_history(tmp, &title, &series)
            .with_context(|| format!("plotting {}", a.out.display()))
    })?;
    out!("{}", a.out.display());
    Ok(ExitCode::SUCCESS)
}
