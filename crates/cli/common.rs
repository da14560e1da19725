//! Shared helpers of the subcommands: scene loading, engine choice, the summary JSON.

use anyhow::{Context, Result};
use clutchpack_analysis::{DiscFatigue, DiscStats, FatigueCollector, InterfaceStats, PeakStats};
use clutchpack_model::{
    Engine, FatigueParams, ImpactEvent, InterfaceSample, Observer, RunStats, Sample,
    SplineGeometry, StackBody,
};
use clutchpack_reference::ReferenceEngine;
use clutchpack_scene::{EngineChoice, Override, Scene};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The default scene, built into the binary so that `clutchpack run` works from anywhere.
pub const DEFAULT_SCENE_TEXT: &str = include_str!("../../scenes/hu-table2.toml");
/// The name the default scene is reported under.
pub const DEFAULT_SCENE_NAME: &str = "scenes/hu-table2.toml (built in)";

/// Marks an error as bad input (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// Loads `path` (or the built-in default scene) with `--set` overrides.
pub fn load_scene(path: Option<&Path>, sets: &[Override]) -> Result<Scene> {
    let scene = match path {
        Some(p) => clutchpack_scene::load(p, sets)?,
        None => clutchpack_scene::parse(
            DEFAULT_SCENE_TEXT,
            DEFAULT_SCENE_NAME,
            &std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
            sets,
        )?,
    };
    Ok(scene)
}

/// Engine names accepted by `--engine`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EngineArg {
    /// The reduced torsional engine (fast; the paper's model for a whole pack).
    Reference,
    /// The rapier3d multibody engine (per tooth).
    Multibody,
}

impl EngineArg {
    /// The scene crate's name for this engine.
    pub fn choice(self) -> EngineChoice {
        match self {
            EngineArg::Reference => EngineChoice::Reference,
            EngineArg::Multibody => EngineChoice::Multibody,
        }
    }
}

/// Builds the engine asked for on the command line, else by the scene, else the reference for
/// a torsional pack and the multibody engine for one with per-tooth effects (radial float,
/// offsets, spacing errors: `PackModel::is_torsional`), which only it can run
/// ([`Scene::engine`]); an engine that cannot run the scene is bad input.
pub fn make_engine(scene: &Scene, arg: Option<EngineArg>) -> Result<Box<dyn Engine + Send>> {
    choose_engine(scene, arg).map(|(engine, _)| engine)
}

/// [`make_engine`], with one line saying which engine and scheme run and why, e.g.
/// `engine: reference (multirate: prescribed shaft, no stack; 8 independent discs on 2
/// threads), the default for a torsional pack (concentric discs on one shaft)`.
pub fn choose_engine(
    scene: &Scene,
    arg: Option<EngineArg>,
) -> Result<(Box<dyn Engine + Send>, String)> {
    let asked = arg.map(EngineArg::choice);
    // The scene crate's rule: refuses (bad input) an engine that cannot run the scene.
    let choice = scene.engine(asked, &scene.name)?;
    let why = scene.engine_reason(asked);
    let sim = &scene.simulation;
    match choice {
        EngineChoice::Reference => {
            let settings = clutchpack_reference::Settings {
                tolerance: sim.tolerance,
                max_step_s: sim.max_step_s,
                record_rate_hz: sim.record_rate_hz,
            };
            let engine = ReferenceEngine::new(scene.pack.clone(), settings);
            let line = format!("engine: reference ({}), {why}", engine.describe());
            Ok((Box::new(engine), line))
        }
        EngineChoice::Multibody => match clutchpack_sim::MultibodyEngine::new(
            scene.pack.clone(),
            clutchpack_sim::MultibodyOptions::with_settings(
                sim.record_rate_hz,
                sim.max_step_s,
                sim.record_per_tooth,
            ),
        ) {
            Ok(e) => {
                let line = format!("engine: multibody ({}), {why}", e.scheme_explanation());
                Ok((Box::new(e), line))
            }
            Err(e) => Err(BadInput(format!("{}: {e}", scene.name)).into()),
        },
    }
}

