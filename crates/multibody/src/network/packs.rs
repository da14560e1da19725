//! Resolved packs on a network on the multibody engine (MODEL.md sections 2-5 and 8): each
//! pack is a multibody pack session ([`MultibodySession`], its discs and plates rapier bodies
//! on their splines, its stack, the multirate scheme) whose shaft and drum are the network's
//! bodies `a` and `b`, advanced over each network step inside it.
//!
//! # Method
//! A network step `[t, t + h]` holds every torque but the packs' over the step (the module's
//! method, step 3). The packs' spline reactions are stiff and act within the step (a tooth
//! contact lasts microseconds), so they are not held: each pack integrates them itself, its
//! carriers being the network's bodies reduced to one degree of freedom each:
//! - **Carrier `a` (and `b`)** turns with its rigid group (the bodies the ideal gears, the
//!   planetary sets and the locked clutches tie to it). With `P` the network's inverse inertia
//!   projected on the constraints (`P = M^-1 - M^-1 C^T (C M^-1 C^T)^-1 C M^-1`, symmetric), a
//!   torque `T` on the bodies accelerates `a` by `(P T)_a`: the carrier is an inertia
//!   `J_a = 1 / P_aa` (the group's inertia reflected to `a`) under the held torque
//!   `(P T)_a / P_aa` of everything else in the network.
//! - **Both carriers in one rigid group** (`P_ab != 0`: a shift element of an automatic, whose
//!   members the gearset ties whether it is open or closed). The carriers' accelerations are
//!   then `P_aa R_a + P_ab R_b` and `P_ab R_a + P_bb R_b` under the pack's reactions `R`: the
//!   2x2 block of `P` over `(a, b)` is their inverse inertia, singular when the group has one
//!   degree of freedom (the drum turning with the shaft at a fixed ratio). The session keeps
//!   its two carriers apart, each on its diagonal term (`J_a = 1 / P_aa`, `J_b = 1 / P_bb`,
//!   exact for the pack's own reaction on it), and the cross term goes into the held torques:
//!   the drum's reaction on the shaft's group `P_ab R_b / P_aa` (and the shaft's on the drum's,
//!   `P_ab R_a / P_bb`) with `R` the estimate of the step before, as the reactions of another
//!   pack on the same group are held. The network then applies this step's `R` through the
//!   whole of `P`, and at the next step every carrier starts from its body's speed, so the
//!   carriers move as the constraints dictate to within `h P_ab (R(t + h) - R(t))` per step
//!   (the change of the pack's mean reaction over one step; a tooth impact's momentum is the
//!   disc's, not the carrier's). With `P_ab = 0` (carriers in two groups) nothing changes.
//!   A network step shorter than the times' precision (a step to a sample time the network
//!   stands at to rounding, `h` about 1e-18 s) does not move the session, and its reaction
//!   `J dw / h - T` would be `-T`: such a pack keeps its estimate, which its other carrier's
//!   held torque and the lumped clutches' stick checks read at the next step.
//! - **The pack's step**: the session's shaft takes `J_a` and the drum `J_b` (inertial
//!   carriers, eq 4), the held torques as its drive and load inputs, and is advanced to
//!   `t + h` (a communication point, landed on exactly). Its mean reaction on `a` over the
//!   step is `R_a = J_a (w_a(t + h) - w_a(t)) / h - T_a`, exact for the session's motion:
//!   the network applies it to `a` (and `R_b` to `b`) with the other torques, so the group's
//!   speed at `t + h` is the pack's carrier's.
//!   A clutch that locks or releases on a carrier's group changes `P_aa`: the session's
//!   carrier takes the new inertia at the next step ([`MultibodySession::set_carrier_inertia`]),
//!   its speed the network's merged one.
//! - **Several packs on one group** (a dual-clutch's two packs on the engine and on the
//!   geared input shafts): the packs advance in the couplings' order, each with the reactions
//!   of those already advanced over this step and the others' of the step before (their
//!   estimate, also in the torques at the step's midpoint). A pack's carrier then ends the
//!   step off the network's speed by the change of the later packs' reactions over `h / J`;
//!   at the start of the next step every carrier's speed is set to its body's
//!   ([`MultibodySession::set_carriers`]), as after a lock merges the speeds of a group.
//!   The angles are the pack's own (its teeth's loads depend only on its relative angles).
//!
//! # Outputs
//! Each closed tooth contact goes to [`Observer::pack_impact`] as it closes; at each
//! network sample the pack's discs and plates to [`Observer::pack_sample`] (their
//! angles shifted by the carrier's network angle less its pack angle); a change of the
//! faces' locked or clamped count, seen at the end of a network step, to
//! [`Observer::pack_faces`] at that time (a lock is timed to a network step); a thermal
//! pack's temperatures at each window's end to [`Observer::pack_temperatures`] (the
//! session's thermal run: its heat booked world step by world step, as in a pack run; a
//! carrier's speed set by the network is not booked as the teeth's work).
//!
//! # Energy
//! The work the carriers do on a pack over a step is `-h (R_a wbar_a + R_b wbar_b)` with the
//! network's mean speeds (the discrete energy identity of the network's step); the pack's
//! loss is that work less its discs' and plates' kinetic energy change.

