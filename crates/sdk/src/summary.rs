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
    /// A thermal run's temperatures and heat balance (absent for an isothermal run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal: Option<ThermalSummary>,
    /// The figures window by window (`run --windows S`; absent without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub windows: Vec<crate::WindowRow>,
}

/// One body's temperatures in a thermal run, K.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodyTemperature {
    /// The body's name (a disc or a plate).
    pub name: String,
    /// Temperature at the end, K.
    pub final_k: f64,
    /// Highest temperature at a thermal window's end, K.
    pub max_k: f64,
}

/// A thermal run's temperatures (K) and heat balance (J) (MODEL.md section 9).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalSummary {
    /// Per body (friction discs, then separator plates).
    pub bodies: Vec<BodyTemperature>,
    /// The oil's temperature at the end, K.
    pub oil_final_k: f64,
    /// The oil's highest temperature at a window's end, K.
    pub oil_max_k: f64,
    /// Heat of the slipping faces, J (split between their bodies by effusivity).
    pub friction_heat_j: f64,
    /// Heat of the open gaps' drag, J (into the oil).
    pub gap_heat_j: f64,
    /// Heat of the tooth impacts, J (into the oil).
    pub impact_heat_j: f64,
    /// Heat generated, J: the three above.
    pub generated_j: f64,
    /// Heat stored in the bodies, J.
    pub stored_bodies_j: f64,
    /// Heat stored in the oil, J.
    pub stored_oil_j: f64,
    /// Heat the cooler took, J.
    pub cooler_j: f64,
    /// Generated minus (stored + cooler), J: rounding only.
    pub balance_error_j: f64,
    /// Thermal windows taken.
    pub windows: u64,
}

impl ThermalSummary {
    /// The summary of `report` with the bodies' `names` (discs, then plates).
    pub fn new(report: &clutchpack_model::thermal::ThermalReport, names: &[String]) -> Self {
        ThermalSummary {
            bodies: report
                .final_k
                .iter()
                .zip(&report.max_k)
                .enumerate()
                .map(|(i, (f, m))| BodyTemperature {
                    name: names.get(i).cloned().unwrap_or_default(),
                    final_k: *f,
                    max_k: *m,
                })
                .collect(),
            oil_final_k: report.oil_final_k,
            oil_max_k: report.oil_max_k,
            friction_heat_j: report.friction_heat_j,
            gap_heat_j: report.gap_heat_j,
            impact_heat_j: report.impact_heat_j,
            generated_j: report.generated_j(),
            stored_bodies_j: report.stored_bodies_j,
            stored_oil_j: report.stored_oil_j,
            cooler_j: report.cooler_j,
            balance_error_j: report.generated_j() - report.accounted_j(),
            windows: report.windows,
        }
    }
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
        let names: Vec<String> = discs.iter().map(|d| d.name.clone()).collect();
        RunSummary {
            thermal: stats
                .thermal
                .as_ref()
                .map(|r| ThermalSummary::new(r, &names)),
            scene: scene.to_string(),
            engine: engine.to_string(),
            duration_s: stats.simulated_s,
            wall_time_s,
            steps: stats.steps,
            rejected_steps: stats.rejected_steps,
            discs,
            interfaces: Vec::new(),
            fatigue: Vec::new(),
            windows: Vec::new(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::thermal::ThermalReport;

    /// A thermal report in the summary: the bodies named in order, the heat generated and the
    /// balance's error (generated minus stored and cooled, exact here: 0).
    #[test]
    fn thermal_summary_names_bodies_and_closes_the_balance() {
        let report = ThermalReport {
            final_k: vec![354.0, 360.5],
            max_k: vec![354.5, 361.0],
            oil_final_k: 353.5,
            oil_max_k: 353.6,
            friction_heat_j: 100.0,
            gap_heat_j: 20.0,
            impact_heat_j: 5.0,
            stored_bodies_j: 90.0,
            stored_oil_j: 25.0,
            cooler_j: 10.0,
            windows: 3,
            updates: 2,
        };
        let s = ThermalSummary::new(&report, &["disc-1".into(), "plate-1".into()]);
        assert_eq!(s.bodies[1].name, "plate-1");
        assert_eq!((s.bodies[1].final_k, s.bodies[1].max_k), (360.5, 361.0));
        assert_eq!(s.generated_j, 125.0);
        assert_eq!(s.balance_error_j, 0.0);
        // an isothermal run has none (and `--summary-json` writes no `thermal` key: the field
        // is skipped when `None`)
        let mut stats = RunStats::default();
        assert!(RunSummary::new("x", "reference", &stats, 0.0, Vec::new())
            .thermal
            .is_none());
        stats.thermal = Some(report);
        let th = RunSummary::new("x", "reference", &stats, 0.0, Vec::new());
        assert_eq!(th.thermal.map(|t| t.oil_final_k), Some(353.5));
    }
}