/// Keeps what a run's outputs need, in memory that does not grow with the run unless an
/// output asks for every value: the impact peaks' statistics ([`PeakStats`]), the teeth's
/// fatigue as running sums ([`FatigueCollector::summing`]), what each friction interface did
/// (when named with [`RunCollector::with_interfaces`]), the impacts CSV written as the
/// impacts come ([`RunCollector::with_impacts_csv`]). Kept whole only when asked: the load
/// histories and impacts for `--plot` (`keep_history`) and every counted cycle for
/// `--fatigue-json` ([`RunCollector::with_fatigue`]).
pub struct RunCollector {
    /// Every impact, only when `keep_history` (the plot merges their peaks in).
    pub impacts: Vec<ImpactEvent>,
    /// The statistics of every impact's peak.
    pub peaks: PeakStats,
    pub interfaces: Vec<InterfaceStats>,
    /// Per disc: (t s, load N) samples, only when `keep_history`.
    pub history: Vec<Vec<(f64, f64)>>,
    pub keep_history: bool,
    pub progress: Option<indicatif::ProgressBar>,
    /// The load histories' cycles for the teeth's fatigue (MODEL.md section 7).
    pub fatigue: FatigueCollector,
    /// Spline and fatigue parameters of each coupling (engine order), set by
    /// [`RunCollector::with_fatigue`]; empty: no fatigue in the recording's summary.
    pub fatigue_params: Vec<(SplineGeometry, FatigueParams)>,
    /// The impacts CSV being written, if asked.
    csv: Option<ImpactsCsv>,
    /// Asks the engine to stop when set (a stop signal); see [`RunCollector::with_stop`].
    stop: Option<Arc<AtomicBool>>,
}

impl RunCollector {
    /// Stops the run (cleanly, at the engine's next progress poll) once `stop` is set.
    pub fn with_stop(mut self, stop: Arc<AtomicBool>) -> RunCollector {
        self.stop = Some(stop);
        self
    }

    pub fn new(discs: usize, keep_history: bool) -> RunCollector {
        RunCollector {
            impacts: Vec::new(),
            peaks: PeakStats::new(),
            interfaces: Vec::new(),
            history: vec![Vec::new(); discs],
            keep_history,
            progress: None,
            fatigue: FatigueCollector::new(),
            fatigue_params: Vec::new(),
            csv: None,
            stop: None,
        }
    }

    /// Also assesses the teeth's fatigue with the scene's parameters ([`fatigue_params`]),
    /// summing the damage as the cycles are counted; `keep_cycles` also keeps every cycle
    /// (for `--fatigue-json`'s spectra; memory grows with the run).
    pub fn with_fatigue(mut self, scene: &Scene, keep_cycles: bool) -> RunCollector {
        self.fatigue_params = fatigue_params(scene);
        let curves = self
            .fatigue_params
            .iter()
            .map(|(g, p)| {
                (
                    clutchpack_model::fatigue::stress_per_newton(g, &p.form),
                    p.material,
                )
            })
            .collect();
        self.fatigue = FatigueCollector::summing(curves, keep_cycles);
        self
    }

    /// Also writes every impact to the CSV file `path` as it comes (a temporary sibling,
    /// renamed into place by [`Self::finish_impacts_csv`]); `names` are the disc names in
    /// engine order.
    pub fn with_impacts_csv(mut self, path: &Path, names: &[String]) -> Result<RunCollector> {
        self.csv = Some(ImpactsCsv::create(path, names)?);
        Ok(self)
    }

    /// Completes the impacts CSV (if one is written) with the impacts so far and renames it
    /// into place.
    pub fn finish_impacts_csv(&mut self) -> Result<()> {
        match self.csv.take() {
            Some(c) => c.finish(),
            None => Ok(()),
        }
    }

    /// Impacts so far.
    pub fn impact_count(&self) -> usize {
        self.peaks.impacts()
    }

    /// The per-disc statistics of the impacts so far, named `names`.
    pub fn disc_stats(&self, names: &[String]) -> Result<Vec<DiscStats>> {
        self.peaks
            .stats(names)
            .context("reading back the impact peaks kept in a temporary file")
    }