use super::{NetworkStepOptions, Run};
use crate::engine::{Carried, MultibodySession};
use crate::options::MultibodyOptions;
use crate::MultibodyEngine;
use clutchpack_model::network::Network;
use clutchpack_model::session::{Driven, Session, Snapshot};
use clutchpack_model::thermal::ThermalReport;
use clutchpack_model::{DrumModel, EngineError, ImpactEvent, Observer, Shaft, ShaftExcitation};
use std::sync::Arc;

/// One resolved pack of a multibody network run.
#[derive(Clone)]
pub(super) struct NetPack {
    /// Its coupling's index.
    pub k: usize,
    /// The friction discs' carrier (body index).
    pub a: usize,
    /// The plates' carrier (body index); its drum is `None` when it is the fixed body.
    pub b: usize,
    session: MultibodySession,
    /// Whether the plates sit on the fixed body (no drum).
    pub housing: bool,
    /// Whether the discs' carrier is a prescribed body: the session's shaft is then
    /// prescribed by its profile (as a one-pack scene's), and its reaction on it is the teeth's
    /// work over the step (the session's drive work) on the step's mean speed.
    pub prescribed: Option<clutchpack_model::SpeedProfile>,
    /// The session's drive work at the last step's end, J (a prescribed shaft's), and the
    /// network's time there, s (a session not driven may stand a world step past it).
    drive_work_j: f64,
    t_last: f64,
    /// The discs' then the plates' inertias, kg m^2.
    inertia: Vec<f64>,
    /// How many of them are friction discs (on `a`).
    n_discs: usize,
    /// `P_aa` and `P_bb` the session's carriers were built with, 1/(kg m^2).
    p_diag: [f64; 2],
    /// The pack's mean torque on `a` and on `b` over the last step, N m (positive along the
    /// positive rotation): the estimate of the next.
    pub reaction: [f64; 2],
    /// Work of the carriers on the pack since t = 0, J.
    pub work_in_j: f64,
    /// The discs' and plates' kinetic energy at t = 0, J.
    kinetic0_j: f64,
    /// Faces locked and clamped at the last check.
    faces: (usize, usize),
}

/// The pack session's observer inside a network run: its impacts go to the network's
/// observer as the pack's, the rest is read from snapshots.
struct Forward<'a> {
    k: usize,
    obs: &'a mut dyn Observer,
}

impl Observer for Forward<'_> {
    fn impact(&mut self, event: &ImpactEvent) {
        self.obs.pack_impact(self.k, event);
    }
    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        let mut all = bodies_k.to_vec();
        all.push(oil_k);
        self.obs.pack_temperatures(self.k, t_s, &all);
    }
}

