//! What a fit compares: the signals a scene's run produces, by name, and their values at
//! the measured rows.
//!
//! Two kinds of rows. **Time series** (a time column): a network scene (`[[bodies]]`)
//! produces, per body `B`, `B.speed_rad_s` (also written `B` alone) and `B.angle_rad`, and
//! per coupling `C`, `C.torque_n_m` (the torque on its body `a`, sign as in
//! [`clutchpack_model::network::NetworkSample`]), interpolated linearly between the run's
//! samples; a pack scene produces its co-simulation outputs by their one public name (the
//! FMU's and Python's: `drum.speed_rad_s`, `pack.carrier_torque_n_m`,
//! `interfaces[1].torque_n_m`, `discs[2].speed_rad_s`, ...; [`crate::cosim::variables`]),
//! read at the measured times themselves (the run's communication points). **Variants**
//! (`--variant KEY`: each row sets KEY): a statistic of one body's impact peaks over the
//! whole run, `B.max_positive_n`, `B.max_negative_n`, `B.p99_abs_n`, `B.mean_top10_abs_n`
//! (N per tooth, [`clutchpack_analysis::DiscStats`]), the mean over an ensemble of runs
//! ([`crate::ensemble_member`]) when one is asked: a rattle is chaotic, so one run's peak is
//! one sample of a scatter of a few per cent (MODEL.md section 4), and only the ensemble's
//! mean is a smooth function of the keys.

use crate::cosim::{Causality, Kind};
use crate::{CoSimulation, Error, NetworkRequest, Result, RunRequest, Simulation};
use clutchpack_analysis::DiscStats;
use clutchpack_model::network::NetworkSample;
use clutchpack_model::session::Driven;
use clutchpack_scene::{EngineChoice, Scene};
use std::sync::atomic::AtomicBool;

/// A statistic of one body's impact peaks over a run (per tooth, N).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PeakStat {
    /// Largest positive peak (the body leads).
    MaxPositive,
    /// Most negative peak (its carrier leads).
    MaxNegative,
    /// 99th percentile of `|peak|`.
    P99Abs,
    /// Mean of the ten largest `|peak|`.
    MeanTop10Abs,
}

/// The statistics by their names (the fields of [`DiscStats`]).
const PEAK_STATS: [(&str, PeakStat); 4] = [
    ("max_positive_n", PeakStat::MaxPositive),
    ("max_negative_n", PeakStat::MaxNegative),
    ("p99_abs_n", PeakStat::P99Abs),
    ("mean_top10_abs_n", PeakStat::MeanTop10Abs),
];

impl PeakStat {
    fn of(self, s: &DiscStats) -> f64 {
        match self {
            PeakStat::MaxPositive => s.max_positive_n,
            PeakStat::MaxNegative => s.max_negative_n,
            PeakStat::P99Abs => s.p99_abs_n,
            PeakStat::MeanTop10Abs => s.mean_top10_abs_n,
        }
    }
}

/// One signal of a run: which series (or statistic), and which item.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Signal {
    /// A network body's speed, rad/s.
    Speed(usize),
    /// A network body's angle, rad.
    Angle(usize),
    /// A network coupling's torque on its body `a`, N m.
    Torque(usize),
    /// A pack's co-simulation output, by its name.
    Output(String),
    /// A statistic of body `i`'s impact peaks (the discs, then the plates), one value per
    /// run.
    Peak(usize, PeakStat),
}

impl Signal {
    /// Whether it is one value per run (rows are variants), not a series in time.
    pub(crate) fn per_run(&self) -> bool {
        matches!(self, Signal::Peak(..))
    }

