//! The equations of motion of a shaft and a set of its discs (Hu et al. eqs 3-5), in the
//! state layout the integrator advances; for a whole pack also the separator plates on the
//! housing or the drum, the drum (MODEL.md section 5) and the open stack's oil gaps.

use crate::gaps::Gaps;
use clutchpack_model::{
    Carrier, DiscModel, DiscSample, Engagement, InterfaceSample, PackModel, Sample, Shaft,
    StackBody, ToothKinematics,
};
use std::sync::Arc;

/// What a friction interface does between two stick-slip events: the model's one
/// definition, for both engines.
pub(crate) use clutchpack_model::Face;

/// The stack's forces at one instant ([`System::stack_eval`]); interfaces from the piston,
/// bodies in stack order.
#[derive(Debug, Clone, Default)]
pub(crate) struct StackEval {
    /// `F_p - sum_{b <= m} mu_spline Q_b`, N (the clamp before it is cut at 0).
    pub raw_clamp: Vec<f64>,
    /// Clamp force, N (>= 0).
    pub clamp: Vec<f64>,
    /// Slip `omega_upper - omega_lower`, rad/s.
    pub slip: Vec<f64>,
    /// Torque of the interface on its upper body, N m (the lower body gets the opposite); for
    /// a locked interface the torque that holds it.
    pub torque: Vec<f64>,
    /// Heat rate `-torque * slip`, W (>= 0).
    pub heat_rate: Vec<f64>,
    /// Acceleration of each stack body, rad/s^2.
    pub alpha: Vec<f64>,
    /// Power of the teeth's forces dissipated on the relative motions, `sum -n F Rb psi`, W
    /// (its integral is the teeth's work, [`System::teeth_work`]).
    pub teeth_power: f64,
}

/// A [`StackEval`] with the per-body sums it is built from, reused from one evaluation to
/// the next ([`System::with_stack_eval`]).
#[derive(Debug, Default)]
struct StackScratch {
    ev: StackEval,
    omega: Vec<f64>,
    free: Vec<f64>,
    inertia: Vec<f64>,
}

thread_local! {
    /// Each thread's [`StackScratch`]: the right-hand side and the face probes of a stack
    /// evaluate it at every stage and every bisection, and allocated its nine vectors each
    /// time (issue 46: no allocation in a host's frame loop once started).
    static STACK_SCRATCH: std::cell::RefCell<StackScratch> = std::cell::RefCell::default();
    /// Each thread's bodies' loads for one evaluation ([`System::with_loads`]): the pack's
    /// right-hand side and face probes take them once for the carriers' reactions and the
    /// stack's teeth and clamp (issue 46).
    static LOADS: std::cell::RefCell<Vec<f64>> = std::cell::RefCell::default();
}

/// `v` as `n` zeros, in its own buffer.
fn zeroed(v: &mut Vec<f64>, n: usize) {
    v.clear();
    v.resize(n, 0.0);
}

/// The shaft and the couplings in `ids` (global indices: the discs `0..N`, then the plates
/// `N..N + P`, as the engines number bodies), in slots 0, 1, ...
///
/// State layout: for an inertial shaft `y[0] = theta_s` (rad), `y[1] = omega_s` (rad/s), then
/// per slot `j` at `off + 2 j` the relative angle `phi = theta_c - theta_b` (rad) and the
/// relative speed `psi = omega_c - omega_b` (rad/s) of the body `b` against its carrier `c`
/// (the shaft for a disc, the drum or the housing for a plate); for a prescribed shaft
/// `off = 0` and the shaft comes from its profile. A whole pack (plates, a drum or a stack:
/// every coupling in its slot, in order) continues with the drum's angle (rad) and speed
/// (rad/s) when there is a drum, then the heat (J) each open interface has dissipated. A body
/// of an open pack run on its own (the open-pack multirate scheme, [`System::open_body`])
/// continues instead with the work (J) the gap below and the gap above have done on it.
pub(crate) struct System {
    /// The model (shared by a run's steppers; `session.rs` swaps it when an input changes).
    pub pack: Arc<PackModel>,
    /// Index of the first disc state: 0 for a prescribed shaft, 2 for an inertial one.
    pub off: usize,
    /// Global coupling index of each slot.
    pub ids: Vec<usize>,
    /// Number of friction discs of the pack.
    nd: usize,
    /// What each friction interface does between stick-slip events (with a stack).
    pub faces: Vec<Face>,
    /// Base radius `Rb` of every coupling (by global index), m.
    rb: Vec<f64>,
    /// Open-gap damping `c = pi eta (Ro^4 - Ri^4) / (2 h)` of every interface, N m s/rad (0
    /// without a stack or its oil gap; MODEL.md section 5).
    c_gap: f64,
    /// The open gaps on both sides of the one body of an open-pack multirate run
    /// ([`System::open_body`]); `None` otherwise.
    pub gaps: Option<Gaps>,
    /// Whether the state carries the teeth's work on the relative motion, `-n F Rb psi`
    /// integrated over the run (J), after everything else (a thermal run's heat of the
    /// teeth, MODEL.md section 9; outside the step's error norm, [`Dopri5::norm_len`]).
    ///
    /// [`Dopri5::norm_len`]: crate::dopri::Dopri5::norm_len
    pub teeth_work: bool,
    /// Whether the carriers are bodies outside the system (a pack on a network, MODEL.md
    /// section 8; [`System::carried`]): the state holds neither the shaft nor the drum, the
    /// discs ride on carrier `a` and every plate on carrier `b`, and the caller gives the
    /// carriers' motion ([`Self::rhs_with_loads`], [`Self::reactions_n_m`]).
    pub carried: bool,
}

clone_reusing!(System {
    pack,
    off,
    ids,
    nd,
    faces,
    rb,
    c_gap,
    gaps,
    teeth_work,
    carried,
});

impl System {
    /// The shaft and the couplings `ids` of `pack`. A pack with plates, a drum or a stack
    /// needs every coupling in order (`ids = 0..N + P`).
    pub fn new(pack: Arc<PackModel>, ids: Vec<usize>) -> System {
        let sys = System::build(pack, ids);
        debug_assert!(
            !sys.pack.is_whole()
                || sys.ids == (0..sys.nd + sys.pack.plates.len()).collect::<Vec<_>>()
        );
        sys
    }

