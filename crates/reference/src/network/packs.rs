//! Resolved packs on a network (MODEL.md sections 2-5 and 8): each pack's friction discs on
//! the network's body `a`, its separator plates on body `b`, every disc and plate a degree of
//! freedom of its own against its carrier (the pack engine's [`System`], carried by the
//! network's bodies: [`System::carried`]), its stack's faces with exact stick and slip.
//!
//! # The right-hand side in three passes
//! The teeth are compliant, so their loads follow from the state alone: (1) every pack's
//! spline reactions on its two carriers ([`System::reactions_n_m`]) join the other torques on
//! the network's bodies; (2) the network solves its bodies' accelerations (its rigid groups as
//! without packs); (3) each pack's own relative accelerations follow with its carriers'
//! speeds and accelerations given ([`System::rhs_with_loads`]).
//!
//! # Events
//! Every disc's and plate's engagement depth (a tooth contact's onset and separation) and every
//! face's switching condition (it clamps, sticks, breaks or opens) join the network's guard
//! vector, after the couplings' own; one DOPRI5 over all, each crossing bisected on the dense
//! output. A contact's onset takes the tooth law's per-event memory; its peak is located on
//! the dense output of the step that holds it: the load probed at the quarter points of every
//! step in contact (the state interpolated once per point for every pack), and a largest probe
//! inside the step above the event's largest so far refined there by golden-section search;
//! its separation sends the impact ([`clutchpack_model::Observer::pack_impact`]).
//!
//! # State
//! Per pack, after the network's own state: its [`System`]'s (each body's relative angle and
//! speed against its carrier, each face's heat, the teeth's work), then the work of its
//! bodies' oil drag (J).

use crate::dopri::Dense;
use crate::stepper::golden_peak;
use crate::system::{Face, System};
use clutchpack_model::network::{Network, NetworkInput};
use clutchpack_model::{Engagement, ImpactTracker, Observer};
use std::sync::Arc;

/// Samples of a load per step in contact before the refinement: the step's quarter points
/// (a contact takes tens of steps, so the load is smooth within one; the refinement searches
/// a quarter step either side of the largest).
const PROBES: usize = 4;

/// One resolved pack of a network run.
#[derive(Clone)]
pub(super) struct NetPack {
    /// Its coupling's index.
    pub k: usize,
    /// The friction discs' carrier (body index).
    pub a: usize,
    /// The plates' carrier (body index).
    pub b: usize,
    /// Its equations, on carriers outside it.
    pub sys: System,
    /// Index of its first state component in the network's state.
    pub at: usize,
    /// Index of its first guard in the network's guard vector.
    pub guard_at: usize,
    /// Each body's contact mode (discs, then plates).
    pub modes: Vec<Option<Engagement>>,
    trackers: Vec<ImpactTracker>,
    /// Per body: the largest |F| of its open event so far, N.
    best: Vec<f64>,
    /// Per body: the largest probe of the step being observed, `(t s, signed F N)`.
    top: Vec<(f64, f64)>,
    /// Whether any of its discs and plates has an oil drag (`drag_n_m_s_rad != 0`), for the
    /// model its system holds ([`Self::set_pack`]).
    pub(super) drag: bool,
    /// Its temperatures, if its pack file has `[thermal]` (MODEL.md section 9): the heat of
    /// every accepted step booked, the pack's viscosity-dependent parameters swapped at each
    /// thermal window's end ([`crate::thermal::Thermal`], as a pack run).
    pub thermal: Option<Box<crate::thermal::Thermal>>,
}

impl NetPack {
    /// Sets its system's model (an input held, or a thermal window's parameters).
    pub fn set_pack(&mut self, pack: Arc<clutchpack_model::PackModel>) {
        self.drag = has_drag(&pack);
        self.sys.set_pack(pack);
    }

    /// Its state's length: the system's, then the drag's work.
    pub fn len(&self) -> usize {
        self.sys.dim() + 1
    }

    /// Its guards: one per body, then one per face.
    pub fn guards(&self) -> usize {
        self.sys.ids.len() + self.sys.faces.len()
    }

