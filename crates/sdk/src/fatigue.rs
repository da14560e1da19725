//! The spline teeth's fatigue of a run (MODEL.md section 7), with each coupling's parameters
//! from its scene.

use clutchpack_analysis::{DiscFatigue, FatigueCollector};
use clutchpack_model::{FatigueParams, SplineGeometry};
use clutchpack_scene::Scene;

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

/// Each coupling's S-N curve for a summing [`FatigueCollector`]: (root stress per newton of
/// tooth load, Pa/N; material) from its spline and fatigue parameters.
pub(crate) fn curves(
    params: &[(SplineGeometry, FatigueParams)],
) -> Vec<(f64, clutchpack_model::Material)> {
    params
        .iter()
        .map(|(g, p)| {
            (
                clutchpack_model::fatigue::stress_per_newton(g, &p.form),
                p.material,
            )
        })
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

/// The teeth's fatigue of a recorded run (`clutchpack plot --spectrum`), from its samples and
/// impacts with the tooth form and material of the recorded scene (with its overrides).
pub struct RecordedFatigue {
    /// The bodies' names, in the recording's order.
    pub names: Vec<String>,
    /// Each body's counted load cycles.
    pub histories: Vec<clutchpack_analysis::fatigue::DiscHistories>,
    /// Each body's fatigue; empty when the recorded scene cannot be read back.
    pub fatigue: Vec<DiscFatigue>,
    /// The recorded duty, s.
    pub duration_s: f64,
    /// Why there are no fatigue figures, if the recorded scene does not read back.
    pub warning: Option<String>,
}

impl RecordedFatigue {
    /// The fatigue of the run `reader` holds.
    pub fn of(reader: &clutchpack_record::RecordingReader) -> RecordedFatigue {
        let names = reader.disc_names();
        let samples = reader.samples();
        let impacts = reader.impacts();
        let duration_s = reader
            .summary()
            .map(|s| s.t_end_s)
            .or(reader.info().end_s)
            .unwrap_or(0.0);
        let mut warning = None;
        let scene = reader.run_info().and_then(|info| {
            let sets: Vec<clutchpack_scene::Override> = info
                .overrides
                .iter()
                .filter_map(|o| o.parse().ok())
                .collect();
            let here = std::path::Path::new(".");
            match clutchpack_scene::parse(&info.scene_text, &info.scene_file, here, &sets) {
                Ok(s) => Some(s),
                Err(e) => {
                    warning = Some(format!(
                        "the recorded scene does not read back ({e}); no damage figures"
                    ));
                    None
                }
            }
        });
        let params = scene.as_ref().map(fatigue_params).unwrap_or_default();
        let collector = FatigueCollector::replay(&samples, &impacts);
        let histories = collector.finish(names.len());
        let fatigue = assess_histories(&histories, &params, &names, duration_s);
        RecordedFatigue {
            names,
            histories,
            fatigue,
            duration_s,
            warning,
        }
    }
}