    /// Every coupling of `pack` (discs, then plates) on carriers outside the system: the
    /// discs' carrier `a` and the plates' carrier `b` are bodies of a network (MODEL.md
    /// section 8), whose motion the caller gives; the pack's own shaft and drum are not used.
    /// The state carries the teeth's work ([`Self::teeth_work`]).
    pub fn carried(pack: Arc<PackModel>) -> System {
        let ids = (0..pack.discs.len() + pack.plates.len()).collect();
        let mut sys = System::build(pack, ids);
        sys.off = 0;
        sys.carried = true;
        sys.teeth_work = true;
        sys
    }

    /// The system of the couplings `ids`, unchecked.
    fn build(pack: Arc<PackModel>, ids: Vec<usize>) -> System {
        let off = if matches!(pack.shaft, Shaft::Inertial { .. }) {
            2
        } else {
            0
        };
        let c_gap = pack
            .stack
            .as_ref()
            .map_or(0.0, |s| -s.open_gap_torque_n_m(1.0));
        let faces = vec![Face::Open; pack.stack.as_ref().map_or(0, |_| 2 * pack.discs.len())];
        // `pack` moves last: the fields before it read it
        System {
            off,
            ids,
            nd: pack.discs.len(),
            c_gap,
            faces,
            gaps: None,
            teeth_work: false,
            carried: false,
            rb: pack
                .discs
                .iter()
                .chain(&pack.plates)
                .map(|d| d.spline.base_radius_m())
                .collect(),
            pack,
        }
    }

    /// The body `id` of an open pack (plates on the housing, a prescribed shaft, a stack whose
    /// piston never clamps) alone: its spline coupling, its drag and the open gaps to its
    /// neighbours, whose speeds the caller sets in [`Self::gaps`] window by window.
    pub fn open_body(pack: Arc<PackModel>, id: usize) -> System {
        let mut sys = System::build(pack, vec![id]);
        sys.faces.clear();
        sys.gaps = Some(Gaps {
            c: sys.c_gap,
            below: None,
            above: None,
        });
        sys
    }

    /// The work (J) the gap below and the gap above have done on the body of an
    /// [`Self::open_body`] system in state `y`.
    pub fn gap_work_j(&self, y: &[f64]) -> [f64; 2] {
        let h = self.heat_at();
        [y[h], y[h + 1]]
    }

    /// Index of the drum's angle in the state (its speed follows).
    fn drum_at(&self) -> usize {
        self.off + 2 * self.ids.len()
    }

    /// The drum's angle (rad) and speed (rad/s) in state `y`; `None` without a drum.
    pub fn drum_state(&self, y: &[f64]) -> Option<(f64, f64)> {
        let r = self.drum_at();
        self.pack.drum.map(|_| (y[r], y[r + 1]))
    }

    /// Index of the first interface's heat in the state.
    fn heat_at(&self) -> usize {
        self.drum_at()
            + if self.pack.drum.is_some() && !self.carried {
                2
            } else {
                0
            }
    }