    /// The signal called `name` in `scene` run by `engine`, or an error listing the
    /// signals the scene has.
    pub(crate) fn resolve(scene: &Scene, engine: EngineChoice, name: &str) -> Result<Signal> {
        let Some(net) = &scene.network else {
            return Signal::resolve_pack(scene, engine, name);
        };
        let body = |b: &str| net.bodies.iter().position(|x| x.name == b);
        let coupling = |c: &str| net.couplings.iter().position(|x| x.name == c);
        let (item, quantity) = name.rsplit_once('.').unwrap_or((name, "speed_rad_s"));
        let found = match quantity {
            "speed_rad_s" => body(item).map(Signal::Speed),
            "angle_rad" => body(item).map(Signal::Angle),
            "torque_n_m" => coupling(item).map(Signal::Torque),
            _ => None,
        };
        found.ok_or_else(|| {
            let mut names: Vec<String> = net
                .bodies
                .iter()
                .flat_map(|b| {
                    [
                        format!("{}.speed_rad_s", b.name),
                        format!("{}.angle_rad", b.name),
                    ]
                })
                .collect();
            names.extend(
                net.couplings
                    .iter()
                    .map(|c| format!("{}.torque_n_m", c.name)),
            );
            Error::BadInput(format!(
                "signal {name:?}: {} does not produce it (it produces: {}; a body's name alone \
                 is its speed)",
                scene.name,
                names.join(", ")
            ))
        })
    }

    /// A pack's signal: a statistic of a body's peaks, or a co-simulation output.
    fn resolve_pack(scene: &Scene, engine: EngineChoice, name: &str) -> Result<Signal> {
        let pack = &scene.pack;
        let bodies: Vec<&str> = pack
            .discs
            .iter()
            .chain(&pack.plates)
            .map(|b| b.name.as_str())
            .collect();
        if let Some((body, stat)) = name.rsplit_once('.') {
            let i = bodies.iter().position(|b| *b == body);
            let s = PEAK_STATS.iter().find(|(n, _)| *n == stat);
            if let (Some(i), Some((_, s))) = (i, s) {
                return Ok(Signal::Peak(i, *s));
            }
        }
        let vars = crate::cosim::variables(scene, engine.name(), Driven::NONE);
        let outputs: Vec<&str> = vars
            .iter()
            .filter(|v| v.causality == Causality::Output && v.kind == Kind::Real)
            .map(|v| v.name.as_str())
            .collect();
        if outputs.contains(&name) {
            return Ok(Signal::Output(name.to_string()));
        }
        let stats: Vec<&str> = PEAK_STATS.iter().map(|(n, _)| *n).collect();
        Err(Error::BadInput(format!(
            "signal {name:?}: {} does not produce it (its series in time: {}; one value per \
             run, with --variant: BODY.{} for BODY in {})",
            scene.name,
            outputs.join(", "),
            stats.join(", BODY."),
            bodies.join(", ")
        )))
    }

    /// Its value in one network sample (NaN for a pack's signal).
    fn value(&self, s: &NetworkSample) -> f64 {
        match *self {
            Signal::Speed(i) => s.speed_rad_s[i],
            Signal::Angle(i) => s.angle_rad[i],
            Signal::Torque(k) => s.torque_n_m[k],
            Signal::Output(_) | Signal::Peak(..) => f64::NAN,
        }
    }

    /// Its values at the times `t` (ascending, within the run), linear between the samples.
    pub(crate) fn at(&self, history: &[NetworkSample], t: &[f64]) -> Vec<f64> {
        t.iter()
            .map(|&t| {
                let k = history.partition_point(|s| s.t_s <= t);
                match (k.checked_sub(1).map(|i| &history[i]), history.get(k)) {
                    (Some(a), Some(b)) if b.t_s > a.t_s => {
                        let w = (t - a.t_s) / (b.t_s - a.t_s);
                        self.value(a) + w * (self.value(b) - self.value(a))
                    }
                    (Some(a), _) => self.value(a),
                    (None, Some(b)) => self.value(b),
                    (None, None) => f64::NAN,
                }
            })
            .collect()
    }
}

/// The error of a stopped evaluation (the fit then returns its best point so far).
fn stopped() -> Error {
    Error::BadInput("stopped".into())
}

