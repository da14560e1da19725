//! The gear meshes of a driveline network on the multibody engine (MODEL.md section 8): each
//! mesh's relative displacement along its line of action `x` (m; `x = Rb_a theta_a +
//! Rb_b theta_b` plus its value at t = 0, internal mesh: minus) kept as its own state, the
//! tooth law of section 2 on the penetration `|x| - b/2` through the model's
//! [`GearMesh`] (never re-implemented here), the step a contact allows, the landing of a step
//! on a contact's onset and separation, and the contact events
//! ([`clutchpack_model::ImpactEvent`], through [`Observer::mesh_impact`]).
//!
//! Over a step the engine holds every torque (`mod.rs`), so each body's speed is affine in
//! time and a mesh's `x` is quadratic: its [`Path`]. The engine lands on the first instant the
//! engagement depth ([`clutchpack_model::ToothLaw::engagement_depth_m`]) crosses 0 on that
//! path, bisected to 1e-13 s on a piece where `x` is monotone, as it lands on a slip's zero.

use clutchpack_model::law::{damping_factor, squeeze_load};
use clutchpack_model::network::{GearMesh, Network};
use clutchpack_model::Observer;
use clutchpack_model::{Engagement, ImpactTracker, LawKind, ToothKinematics};

/// Steps per predicted contact duration (dimensionless): a contact's step is its predicted
/// Hertz duration ([`clutchpack_model::free_impact_duration_s`] at the closing speed of its
/// onset) over this. Twice the pack engine's default `steps_per_contact` (128, with the
/// classical Runge-Kutta step): the midpoint rule is second order. Measured on the free
/// impact across a mesh (`tests/network.rs`): the peak 2.4e-5, 5.7e-6 and 1.4e-6 off the
/// closed form at 128, 256 and 512, the duration 1.6e-5, 4.0e-6 and 9.9e-7.
const STEPS_PER_CONTACT: f64 = 256.0;

/// Predicted contact durations after which a contact counts as sustained (a loaded mesh
/// rather than an impact; dimensionless). Its step is then the local period of the
/// linearised contact over [`SUSTAINED_STEPS_PER_PERIOD`].
const SUSTAINED_AFTER: f64 = 4.0;

/// Steps per local period of a sustained contact (dimensionless). The explicit midpoint rule
/// gains `(w h)^4 / 8` of amplitude per step on an undamped oscillation: 7e-4 per period at
/// 64 steps, which the law's impact damping (`p`) outweighs.
const SUSTAINED_STEPS_PER_PERIOD: f64 = 64.0;

/// Floor of the closing speed in the duration's estimate, m/s (a grazing contact's predicted
/// duration grows as `v^(-1/5)`; the local period bounds the step too).
const V_MIN_M_S: f64 = 1e-3;

/// The squeeze film's step: at most this fraction of the film's time constant
/// `m_eff / c` (`c` the damper's N s/m; the explicit midpoint rule is stable below 2).
const SQUEEZE_STEP_FRACTION: f64 = 0.25;

/// Samples of the force per step in contact, beside the step's end, before the refinement of
/// an event's peak.
const PROBES: usize = 16;

/// A mesh's motion along its line of action over one step under held torques: `x(tau) = x0 +
/// v0 tau + acc tau^2 / 2` for `tau` in `[0, h]` from `t0`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Path {
    /// The step's start, s, and its length, s.
    pub t0: f64,
    pub h: f64,
    /// `x` at the start, m; its rate there, m/s; its (constant) acceleration, m/s^2.
    pub x0: f64,
    pub v0: f64,
    pub acc: f64,
}

impl Path {
    /// `x` (m) and its rate (m/s) at `tau` s into the step.
    fn at(&self, tau: f64) -> (f64, f64) {
        (
            self.x0 + tau * (self.v0 + 0.5 * self.acc * tau),
            self.v0 + self.acc * tau,
        )
    }
}