    /// The fatigue of every coupling (named `names`) over `duration_s` of simulated duty,
    /// from the histories collected so far.
    pub fn assess_fatigue(&self, names: &[String], duration_s: f64) -> Vec<DiscFatigue> {
        assess_fatigue(
            self.fatigue.clone(),
            &self.fatigue_params,
            names,
            duration_s,
        )
    }

    /// Also keeps the figures of the stack's friction interfaces, named in stack order.
    pub fn with_interfaces(mut self, names: impl IntoIterator<Item = String>) -> RunCollector {
        self.interfaces = names.into_iter().map(InterfaceStats::new).collect();
        self
    }

    /// Load histories with each impact's onset, peak and separation merged in (see
    /// [`merge_peaks`]); only with `keep_history`.
    pub fn histories_with_peaks(&self) -> Vec<Vec<(f64, f64)>> {
        let mut h = self.history.clone();
        merge_peaks(&mut h, &self.impacts);
        h
    }
}

/// The impacts CSV of a run, written row by row to a temporary sibling of its path.
struct ImpactsCsv {
    pending: clutchpack_record::PendingFile,
    out: std::io::BufWriter<std::fs::File>,
    names: Vec<String>,
    /// the first write error (reported by `finish`)
    error: Option<std::io::Error>,
}

impl ImpactsCsv {
    fn create(path: &Path, names: &[String]) -> Result<ImpactsCsv> {
        let (pending, file) =
            clutchpack_record::PendingFile::create(path, clutchpack_record::Replace::Existing)
                .with_context(|| format!("creating {}", path.display()))?;
        let mut c = ImpactsCsv {
            pending,
            out: std::io::BufWriter::new(file),
            names: names.to_vec(),
            error: None,
        };
        c.write(|w| writeln!(w, "disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n"));
        Ok(c)
    }

    fn write(&mut self, f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>) {
        if self.error.is_none() {
            if let Err(e) = f(&mut self.out) {
                self.error = Some(e);
            }
        }
    }

    fn row(&mut self, e: &ImpactEvent) {
        let name = self
            .names
            .get(e.disc)
            .cloned()
            .unwrap_or_else(|| format!("disc {}", e.disc));
        self.write(|w| {
            writeln!(
                w,
                "{},{:.9},{:.9},{:.9},{},{:.6},{:.4}",
                clutchpack_analysis::csv_field(&name),
                e.t_on_s,
                e.t_peak_s,
                e.t_off_s,
                e.flank.label(),
                e.v_on_m_s,
                e.peak_n
            )
        });
    }

    fn finish(mut self) -> Result<()> {
        use std::io::Write as _;
        let path = self.pending.target().to_path_buf();
        let flushed = match self.error.take() {
            Some(e) => Err(e),
            None => self
                .out
                .flush()
                .and_then(|()| self.out.get_ref().sync_all()),
        };
        match flushed {
            Ok(()) => {
                drop(self.out);
                self.pending
                    .commit()
                    .with_context(|| format!("writing {}", path.display()))?;
                Ok(())
            }
            Err(e) => {
                self.pending.discard();
                Err(anyhow::Error::new(e).context(format!("writing {}", path.display())))
            }
        }
    }
}

/// Merges each impact's onset (0 N), located peak and separation (0 N) into the sampled load
/// histories `(t s, load N)` of its disc, in time order, so that plotted spikes reach the
/// located peaks whatever the sample rate.
pub fn merge_peaks(histories: &mut [Vec<(f64, f64)>], impacts: &[ImpactEvent]) {
    for e in impacts {
        if let Some(v) = histories.get_mut(e.disc) {
            v.extend([(e.t_on_s, 0.0), (e.t_peak_s, e.peak_n), (e.t_off_s, 0.0)]);
        }
    }
    for v in histories.iter_mut() {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
}

impl Observer for RunCollector {
    fn sample(&mut self, s: &Sample) {
        self.fatigue.sample(s);
        if self.keep_history {
            for (i, d) in s.discs.iter().enumerate() {
                self.history[i].push((s.t_s, d.load_n));
            }
        }
    }
    fn impact(&mut self, e: &ImpactEvent) {
        if self.keep_history {
            self.impacts.push(*e);
        }
        self.peaks.push(e.disc, e.peak_n);
        if let Some(c) = &mut self.csv {
            c.row(e);
        }
        self.fatigue.impact(e);
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        for (st, f) in self.interfaces.iter_mut().zip(interfaces) {
            st.update(t_s, f);
        }
    }
    fn progress(&mut self, t_s: f64) -> bool {
        if let Some(p) = &self.progress {
            p.set_position((t_s * 1e6) as u64);
            let wall = p.elapsed().as_secs_f64().max(1e-9);
            p.set_message(format!(
                "t = {t_s:.4} s, {:.3} simulated s per wall s",
                t_s / wall
            ));
        }
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed))
    }
}