/// The time series `signals` of one run of `scene` at the times `t` (s, ascending, within
/// the run): a network's from its samples, a pack's read at `t` as communication points of a
/// co-simulated run that drives no input (the scene's own run, split into calls). `asked`
/// is the engine asked, `engine` the one the scene's rule chose with it.
pub(crate) fn series(
    scene: &Scene,
    asked: Option<EngineChoice>,
    engine: EngineChoice,
    signals: &[&Signal],
    t: &[f64],
    stop: Option<&AtomicBool>,
) -> Result<Vec<Vec<f64>>> {
    if scene.network.is_some() {
        let outcome = Simulation::new(scene.clone(), asked)?
            .run(NetworkRequest {
                keep_history: true,
                stop,
                ..NetworkRequest::default()
            })?
            .into_network()?;
        return Ok(signals.iter().map(|s| s.at(&outcome.history, t)).collect());
    }
    let bad = Error::BadInput;
    let mut co = CoSimulation::driving(scene.clone(), Driven::NONE)?;
    co.set_string_parameter(crate::cosim::Quantity::Engine, engine.name())?;
    let vrs = signals
        .iter()
        .map(|s| {
            let name = match s {
                Signal::Output(n) => n.as_str(),
                _ => "",
            };
            co.variables()
                .iter()
                .find(|v| v.name == name && v.kind == Kind::Real)
                .map(|v| v.vr)
                .ok_or_else(|| bad(format!("{s:?} is not a series of a pack's run")))
        })
        .collect::<Result<Vec<u32>>>()?;
    co.start(None)?;
    let mut out = vec![Vec::with_capacity(t.len()); signals.len()];
    for &ti in t {
        if ti > co.time_s() {
            match co.advance_to(ti, stop) {
                Ok(true) => {}
                Ok(false) => return Err(stopped()),
                Err(e) => {
                    // an engine failure comes back typed from the finished run
                    let _ = co.finish();
                    if let Some(Err(e)) = co.outcome().map(|o| o.stats().map(|_| ())) {
                        return Err(e);
                    }
                    return Err(e);
                }
            }
        }
        for (k, &vr) in vrs.iter().enumerate() {
            out[k].push(co.get_real(vr)?);
        }
    }
    let _ = co.finish();
    Ok(out)
}

/// The per-run statistics `signals` ([`Signal::Peak`]) of `scene`: their mean over the
/// `ensemble` members of [`crate::ensemble_member`] (run in parallel; `ensemble <= 1`: the
/// scene's own run).
pub(crate) fn statistics(
    scene: &Scene,
    asked: Option<EngineChoice>,
    signals: &[&Signal],
    ensemble: u64,
    stop: Option<&AtomicBool>,
) -> Result<Vec<f64>> {
    use rayon::prelude::*;
    let count = ensemble.max(1);
    let members = (0..count)
        .into_par_iter()
        .map(|k| {
            let member = crate::ensemble_member(scene, k, ensemble);
            let mut sim = Simulation::new(member, asked)?;
            let outcome = sim.run_pack(RunRequest {
                stop,
                ..RunRequest::default()
            })?;
            outcome.stats()?;
            if outcome.stopped_early() {
                return Err(stopped());
            }
            let stats = outcome.body_stats()?;
            Ok(signals
                .iter()
                .map(|s| match s {
                    Signal::Peak(i, stat) => stat.of(&stats[*i]),
                    _ => f64::NAN,
                })
                .collect::<Vec<f64>>())
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((0..signals.len())
        .map(|k| members.iter().map(|m| m[k]).sum::<f64>() / count as f64)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, w: f64) -> NetworkSample {
        NetworkSample {
            t_s: t,
            angle_rad: vec![0.0],
            speed_rad_s: vec![w],
            torque_n_m: vec![],
            mode: vec![],
            reaction_n_m: vec![],
        }
    }

    /// Linear between samples, the sample itself at its time, held at the ends.
    #[test]
    fn interpolates_between_samples() {
        let h = [sample(0.0, 1.0), sample(1.0, 3.0), sample(2.0, 3.0)];
        let v = Signal::Speed(0).at(&h, &[0.0, 0.25, 1.0, 1.5, 2.0]);
        assert_eq!(v, [1.0, 1.5, 3.0, 3.0, 3.0]);
    }
}