/// One gear mesh of the network and its contact state.
#[derive(Clone)]
pub(super) struct Mesh {
    /// The coupling's index and its bodies `a`, `b`.
    pub coupling: usize,
    pub a: usize,
    pub b: usize,
    /// The mesh (geometry and tooth law), the model's.
    pub gear: GearMesh,
    /// The relative displacement along the line of action, m (with the initial offset).
    pub x: f64,
    /// The open contact event's memory of the law, `None` in free flight.
    pub contact: Option<Engagement>,
    /// The effective mass of one tooth pair, kg (a fixed body's inertia infinite).
    m_eff: f64,
    /// The open contact's onset, s, and its predicted duration, s.
    t_on: f64,
    duration: f64,
    tracker: ImpactTracker,
    /// The step of the open contact with the largest |force| so far, where in it (s), and
    /// that force's magnitude (N).
    best: Option<(Path, f64, f64)>,
}

impl Mesh {
    /// The meshes of `net`, in the couplings' order.
    pub fn of(net: &Network) -> Vec<Mesh> {
        let inertia = |i: usize| {
            let b = &net.bodies[i];
            if !b.is_free() {
                f64::INFINITY
            } else {
                b.inertia_kg_m2
            }
        };
        net.couplings
            .iter()
            .enumerate()
            .filter_map(|(k, c)| {
                let g = c.mesh()?;
                Some(Mesh {
                    coupling: k,
                    a: c.a,
                    b: c.b,
                    gear: g.clone(),
                    x: g.initial_offset_m,
                    contact: None,
                    m_eff: g.effective_mass_kg(inertia(c.a), inertia(c.b)),
                    t_on: 0.0,
                    duration: f64::INFINITY,
                    tracker: ImpactTracker::new(k),
                    best: None,
                })
            })
            .collect()
    }

    /// The rate of `x` (m/s) at the bodies' speeds `w` (rad/s): `Rb_a w_a +- Rb_b w_b`.
    pub fn speed(&self, w: &[f64]) -> f64 {
        self.gear.displacement((0.0, 0.0), (w[self.a], w[self.b])).1
    }

    /// The mesh force per pair `F`, N, signed as `x` (MODEL.md section 8), at `x` (m) and its
    /// rate `v` (m/s): the law of the open contact, 0 in free flight.
    pub fn force_n(&self, x: f64, v: f64) -> f64 {
        match &self.contact {
            Some(e) => self.gear.force_n(&self.gear.kinematics(x, v), e),
            None => 0.0,
        }
    }

    /// The path of `x` over a step of `h` s from `t0`, from the bodies' speeds `w` (rad/s) and
    /// accelerations `acc` (rad/s^2) held over it.
    pub fn path(&self, t0: f64, h: f64, w: &[f64], acc: &[f64]) -> Path {
        Path {
            t0,
            h,
            x0: self.x,
            v0: self.speed(w),
            acc: self.speed(acc),
        }
    }

    /// The engagement depth at `x`, m (> 0 while the law acts).
    fn depth(&self, x: f64) -> f64 {
        let kin = self.gear.kinematics(x, 0.0);
        self.gear.law.engagement_depth_m(&kin)
    }

    /// Whether the mesh has left its state along `path` at `tau`: in free flight, the depth
    /// above 0 (an onset); in contact, the depth at or below 0, or `x` over on the other side
    /// (a separation). Monotone on a piece of the path where `x` is.
    fn left(&self, path: &Path, tau: f64) -> bool {
        let (x, _) = path.at(tau);
        match &self.contact {
            None => self.depth(x) > 0.0,
            Some(e) => e.flank.phi_sign() * x <= 0.0 || self.depth(x) <= 0.0,
        }
    }