    /// The heat each friction interface has dissipated since t = 0 in state `y`, J (empty
    /// without a stack).
    pub fn interface_heat_j<'y>(&self, y: &'y [f64]) -> &'y [f64] {
        let h = self.heat_at();
        &y[h..h + self.interfaces()]
    }

    /// Swaps the model for `pack` (the same bodies and stack; parameters changed, as a thermal
    /// window changes the oil's viscosities), recomputing what is cached from it.
    pub fn set_pack(&mut self, pack: Arc<PackModel>) {
        self.c_gap = pack
            .stack
            .as_ref()
            .map_or(0.0, |s| -s.open_gap_torque_n_m(1.0));
        if let Some(g) = self.gaps.as_mut() {
            g.c = self.c_gap;
        }
        self.pack = pack;
    }

    /// Number of friction interfaces in the state (`2N` for a whole pack with a stack; none
    /// for one body of an open pack, which carries its gaps' work instead).
    pub fn interfaces(&self) -> usize {
        if self.pack.stack.is_some() && self.gaps.is_none() {
            2 * self.nd
        } else {
            0
        }
    }

    pub fn dim(&self) -> usize {
        self.heat_at()
            + self.interfaces()
            + if self.gaps.is_some() { 2 } else { 0 }
            + usize::from(self.teeth_work)
    }

    /// The teeth's work on the relative motion since t = 0 in state `y`, `-n F Rb psi`
    /// integrated (J; [`Self::teeth_work`], else 0).
    pub fn teeth_work_j(&self, y: &[f64]) -> f64 {
        if self.teeth_work {
            y[self.dim() - 1]
        } else {
            0.0
        }
    }

    /// The coupling with global index `id`: disc `id`, or plate `id - N`.
    fn coupling(&self, id: usize) -> &DiscModel {
        if id < self.nd {
            &self.pack.discs[id]
        } else {
            &self.pack.plates[id - self.nd]
        }
    }

    pub fn disc(&self, slot: usize) -> &DiscModel {
        self.coupling(self.ids[slot])
    }

    fn carrier(&self, slot: usize) -> Carrier {
        let id = self.ids[slot];
        if self.carried {
            // carrier a plays the shaft's part, carrier b the drum's (0 when b is fixed)
            if id < self.nd {
                Carrier::Shaft
            } else {
                Carrier::Drum
            }
        } else {
            self.pack.carrier(id)
        }
    }

    /// Angle (rad) and speed (rad/s) of the carrier of `slot` at `t` for state `y`.
    fn carrier_motion(&self, slot: usize, t: f64, y: &[f64]) -> (f64, f64) {
        match self.carrier(slot) {
            Carrier::Shaft => self.shaft(t, y),
            Carrier::Drum => (y[self.drum_at()], y[self.drum_at() + 1]),
            Carrier::Housing => (0.0, 0.0),
        }
    }

    /// Shaft angle (rad) and speed (rad/s) at `t` for state `y`.
    pub fn shaft(&self, t: f64, y: &[f64]) -> (f64, f64) {
        match &self.pack.shaft {
            Shaft::Prescribed(p) => {
                let (speed, angle) = p.speed_and_angle(t);
                (angle, speed)
            }
            Shaft::Inertial { .. } => (y[0], y[1]),
        }
    }

    pub fn kin(&self, slot: usize, y: &[f64]) -> ToothKinematics {
        let k = self.off + 2 * slot;
        let id = self.ids[slot];
        self.coupling(id)
            .spline
            .kinematics_at(y[k], y[k + 1], self.rb[id])
    }

    /// Signed per-tooth load of the disc in `slot`, N, for its mode.
    pub fn load(&self, slot: usize, y: &[f64], mode: &Option<Engagement>) -> f64 {
        match mode {
            Some(e) => self.disc(slot).law.load_n(&self.kin(slot, y), e),
            None => 0.0,
        }
    }

    /// Engagement depth of the disc in `slot`, m (positive inside a contact event).
    pub fn depth(&self, slot: usize, y: &[f64]) -> f64 {
        self.disc(slot).law.engagement_depth_m(&self.kin(slot, y))
    }

    /// The carriers' motion at `t` for state `y` and contact modes `modes`: the shaft's speed
    /// and acceleration, the drum's (0 without a drum), rad/s and rad/s^2. The carriers feel
    /// their couplings' spline reactions (eq 4; the drum's load and drag) and the pack's
    /// couplings between them (a spring-damper, MODEL.md section 8), never the stack, which
    /// acts between discs and plates.
    pub fn carriers(&self, t: f64, y: &[f64], modes: &[Option<Engagement>]) -> [f64; 4] {
        self.carriers_with_loads(t, y, modes, None)
    }

    /// [`Self::carriers`] with the bodies' loads at `y` already known (`loads`, from
    /// [`Self::loads_into`]; `None`: taken here for the reactions), the same values.
    pub fn carriers_with_loads(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        loads: Option<&[f64]>,
    ) -> [f64; 4] {
        let (omega_s, alpha_prescribed) = match &self.pack.shaft {
            Shaft::Prescribed(p) => p.speed_and_acceleration(t),
            Shaft::Inertial { .. } => (y[1], 0.0),
        };
        let inertial = matches!(self.pack.shaft, Shaft::Inertial { .. });
        let (mut shaft_torque, mut drum_torque) = (0.0, 0.0);
        if inertial || self.pack.drum.is_some() {
            [shaft_torque, drum_torque] = match loads {
                Some(loads) => self.reactions_from_n_m(loads, modes),
                None => self.reactions_n_m(y, modes),
            };
        }
        if !self.pack.couplings.is_empty() {
            // MODEL.md section 8: the couplings between the shaft and the drum (a spring-damper:
            // T = k (theta_a - theta_b - theta_0) + d (omega_a - omega_b) on b, -T on a)
            let drum = self.drum_state(y).unwrap_or((0.0, 0.0));
            let loads = self.pack.coupling_loads(self.shaft(t, y), drum);
            shaft_torque += loads.shaft_n_m;
            drum_torque += loads.drum_n_m;
        }
        let alpha_s = match &self.pack.shaft {
            Shaft::Inertial {
                inertia_kg_m2,
                damping_n_m_s_rad,
                ..
            } => {
                (self.pack.shaft.drive_torque_n_m(t) + shaft_torque - damping_n_m_s_rad * omega_s)
                    / inertia_kg_m2
            }
            Shaft::Prescribed(_) => alpha_prescribed,
        };
        let (omega_r, alpha_r) = match &self.pack.drum {
            // the drum: its load, its drag and the plates' spline reactions (MODEL.md section 5)
            Some(drum) => {
                let omega_r = y[self.drum_at() + 1];
                let alpha_r = (drum.load_torque_n_m + drum_torque - drum.drag_n_m_s_rad * omega_r)
                    / drum.inertia_kg_m2;
                (omega_r, alpha_r)
            }
            None => (0.0, 0.0),
        };
        [omega_s, alpha_s, omega_r, alpha_r]
    }

    /// The spline reactions on the disc carrier (the shaft) and on the plate carrier (the
    /// drum), N m, at state `y` with contact modes `modes` (Hu et al. eq (4): `n F Rb` summed
    /// over the carrier's couplings in contact; nothing on the housing). The teeth are
    /// compliant: the reactions follow from the state alone, so a network (MODEL.md section
    /// 8) takes them before it solves its bodies' accelerations.
    pub fn reactions_n_m(&self, y: &[f64], modes: &[Option<Engagement>]) -> [f64; 2] {
        self.reactions_by(modes, |slot| self.load(slot, y, &modes[slot]))
    }

    /// Each body's signed per-tooth load ([`Self::load`], N; 0 in free flight) at state `y`
    /// with contact modes `modes`, into `out` by slot (its contents replaced).
    pub fn loads_into(&self, y: &[f64], modes: &[Option<Engagement>], out: &mut Vec<f64>) {
        out.clear();
        out.extend((0..self.ids.len()).map(|slot| self.load(slot, y, &modes[slot])));
    }

    /// `f` given the bodies' loads at `y` ([`Self::loads_into`], in this thread's buffer: no
    /// allocation per evaluation; a fresh one if `f` asks again), N by slot.
    pub fn with_loads<R>(
        &self,
        y: &[f64],
        modes: &[Option<Engagement>],
        f: impl FnOnce(&[f64]) -> R,
    ) -> R {
        LOADS.with(|cell| match cell.try_borrow_mut() {
            Ok(mut loads) => {
                self.loads_into(y, modes, &mut loads);
                f(&loads)
            }
            Err(_) => {
                let mut loads = Vec::new();
                self.loads_into(y, modes, &mut loads);
                f(&loads)
            }
        })
    }

    /// The carriers' motion ([`Self::carriers`]) and the stack at `(t, y)` ([`Self::stack_eval`])
    /// given to `f`, each body's load taken once for both (the carriers' reactions, the stack's
    /// teeth and clamp): the same values, to the bit, as each taking them itself.
    pub fn with_carriers_and_stack<R>(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        f: impl FnOnce(&[f64; 4], &StackEval) -> R,
    ) -> R {
        let eval = |loads: Option<&[f64]>| {
            let c = self.carriers_with_loads(t, y, modes, loads);
            self.with_stack_eval_loads(t, y, modes, &c, loads, |ev| f(&c, ev))
        };
        if self.reuses_loads(modes) {
            self.with_loads(y, modes, |loads| eval(Some(loads)))
        } else {
            eval(None)
        }
    }

    /// [`Self::reactions_n_m`] from the loads [`Self::loads_into`] gave at the same state
    /// (the same sums in the same order).
    pub fn reactions_from_n_m(&self, loads: &[f64], modes: &[Option<Engagement>]) -> [f64; 2] {
        if self.carried {
            // a pack on a network ([`Self::carried`]: every body in its own slot): its discs'
            // reactions on carrier a, its plates' on b, each sum in slot order as
            // `reactions_by` adds them, without looking up each slot's body and carrier
            // (the network takes them at every evaluation; issue 45, the resolved shift's cost)
            let side = |bodies: &[DiscModel], first: usize| {
                let mut sum = 0.0;
                for (j, d) in bodies.iter().enumerate() {
                    let slot = first + j;
                    if modes[slot].is_some() {
                        // Hu et al. eq (4), as in `reactions_by`
                        sum += d.spline.teeth as f64 * loads[slot] * self.rb[slot];
                    }
                }
                sum
            };
            return [side(&self.pack.discs, 0), side(&self.pack.plates, self.nd)];
        }
        self.reactions_by(modes, |slot| loads[slot])
    }

    /// [`Self::reactions_n_m`] with each body's load in contact from `load`.
    fn reactions_by(&self, modes: &[Option<Engagement>], load: impl Fn(usize) -> f64) -> [f64; 2] {
        let (mut shaft_torque, mut drum_torque) = (0.0, 0.0);
        for slot in 0..self.ids.len() {
            if modes[slot].is_none() {
                continue;
            }
            let d = self.disc(slot);
            let f = load(slot);
            // Hu et al. eq (4): the spline reaction n F Rb acts back on the carrier
            let reaction = d.spline.teeth as f64 * f * self.rb[self.ids[slot]];
            match self.carrier(slot) {
                Carrier::Shaft => shaft_torque += reaction,
                Carrier::Drum => drum_torque += reaction,
                Carrier::Housing => {}
            }
        }
        [shaft_torque, drum_torque]
    }

    /// Speed and acceleration of the carrier of `slot` from [`Self::carriers`].
    fn carrier_of(&self, slot: usize, c: &[f64; 4]) -> (f64, f64) {
        match self.carrier(slot) {
            Carrier::Shaft => (c[0], c[1]),
            Carrier::Drum => (c[2], c[3]),
            Carrier::Housing => (0.0, 0.0),
        }
    }

    /// `dy = f(t, y)` with the slots' contact modes `modes`.
    pub fn rhs(&self, t: f64, y: &[f64], modes: &[Option<Engagement>], dy: &mut [f64]) {
        if let Some(gaps) = &self.gaps {
            // one body of an open pack on a prescribed shaft: its teeth, its drag and its gaps
            // (MODEL.md section 5); the shaft's acceleration only for a disc
            let Shaft::Prescribed(p) = &self.pack.shaft else {
                unreachable!("an open pack's shaft is prescribed")
            };
            let k = self.off;
            // a disc's carrier speed and acceleration in one pass, a plate's carrier at rest
            // (the shaft's speed only for its neighbours, the discs)
            let (omega_s, alpha_s) = match self.carrier(0) {
                Carrier::Shaft => p.speed_and_acceleration(t),
                _ => (p.speed(t), 0.0),
            };
            let (omega_c, alpha_c) = match self.carrier(0) {
                Carrier::Shaft => (omega_s, alpha_s),
                _ => (0.0, 0.0),
            };
            let omega_b = omega_c - y[k + 1];
            let [below, above] = gaps.torques_n_m(t, omega_b, || omega_s);
            let free = self.free_torque_n_m(0, y, &modes[0], omega_c) + below + above;
            dy[k] = y[k + 1];
            dy[k + 1] = alpha_c - free / self.disc(0).inertia_kg_m2;
            let h = self.heat_at();
            dy[h] = below * omega_b;
            dy[h + 1] = above * omega_b;
            return;
        }
        // each body's load taken once where it would be taken again: the carriers'
        // reactions, then the teeth (and the stack's clamp) take the same values
        let rhs = |loads: Option<&[f64]>, dy: &mut [f64]| {
            let c = self.carriers_with_loads(t, y, modes, loads);
            if matches!(self.pack.shaft, Shaft::Inertial { .. }) {
                dy[0] = c[0];
                dy[1] = c[1];
            }
            if self.pack.drum.is_some() {
                dy[self.drum_at()] = c[2];
                dy[self.drum_at() + 1] = c[3];
            }
            self.rhs_with_loads(t, y, modes, &c, loads, dy);
        };
        if self.reuses_loads(modes) {
            self.with_loads(y, modes, |loads| rhs(Some(loads), dy));
        } else {
            rhs(None, dy);
        }
    }

    /// Whether an evaluation at contact modes `modes` would take a body's load more than
    /// once (a body in contact, and a stack or the carriers' reactions besides the teeth):
    /// else the loads are left to be taken where needed, with no buffer to fill.
    fn reuses_loads(&self, modes: &[Option<Engagement>]) -> bool {
        (self.pack.stack.is_some()
            || matches!(self.pack.shaft, Shaft::Inertial { .. })
            || self.pack.drum.is_some())
            && modes.iter().any(Option::is_some)
    }

    /// The couplings' part of [`Self::rhs`] (every slot's relative angle and speed, the
    /// faces' heat, the teeth's work) with the carriers' speeds and accelerations `c`
    /// (`[omega_s, alpha_s, omega_r, alpha_r]`, rad/s and rad/s^2, as [`Self::carriers`]
    /// gives them; a network's bodies for a [`Self::carried`] system) and the bodies' loads
    /// at `y` if already known (`loads`, from [`Self::loads_into`]: a network has them from
    /// its carriers' reactions, [`Self::rhs`] from its own; `None`: taken here), each taken
    /// once instead of again for the teeth and the stack's clamp.
    pub fn rhs_with_loads(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
        loads: Option<&[f64]>,
        dy: &mut [f64],
    ) {
        let c = *c;
        if self.pack.stack.is_some() {
            // every body is a stack body: its acceleration comes from the stack's balance
            self.with_stack_eval_loads(t, y, modes, &c, loads, |ev| {
                for slot in 0..self.ids.len() {
                    let k = self.off + 2 * slot;
                    let alpha_c = self.carrier_of(slot, &c).1;
                    dy[k] = y[k + 1];
                    dy[k + 1] = alpha_c - ev.alpha[self.position(slot)];
                }
                let h = self.heat_at();
                dy[h..h + self.interfaces()].copy_from_slice(&ev.heat_rate);
                if self.teeth_work {
                    dy[self.dim() - 1] = ev.teeth_power;
                }
            });
            return;
        }
        for slot in 0..self.ids.len() {
            let k = self.off + 2 * slot;
            let (omega_c, alpha_c) = self.carrier_of(slot, &c);
            let known = loads.map(|l| l[slot]);
            let alpha_b = self
                .free_and_teeth_n_m(slot, y, &modes[slot], omega_c, known)
                .0
                / self.disc(slot).inertia_kg_m2;
            dy[k] = y[k + 1];
            dy[k + 1] = alpha_c - alpha_b;
        }
    }

    /// The torque on the body in `slot` from its teeth and its oil drag (Hu et al. eq 5), N m,
    /// with its carrier at `omega_c` (rad/s).
    fn free_torque_n_m(
        &self,
        slot: usize,
        y: &[f64],
        mode: &Option<Engagement>,
        omega_c: f64,
    ) -> f64 {
        self.free_and_teeth_n_m(slot, y, mode, omega_c, None).0
    }

    /// [`Self::free_torque_n_m`] and its teeth's part `-n F Rb` (eq 5), N m (`load` the
    /// body's load if known, N).
    fn free_and_teeth_n_m(
        &self,
        slot: usize,
        y: &[f64],
        mode: &Option<Engagement>,
        omega_c: f64,
        load: Option<f64>,
    ) -> (f64, f64) {
        let d = self.disc(slot);
        let omega_b = omega_c - y[self.off + 2 * slot + 1];
        let teeth = match mode {
            // eq (5): -n F Rb
            Some(_) => {
                let f = load.unwrap_or_else(|| self.load(slot, y, mode));
                -(d.spline.teeth as f64) * f * self.rb[self.ids[slot]]
            }
            None => 0.0,
        };
        (teeth - d.drag_n_m_s_rad * omega_b, teeth)
    }

    /// Stack position of the body in `slot` (whole pack: slot = coupling index).
    fn position(&self, slot: usize) -> usize {
        let id = self.ids[slot];
        if id < self.nd {
            StackBody::Disc(id)
        } else {
            StackBody::Plate(id - self.nd)
        }
        .position()
    }

    /// The stack at `t` for state `y` (MODEL.md section 5), with the faces in
    /// [`Self::faces`]: clamp forces, slips, each interface's torque on its upper body, the
    /// heat rates and every stack body's acceleration. An open interface drags with the
    /// Couette law; a slipping one with `mu(|v|) F R_eff` against its slip direction; the
    /// bodies joined by locked interfaces move as one (one acceleration, from their summed
    /// free torques), and each locked interface carries the torque that holds it,
    /// `X_m = sum over the group's bodies below it of (T_b - J_b alpha)`. The bodies' loads
    /// from `loads` if known at `y` (N, by slot: [`Self::loads_into`]), else taken here.
    pub fn stack_eval(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
        loads: Option<&[f64]>,
    ) -> StackEval {
        let mut s = StackScratch::default();
        self.stack_eval_into(t, y, modes, c, loads, &mut s);
        s.ev
    }

    /// `f` of [`Self::stack_eval`]'s evaluation, made in this thread's buffers (no allocation
    /// once they have grown; in new ones if `f` itself asks for another).
    pub fn with_stack_eval<R>(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
        f: impl FnOnce(&StackEval) -> R,
    ) -> R {
        self.with_stack_eval_loads(t, y, modes, c, None, f)
    }

    /// [`Self::with_stack_eval`] with the bodies' loads at `y` already known (`loads`, from
    /// [`Self::loads_into`]; `None`: taken here), the same values.
    pub fn with_stack_eval_loads<R>(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
        loads: Option<&[f64]>,
        f: impl FnOnce(&StackEval) -> R,
    ) -> R {
        STACK_SCRATCH.with(|cell| match cell.try_borrow_mut() {
            Ok(mut s) => {
                self.stack_eval_into(t, y, modes, c, loads, &mut s);
                f(&s.ev)
            }
            Err(_) => f(&self.stack_eval(t, y, modes, c, loads)),
        })
    }

    /// [`Self::stack_eval`] into `s`'s buffers (the bodies' loads from `loads` if given).
    fn stack_eval_into(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
        loads: Option<&[f64]>,
        s: &mut StackScratch,
    ) {
        let stack = self.pack.stack.as_ref().expect("a stack");
        let n_b = 2 * self.nd + 1;
        let n_if = n_b - 1;
        let r_eff = stack.effective_radius_m();
        let StackScratch {
            ev,
            omega,
            free,
            inertia,
        } = s;
        for v in [
            &mut ev.raw_clamp,
            &mut ev.clamp,
            &mut ev.slip,
            &mut ev.torque,
            &mut ev.heat_rate,
        ] {
            zeroed(v, n_if);
        }
        zeroed(&mut ev.alpha, n_b);
        ev.teeth_power = 0.0;
        zeroed(omega, n_b);
        zeroed(free, n_b);
        zeroed(inertia, n_b);
        let mut f_p = stack.piston.force_n(t);
        for b in 0..n_b {
            let slot = StackBody::at(b).body_index(self.nd);
            let (omega_c, _) = self.carrier_of(slot, c);
            omega[b] = omega_c - y[self.off + 2 * slot + 1];
            let known = loads.map(|l| l[slot]);
            let (f, teeth) = self.free_and_teeth_n_m(slot, y, &modes[slot], omega_c, known);
            free[b] = f;
            // the teeth's torque on the body times psi = omega_c - omega_b: -n F Rb psi
            ev.teeth_power += teeth * y[self.off + 2 * slot + 1];
            inertia[b] = self.disc(slot).inertia_kg_m2;
            if b < n_if {
                // MODEL.md section 5: each body holds back mu_spline n |F| of the clamp
                let d = self.disc(slot);
                let load = known.unwrap_or_else(|| self.load(slot, y, &modes[slot]));
                let q = d.spline.teeth as f64 * load.abs();
                f_p -= stack.spline_friction * q;
                ev.raw_clamp[b] = f_p;
                ev.clamp[b] = f_p.max(0.0);
            }
        }
        for m in 0..n_if {
            let slip = omega[m + 1] - omega[m];
            ev.slip[m] = slip;
            let torque = match self.faces[m] {
                Face::Open => -self.c_gap * slip,
                Face::Slip(dir) => {
                    -dir * stack.friction_of(m).mu(slip * r_eff) * ev.clamp[m] * r_eff
                }
                Face::Locked => 0.0,
            };
            ev.torque[m] = torque;
            ev.heat_rate[m] = -torque * slip;
            free[m + 1] += torque;
            free[m] -= torque;
        }
        // locked groups: runs of bodies joined by locked interfaces
        let mut b0 = 0;
        while b0 < n_b {
            let mut b1 = b0;
            while b1 < n_if && self.faces[b1] == Face::Locked {
                b1 += 1;
            }
            let (sum_t, sum_j): (f64, f64) = (b0..=b1)
                .map(|b| (free[b], inertia[b]))
                .fold((0.0, 0.0), |(a, j), (tb, jb)| (a + tb, j + jb));
            let alpha = sum_t / sum_j;
            let mut hold = 0.0;
            for b in b0..=b1 {
                ev.alpha[b] = alpha;
                if b < b1 {
                    hold += free[b] - inertia[b] * alpha;
                    ev.torque[b] = hold;
                }
            }
            b0 = b1 + 1;
        }
    }

    /// The interfaces' states at `t` for state `y` (empty without a stack).
    pub fn interface_samples(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
    ) -> Vec<InterfaceSample> {
        let mut out = Vec::new();
        self.interface_samples_into(t, y, modes, &mut out);
        out
    }

    /// [`Self::interface_samples`] into `out` (its contents replaced; its buffer reused).
    pub fn interface_samples_into(
        &self,
        t: f64,
        y: &[f64],
        modes: &[Option<Engagement>],
        out: &mut Vec<InterfaceSample>,
    ) {
        out.clear();
        let Some(stack) = &self.pack.stack else {
            return;
        };
        let r_eff = stack.effective_radius_m();
        self.with_carriers_and_stack(t, y, modes, |_, ev| {
            out.extend((0..self.interfaces()).map(|m| InterfaceSample {
                slip_rad_s: ev.slip[m],
                slip_m_s: ev.slip[m] * r_eff,
                mu: match self.faces[m] {
                    Face::Open => 0.0,
                    _ => stack.friction_of(m).mu(ev.slip[m] * r_eff),
                },
                clamp_n: ev.clamp[m],
                torque_n_m: ev.torque[m],
                locked: self.faces[m] == Face::Locked,
                dissipated_j: y[self.heat_at() + m],
            }))
        })
    }

    /// Whether interface `m` must change its mode at the state `ev` (a stick-slip event):
    /// an open one clamps, a slipping one's slip reaches zero (against its direction) or its
    /// clamp vanishes, a locked one needs more torque than `mu(0) F R_eff` or loses its clamp.
    pub fn face_switches(&self, m: usize, ev: &StackEval) -> bool {
        let stack = self.pack.stack.as_ref().expect("a stack");
        match self.faces[m] {
            Face::Open => ev.raw_clamp[m] > 0.0,
            Face::Slip(dir) => dir * ev.slip[m] <= 0.0 || ev.raw_clamp[m] <= 0.0,
            Face::Locked => {
                ev.raw_clamp[m] <= 0.0
                    || ev.torque[m].abs()
                        > stack.friction_of(m).static_mu()
                            * ev.clamp[m]
                            * stack.effective_radius_m()
            }
        }
    }

    /// The mode interface `m` takes at `(t, y)` when its event fires (or at t = 0): open
    /// without clamp; else locked if the torque that holds it stays within `mu(0) F R_eff`
    /// and its slip is zero (or has just reached zero), else slipping in the direction its
    /// slip goes (the direction the unbalanced torque drives it, when it starts from zero).
    /// A lock sets the slip exactly to zero, moving the bodies above it (with those locked to
    /// them) to the speed below.
    pub fn settle_face(&mut self, m: usize, t: f64, y: &mut [f64], modes: &[Option<Engagement>]) {
        let c = self.carriers(t, y, modes);
        self.settle_face_with(m, t, y, modes, &c);
    }

    /// [`Self::settle_face`] with the carriers' speeds and accelerations `c` given (a
    /// [`Self::carried`] system).
    pub fn settle_face_with(
        &mut self,
        m: usize,
        t: f64,
        y: &mut [f64],
        modes: &[Option<Engagement>],
        c: &[f64; 4],
    ) {
        let c = *c;
        let stack = self.pack.stack.as_ref().expect("a stack");
        let (raw_clamp, slip) =
            self.with_stack_eval(t, y, modes, &c, |ev| (ev.raw_clamp[m], ev.slip[m]));
        if raw_clamp <= 0.0 {
            self.faces[m] = Face::Open;
            return;
        }
        let reached_zero = match self.faces[m] {
            Face::Slip(dir) => dir * slip <= 0.0,
            Face::Locked => true,
            Face::Open => slip == 0.0,
        };
        if !reached_zero {
            self.faces[m] = Face::Slip(slip.signum());
            return;
        }
        let was = self.faces[m];
        self.faces[m] = Face::Locked;
        let (clamp, torque) =
            self.with_stack_eval(t, y, modes, &c, |ev| (ev.clamp[m], ev.torque[m]));
        let bound = stack.friction_of(m).static_mu() * clamp * stack.effective_radius_m();
        if torque.abs() <= bound && was != Face::Locked {
            // lock: the upper bodies (and those locked above them) take the lower's speed
            let mut b = m + 1;
            loop {
                let slot = StackBody::at(b).body_index(self.nd);
                y[self.off + 2 * slot + 1] += slip;
                if b >= 2 * self.nd || self.faces[b] != Face::Locked {
                    break;
                }
                b += 1;
            }
        } else if torque.abs() > bound {
            // the lock cannot hold: the upper body slips against the torque it would need
            self.faces[m] = Face::Slip(-torque.signum());
        }
    }

    /// The state at t = 0.
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        if self.off == 2 {
            y[0] = 0.0;
            y[1] = self.pack.shaft.initial_speed_rad_s();
        }
        for slot in 0..self.ids.len() {
            let d = self.disc(slot);
            y[self.off + 2 * slot] = d.initial_rel_angle_rad;
            y[self.off + 2 * slot + 1] = d.initial_rel_speed_rad_s;
        }
        if let (Some(drum), false) = (&self.pack.drum, self.carried) {
            y[self.drum_at() + 1] = drum.initial_speed_rad_s;
        }
        y
    }

    /// The sample of the disc in `slot` at `t` for state `y`.
    pub fn disc_sample(
        &self,
        t: f64,
        slot: usize,
        y: &[f64],
        mode: &Option<Engagement>,
    ) -> DiscSample {
        let (theta_c, omega_c) = self.carrier_motion(slot, t, y);
        let k = self.off + 2 * slot;
        disc_sample(self.disc(slot), theta_c, omega_c, y[k], y[k + 1], mode)
    }

    /// The sample of the whole system at `t` (every coupling of the pack in its slot, discs
    /// then plates: only for a system of all the pack's couplings in order).
    pub fn sample(&self, t: f64, y: &[f64], modes: &[Option<Engagement>]) -> Sample {
        let mut s = Sample::default();
        self.sample_into(t, y, modes, &mut s);
        s
    }

    /// [`Self::sample`] into `out` (its contents replaced; its bodies' buffer reused).
    pub fn sample_into(&self, t: f64, y: &[f64], modes: &[Option<Engagement>], out: &mut Sample) {
        let (theta_s, omega_s) = self.shaft(t, y);
        out.t_s = t;
        out.shaft_angle_rad = theta_s;
        out.shaft_speed_rad_s = omega_s;
        out.discs.clear();
        out.discs
            .extend((0..self.ids.len()).map(|slot| self.disc_sample(t, slot, y, &modes[slot])));
    }
}

