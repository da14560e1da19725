//! `clutchpack study`: run, merge, submit and compare studies (clutchpack_study).

use crate::common::BadInput;
use crate::outputs::Output;
use crate::signals;
use anyhow::{Context, Result};
use clutchpack_sdk::study::merge::Merged;
use clutchpack_sdk::study::part::array_syntax;
use clutchpack_sdk::study::stats::{welch, Summary};
use clutchpack_sdk::study::{scheduler, MergeError, Shard, Study};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Arguments of `clutchpack study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    #[command(subcommand)]
    pub command: StudyCommand,
}

/// The study subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum StudyCommand {
    /// Run a study's cases (all, or one shard) and write their part file in DIR.
    Run(RunArgs),
    /// Check that every shard's part is in DIR and write the results table (Parquet, CSV),
    /// the per-design-point summary and the main-effects plot.
    Merge(MergeArgs),
    /// Write (and submit) the batch scripts of a study: a Slurm job array with a dependent
    /// merge job, or Kubernetes Jobs.
    Submit(SubmitArgs),
    /// Compare two merged studies (or ensembles): per disc, the change of the mean peak with
    /// its 95 % confidence interval (Welch), and whether it is significant.
    Compare(CompareArgs),
}

#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  clutchpack study run studies/spacing-mc.toml --out out/mc --jobs 2\n  clutchpack study run studies/spacing-mc.toml --out out/mc --shard 3/16\n  clutchpack study run studies/spacing-mc.toml --out out/mc --shard auto --shards 16   # in a job array"
)]
pub struct RunArgs {
    /// The study file (TOML).
    pub study: PathBuf,
    /// Output folder (shared storage on a cluster).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Threads (default: SLURM_CPUS_PER_TASK, else the number of cores).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
    /// Run shard I of N (`3/16`), or `auto`: I from SLURM_ARRAY_TASK_ID or
    /// JOB_COMPLETION_INDEX, N from --shards. Default: the whole study (0/1).
    #[arg(long, value_name = "I/N|auto")]
    pub shard: Option<String>,
    /// Number of shards with `--shard auto` (never guessed).
    #[arg(long, value_name = "N")]
    pub shards: Option<u64>,
    /// Exit 1 when a case failed (default: failed cases are rows of the table and the shard
    /// exits 0, so that a scheduler's `afterok` means "the shard ran").
    #[arg(long)]
    pub strict: bool,
}

#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The study's output folder (with the part files).
    pub dir: PathBuf,
    /// Main-effects figure format.
    #[arg(long, default_value = "png", value_parser = ["png", "svg"])]
    pub plot_format: String,
}

#[derive(clap::Args, Debug)]
pub struct SubmitArgs {
    /// The study file (TOML).
    pub study: PathBuf,
    /// Output folder (on storage every node sees; default `<study stem>-out` beside the
    /// study file).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Submit to Slurm (sbatch).
    #[arg(long, conflicts_with = "k8s", required_unless_present = "k8s")]
    pub slurm: bool,
    /// Write Kubernetes manifests (an Indexed Job and the merge Job; not applied).
    #[arg(long)]
    pub k8s: bool,
    /// Number of shards (array tasks); default min(cases, 16).
    #[arg(long, value_name = "N")]
    pub shards: Option<u64>,
    /// Only these array indexes (`--array` syntax, `1,3-4`): resubmits missing shards.
    #[arg(long, value_name = "LIST")]
    pub array: Option<String>,
    /// Time limit of a shard (Slurm syntax).
    #[arg(long, value_name = "T", default_value = "01:00:00")]
    pub time: String,
    /// Time limit of the merge job.
    #[arg(long, value_name = "T", default_value = "00:15:00")]
    pub merge_time: String,
    /// Slurm partition.
    #[arg(long, value_name = "P")]
    pub partition: Option<String>,
    /// CPUs (threads) per shard.
    #[arg(long, value_name = "C", default_value_t = 1)]
    pub cpus_per_task: u32,
    /// SIGTERM a shard this many seconds before its time limit (`--signal=B:TERM@S`).
    #[arg(long, value_name = "S", default_value_t = 60)]
    pub signal_before: u32,
    /// Print the scripts and the commands instead of submitting.
    #[arg(long)]
    pub dry_run: bool,
    /// Wait for the merge job to end (sbatch --wait).
    #[arg(long)]
    pub wait: bool,
    /// Submit the shards held (`sbatch --hold`): nothing starts until
    /// `scontrol release <array job id>`.
    #[arg(long)]
    pub hold: bool,
    /// Kubernetes: container image with clutchpack on its PATH.
    #[arg(long, default_value = "clutchpack:latest")]
    pub image: String,
    /// Kubernetes: the ReadWriteMany PersistentVolumeClaim mounted at /work, the pods' working
    /// folder; it holds the study, its scene and the output (relative paths start there).
    #[arg(long, default_value = "clutchpack-work")]
    pub claim: String,
}

#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The baseline study's output folder.
    pub a: PathBuf,
    /// The other study's output folder.
    pub b: PathBuf,
    /// The per-disc statistic compared.
    #[arg(long, default_value = "peak_abs_n", value_parser = clutchpack_sdk::study::spec::STATS)]
    pub stat: String,
}

pub fn study(a: StudyArgs) -> Result<ExitCode> {
    match a.command {
        StudyCommand::Run(a) => run(a),
        StudyCommand::Merge(a) => merge(a),
        StudyCommand::Submit(a) => submit(a),
        StudyCommand::Compare(a) => compare(a),
    }
}

/// Loads a study; its problems are bad input (exit 2).
pub fn load_study(path: &Path) -> Result<Study> {
    clutchpack_sdk::study::load(path).map_err(|e| BadInput(e.to_string()).into())
}

/// Threads: `--jobs`, else SLURM_CPUS_PER_TASK (a task may see every core of its node), else
/// the number of cores.
fn threads(jobs: Option<usize>) -> Result<usize> {
    if let Some(j) = jobs {
        if j == 0 {
            return Err(BadInput("--jobs must be at least 1".into()).into());
        }
        return Ok(j);
    }
    if let Ok(v) = std::env::var("SLURM_CPUS_PER_TASK") {
        return match v.trim().parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(BadInput(format!(
                "SLURM_CPUS_PER_TASK = {v:?}: expected an integer >= 1"
            ))
            .into()),
        };
    }
    Ok(std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// The shard from `--shard` / `--shards` and the environment.
pub fn shard_of(shard: Option<&str>, shards: Option<u64>) -> Result<Shard> {
    let bad = |m: String| -> anyhow::Error { BadInput(m).into() };
    let (index, count) = match shard {
        None => {
            if let Some(n) = shards {
                return Err(bad(format!(
                    "--shards {n} needs --shard auto (or give --shard I/N)"
                )));
            }
            (0, 1)
        }
        Some("auto") => {
            let count = shards.ok_or_else(|| {
                bad("--shard auto needs --shards N: the number of shards is never guessed from the environment".into())
            })?;
            let (var, val) = ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"]
                .iter()
                .find_map(|v| std::env::var(v).ok().map(|x| (*v, x)))
                .ok_or_else(|| bad("--shard auto: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set (not in a job array); give --shard I/N".into()))?;
            let index = val
                .trim()
                .parse::<u64>()
                .map_err(|_| bad(format!("--shard auto: {var} = {val:?} is not an index")))?;
            (index, count)
        }
        Some(s) => {
            let parsed = s.split_once('/').and_then(|(i, n)| {
                Some((i.trim().parse::<u64>().ok()?, n.trim().parse::<u64>().ok()?))
            });
            let (i, n) = parsed
                .ok_or_else(|| bad(format!("--shard {s:?}: expected I/N (e.g. 3/16) or auto")))?;
            if shards.is_some_and(|m| m != n) {
                return Err(bad(format!(
                    "--shard {s} and --shards {} disagree",
                    shards.unwrap_or(0)
                )));
            }
            (i, n)
        }
    };
    if count == 0 || index >= count {
        return Err(bad(format!(
            "shard {index} of {count}: the index must be in 0..{count} (N >= 1)"
        )));
    }
    Ok(Shard { index, count })
}

fn run(a: RunArgs) -> Result<ExitCode> {
    let study = load_study(&a.study)?;
    let shard = shard_of(a.shard.as_deref(), a.shards)?;
    let jobs = threads(a.jobs)?;
    let stop = signals::flag();
    let label = format!("{} shard {}/{}", study.name, shard.index, shard.count);
    eprintln!(
        "{label}: {} of {} cases on {jobs} threads, part in {}",
        shard.cases(study.cases()).count(),
        study.cases(),
        a.out.display()
    );
    let t0 = Instant::now();
    let last = std::sync::Mutex::new(Instant::now() - Duration::from_secs(10));
    let progress = |done: usize, total: usize| {
        let mut l = last.lock().expect("no panics hold it");
        if done == total || l.elapsed() >= Duration::from_secs(2) {
            *l = Instant::now();
            eprintln!(
                "{label}: {done}/{total} cases, {:.1} s",
                t0.elapsed().as_secs_f64()
            );
        }
    };
    let outcome = clutchpack_sdk::run_study_shard(&study, &a.out, shard, jobs, &stop, &progress)?;
    if let Some((to, reason)) = &outcome.set_aside {
        eprintln!(
            "warning: {label}: the part was damaged ({reason}); moved to {} and its cases ran again",
            to.display()
        );
    }
    let overhead = (outcome.wall_s * jobs as f64 - outcome.case_wall_s).max(0.0);
    eprintln!(
        "{label}: {} cases, {} skipped (already done), {} run, {} failed; {:.2} s wall, engine {:.2} s over {jobs} threads; part {}{}",
        outcome.cases,
        outcome.skipped,
        outcome.ran,
        outcome.failed,
        outcome.wall_s,
        outcome.case_wall_s,
        outcome.path.display(),
        if outcome.ran > 0 {
            format!("; idle/overhead {:.1} % of thread time", 100.0 * overhead / (outcome.wall_s * jobs as f64).max(1e-9))
        } else {
            String::new()
        }
    );
    if stop.load(Ordering::SeqCst) {
        eprintln!(
            "{label}: stopped by {} with {}/{} cases done; run the same command again to finish",
            signals::received_name(),
            outcome.skipped + outcome.ran,
            outcome.cases
        );
        return Ok(signals::exit_code());
    }
    if a.strict && outcome.failed > 0 {
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Exit code of `merge` when shards are missing.
pub const EXIT_MISSING: u8 = 3;

/// The files `study merge` writes in a study's output folder: the results table (CSV and
/// Parquet), the per-design-point summary and the main-effects figure.
fn merge_outputs(dir: &Path, plot_format: &str) -> [PathBuf; 4] {
    [
        dir.join("results.csv"),
        dir.join("summary.csv"),
        dir.join("results.parquet"),
        dir.join(format!("main-effects.{plot_format}")),
    ]
}

fn merge(a: MergeArgs) -> Result<ExitCode> {
    // Every output checked before any work, as `run`'s (crate::outputs): a FIFO named
    // main-effects.png blocked the merge for ever (issue 36). A missing folder is the sdk's
    // to say ("not a folder").
    if a.dir.is_dir() {
        let paths = merge_outputs(&a.dir, &a.plot_format);
        let outs: Vec<Output> = paths
            .iter()
            .map(|p| {
                if p.extension().is_some_and(|e| e == "png" || e == "svg") {
                    Output::figure("output", p)
                } else {
                    Output::file("output", p)
                }
            })
            .collect();
        crate::outputs::check_outputs(&outs, &[])?;
    }
    let done = match clutchpack_sdk::merge_study(&a.dir, &a.plot_format) {
        Ok(d) => d,
        Err(clutchpack_sdk::Error::StudyIncomplete(MergeError::Missing {
            count,
            missing,
            set_aside,
        })) => {
            for (to, reason) in &set_aside {
                eprintln!(
                    "warning: a damaged part ({reason}) was moved to {}; its shard runs again",
                    to.display()
                );
            }
            eprintln!(
                "error: {}: {} of {count} shards missing or unfinished: {}",
                a.dir.display(),
                missing.len(),
                array_syntax(&missing)
            );
            eprintln!("resubmit them, e.g. clutchpack study submit STUDY --slurm --shards {count} --array={}", array_syntax(&missing));
            out!("--array={}", array_syntax(&missing));
            return Ok(ExitCode::from(EXIT_MISSING));
        }
        Err(e) => return Err(e.into()),
    };
    let m = &done.merged;
    let failed = m.records.iter().filter(|r| r.error.is_some()).count();
    out!(
        "{}: {} cases ({} failed) merged from {} into results.parquet, results.csv, summary.csv{}",
        m.header.name,
        m.records.len(),
        failed,
        a.dir.display(),
        match &done.plot {
            Some(plot) => format!(
                ", {}",
                plot.file_name().unwrap_or_default().to_string_lossy()
            ),
            None => String::new(),
        }
    );
    print_effects(m);
    Ok(ExitCode::SUCCESS)
}

fn print_effects(m: &Merged) {
    let Some(d) = m.hardest_disc() else { return };
    out!("hardest-hit disc: {} (largest mean peak); its peak |load| per tooth by factor level (mean, 95 % CI, n):", m.discs[d]);
    for ef in clutchpack_sdk::study::plot::main_effects(m, d) {
        for (l, s) in &ef.points {
            out!(
                "  {} = {}: {:.1} N +- {:.1} N (n = {})",
                ef.factor,
                l,
                s.mean,
                s.ci95_half,
                s.n
            );
        }
    }
}

fn submit(a: SubmitArgs) -> Result<ExitCode> {
    let study = load_study(&a.study)?;
    let abs = |p: &Path| -> Result<PathBuf> {
        std::path::absolute(p).with_context(|| format!("resolving {}", p.display()))
    };
    let study_path = abs(&a.study)?;
    let out = match &a.out {
        Some(o) => abs(o)?,
        None => study_path.with_file_name(format!("{}-out", study.name)),
    };
    let shards = a.shards.unwrap_or_else(|| study.cases().clamp(1, 16));
    if shards == 0 {
        return Err(BadInput("--shards must be at least 1".into()).into());
    }
    let array = match &a.array {
        Some(list) => {
            let ok = list.split(',').all(|p| {
                let mut it = p.splitn(2, '-').map(|x| x.trim().parse::<u64>());
                match (it.next(), it.next()) {
                    (Some(Ok(i)), None) => i < shards,
                    (Some(Ok(i)), Some(Ok(j))) => i <= j && j < shards,
                    _ => false,
                }
            });
            if !ok {
                return Err(BadInput(format!(
                    "--array {list:?}: expected indexes or ranges in 0..{shards} (`1,3-4`)"
                ))
                .into());
            }
            list.clone()
        }
        None => format!("0-{}", shards - 1),
    };
    let exe = std::env::current_exe().context("finding the clutchpack executable")?;
    if a.k8s {
        // paths as given: relative ones resolve in the pods' working folder, the claim
        let k8s_out = a
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{}-out", study.name)));
        let j = scheduler::K8sJob {
            name: &study.name,
            image: &a.image,
            study: &a.study.display().to_string(),
            out: &k8s_out.display().to_string(),
            shards,
            parallelism: shards.min(16),
            cpus: a.cpus_per_task,
            claim: &a.claim,
        };
        let (job, merge) = (scheduler::k8s_indexed_job(&j), scheduler::k8s_merge_job(&j));
        if a.dry_run {
            out!("{job}---\n{merge}");
            return Ok(ExitCode::SUCCESS);
        }
        let dir = out.join("k8s");
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        crate::outputs::write_text(&dir.join("shards-job.yaml"), &job)?;
        crate::outputs::write_text(&dir.join("merge-job.yaml"), &merge)?;
        let name = scheduler::dns_label(&study.name);
        out!("wrote {}/shards-job.yaml and merge-job.yaml; apply with:\n  kubectl apply -f {0}/shards-job.yaml\n  kubectl wait --for=condition=complete --timeout=24h job/{name}-shards\n  kubectl apply -f {0}/merge-job.yaml", dir.display());
        return Ok(ExitCode::SUCCESS);
    }
    let j = scheduler::SlurmJob {
        name: &study.name,
        exe: &exe,
        study: &study_path,
        out: &out,
        shards,
        array,
        time: &a.time,
        merge_time: &a.merge_time,
        partition: a.partition.as_deref(),
        cpus_per_task: a.cpus_per_task,
        signal_s: a.signal_before,
    };
    let script_error =
        |e: scheduler::ScriptError| -> anyhow::Error { BadInput(e.to_string()).into() };
    let (arr, mrg) = (
        scheduler::slurm_array_script(&j).map_err(script_error)?,
        scheduler::slurm_merge_script(&j).map_err(script_error)?,
    );
    let dir = out.join("slurm");
    let (arr_path, mrg_path) = (dir.join("shards.sbatch"), dir.join("merge.sbatch"));
    let submit = scheduler::slurm_submit_commands(&arr_path, &mrg_path).map_err(script_error)?;
    if a.dry_run {
        out!(
            "# {}\n{arr}\n# {}\n{mrg}\n# submit:\n{submit}",
            arr_path.display(),
            mrg_path.display(),
        );
        return Ok(ExitCode::SUCCESS);
    }
    for d in [&dir, &out.join("logs")] {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    crate::outputs::write_text(&arr_path, &arr)?;
    crate::outputs::write_text(&mrg_path, &mrg)?;
    let sbatch = |args: &[&str]| -> Result<String> {
        let o = std::process::Command::new("sbatch")
            .args(args)
            .output()
            .context("running sbatch (is Slurm installed and SLURM_CONF set?)")?;
        if !o.status.success() {
            anyhow::bail!(
                "sbatch {}: {}",
                args.join(" "),
                String::from_utf8_lossy(&o.stderr).trim()
            );
        }
        let id = String::from_utf8_lossy(&o.stdout).trim().to_string();
        Ok(id.split(';').next().unwrap_or_default().to_string())
    };
    let arr_arg = arr_path.display().to_string();
    let mut aargs = vec!["--parsable"];
    if a.hold {
        aargs.push("--hold");
    }
    aargs.push(&arr_arg);
    let aid = sbatch(&aargs)?;
    out!(
        "submitted shards as job array {aid} ({} of {shards} shards){}",
        j.array,
        if a.hold {
            format!(", held: scontrol release {aid}")
        } else {
            String::new()
        }
    );
    let dep = format!("--dependency=afterok:{aid}");
    let mut margs = vec!["--parsable", &dep, "--kill-on-invalid-dep=yes"];
    if a.wait {
        margs.push("--wait");
    }
    let mp = mrg_path.display().to_string();
    margs.push(&mp);
    let mid = sbatch(&margs)?;
    out!(
        "submitted merge as job {mid} (after the array succeeds); results in {}",
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn compare(a: CompareArgs) -> Result<ExitCode> {
    let load = |d: &Path| -> Result<Merged> {
        clutchpack_sdk::study::collect(d)
            .map_err(|e| BadInput(format!("{}: {e}", d.display())).into())
    };
    let (ma, mb) = (load(&a.a)?, load(&a.b)?);
    let text = compare_text(&ma, &mb, &a.stat).map_err(BadInput)?;
    out!("{text}");
    Ok(ExitCode::SUCCESS)
}

/// The per-disc comparison of two merged studies: each disc's `stat` over every successful
/// case of each (an ensemble), the change of the mean with Welch's 95 % interval.
/// The comparison table of `stat` per disc, or why there is nothing to compare (no disc of
/// one study in the other with values of `stat` on both sides).
pub fn compare_text(a: &Merged, b: &Merged, stat: &str) -> Result<String, String> {
    let mut s = format!(
        "{stat} per disc: {} ({} cases) -> {} ({} cases); change of the mean with its 95 % CI (Welch)\n",
        a.header.name,
        a.records.len(),
        b.header.name,
        b.records.len()
    );
    s.push_str(&format!(
        "{:<12} {:>22} {:>22} {:>26} {:>9}  {}\n",
        "disc", "A mean +- CI", "B mean +- CI", "change +- CI", "change", "significant?"
    ));
    let mut rows = 0;
    for (i, d) in a.discs.iter().enumerate() {
        let Some(j) = b.discs.iter().position(|x| x == d) else {
            continue;
        };
        let (Some(sa), Some(sb)) = (
            Summary::of(&a.values(i, stat, |_| true)),
            Summary::of(&b.values(j, stat, |_| true)),
        ) else {
            continue;
        };
        rows += 1;
        let pm = |m: f64, h: f64| format!("{m:.1} +- {h:.1}");
        match welch(&sa, &sb) {
            Some(w) => s.push_str(&format!(
                "{:<12} {:>22} {:>22} {:>26} {:>8.1}%  {}\n",
                d,
                pm(sa.mean, sa.ci95_half),
                pm(sb.mean, sb.ci95_half),
                pm(w.delta, w.ci95_half),
                100.0 * w.delta / sa.mean.abs().max(1e-300),
                if w.significant {
                    "yes (CI excludes 0)"
                } else {
                    "no (within run-to-run spread)"
                }
            )),
            None => s.push_str(&format!(
                "{d:<12} one case per side: no interval (run ensembles)\n"
            )),
        }
    }
    if rows == 0 {
        return Err(format!(
            "{} and {} have nothing to compare: no disc is in both with values of {stat} \
             (discs of {}: {}; of {}: {}; a statistic is compared where both studies kept it \
             in study.outputs)",
            a.header.name,
            b.header.name,
            a.header.name,
            a.discs.join(", "),
            b.header.name,
            b.discs.join(", ")
        ));
    }
    Ok(s)
}

/// `compare`'s hook: two study output folders are compared as ensembles.
pub fn compare_hook(files: &[PathBuf]) -> Option<Result<ExitCode>> {
    if files.len() == 2 && files.iter().all(|f| f.is_dir()) {
        return Some(compare(CompareArgs {
            a: files[0].clone(),
            b: files[1].clone(),
            stat: "peak_abs_n".into(),
        }));
    }
    None
}

/// What `compare` of single recordings says about them.
pub const ONE_SAMPLE_NOTE: &str = "note: each recording is one run, one sample of a chaotic rattle: changes of a few per cent can be run-to-run spread. For a verdict with confidence intervals, run ensembles (`clutchpack study run`, `[ensemble] members`) and compare the studies' folders (`clutchpack compare A_DIR B_DIR`).";