    /// Its system's part of the network state `y`.
    pub fn part<'y>(&self, y: &'y [f64]) -> &'y [f64] {
        &y[self.at..self.at + self.sys.dim()]
    }

    /// The carriers' speeds and accelerations as [`System::rhs_with_loads`] takes them, from the
    /// bodies' speeds `w` (rad/s) and accelerations `acc` (rad/s^2).
    pub fn carriers(&self, w: &[f64], acc: &[f64]) -> [f64; 4] {
        [w[self.a], acc[self.a], w[self.b], acc[self.b]]
    }

    /// The absolute speed (rad/s) of the body in `slot` at the network state `y` (`w` the
    /// bodies' speeds).
    fn body_speed(&self, slot: usize, y: &[f64], w: &[f64]) -> f64 {
        let carrier = if slot < self.sys.pack.discs.len() {
            w[self.a]
        } else {
            w[self.b]
        };
        carrier - y[self.at + 2 * slot + 1]
    }

    /// The power of its bodies' oil drag (W, >= 0): `sum C w_b^2`.
    pub fn drag_power_w(&self, y: &[f64], w: &[f64]) -> f64 {
        if !self.drag {
            // every term `0 w_b^2` is +0 (a finite speed; a speed that is not finite fails
            // the step's error norm first): the sum's value, without the bodies' speeds (the
            // right-hand side takes it at every evaluation; issue 45, the resolved shift's
            // cost)
            return 0.0;
        }
        (0..self.sys.ids.len())
            .map(|slot| {
                let wb = self.body_speed(slot, y, w);
                self.sys.disc(slot).drag_n_m_s_rad * wb * wb
            })
            .sum()
    }

    /// Its bodies' kinetic energy (J) at the network state `y`.
    pub fn kinetic_j(&self, y: &[f64], w: &[f64]) -> f64 {
        (0..self.sys.ids.len())
            .map(|slot| {
                let wb = self.body_speed(slot, y, w);
                0.5 * self.sys.disc(slot).inertia_kg_m2 * wb * wb
            })
            .sum()
    }

    /// What it has turned into heat or stored in its teeth since t = 0 at the state `y`, J:
    /// its faces' heat, its teeth's work (their impact losses, plus the elastic energy of a
    /// contact still closed) and its bodies' drag.
    pub fn loss_j(&self, y: &[f64]) -> f64 {
        let part = self.part(y);
        self.sys.interface_heat_j(part).iter().sum::<f64>()
            + self.sys.teeth_work_j(part)
            + y[self.at + self.sys.dim()]
    }

    /// Its faces' heat since t = 0 at the state `y`, J.
    pub fn face_heat_j(&self, y: &[f64]) -> f64 {
        self.sys.interface_heat_j(self.part(y)).iter().sum()
    }

    /// The guards at the network state `y` with the bodies' speeds `w`, into `out` (its
    /// slice): per body its engagement depth (m; negated in free flight, so that an onset and
    /// a separation both cross from above), per face -1 where its mode must change, else 1.
    /// With `want` (its slice of the marks), only the marked ones (the others left as they
    /// were; the faces all, from one stack, when one is marked); `loads` its bodies' loads at `y`
    /// if known (N, by slot).
    pub fn guard_values(
        &self,
        t: f64,
        y: &[f64],
        w: &[f64],
        out: &mut [f64],
        want: Option<&[bool]>,
        loads: Option<&[f64]>,
    ) {
        let part = self.part(y);
        let nb = self.sys.ids.len();
        for slot in 0..nb {
            if want.is_some_and(|x| !x[slot]) {
                continue;
            }
            let depth = self.sys.depth(slot, part);
            out[slot] = if self.modes[slot].is_some() {
                depth
            } else {
                -depth
            };
        }
        if self.sys.faces.is_empty() || want.is_some_and(|x| !x[nb..].contains(&true)) {
            return;
        }
        let open = self.sys.faces.iter().all(|f| *f == Face::Open);
        if open
            && self
                .sys
                .pack
                .stack
                .as_ref()
                .map_or(0.0, |s| s.piston.force_n(t))
                <= 0.0
        {
            // an open face clamps when its clamp force turns positive, and that is at most
            // the piston's
            out[nb..].iter_mut().for_each(|g| *g = 1.0);
            return;
        }
        // the faces' conditions need the carriers' speeds only
        // (in this thread's buffers: no allocation per evaluation, the same values)
        let c = [w[self.a], 0.0, w[self.b], 0.0];
        self.sys
            .with_stack_eval_loads(t, part, &self.modes, &c, loads, |ev| {
                for m in 0..self.sys.faces.len() {
                    out[nb + m] = if self.sys.face_switches(m, ev) {
                        -1.0
                    } else {
                        1.0
                    };
                }
            });
    }

    /// Opens and closes contact events at an event at `t` (`crossed[slot] <= 0`: the body's
    /// guard crossed; `None`: every body checked, as at t = 0).
    pub fn switch_teeth(
        &mut self,
        t: f64,
        y: &[f64],
        crossed: Option<&[f64]>,
        obs: &mut dyn Observer,
    ) {
        for slot in 0..self.sys.ids.len() {
            if crossed.is_some_and(|c| c[slot] > 0.0) {
                continue;
            }
            let kin = self.sys.kin(slot, self.part(y));
            let inside = self.sys.depth(slot, self.part(y)) > 0.0;
            match (self.modes[slot], inside) {
                (None, true) => {
                    self.modes[slot] = Some(self.sys.disc(slot).law.engage(&kin));
                    self.trackers[slot].begin(t, kin.flank, kin.v_n_m_s);
                    self.best[slot] = 0.0;
                }
                (Some(_), false) => {
                    self.close(slot, t, obs);
                    self.modes[slot] = None;
                }
                _ => {}
            }
        }
    }

    /// Settles the faces whose guards crossed (`crossed[m] <= 0`; `None`: every face, as at
    /// t = 0 or when an input changes) at `t`, the state `y` (a lock sets the slip to zero
    /// there), the bodies' speeds and accelerations in `c`.
    pub fn settle_faces(&mut self, t: f64, y: &mut [f64], crossed: Option<&[f64]>, c: &[f64; 4]) {
        let nb = self.sys.ids.len();
        let (at, dim) = (self.at, self.sys.dim());
        for m in 0..self.sys.faces.len() {
            if crossed.is_some_and(|g| g[nb + m] > 0.0) {
                continue;
            }
            self.sys
                .settle_face_with(m, t, &mut y[at..at + dim], &self.modes, c);
        }
    }

    /// How many of its faces are locked, and how many clamped (locked or slipping).
    fn face_counts(&self) -> (usize, usize) {
        let f = &self.sys.faces;
        (
            f.iter().filter(|m| **m == Face::Locked).count(),
            f.iter().filter(|m| **m != Face::Open).count(),
        )
    }

    /// Closes `slot`'s open event at `t` (its peak was located as the steps went).
    fn close(&mut self, slot: usize, t: f64, obs: &mut dyn Observer) {
        if let Some(e) = self.trackers[slot].end(t) {
            obs.pack_impact(self.k, &e);
        }
    }

    /// Every open contact of its discs and plates as it would close at `t` (`(its coupling,
    /// the body, event)`, the peak the largest located so far), appended to `out`.
    pub fn open(
        &self,
        t: f64,
        out: &mut Vec<(usize, Option<usize>, clutchpack_model::ImpactEvent)>,
    ) {
        for (slot, tracker) in self.trackers.iter().enumerate() {
            out.extend(tracker.peek(t).map(|e| (self.k, Some(slot), e)));
        }
    }

    /// Closes every open event at the end of the run at `t`.
    pub fn finish(&mut self, t: f64, obs: &mut dyn Observer) {
        for slot in 0..self.sys.ids.len() {
            if self.modes[slot].is_some() {
                self.close(slot, t, obs);
            }
        }
    }
}