/// The sample of the body `d` with its carrier at `theta_s` (rad), `omega_s` (rad/s),
/// relative angle `phi` (rad), relative speed `psi` (rad/s) and contact mode `mode`.
pub(crate) fn disc_sample(
    d: &DiscModel,
    theta_s: f64,
    omega_s: f64,
    phi: f64,
    psi: f64,
    mode: &Option<Engagement>,
) -> DiscSample {
    let kin = d.spline.kinematics(phi, psi);
    let f = match mode {
        Some(e) => d.law.load_n(&kin, e),
        None => 0.0,
    };
    DiscSample {
        angle_rad: theta_s - phi,
        speed_rad_s: omega_s - psi,
        rel_angle_rad: phi,
        penetration_m: kin.delta_m,
        closing_speed_m_s: kin.v_n_m_s,
        load_n: f,
        torque_n_m: d.spline.disc_torque_n_m(f),
        engaged: mode.is_some(),
        stiffness: mode.map(|e| e.stiffness).unwrap_or(0.0),
        tooth_loads_n: Vec::new(),
        center_offset_m: [0.0, 0.0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::cases::paper_disc;
    use clutchpack_model::{
        DrumModel, FrictionCurve, LawKind, OpenGap, Piston, PressureProfile, ShaftExcitation,
        SpeedProfile, StackModel,
    };

    /// An undriven, undamped whole pack: an inertial shaft, 2 dry lossless discs, 3 plates on
    /// a free drum, the open stack's oil gaps between them.
    fn free_pack() -> PackModel {
        let disc = |name: &str| {
            let mut d = paper_disc(0.0);
            d.name = name.into();
            d.law.kind = LawKind::Dry;
            d.law.hertz.loss_coefficient_s_m = 0.0;
            d.drag_n_m_s_rad = 0.0;
            d
        };
        let mut pack = PackModel::new(
            Shaft::Inertial {
                inertia_kg_m2: 2.0,
                damping_n_m_s_rad: 0.0,
                excitation: ShaftExcitation::Profile(SpeedProfile::sine(100.0, 0.0, 1.0)),
            },
            vec![disc("d0"), disc("d1")],
        );
        pack.plates = vec![disc("p0"), disc("p1"), disc("p2")];
        for (j, p) in pack.plates.iter_mut().enumerate() {
            p.inertia_kg_m2 = 0.1 + 0.02 * j as f64;
        }
        pack.drum = Some(DrumModel {
            inertia_kg_m2: 1.5,
            load_torque_n_m: 0.0,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
        });
        pack.stack = Some(StackModel {
            face_friction: Vec::new(),
            face_inner_radius_m: 0.235,
            face_outer_radius_m: 0.29,
            friction: FrictionCurve::constant(0.1),
            piston: Piston {
                area_m2: 0.01,
                pressure: PressureProfile::Constant { pressure_pa: 0.0 },
                return_spring_n: 0.0,
            },
            open_gap: Some(OpenGap {
                viscosity_pa_s: 0.01,
                gap_m: 1e-3,
            }),
            spline_friction: 0.1,
        });
        // MODEL.md section 8: a spring-damper from the shaft to the drum
        pack.couplings = vec![clutchpack_model::PackCoupling {
            a: clutchpack_model::PackBody::Shaft,
            b: clutchpack_model::PackBody::Drum,
            kind: clutchpack_model::PackCouplingKind::SpringDamper(
                clutchpack_model::SpringDamper {
                    stiffness_n_m_per_rad: 800.0,
                    damping_n_m_s_per_rad: 0.7,
                    free_angle_rad: 0.01,
                },
            ),
        }];
        pack
    }

    /// The relative angles of [`contact_state`]'s two test states, in half plays (beyond 1:
    /// in contact; at least two bodies in contact in each, on the shaft and on the drum).
    const CONTACTS: [[f64; 5]; 2] = [
        [0.3, 1.02, -0.7, -1.01, 0.2],
        [1.01, 0.1, 1.03, -0.5, -1.02],
    ];

    /// The `k`-th test state of [`free_pack`]'s five bodies: each body's relative angle at
    /// `contact` times the half play `g0` (beyond 1: in contact), its relative speed, the
    /// shaft's and the drum's, and the modes engaged where a body is in contact.
    fn contact_state(
        sys: &System,
        k: usize,
        contact: &[f64; 5],
        g0: f64,
    ) -> (Vec<f64>, Vec<Option<Engagement>>) {
        let mut y = sys.initial_state();
        y[1] = 100.0 + k as f64;
        for slot in 0..5 {
            y[2 + 2 * slot] = contact[slot] * g0;
            y[2 + 2 * slot + 1] = 3.0 - 1.7 * slot as f64 + k as f64;
        }
        y[sys.drum_at()] = 0.03 - 0.05 * k as f64;
        y[sys.drum_at() + 1] = -4.0;
        let modes: Vec<Option<Engagement>> = (0..5)
            .map(|slot| {
                (sys.depth(slot, &y) > 0.0).then(|| sys.disc(slot).law.engage(&sys.kin(slot, &y)))
            })
            .collect();
        (y, modes)
    }

    /// At states with some couplings in contact and every gap slipping, the right-hand side
    /// conserves angular momentum exactly (`sum J alpha = 0`: every spline reaction, gap
    /// torque and the spring-damper's torque is paired) and power (`sum J omega alpha = sum n
    /// F Rb psi - sum heat rates - dV/dt - d dw^2`: the teeth's power is what their potential
    /// gives up, the gaps' is the heat they make, the spring-damper's what its spring stores
    /// and its damper loses, MODEL.md section 8).
    #[test]
    fn whole_pack_rhs_conserves_momentum_and_power() {
        let pack = free_pack();
        let g0 = pack.discs[0].spline.half_play_rad();
        let sys = System::new(std::sync::Arc::new(pack), (0..5).collect());
        assert_eq!(sys.dim(), 2 + 2 * 5 + 2 + 4);
        for (k, contact) in CONTACTS.iter().enumerate() {
            let (y, modes) = contact_state(&sys, k, contact, g0);
            assert!(modes.iter().filter(|m| m.is_some()).count() >= 2);
            let mut dy = vec![0.0; sys.dim()];
            sys.rhs(0.0, &y, &modes, &mut dy);
            let r = sys.drum_at();
            let (w_s, a_s, w_r, a_r) = (y[1], dy[1], y[r + 1], dy[r + 1]);
            let (mut momentum, mut scale, mut power, mut teeth) = (
                2.0 * a_s + 1.5 * a_r,
                (2.0 * a_s).abs() + (1.5 * a_r).abs(),
                2.0 * w_s * a_s + 1.5 * w_r * a_r,
                0.0,
            );
            for slot in 0..5 {
                let (w_c, a_c) = if slot < 2 { (w_s, a_s) } else { (w_r, a_r) };
                let d = sys.disc(slot);
                let (psi, j) = (y[2 + 2 * slot + 1], d.inertia_kg_m2);
                let (w_b, a_b) = (w_c - psi, a_c - dy[2 + 2 * slot + 1]);
                (momentum, scale) = (momentum + j * a_b, scale + (j * a_b).abs());
                power += j * w_b * a_b;
                teeth += d.spline.teeth as f64
                    * sys.load(slot, &y, &modes[slot])
                    * d.spline.base_radius_m()
                    * psi;
            }
            let heat: f64 = dy[sys.heat_at()..].iter().sum();
            assert!(heat > 0.0);
            // the spring-damper: its potential's rate and its damper's loss
            let c = &sys.pack.couplings[0];
            let (t_s, t_r) = (y[0], y[r]);
            let spring = c.torque_on_b_n_m((t_s, w_s), (t_r, w_r));
            assert!(spring.abs() > 1.0, "{spring}");
            let loss = c.loss_rate_w(w_s, w_r);
            // dV/dt = k (dtheta - theta_0) dw = T dw - d dw^2
            let v_rate = spring * (w_s - w_r) - loss;
            let heat = heat + loss;
            assert!(momentum.abs() <= 1e-12 * scale, "{momentum} of {scale}");
            assert!(
                (power - teeth + heat + v_rate).abs()
                    <= 1e-11 * (teeth.abs() + heat + v_rate.abs()),
                "{power} {teeth} {heat} {v_rate}"
            );
        }
    }

    /// The pack path took each body's tooth load three times per right-hand side and face
    /// probe: for the carriers' reactions, the teeth's torque and the stack's clamp (issue
    /// 46); now once. At two states of [`free_pack`] pressed by the piston (2 kN) with bodies
    /// in contact on both carriers and the faces locked, slipping and open in turn (three
    /// rotations), the right-hand side ([`System::rhs`]) and the face probes' carriers and
    /// stack ([`System::with_carriers_and_stack`]) are those of the carriers and the stack
    /// each taking the loads themselves, to the bit (no margin: the same operations in the
    /// same order); and so for the same pack without a stack (the teeth from the same loads).
    #[test]
    fn pack_rhs_took_each_load_three_times() {
        for stacked in [true, false] {
            let mut pack = free_pack();
            match &mut pack.stack {
                Some(stack) if stacked => {
                    stack.piston.pressure = PressureProfile::Constant { pressure_pa: 2e5 };
                }
                _ => pack.stack = None,
            }
            let g0 = pack.discs[0].spline.half_play_rad();
            let mut sys = System::new(std::sync::Arc::new(pack), (0..5).collect());
            let faces = [Face::Locked, Face::Slip(1.0), Face::Open];
            let mut clamped = 0;
            for (k, contact) in CONTACTS.iter().enumerate() {
                let (y, modes) = contact_state(&sys, k, contact, g0);
                // in contact on the shaft (slots 0, 1) and on the drum (slots 2 to 4)
                assert!(modes[..2].iter().any(Option::is_some));
                assert!(modes[2..].iter().any(Option::is_some));
                for turn in 0..3 {
                    for m in 0..sys.faces.len() {
                        sys.faces[m] = faces[(m + turn) % 3];
                    }
                    let t = 0.01 * turn as f64;
                    let mut once = vec![7.0; sys.dim()];
                    sys.rhs(t, &y, &modes, &mut once);
                    // the carriers' reactions and the stack each taking the loads themselves
                    let c = sys.carriers(t, &y, &modes);
                    let mut own = vec![7.0; sys.dim()];
                    own[..2].copy_from_slice(&c[..2]);
                    let r = sys.drum_at();
                    own[r..r + 2].copy_from_slice(&c[2..]);
                    sys.rhs_with_loads(t, &y, &modes, &c, None, &mut own);
                    assert_eq!(
                        once.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        own.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        "stacked {stacked}, state {k}, turn {turn}"
                    );
                    if !stacked {
                        continue;
                    }
                    let own_ev = sys.stack_eval(t, &y, &modes, &c, None);
                    sys.with_carriers_and_stack(t, &y, &modes, |c_once, ev| {
                        assert_eq!(c_once.map(f64::to_bits), c.map(f64::to_bits));
                        assert_eq!(format!("{ev:?}"), format!("{own_ev:?}"));
                        // the clamp is reduced by the teeth's spline friction (the loads')
                        clamped += ev.clamp.iter().filter(|f| **f > 0.0).count();
                        assert!(
                            ev.raw_clamp[ev.raw_clamp.len() - 1] < 2000.0,
                            "{:?}",
                            ev.raw_clamp
                        );
                    });
                }
            }
            assert!(!stacked || clamped > 0);
        }
    }
}
