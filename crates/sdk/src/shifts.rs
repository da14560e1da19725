//! The shifts of an automatic's schedule as a run made them (MODEL.md section 10): per shift,
//! when the off-going element let go and the on-coming one locked (the torque and inertia
//! phases as they happened, not as scheduled), the heat each took, the output torque before,
//! during and after, and a tie-up or a flare flagged. Measured on the run's samples (the
//! record rate: the heat and the torque extremes are as fine as it), the instants from the
//! located mode changes.

use clutchpack_model::network::gears::{torque_factor, Handover};
use clutchpack_model::network::{
    ClutchEvent, ClutchMode, Network, NetworkEnergy, NetworkSample, Transmission,
};
use serde::Serialize;

/// The output torque below which a shift counts as a tie-up: this fraction of the smaller of
/// the output torques before and after it (ASSUMED: the dip a driver feels as a tie-up; a
/// clean clutch-to-clutch shift dips to about the new gear's share).
pub const TIE_UP_FRACTION: f64 = 0.5;

/// The rise of the input speed between the off-going element's release and the on-coming's
/// lock above which a power-on upshift counts as a flare (relative; ASSUMED).
pub const FLARE_FRACTION: f64 = 0.01;

/// One shift of a run.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ShiftSummary {
    /// The gear it left and the one it reached (their names).
    pub from: String,
    /// The gear it reached.
    pub to: String,
    /// Its scheduled start, s.
    pub start_s: f64,
    /// The element it opened and the one it closed (coupling names).
    pub off_going: String,
    /// The element it closed.
    pub on_coming: String,
    /// When the off-going element stopped holding (its first change from locked), s.
    pub off_going_released_s: Option<f64>,
    /// When the on-coming element locked, s.
    pub on_coming_locked_s: Option<f64>,
    /// The torque phase as it happened: from the start to the off-going's release, s.
    pub torque_phase_s: Option<f64>,
    /// The inertia phase as it happened: from the off-going's release to the on-coming's
    /// lock, s (0 when the on-coming locked first).
    pub inertia_phase_s: Option<f64>,
    /// The heat the off-going element took during the shift, J (from the samples).
    pub off_going_heat_j: f64,
    /// The heat the on-coming element took, J.
    pub on_coming_heat_j: f64,
    /// The transmission's torque on its output (its planetary sets' and shift elements'; not
    /// a final drive's) at the shift's start, N m.
    pub output_torque_before_n_m: f64,
    /// Its smallest value while the shift is under way (to the later of its scheduled end and
    /// the on-coming's lock), N m.
    pub output_torque_min_n_m: f64,
    /// Its largest value, N m.
    pub output_torque_max_n_m: f64,
    /// Its value at the next shift's start (or the run's end), N m.
    pub output_torque_after_n_m: f64,
    /// The output torque fell below [`TIE_UP_FRACTION`] of the smaller of its values before
    /// and after.
    pub tie_up: bool,
    /// The input sped up by more than [`FLARE_FRACTION`] between the release and the lock.
    pub flare: bool,
    /// The drives' work from the shift's start to the next shift's start (or the run's end),
    /// J (`None` when the run did not take the balance there: a co-simulation, a stopped run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work_in_j: Option<f64>,
    /// The energy balance over that interval, J (MODEL.md section 8, "Energy": the work of
    /// the drives and loads less the change of kinetic energy, the heat, the drag, mesh,
    /// damper and pack losses and the springs' energy change over it; zero to the engine's
    /// tolerance), from the run's balance at the two instants.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_residual_j: Option<f64>,
}

/// One sample as a shift needs it.
#[derive(Debug, Clone)]
struct Row {
    t_s: f64,
    output_torque_n_m: f64,
    input_speed_rad_s: f64,
    /// Each element's heat rate, W (`tau (w_b - w_a)` while it slips, else 0).
    power_w: Vec<f64>,
}

/// What a run keeps for its shifts.
#[derive(Debug, Clone)]
pub(crate) struct ShiftProbe {
    input: usize,
    /// `(coupling, factor)`: the output torque is `sum factor tau_k`.
    output_factors: Vec<(usize, f64)>,
    /// The elements `(coupling, a, b)`.
    elements: Vec<(usize, usize, usize)>,
    /// Each element's faces' mode as its pack reported it last (`None`: a lumped clutch,
    /// whose mode is in every sample).
    pack_modes: Vec<Option<ClutchMode>>,
    /// The resolved packs' mode changes, as a clutch's ([`Self::pack_faces`]).
    pack_events: Vec<ClutchEvent>,
    handovers: Vec<Handover>,
    rows: Vec<Row>,
    /// The run's energy balance at each shift's start (`(t s, balance)`, [`Self::starts_s`]).
    energies: Vec<(f64, NetworkEnergy)>,
}