/// Whether any disc or plate of `pack` has an oil drag.
fn has_drag(pack: &clutchpack_model::PackModel) -> bool {
    (pack.discs.iter().chain(&pack.plates)).any(|d| d.drag_n_m_s_rad != 0.0)
}

/// The network's packs, their state from `first` on and their guards from `first_guard` on,
/// in coupling order.
pub(super) fn build(net: &Network, first: usize, first_guard: usize) -> Vec<NetPack> {
    let (mut at, mut guard_at) = (first, first_guard);
    let mut out = Vec::new();
    for (k, c) in net.couplings.iter().enumerate() {
        let Some(pack) = c.pack() else { continue };
        let sys = System::carried(Arc::new(pack.clone()));
        let drag = has_drag(&sys.pack);
        let nb = sys.ids.len();
        let p = NetPack {
            k,
            a: c.a,
            b: c.b,
            at,
            guard_at,
            modes: vec![None; nb],
            trackers: (0..nb).map(ImpactTracker::new).collect(),
            best: vec![0.0; nb],
            top: vec![(0.0, 0.0); nb],
            thermal: None,
            drag,
            sys,
        };
        at += p.len();
        guard_at += p.guards();
        out.push(p);
    }
    out
}

/// At an event at `t` (or at t = 0 and when an input changes, `crossed = None`): every pack's
/// tooth contacts opened and closed where their guards crossed, then its faces settled (with
/// the carriers' speeds of the state `y`; a face's settling needs no acceleration).
pub(super) fn switch(
    packs: &mut [NetPack],
    n: usize,
    t: f64,
    y: &mut [f64],
    crossed: Option<&[f64]>,
    obs: &mut dyn Observer,
) {
    for p in packs {
        let mine = crossed.map(|g| &g[p.guard_at..p.guard_at + p.guards()]);
        p.switch_teeth(t, y, mine, obs);
        if !p.sys.faces.is_empty() {
            let before = p.face_counts();
            let c = [y[n + p.a], 0.0, y[n + p.b], 0.0];
            p.settle_faces(t, y, mine, &c);
            let (locked, clamped) = p.face_counts();
            if (locked, clamped) != before || crossed.is_none() && t == 0.0 {
                obs.pack_faces(p.k, t, locked, clamped, p.sys.faces.len());
            }
        }
    }
}