/// Whether `x` is 0 against the scale `s` (a cross term of `P` between two rigid groups).
fn negligible(x: f64, s: f64) -> bool {
    x.abs() <= 1e-12 * s
}

impl NetPack {
    /// The packs of `net` with their carriers' speeds `w` (rad/s) at t = 0 and the columns
    /// of `P` of each body (`p(i)`), on the engine's steps of at most `options.step_s`.
    /// A thermal pack (`net.pack_thermal`) carries its temperatures. Refused: discs on the
    /// fixed body, a pack the pack engine refuses.
    pub fn of(
        net: &Network,
        w: &[f64],
        p: impl Fn(usize) -> Vec<f64>,
        options: &NetworkStepOptions,
    ) -> Result<Vec<NetPack>, EngineError> {
        let mut out = Vec::new();
        for (k, c) in net.couplings.iter().enumerate() {
            let Some(model) = c.pack() else { continue };
            if net.bodies[c.a].is_fixed() {
                return Err(EngineError::Unsupported(format!(
                    "coupling \"{}\": its friction discs' carrier is the fixed body (put the \
                     plates there: body b)",
                    c.name
                )));
            }
            if net.bodies[c.b].prescribed().is_some() {
                return Err(EngineError::Unsupported(format!(
                    "coupling \"{}\": its plates' carrier is a prescribed body: put the \
                     friction discs there (body a), the plates on a body that turns freely or \
                     on the fixed one",
                    c.name
                )));
            }
            let (pa, pb) = (p(c.a), p(c.b));
            let housing = net.bodies[c.b].is_fixed();
            let prescribed = net.bodies[c.a].prescribed().cloned();
            let mut pack = model.clone();
            pack.shaft = if let Some(profile) = &prescribed {
                Shaft::Prescribed(profile.clone())
            } else {
                Shaft::Inertial {
                    inertia_kg_m2: 1.0 / pa[c.a],
                    damping_n_m_s_rad: 0.0,
                    excitation: ShaftExcitation::Held {
                        t0_s: 0.0,
                        torque_n_m: 0.0,
                        rate_n_m_s: 0.0,
                        initial_speed_rad_s: w[c.a],
                    },
                }
            };
            pack.drum = (!housing).then(|| DrumModel {
                inertia_kg_m2: 1.0 / pb[c.b],
                load_torque_n_m: 0.0,
                drag_n_m_s_rad: 0.0,
                initial_speed_rad_s: w[c.b],
            });
            let inertia: Vec<f64> = pack
                .discs
                .iter()
                .chain(&pack.plates)
                .map(|d| d.inertia_kg_m2)
                .collect();
            let record = if options.record_rate_hz > 0.0 {
                options.record_rate_hz
            } else {
                1e3
            };
            // a thermal pack carries its temperatures as in a pack run (MODEL.md section 9)
            let engine = MultibodyEngine::new(
                pack,
                MultibodyOptions::with_settings(record, options.step_s, false),
            )
            .map_err(|e| in_pack(&c.name, e))?
            .with_thermal(net.pack_thermal.get(&k).cloned());
            let session = engine
                .session(Driven {
                    shaft_torque: prescribed.is_none(),
                    drum_load: !housing,
                    ..Driven::NONE
                })
                .map_err(|e| in_pack(&c.name, e))?;
            let mut pack = NetPack {
                k,
                a: c.a,
                b: c.b,
                session,
                housing,
                prescribed: prescribed.clone(),
                drive_work_j: 0.0,
                t_last: 0.0,
                inertia,
                n_discs: model.discs.len(),
                p_diag: [pa[c.a], if housing { 0.0 } else { pb[c.b] }],
                reaction: [0.0; 2],
                work_in_j: 0.0,
                kinetic0_j: 0.0,
                faces: (0, 0),
            };
            pack.kinetic0_j = pack.kinetic_j(&pack.session.snapshot());
            out.push(pack);
        }
        Ok(out)
    }