    /// The first instant along `path` (s into the step, in `(0, h]`) where the mesh leaves
    /// its state ([`Self::left`]), bisected to `tol` s; `None` if it stays all along. `x` is
    /// monotone on each side of its extremum, where [`Self::left`] is too.
    fn crossing(&self, path: &Path, tol: f64) -> Option<f64> {
        let mut ends = Vec::with_capacity(2);
        if path.acc != 0.0 {
            let ext = -path.v0 / path.acc;
            if ext > 0.0 && ext < path.h {
                ends.push(ext);
            }
        }
        ends.push(path.h);
        let mut start = 0.0;
        for end in ends {
            if self.left(path, end) {
                let (mut a, mut b) = (start, end);
                while b - a > tol {
                    let mid = 0.5 * (a + b);
                    if self.left(path, mid) {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                return Some(b);
            }
            start = end;
        }
        None
    }

    /// The longest step the open contact allows at `t` with `x` at rate `v` (m/s), s
    /// (`INFINITY` in free flight): its predicted duration over [`STEPS_PER_CONTACT`], and the
    /// local period of the linearised law `2 pi sqrt(m_eff / (1.5 K (1 + p v_n) sqrt(s)))`
    /// over it; a sustained contact the local period over [`SUSTAINED_STEPS_PER_PERIOD`]; the
    /// squeeze film a fraction of its time constant.
    pub fn step_bound(&self, t: f64, v: f64) -> f64 {
        let Some(e) = &self.contact else {
            return f64::INFINITY;
        };
        let law = &self.gear.law;
        let kin = self.gear.kinematics(self.x, v);
        let k = e.stiffness * damping_factor(law.hertz.loss_coefficient_s_m, kin.v_n_m_s).max(1.0);
        let s = law.engagement_depth_m(&kin).max(0.0);
        let period = std::f64::consts::TAU * (self.m_eff / (1.5 * k * s.sqrt())).sqrt();
        let mut h = if t - self.t_on > SUSTAINED_AFTER * self.duration {
            period / SUSTAINED_STEPS_PER_PERIOD
        } else {
            self.duration.min(period) / STEPS_PER_CONTACT
        };
        if law.kind == LawKind::Squeeze {
            // the damper's coefficient at the metal gap, N s/m (the model's law at 1 m/s)
            let c = squeeze_load(&law.oil, -kin.delta_m, 1.0);
            if c > 0.0 {
                h = h.min(SQUEEZE_STEP_FRACTION * self.m_eff / c);
            }
        }
        h
    }

    /// Opens or closes the contact at the start of a step at `t`, the bodies at speeds `w`:
    /// an onset (the depth above 0 in free flight) takes the law's memory
    /// ([`clutchpack_model::ToothLaw::engage`]) and predicts the contact's duration; a
    /// separation (the depth at or below 0, or the other flank) sends the event.
    pub fn switch(&mut self, t: f64, w: &[f64], obs: &mut dyn Observer) {
        let v = self.speed(w);
        let kin = self.gear.kinematics(self.x, v);
        let depth = self.gear.law.engagement_depth_m(&kin);
        if let Some(e) = &self.contact {
            if depth > 0.0 && e.flank == kin.flank {
                return;
            }
            self.close(t, obs);
        }
        if depth > 0.0 {
            self.engage(t, &kin);
        }
    }

    fn engage(&mut self, t: f64, kin: &ToothKinematics) {
        let law = &self.gear.law;
        let e = law.engage(kin);
        let v = kin.v_n_m_s.max(V_MIN_M_S);
        // MODEL.md section 4: the free impact's duration 2.9433 s_max / v0 at the onset's
        // closing speed, the stiffness with the law's impact damping there
        let k = e.stiffness * damping_factor(law.hertz.loss_coefficient_s_m, v).max(1.0);
        self.duration = clutchpack_model::free_impact_duration_s(k, self.m_eff, v);
        self.contact = Some(e);
        self.t_on = t;
        self.best = None;
        self.tracker.begin(t, kin.flank, kin.v_n_m_s);
    }

    /// The load on the open contact's flank along `path` at `tau`, N, as an event's peak is
    /// signed (eq 6: negative when body `a` leads, `x > 0`).
    fn load(&self, path: &Path, tau: f64) -> f64 {
        let (x, v) = path.at(tau);
        -self.force_n(x, v)
    }

    /// Advances `x` over the step taken along `path` to the bodies' speeds `w1` (rad/s) at
    /// its end, under the force per pair `force_n` (N) held over it, and observes the open
    /// contact; returns the work done on the mesh, J: `F pairs (x_{k+1} - x_k)`, `x`'s advance
    /// exact on the step's affine speeds (the mesh torques' work on the bodies, negated).
    pub fn advance(&mut self, path: &Path, w1: &[f64], force_n: f64) -> f64 {
        let dx = 0.5 * path.h * (path.v0 + self.speed(w1));
        self.x += dx;
        self.observe(path);
        force_n * self.gear.pairs * dx
    }

    /// Observes the open contact over a step taken along `path`: the step with the largest
    /// |force| at its probes is kept for the peak's refinement.
    fn observe(&mut self, path: &Path) {
        if self.contact.is_none() {
            return;
        }
        let mut top: Option<(f64, f64)> = None;
        for j in 1..=PROBES {
            let tau = path.h * j as f64 / PROBES as f64;
            let f = self.load(path, tau).abs();
            if top.is_none_or(|(_, b)| f > b) {
                top = Some((tau, f));
            }
        }
        if let Some((tau, f)) = top {
            if self.best.is_none_or(|(_, _, b)| f > b) {
                self.best = Some((*path, tau, f));
            }
        }
    }

    /// Closes the open contact at `t`: its peak refined by golden-section search on the best
    /// step's path, the event sent.
    fn close(&mut self, t: f64, obs: &mut dyn Observer) {
        if let Some((path, tau, _)) = self.best.take() {
            let span = path.h / PROBES as f64;
            let (lo, hi) = ((tau - span).max(0.0), (tau + span).min(path.h));
            let (tp, fp) = golden_peak(lo, hi, |s| self.load(&path, s));
            self.tracker.observe(path.t0 + tp, fp);
        }
        self.contact = None;
        if let Some(e) = self.tracker.end(t) {
            obs.mesh_impact(&e);
        }
    }

    /// The open contact as it would close at `t` s (its peak the largest probed so far),
    /// left open.
    pub fn open(&self, t: f64) -> Option<clutchpack_model::ImpactEvent> {
        let probe = self.best.as_ref().map(|(path, tau, f)| (path.t0 + tau, *f));
        self.tracker.peek_with(t, probe)
    }

    /// Closes an open contact at the end of the run, `t` s (its separation then).
    pub fn finish(&mut self, t: f64, obs: &mut dyn Observer) {
        if self.contact.is_some() {
            self.close(t, obs);
        }
    }
}

/// Opens and closes the contacts of `meshes` at the start of a step at `t` (s), the bodies
/// at speeds `w` (rad/s; [`Mesh::switch`]); returns the longest step the open contacts allow,
/// s ([`Mesh::step_bound`]; `INFINITY` with none).
pub(super) fn start_step(meshes: &mut [Mesh], t: f64, w: &[f64], obs: &mut dyn Observer) -> f64 {
    let mut h = f64::INFINITY;
    for m in meshes {
        m.switch(t, w, obs);
        h = h.min(m.step_bound(t, m.speed(w)));
    }
    h
}

/// Adds the meshes' torques at their `x` (m, one per mesh) and the bodies' speeds `w` (rad/s)
/// to the bodies' torques `body` (N m) and sets each mesh's torque on its body `a` in
/// `coupling` (N m) and its force per pair in `force` (N): MODEL.md section 8, `F` signed as
/// `x`, `-Rb_a F` on `a`, `-Rb_b F` on `b` (internal: `+Rb_b F`), times the pairs.
pub(super) fn add_torques(
    meshes: &[Mesh],
    x: &[f64],
    w: &[f64],
    body: &mut [f64],
    coupling: &mut [f64],
    force: &mut Vec<f64>,
) {
    force.clear();
    for (m, x) in meshes.iter().zip(x) {
        let f = m.force_n(*x, m.speed(w));
        let (ta, tb) = m.gear.torques_n_m(f);
        force.push(f);
        coupling[m.coupling] = ta;
        body[m.a] += ta;
        body[m.b] += tb;
    }
}

/// Each mesh's `x` (m) after `hh` s on the trajectory of the bodies' speeds `w` (rad/s) under
/// the accelerations `acc` (rad/s^2) held: `x + hh (v + hh a / 2)`.
pub(super) fn positions(meshes: &[Mesh], hh: f64, w: &[f64], acc: &[f64]) -> Vec<f64> {
    meshes
        .iter()
        .map(|m| m.x + hh * (m.speed(w) + 0.5 * hh * m.speed(acc)))
        .collect()
}

/// The length of the step from `t` (s), at most `h`, that lands on the first onset or
/// separation of `meshes` on the step's trajectory (the bodies' speeds `w`, rad/s, affine
/// with the accelerations `acc`, rad/s^2): bisected to 1e-13 (1 + t) s.
pub(super) fn landing(meshes: &[Mesh], t: f64, h: f64, w: &[f64], acc: &[f64]) -> f64 {
    let mut best = h;
    for m in meshes {
        if let Some(tau) = m.crossing(&m.path(t, best, w, acc), 1e-13 * (1.0 + t)) {
            best = best.min(tau);
        }
    }
    best
}

/// Maximises `|f|` on `[a, b]` by golden-section search (`|f|` unimodal there); returns the
/// argument and the signed value. The bracket shrinks by 0.618 an iteration, to 1e-15 s or
/// 80 iterations.
fn golden_peak(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut c, mut d) = (b - R * (b - a), a + R * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if b - a < 1e-15 {
            break;
        }
        if fc.abs() > fd.abs() {
            (b, d, fd) = (d, c, fc);
            c = b - R * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + R * (b - a);
            fd = f(d);
        }
    }
    if fc.abs() > fd.abs() {
        (c, fc)
    } else {
        (d, fd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossing of a path out of the backlash: `x` from the centre at 0.3 m/s with no
    /// acceleration reaches the flank `b/2 = 5e-5` m at 1.6667e-4 s; decelerated so that it
    /// turns back before the flank, none; turning back towards the other flank, it crosses
    /// on its way back (the second monotone piece).
    #[test]
    fn onsets_are_found_on_either_piece_of_the_path() {
        let mut net = clutchpack_model::cases::coupled_clutches();
        net.couplings.push(clutchpack_model::network::Coupling {
            name: "mesh".into(),
            a: 0,
            b: 1,
            kind: clutchpack_model::network::CouplingKind::GearMesh(
                clutchpack_model::cases::dry_gear_mesh(false),
            ),
        });
        let m = Mesh::of(&net).pop().unwrap();
        let path = |v0: f64, acc: f64, h: f64| Path {
            t0: 0.0,
            h,
            x0: 0.0,
            v0,
            acc,
        };
        let t = m.crossing(&path(0.3, 0.0, 1e-3), 1e-15).unwrap();
        assert!((t - 5e-5 / 0.3).abs() < 1e-14, "{t}");
        // turns at x = v^2 / 2a = 0.09 / 2e4 = 4.5e-6 m
        assert!(m.crossing(&path(0.3, -1e4, 5e-5), 1e-15).is_none());
        // back to -5e-5 m: 0.3 t - 5e3 t^2 = -5e-5
        let t = m.crossing(&path(0.3, -1e4, 2e-4), 1e-15).unwrap();
        let want = (0.3 + (0.09f64 + 4.0 * 5e3 * 5e-5).sqrt()) / (2.0 * 5e3);
        assert!((t - want).abs() < 1e-14, "{t} {want}");
        let (tp, fp) = golden_peak(0.0, 2.0, |s| (s - 1.3) * (s - 1.3) - 4.0);
        assert!(
            (tp - 1.3).abs() < 1e-7 && (fp + 4.0).abs() < 1e-12,
            "{tp} {fp}"
        );
    }
}