/// An automatic's output torque over the samples `history`: `(t s, N m)` per sample, the
/// torque its planetary sets and shift elements put on the output body, positive in the
/// output's direction of positive speed (`None` without a schedule, or when a coupling on the
/// output does not give its torque there).
pub fn output_torque_series(
    net: &Network,
    tr: &Transmission,
    history: &[NetworkSample],
) -> Option<Vec<(f64, f64)>> {
    let probe = ShiftProbe::new(net, tr)?;
    Some(
        history
            .iter()
            .map(|s| (s.t_s, probe.output_torque_n_m(s)))
            .collect(),
    )
}

impl ShiftProbe {
    /// The probe of a transmission with a schedule; `None` without shifts, or when a coupling
    /// on the output does not give its torque there (a gear mesh, a resolved pack's other side).
    pub fn new(net: &Network, tr: &Transmission) -> Option<ShiftProbe> {
        let handovers = tr.handovers()?.ok()?;
        if handovers.is_empty() {
            return None;
        }
        // the transmission's own couplings: its gear sets (its elements of three ports) and its
        // shift elements (a final drive or a damper on the output is the output's load, not
        // the transmission)
        let elements_k = tr.elements();
        let mut output_factors = Vec::new();
        for (k, c) in net.couplings.iter().enumerate() {
            let own = c.ports().len() > 2 || elements_k.contains(&k);
            if !own {
                continue;
            }
            let f = torque_factor(c, tr.output)?;
            if f != 0.0 {
                output_factors.push((k, f));
            }
        }
        let elements = tr
            .elements()
            .into_iter()
            .map(|k| (k, net.couplings[k].a, net.couplings[k].b))
            .collect();
        let pack_modes = tr
            .elements()
            .into_iter()
            .map(|k| net.couplings[k].law().session_mode())
            .collect();
        Some(ShiftProbe {
            input: tr.input,
            output_factors,
            elements,
            pack_modes,
            pack_events: Vec::new(),
            handovers,
            rows: Vec::new(),
            energies: Vec::new(),
        })
    }

    /// The shifts' starts, s, in time order: where a run takes its energy balance for
    /// [`Self::set_energies`].
    pub fn starts_s(&self) -> Vec<f64> {
        self.handovers.iter().map(|h| h.corners_s[0]).collect()
    }

    /// The run's energy balance at the shifts' starts (`(t s, balance)`, those of
    /// [`Self::starts_s`] the run reached), so that [`Self::report`] gives each shift's.
    pub fn set_energies(&mut self, energies: Vec<(f64, NetworkEnergy)>) {
        self.energies = energies;
    }

    /// The transmission's torque on its output in the sample `s`, N m (its planetary sets'
    /// and shift elements' torques on the output body, positive in the output's direction of
    /// positive speed; a final drive or damper on the output is its load, not counted).
    pub fn output_torque_n_m(&self, s: &NetworkSample) -> f64 {
        self.output_factors
            .iter()
            .map(|(k, f)| f * s.torque_n_m[*k])
            .sum()
    }

    /// Keeps what the shifts need of a sample.
    pub fn sample(&mut self, s: &NetworkSample) {
        let output_torque_n_m = self.output_torque_n_m(s);
        let power_w = self
            .elements
            .iter()
            .zip(&self.pack_modes)
            .map(|(&(k, a, b), pack)| match pack.or(s.mode[k]) {
                // a pack's torque is its discs' reaction on `a`: its faces' friction torque
                // while they slip (and the discs' inertia, small beside it)
                Some(ClutchMode::Slipping(_)) => {
                    s.torque_n_m[k] * (s.speed_rad_s[b] - s.speed_rad_s[a])
                }
                _ => 0.0,
            })
            .collect();
        self.rows.push(Row {
            t_s: s.t_s,
            output_torque_n_m,
            input_speed_rad_s: s.speed_rad_s[self.input],
            power_w,
        });
    }

    /// A resolved pack's faces changed mode at `t_s` (s): `locked` of its `faces` friction faces
    /// locked and `clamped` clamped. For a shift element it counts as a clutch's mode change:
    /// all faces locked is `locked`, some clamped `slipping`, none `free`.
    pub fn pack_faces(
        &mut self,
        coupling: usize,
        t_s: f64,
        locked: usize,
        clamped: usize,
        faces: usize,
    ) {
        let Some(e) = self.elements.iter().position(|x| x.0 == coupling) else {
            return;
        };
        let Some(from) = self.pack_modes[e] else {
            return;
        };
        let to = if locked == faces {
            ClutchMode::Locked
        } else if clamped > 0 {
            ClutchMode::Slipping(1)
        } else {
            ClutchMode::Free
        };
        if to != from {
            self.pack_modes[e] = Some(to);
            self.pack_events.push(ClutchEvent {
                t_s,
                coupling,
                from,
                to,
            });
        }
    }