/// The spline and fatigue parameters of each coupling of `scene`, in the engines' order
/// (discs, then plates).
pub fn fatigue_params(scene: &Scene) -> Vec<(SplineGeometry, FatigueParams)> {
    scene
        .pack
        .discs
        .iter()
        .chain(&scene.pack.plates)
        .enumerate()
        .map(|(i, d)| (d.spline, scene.fatigue.get(i).copied().unwrap_or_default()))
        .collect()
}

/// The fatigue of every coupling named `names` from the histories of `collector`, with
/// `params` per coupling (defaults past its end), over `duration_s` of simulated duty.
pub fn assess_fatigue(
    collector: FatigueCollector,
    params: &[(SplineGeometry, FatigueParams)],
    names: &[String],
    duration_s: f64,
) -> Vec<DiscFatigue> {
    assess_histories(&collector.finish(names.len()), params, names, duration_s)
}

/// The fatigue of each coupling from its finished `histories` (see [`assess_fatigue`]).
pub fn assess_histories(
    histories: &[clutchpack_analysis::fatigue::DiscHistories],
    params: &[(SplineGeometry, FatigueParams)],
    names: &[String],
    duration_s: f64,
) -> Vec<DiscFatigue> {
    names
        .iter()
        .zip(histories)
        .enumerate()
        .filter_map(|(i, (name, h))| {
            let (spline, p) = params.get(i)?;
            Some(clutchpack_analysis::assess(
                name,
                h,
                spline,
                &p.form,
                &p.material,
                duration_s,
            ))
        })
        .collect()
}

/// `--summary-json` of a run.
#[derive(Debug, Serialize)]
pub struct RunSummary {
    pub scene: String,
    pub engine: String,
    pub duration_s: f64,
    pub wall_time_s: f64,
    pub steps: u64,
    pub rejected_steps: u64,
    pub discs: Vec<DiscStats>,
    /// The stack's friction interfaces (absent for packs without one).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub interfaces: Vec<InterfaceStats>,
    /// Fatigue of each disc's spline teeth (MODEL.md section 7): damage, damage rate per
    /// hour of this duty, life in hours, damage-equivalent load; per tooth where the engine
    /// resolved teeth.
    pub fatigue: Vec<DiscFatigue>,
}

impl RunSummary {
    pub fn new(
        scene: &Scene,
        engine: &str,
        stats: &RunStats,
        wall_time_s: f64,
        discs: Vec<DiscStats>,
    ) -> RunSummary {
        RunSummary {
            scene: scene.name.clone(),
            engine: engine.to_string(),
            duration_s: stats.simulated_s,
            wall_time_s,
            steps: stats.steps,
            rejected_steps: stats.rejected_steps,
            discs,
            interfaces: Vec::new(),
            fatigue: Vec::new(),
        }
    }
}

/// Writes `value` as pretty JSON to `path`.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    // whole or not at all (crate::outputs)
    crate::outputs::write_text(path, &(text + "\n"))
}

