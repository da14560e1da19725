//! Many runs: ensembles of a scene, the cases of a sweep on a pool of threads, a study's case.

use crate::{Error, Result, RunRequest, Simulation};
use clutchpack_analysis::{DiscFatigue, DiscFatigueSpread, DiscStats, SweepCase};
use clutchpack_scene::{EngineChoice, Scene};
use clutchpack_study::part::{CaseFatigue, RunResult};
use clutchpack_study::CaseOutput;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Ensemble member `k` of `count` of `scene`: every disc starts at the same fraction of its
/// start free play, by the model's one rule ([`clutchpack_model::ensemble_angle_rad`], which
/// the scene validator and a study's `spread` ensemble use too), so members are spread evenly
/// across the free play and none starts with a tooth in contact. With `count <= 1` the scene
/// itself (its own initial positions).
pub fn ensemble_member(scene: &Scene, k: u64, count: u64) -> Scene {
    let mut s = scene.clone();
    if count <= 1 {
        return s;
    }
    for d in s.pack.discs.iter_mut() {
        d.initial_rel_angle_rad = clutchpack_model::ensemble_angle_rad(d, k, count);
    }
    s
}

/// The most cases (values x members) one batch of [`run_cases`] runs: every case's
/// statistics are held in memory until the batch ends.
pub const MAX_BATCH_CASES: usize = 1_000_000;

/// Fatigue of each member of each scene of a batch: `[scene][member][body]`.
pub type MemberFatigue = Vec<Vec<Vec<DiscFatigue>>>;

/// What [`run_cases`] ran.
pub struct CaseRuns {
    /// Per scene, the statistics of the members that finished (`value` as given).
    pub cases: Vec<SweepCase>,
    /// The teeth's fatigue of every finished member, `[scene][member][body]`.
    pub fatigue: MemberFatigue,
    /// Wall time of the batch, s.
    pub wall_s: f64,
    /// Members stopped or never started because `stop` was set.
    pub unfinished: usize,
}

/// A batch of runs: each of `scenes` (labelled by `values[i]` in the result and in errors,
/// the swept parameter `param`'s values) as an ensemble of `ensemble` members
/// ([`ensemble_member`]), on `engine` (else each scene's choice), on a pool of `jobs`
/// threads. Once `stop` is set, cases not started are skipped and running ones stop at
/// their engine's next progress poll; neither is in the result ([`CaseRuns::unfinished`]).
/// `progress(done, total)` is called after each finished case. The first failing case is
/// the error, named by its value and member.
#[allow(clippy::too_many_arguments)]
pub fn run_cases(
    scenes: &[Scene],
    values: &[f64],
    param: &str,
    ensemble: usize,
    jobs: usize,
    engine: Option<EngineChoice>,
    stop: &AtomicBool,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<CaseRuns> {
    let total = scenes.len().saturating_mul(ensemble);
    if ensemble == 0 || total > MAX_BATCH_CASES {
        return Err(Error::BadInput(format!(
            "{} scenes x {ensemble} members: a batch has 1..={MAX_BATCH_CASES} cases",
            scenes.len()
        )));
    }
    let tasks: Vec<(usize, usize)> = (0..scenes.len())
        .flat_map(|c| (0..ensemble).map(move |k| (c, k)))
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| Error::Threads(e.to_string()))?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let t0 = Instant::now();
    type Member = (Vec<DiscStats>, Vec<DiscFatigue>);
    let results: Vec<Result<Option<Member>>> = pool.install(|| {
        tasks
            .par_iter()
            .map(|&(c, k)| {
                if stop.load(Ordering::SeqCst) {
                    return Ok(None);
                }
                let member = ensemble_member(&scenes[c], k as u64, ensemble as u64);
                let outcome = Simulation::new(member, engine)?.run_pack(RunRequest {
                    stop: Some(stop),
                    ..RunRequest::default()
                })?;
                let stats = outcome.stats().map_err(|e| match e {
                    Error::Engine { context, source } => Error::Engine {
                        context: format!(
                            "case {param} = {}, member {k}: {context}",
                            clutchpack_model::fmt_num(values[c])
                        ),
                        source,
                    },
                    e => e,
                })?;
                if stats.stopped_early {
                    return Ok(None);
                }
                progress(done.fetch_add(1, Ordering::SeqCst) + 1, total);
                Ok(Some((outcome.body_stats()?, outcome.fatigue())))
            })
            .collect()
    });
    let wall_s = t0.elapsed().as_secs_f64();
    let mut cases: Vec<SweepCase> = values
        .iter()
        .map(|&value| SweepCase {
            value,
            members: Vec::new(),
        })
        .collect();
    let mut unfinished = 0;
    let mut fatigue: MemberFatigue = vec![Vec::new(); values.len()];
    for (&(c, _), r) in tasks.iter().zip(results) {
        match r? {
            Some((stats, f)) => {
                cases[c].members.push(stats);
                fatigue[c].push(f);
            }
            None => unfinished += 1,
        }
    }
    Ok(CaseRuns {
        cases,
        fatigue,
        wall_s,
        unfinished,
    })
}

/// The fatigue of each scene's ensemble (`fatigue[scene][member][body]`, as [`run_cases`]
/// gives it): per body the damage rate over the members (mean, spread) and the life at them,
/// with each scene's critical damage.
pub fn ensemble_fatigue(scenes: &[&Scene], fatigue: &MemberFatigue) -> Vec<Vec<DiscFatigueSpread>> {
    scenes
        .iter()
        .zip(fatigue)
        .map(|(scene, members)| {
            let d_crit: Vec<f64> = scene
                .fatigue
                .iter()
                .map(|f| f.material.critical_damage)
                .collect();
            clutchpack_analysis::ensemble_fatigue(members, &d_crit)
        })
        .collect()
}

/// One case of a study: `scene` on `engine` (else the scene's choice), kept as `run` keeps
/// a run (the peak statistics and the teeth's fatigue as running sums, in bounded memory),
/// so that a case's figures are `run`'s figures. `Ok(None)` when `stop` stopped it.
pub fn run_case(scene: &Scene, engine: Option<EngineChoice>, stop: &AtomicBool) -> RunResult {
    let text = |e: Error| e.to_string();
    let outcome = Simulation::new(scene.clone(), engine)
        .map_err(text)?
        .run_pack(RunRequest {
            stop: Some(stop),
            ..RunRequest::default()
        })
        .map_err(text)?;
    let stats = outcome.result.as_ref().map_err(|e| e.to_string())?;
    if stop.load(Ordering::SeqCst) && stats.simulated_s < scene.simulation.duration_s {
        return Ok(None);
    }
    let fatigue = outcome
        .fatigue()
        .iter()
        .map(|f| CaseFatigue {
            damage_rate_per_h: f.lumped.damage_rate_per_h,
            life_h: f.lumped.life_h,
            eq_load_range_n: f.lumped.eq_load_range_n,
        })
        .collect();
    Ok(Some(CaseOutput {
        discs: outcome.body_stats().map_err(text)?,
        fatigue,
        steps: stats.steps,
        rejected_steps: stats.rejected_steps,
        simulated_s: stats.simulated_s,
    }))
}