    /// Each shift as the run made it, from the samples kept, the mode changes `events` and
    /// the resolved packs' (a pack's faces, [`Self::pack_faces`]), and each shift's energy
    /// balance from those at the shifts' starts ([`Self::set_energies`]) and `end`, the run's
    /// at its end.
    pub fn report(
        &self,
        net: &Network,
        tr: &Transmission,
        events: &[ClutchEvent],
        end: &NetworkEnergy,
    ) -> Vec<ShiftSummary> {
        let end_s = self.rows.last().map_or(0.0, |r| r.t_s);
        let mut all: Vec<ClutchEvent> = events.iter().chain(&self.pack_events).copied().collect();
        all.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        let events = &all;
        let mut out = Vec::new();
        for (i, h) in self.handovers.iter().enumerate() {
            let t0 = h.corners_s[0];
            if t0 > end_s {
                break;
            }
            let until = self.handovers.get(i + 1).map_or(end_s, |n| n.corners_s[0]);
            let first = |k: usize, pred: &dyn Fn(&ClutchEvent) -> bool| {
                events
                    .iter()
                    .find(|e| e.coupling == k && e.t_s >= t0 && e.t_s <= until && pred(e))
                    .map(|e| e.t_s)
            };
            let released = first(h.off_going, &|e| {
                e.from == ClutchMode::Locked && e.to != ClutchMode::Locked
            });
            let locked = first(h.on_coming, &|e| e.to == ClutchMode::Locked);
            let window: Vec<&Row> = self
                .rows
                .iter()
                .filter(|r| r.t_s >= t0 && r.t_s <= until)
                .collect();
            let before = self
                .rows
                .iter()
                .take_while(|r| r.t_s <= t0)
                .last()
                .map_or(0.0, |r| r.output_torque_n_m);
            let after = window.last().map_or(before, |r| r.output_torque_n_m);
            // the extremes while the shift is under way: to the later of its scheduled end and
            // the on-coming's lock
            let active_end = locked
                .unwrap_or(h.corners_s[3])
                .max(h.corners_s[3])
                .min(until);
            let (min, max) = window
                .iter()
                .filter(|r| r.t_s <= active_end)
                .fold((before, before), |(lo, hi), r| {
                    (lo.min(r.output_torque_n_m), hi.max(r.output_torque_n_m))
                });
            let heat = |k: usize| {
                let e = self.elements.iter().position(|x| x.0 == k).unwrap_or(0);
                window
                    .windows(2)
                    .map(|w| 0.5 * (w[0].power_w[e] + w[1].power_w[e]) * (w[1].t_s - w[0].t_s))
                    .sum::<f64>()
            };
            let flare = match (released, locked) {
                (Some(r), l) => {
                    let between: Vec<f64> = window
                        .iter()
                        .filter(|x| x.t_s >= r && x.t_s <= l.unwrap_or(until))
                        .map(|x| x.input_speed_rad_s)
                        .collect();
                    let start = between.first().copied().unwrap_or(0.0);
                    between
                        .iter()
                        .any(|w| *w > start + FLARE_FRACTION * start.abs())
                }
                (None, _) => false,
            };
            let floor = before.min(after);
            // the balance over [t0, until]: every term is counted from t = 0, so the
            // interval's is the difference of the run's balances at its ends
            let at = |t: f64| self.energies.iter().find(|e| e.0 == t).map(|e| e.1);
            let ends = match self.handovers.get(i + 1) {
                Some(n) if n.corners_s[0] <= end_s => at(n.corners_s[0]),
                _ => Some(*end),
            };
            let interval = at(t0).zip(ends);
            out.push(ShiftSummary {
                from: tr.gears[h.from].name.clone(),
                to: tr.gears[h.to].name.clone(),
                start_s: t0,
                off_going: net.couplings[h.off_going].name.clone(),
                on_coming: net.couplings[h.on_coming].name.clone(),
                off_going_released_s: released,
                on_coming_locked_s: locked,
                torque_phase_s: released.map(|r| r - t0),
                inertia_phase_s: match (released, locked) {
                    (Some(r), Some(l)) => Some((l - r).max(0.0)),
                    _ => None,
                },
                off_going_heat_j: heat(h.off_going),
                on_coming_heat_j: heat(h.on_coming),
                output_torque_before_n_m: before,
                output_torque_min_n_m: min,
                output_torque_max_n_m: max,
                output_torque_after_n_m: after,
                tie_up: floor > 0.0 && min < TIE_UP_FRACTION * floor,
                flare,
                work_in_j: interval.map(|(a, b)| b.drive_work_j - a.drive_work_j),
                energy_residual_j: interval.map(|(a, b)| b.residual_j() - a.residual_j()),
            });
        }
        out
    }
}