/// Observes every pack's bodies in contact over the accepted step `[t0, t1]` of `dense`: the
/// load probed at [`PROBES`] points (the packs' state interpolated once per point); where a
/// body's largest probe exceeds its event's largest so far, the event sees it, refined by
/// golden-section search on the step when it lies inside it (a peak), as it is at the step's
/// end (still rising).
pub(super) fn observe(packs: &mut [NetPack], dense: &Dense, t0: f64, t1: f64, ybuf: &mut [f64]) {
    if packs.iter().all(|p| p.modes.iter().all(Option::is_none)) {
        return;
    }
    for p in packs.iter_mut() {
        p.top.iter_mut().for_each(|x| *x = (t0, 0.0));
    }
    for j in 1..=PROBES {
        let t = if j == PROBES {
            t1
        } else {
            t0 + (t1 - t0) * j as f64 / PROBES as f64
        };
        // each pack's discs' and plates' relative angles and speeds (what the loads read)
        for p in packs.iter() {
            dense.eval_range(t, p.at..p.at + 2 * p.sys.ids.len(), ybuf);
        }
        for p in packs.iter_mut() {
            let part = &ybuf[p.at..p.at + p.sys.dim()];
            for slot in 0..p.sys.ids.len() {
                if p.modes[slot].is_none() {
                    continue;
                }
                let f = p.sys.load(slot, part, &p.modes[slot]);
                if f.abs() > p.top[slot].1.abs() {
                    p.top[slot] = (t, f);
                }
            }
        }
    }
    let span = (t1 - t0) / PROBES as f64;
    for p in packs.iter_mut() {
        for slot in 0..p.sys.ids.len() {
            let (t, f) = p.top[slot];
            if p.modes[slot].is_none() || f.abs() <= p.best[slot] {
                continue;
            }
            let (tp, fp) = if t < t1 {
                let (at, dim) = (p.at, p.sys.dim());
                let (sys, mode) = (&p.sys, &p.modes[slot]);
                golden_peak((t - span).max(t0), (t + span).min(t1), |tt| {
                    // the body's relative angle and speed, what its load reads
                    dense.eval_range(tt, at + 2 * slot..at + 2 * slot + 2, ybuf);
                    sys.load(slot, &ybuf[at..at + dim], mode)
                })
            } else {
                (t, f)
            };
            p.trackers[slot].observe(tp, fp);
            p.best[slot] = fp.abs().max(f.abs());
        }
    }
}