    /// The discs' and plates' kinetic energy in `snap`, J.
    fn kinetic_j(&self, snap: &Snapshot) -> f64 {
        snap.sample
            .discs
            .iter()
            .zip(&self.inertia)
            .map(|(d, j)| 0.5 * j * d.speed_rad_s * d.speed_rad_s)
            .sum()
    }

    /// The discs' and plates' kinetic energy now less at t = 0, J.
    pub fn kinetic_change_j(&self) -> f64 {
        self.kinetic_j(&self.session.snapshot()) - self.kinetic0_j
    }

    /// Follows the carriers' rigid groups (`P`'s columns `pa`, `pb`): a clutch locking a body
    /// onto a carrier's group or releasing one changes the carrier's inertia `1 / P_aa`, which
    /// the session then takes ([`MultibodySession::set_carrier_inertia`]).
    pub fn follow_groups(&mut self, pa: &[f64], pb: &[f64], name: &str) -> Result<(), EngineError> {
        if self.prescribed.is_none() && pa[self.a] != self.p_diag[0] {
            self.session
                .set_carrier_inertia(false, 1.0 / pa[self.a])
                .map_err(|e| in_pack(name, e))?;
            self.p_diag[0] = pa[self.a];
        }
        if !self.housing && pb[self.b] != self.p_diag[1] {
            self.session
                .set_carrier_inertia(true, 1.0 / pb[self.b])
                .map_err(|e| in_pack(name, e))?;
            self.p_diag[1] = pb[self.b];
        }
        Ok(())
    }

    /// Advances the pack over `[t, t1]`, its carriers set to the network's speeds `w` (rad/s)
    /// and under the held torques `ta` on its shaft and `tb` on its drum (N m, everything else
    /// in the network's), sending its closed impacts to `obs`; returns its mean reactions on
    /// `a` and `b` over the step (N m) and keeps them. With `hold_short`, a step shorter than
    /// the times' precision keeps the reactions of the step before (the module's method).
    pub fn advance(
        &mut self,
        w: &[f64],
        t1: f64,
        (ta, tb): (f64, f64),
        name: &str,
        obs: &mut dyn Observer,
        hold_short: bool,
    ) -> Result<[f64; 2], EngineError> {
        let h = t1 - self.session.time_s();
        let (wa0, wb0) = (w[self.a], w[self.b]);
        // a prescribed shaft is the session's own (its profile, as the network's body)
        let shaft = self.prescribed.is_none().then_some(Carried {
            speed_rad_s: wa0,
            torque_n_m: ta,
        });
        let drum = (!self.housing).then_some(Carried {
            speed_rad_s: wb0,
            torque_n_m: tb,
        });
        if shaft.is_some() || drum.is_some() {
            self.session
                .set_carriers(shaft, drum)
                .map_err(|e| in_pack(name, e))?;
        }
        let mut fwd = Forward { k: self.k, obs };
        self.session
            .advance_to(t1, &mut fwd)
            .map_err(|e| in_pack(name, e))?;
        let speed = |drum: bool| self.session.carrier_motion(drum).map_or(0.0, |m| m.1);
        if hold_short && h <= 1e-12 * (1.0 + t1) {
            // a step shorter than the times' precision (the network's step to a sample time
            // it stands at to rounding): the session does not move, and `dw / h - T` would
            // give -T; the estimate stands
            return Ok(self.reaction);
        }
        let ra = if let Some(profile) = &self.prescribed {
            // the teeth's work on the discs over the step, -R_a wbar_a h (the session's
            // drive work: the shaft's on the teeth); a step shorter than the times' precision
            // keeps the estimate (its work, rounding, goes with the next step's)
            // over the network's step (the session's own may end past it: its work is booked
            // with the step that reaches it)
            let h = t1 - std::mem::replace(&mut self.t_last, t1);
            // the network's mean speed of the step (the session's shaft is booked at its own
            // world steps' ends)
            let wbar = 0.5 * (wa0 + profile.speed(t1));
            if h <= 1e-12 * (1.0 + t1) {
                self.reaction[0]
            } else {
                let work = self.session.drive_work_so_far_j();
                let step = work - std::mem::replace(&mut self.drive_work_j, work);
                if wbar == 0.0 {
                    0.0
                } else {
                    -step / (h * wbar)
                }
            }
        } else {
            (speed(false) - wa0) / (h * self.p_diag[0]) - ta
        };
        let rb = if self.housing {
            0.0
        } else {
            (speed(true) - wb0) / (h * self.p_diag[1]) - tb
        };
        self.reaction = [ra, rb];
        Ok(self.reaction)
    }

