//! The summary of a run (`--summary-json`) and what a recording stores about it.

use clutchpack_analysis::{DiscFatigue, DiscStats, InterfaceStats};
use clutchpack_model::{RunStats, StackBody};
use clutchpack_scene::Scene;
use serde::Serialize;
use std::path::Path;

/// `--summary-json` of a run.
#[derive(Debug, Serialize)]
pub struct RunSummary {
    /// The scene's name (its file as named on the command line).
    pub scene: String,
    /// The engine that ran (`reference` or `multibody`).
    pub engine: String,
    /// Simulated time reached, s (less than asked when the run was stopped).
    pub duration_s: f64,
    /// Wall-clock time of the engine's run, s.
    pub wall_time_s: f64,
    /// Accepted engine steps.
    pub steps: u64,
    /// Rejected engine steps (error control).
    pub rejected_steps: u64,
    /// Per body (friction discs, then separator plates): the per-tooth impact loads' statistics
    /// in N (negative: the shaft or carrier leads).
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
    /// The summary of a run of the scene named `scene` on `engine` from the engine's `stats`,
    /// its wall time in s and the bodies' statistics; no interfaces and no fatigue yet.
    pub fn new(
        scene: &str,
        engine: &str,
        stats: &RunStats,
        wall_time_s: f64,
        discs: Vec<DiscStats>,
    ) -> RunSummary {
        RunSummary {
            scene: scene.to_string(),
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
            // a scene without a file (the built-in paper case, an FMU's packed scene, a
            // Python dict) is named after itself, as `clutchpack run` names the paper case
            .unwrap_or_else(|| format!("{}.toml", scene.name)),
        scene_text: scene.source_text.clone(),
        overrides: scene.overrides.clone(),
        solver,
        params,
        shaft: None,
        discs,
        interfaces,
    }
}