/// A progress bar on stderr for a run of `duration_s` simulated seconds (hidden when stderr
/// is not a terminal).
pub fn time_progress(duration_s: f64, label: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new((duration_s * 1e6) as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template(
            "{prefix} [{bar:30}] {msg} {percent:>3}% eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    pb.set_prefix(label.to_string());
    pb
}

/// The stack's friction interfaces in stack order (empty without a stack). Stack order
/// (`clutchpack_model::clutch`): plate 0, disc 0, plate 1, ..., disc N-1, plate N; interface
/// m lies between stack bodies m and m + 1.
pub fn friction_interfaces(scene: &Scene) -> Vec<clutchpack_record::FrictionInterface> {
    if scene.pack.stack.is_none() {
        return Vec::new();
    }
    let body = |b: usize| {
        let (list, k) = match StackBody::at(b) {
            StackBody::Plate(j) => (&scene.pack.plates, j),
            StackBody::Disc(i) => (&scene.pack.discs, i),
        };
        list.get(k).map(|d| d.name.clone()).unwrap_or_default()
    };
    (0..2 * scene.pack.discs.len())
        .map(|m| clutchpack_record::FrictionInterface {
            lower: body(m),
            upper: body(m + 1),
        })
        .collect()
}

/// Steel density used to draw discs whose outer radius the scene does not give, kg/m^3.
const STEEL_DENSITY_KG_M3: f64 = 7850.0;
/// Disc thickness used to draw discs, m (the paper's 3 mm).
const DRAWN_THICKNESS_M: f64 = 3e-3;

/// What a recording stores about a run: the scene (text, name, overrides), the engine, the
/// solver settings and the geometry drawn in the 3D view. A disc's drawn outer radius is that
/// of a 3 mm steel annulus from its pitch radius with the scene's inertia.
pub fn run_info(
    scene: &Scene,
    engine: &str,
    scene_path: Option<&Path>,
) -> clutchpack_record::RunInfo {
    use clutchpack_record::{DiscGeometry, RunInfo};
    let sim = &scene.simulation;
    let mut solver = std::collections::BTreeMap::new();
    solver.insert("tolerance".to_string(), sim.tolerance.to_string());
    solver.insert("max_step_s".to_string(), sim.max_step_s.to_string());
    let mut params = std::collections::BTreeMap::new();
    params.insert("duration_s".to_string(), sim.duration_s.to_string());
    params.insert("record_rate_hz".to_string(), sim.record_rate_hz.to_string());
    // The engines emit the separator plates after the discs: the recording draws both. A
    // friction disc's spline is its bore (teeth inside), a plate's its rim (teeth outside, on
    // the housing or drum); each is an annulus of the scene's inertia. With a stack the
    // bodies are drawn in stack order along the axis (plate 0, disc 0, plate 1, ...).
    let n_discs = scene.pack.discs.len();
    let stacked = scene.pack.stack.is_some() && scene.pack.plates.len() == n_discs + 1;
    let (t, rho) = (DRAWN_THICKNESS_M, STEEL_DENSITY_KG_M3);
    let discs = scene
        .pack
        .discs
        .iter()
        .chain(&scene.pack.plates)
        .enumerate()
        .map(|(i, d)| {
            let plate = i >= n_discs;
            let r_spline = d.spline.pitch_radius_m;
            let (inner_radius_m, outer_radius_m) = if plate {
                let ri =
                    clutchpack_model::annulus_inner_radius_m(d.inertia_kg_m2, r_spline, t, rho)
                        .unwrap_or(0.5 * r_spline);
                (ri, r_spline)
            } else {
                let ro =
                    clutchpack_model::annulus_outer_radius_m(d.inertia_kg_m2, r_spline, t, rho);
                (r_spline, ro)
            };
            let slot = match (stacked, plate) {
                (true, false) => StackBody::Disc(i).position(),
                (true, true) => StackBody::Plate(i - n_discs).position(),
                (false, _) => i,
            };
            DiscGeometry {
                name: d.name.clone(),
                inner_radius_m,
                outer_radius_m,
                thickness_m: t,
                z_m: slot as f64 * 4.0 * t,
                teeth: d.spline.teeth,
                teeth_outside: plate,
            }
        })
        .collect();
    let interfaces = friction_interfaces(scene);
    RunInfo {
        program_version: env!("CARGO_PKG_VERSION").to_string(),
        engine: engine.to_string(),
        scene_name: scene.name.clone(),
        scene_file: scene_path
            .and_then(|p| p.file_name())
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_else(|| "hu-table2.toml".to_string()),
        scene_text: scene.source_text.clone(),
        overrides: scene.overrides.clone(),
        solver,
        params,
        shaft: None,
        discs,
        interfaces,
    }
}