    /// Holds its piston's pressure at `pressure_pa` (Pa) from now on (a network input).
    pub fn hold_pressure(&mut self, pressure_pa: f64) -> Result<(), EngineError> {
        self.session.hold_pressure(pressure_pa)
    }

    /// Holds its prescribed carrier's speed: `profile` the network body's new one
    /// ([`clutchpack_model::SpeedProfile::Held`] from now), `speed_rad_s` its value (rad/s),
    /// which the session's shaft takes from its own angle now
    /// ([`MultibodySession::hold_shaft_speed`]).
    pub fn hold_speed(
        &mut self,
        profile: &clutchpack_model::SpeedProfile,
        speed_rad_s: f64,
    ) -> Result<(), EngineError> {
        self.session.hold_shaft_speed(speed_rad_s)?;
        self.prescribed = Some(profile.clone());
        Ok(())
    }

    /// Sends the faces' new locked and clamped counts to `obs` at `t` (s) if they changed, or
    /// whatever they are at t = 0 (as the reference engine does).
    pub fn faces_to(&mut self, t: f64, obs: &mut dyn Observer) {
        let faces = self.session.interfaces();
        if faces.is_empty() {
            return;
        }
        // a face's `locked` is its last step's; at t = 0, before any, a clamped face without
        // slip is locked (the reference engine's settling at the start)
        let locked = faces
            .iter()
            .filter(|f| f.locked || t == 0.0 && f.clamp_n > 0.0 && f.slip_rad_s.abs() <= 1e-9)
            .count();
        let clamped = faces.iter().filter(|f| f.clamp_n > 0.0).count();
        if (locked, clamped) != self.faces || t == 0.0 {
            self.faces = (locked, clamped);
            obs.pack_faces(self.k, t, locked, clamped, faces.len());
        }
    }

    /// Sends the discs and plates at `t` (s) to `obs`, their angles shifted by the carriers'
    /// network angles `theta` (rad) less the pack's own.
    pub fn sample_to(&self, t: f64, theta: &[f64], obs: &mut dyn Observer) {
        let snap = self.session.snapshot();
        let shaft = self.session.carrier_motion(false).map_or(0.0, |m| m.0);
        let drum = self.session.carrier_motion(true).map_or(0.0, |m| m.0);
        let angle: Vec<f64> = snap
            .sample
            .discs
            .iter()
            .enumerate()
            .map(|(i, d)| {
                if i < self.n_discs {
                    d.angle_rad + theta[self.a] - shaft
                } else {
                    d.angle_rad + theta[self.b] - drum
                }
            })
            .collect();
        let speed: Vec<f64> = snap.sample.discs.iter().map(|d| d.speed_rad_s).collect();
        let load: Vec<f64> = snap.sample.discs.iter().map(|d| d.load_n).collect();
        obs.pack_sample(self.k, t, &angle, &speed, &load);
    }

    /// Every open contact of its discs and plates as it would close now (`(its coupling, the
    /// body, event)`, the peak the largest so far), appended to `out`.
    pub fn open(&self, out: &mut Vec<(usize, Option<usize>, ImpactEvent)>) {
        for e in self.session.open_impacts() {
            out.push((self.k, Some(e.disc), e));
        }
    }

    /// Its faces' heat since t = 0 (friction and the open gaps' drag), J.
    pub fn face_heat_j(&self) -> f64 {
        self.session
            .interfaces()
            .iter()
            .map(|f| f.dissipated_j)
            .sum()
    }