/// At the start of a step with the guards `g` at `(t, y)`: settles the faces of every pack
/// whose guard is not positive there (a face whose mode must change but whose guard did not
/// cross from above, as when a face's own settling or a neighbour's lock left it so: the
/// bisection only locates guards that were positive at a step's start). Returns whether a
/// face changed (the caller restarts the integration there).
pub(super) fn heal(
    packs: &mut [NetPack],
    n: usize,
    t: f64,
    y: &mut [f64],
    g: &[f64],
    obs: &mut dyn Observer,
) -> bool {
    let mut changed = false;
    for p in packs.iter_mut() {
        let mine = &g[p.guard_at..p.guard_at + p.guards()];
        let nb = p.sys.ids.len();
        if mine[nb..].iter().all(|x| *x > 0.0) {
            continue;
        }
        let (faces, before) = (p.sys.faces.clone(), p.face_counts());
        let mut only_faces = mine.to_vec();
        only_faces[..nb].iter_mut().for_each(|x| *x = 1.0);
        let c = [y[n + p.a], 0.0, y[n + p.b], 0.0];
        p.settle_faces(t, y, Some(&only_faces), &c);
        if p.sys.faces != faces {
            changed = true;
            let (locked, clamped) = p.face_counts();
            if (locked, clamped) != before {
                obs.pack_faces(p.k, t, locked, clamped, p.sys.faces.len());
            }
        }
    }
    changed
}

/// Sends every pack's discs and plates at the network state `y` at `t` (s) to `obs`: each
/// body's absolute angle (its carrier's less its relative angle, rad), speed (rad/s) and
/// per-tooth load (N).
pub(super) fn emit_samples(packs: &[NetPack], n: usize, t: f64, y: &[f64], obs: &mut dyn Observer) {
    for p in packs {
        let nd = p.sys.pack.discs.len();
        let (angles, speeds): (Vec<f64>, Vec<f64>) = (0..p.sys.ids.len())
            .map(|slot| {
                let c = if slot < nd { p.a } else { p.b };
                let k = p.at + 2 * slot;
                (y[c] - y[k], y[n + c] - y[k + 1])
            })
            .unzip();
        let part = p.part(y);
        let loads: Vec<f64> = (0..p.sys.ids.len())
            .map(|slot| p.sys.load(slot, part, &p.modes[slot]))
            .collect();
        obs.pack_sample(p.k, t, &angles, &speeds, &loads);
    }
}

/// Closes the thermal windows of every thermal pack that ended by `t` (s), sending the new
/// temperatures to `obs` and swapping in each pack's new parameters; whether any pack's
/// parameters changed (the integration then restarts).
pub(super) fn close_thermal_windows(
    eq: &mut super::Equations,
    t: f64,
    obs: &mut dyn Observer,
) -> Result<bool, clutchpack_model::EngineError> {
    let mut swapped = false;
    for p in eq.packs.iter_mut() {
        let Some(th) = p.thermal.as_mut() else {
            continue;
        };
        let windows = th.windows();
        let closed = th.close_windows(t, &p.sys.pack)?;
        if th.windows() != windows {
            obs.pack_temperatures(p.k, t, th.temperatures_k());
        }
        if let Some(pack) = closed {
            p.set_pack(Arc::new(pack));
            swapped = true;
        }
    }
    Ok(swapped)
}

/// For a prescribed body's speed held (`input` `NetworkInput::Speed(i)`; nothing for the
/// other inputs): sets body `i`'s speed in the network state `y` (`n` bodies) to `value`
/// (rad/s), its angle kept; the discs of each
/// pack of `packs` it carries keep their own speeds, their speeds relative to it
/// (`psi = w_a - w_disc`) shifted by the jump, as a pack's session shifts them at a jump of
/// its shaft's (`crate::session::shift_disc_speeds`). What a clutch or gear ties to it
/// follows when the modes are settled next (their speeds projected).
pub(super) fn jump_speed(
    packs: &[NetPack],
    y: &mut [f64],
    n: usize,
    input: NetworkInput,
    value: f64,
) {
    let NetworkInput::Speed(i) = input else {
        return;
    };
    let jump = value - y[n + i];
    y[n + i] = value;
    for p in packs.iter().filter(|p| p.a == i) {
        for slot in 0..p.sys.pack.discs.len().min(p.sys.ids.len()) {
            y[p.at + 2 * slot + 1] += jump;
        }
    }
}