    /// A thermal pack's temperatures as at its last window's end, K (its discs', plates',
    /// then oil's); `None` for an isothermal pack.
    pub fn temperatures_k(&self) -> Option<&[f64]> {
        self.session.temperatures_k()
    }

    /// Ends the pack's session at the run's end: its open contacts closed and sent to `obs`,
    /// a thermal pack's last window closed (its temperatures sent); its temperatures' report.
    pub fn finish(&mut self, obs: &mut dyn Observer) -> Option<ThermalReport> {
        let mut fwd = Forward { k: self.k, obs };
        self.session.finish(&mut fwd).thermal
    }
}

impl Run {
    /// Advances every pack over the step to `t1` (s) inside the network's step whose held
    /// torques are `total` (N m) and accelerations `acc` (rad/s^2), with the packs'
    /// reactions of the step before in them; replaces those by this step's as each pack
    /// advances (the module's method), its impacts sent to `obs`.
    pub(super) fn advance_packs(
        &mut self,
        t1: f64,
        total: &mut [f64],
        acc: &mut [f64],
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        let net = Arc::clone(&self.net);
        for j in 0..self.packs.len() {
            let (a, b) = (self.packs[j].a, self.packs[j].b);
            let (pa, pb) = (self.column(a), self.column(b));
            let name = &net.couplings[self.packs[j].k].name;
            let p = &mut self.packs[j];
            p.follow_groups(&pa, &pb, name)?;
            let [ra0, rb0] = p.reaction;
            // everything else's torque on each carrier's group, reduced to the carrier:
            // (P T)_a / P_aa less this pack's own estimate on it; with both carriers in one
            // group the other carrier's estimate stays in (the cross term P_ab R_b, the
            // module's method)
            let apart = p.housing || negligible(pa[b], (pa[a] * pb[b]).sqrt());
            let ta = if p.prescribed.is_some() {
                0.0 // its profile's motion: no torque moves it
            } else if apart {
                (acc[a] - pa[a] * ra0 - pb[a] * rb0) / pa[a]
            } else {
                (acc[a] - pa[a] * ra0) / pa[a]
            };
            let tb = if p.housing {
                0.0
            } else if apart {
                (acc[b] - pa[b] * ra0 - pb[b] * rb0) / pb[b]
            } else {
                (acc[b] - pb[b] * rb0) / pb[b]
            };
            // (on separate groups the tiny steps' reactions are kept as they were, so that
            // those networks' outputs stay bit for bit: docs/DECISIONS.md)
            let hold_short = !apart;
            let [ra, rb] = p.advance(&self.w, t1, (ta, tb), name, obs, hold_short)?;
            for (i, x) in acc.iter_mut().enumerate() {
                *x += pa[i] * (ra - ra0) + pb[i] * (rb - rb0);
            }
            total[a] += ra - ra0;
            total[b] += rb - rb0;
        }
        Ok(())
    }
}

impl Run {
    /// Column `i` of `P` ([`Run::response`]), kept while the rows are those it was computed
    /// with (they change only where a clutch locks or releases).
    fn column(&mut self, i: usize) -> Arc<[f64]> {
        if self.columns.0 != self.rows || self.columns.1.len() != self.w.len() {
            self.columns = (self.rows.clone(), vec![None; self.w.len()]);
        }
        if self.columns.1[i].is_none() {
            self.columns.1[i] = Some(self.response(i).into());
        }
        Arc::clone(self.columns.1[i].as_ref().unwrap())
    }
}

/// `e` said of the pack of coupling `name`.
fn in_pack(name: &str, e: EngineError) -> EngineError {
    match e {
        EngineError::Unsupported(m) => {
            EngineError::Unsupported(format!("coupling \"{name}\" (a resolved pack): {m}"))
        }
        EngineError::Diverged { t_s, reason } => EngineError::Diverged {
            t_s,
            reason: format!("in coupling \"{name}\" (a resolved pack): {reason}"),
        },
    }
}
