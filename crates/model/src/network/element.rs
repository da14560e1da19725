//! The element law (MODEL.md section 8): what a coupling of a driveline network does, said once
//! per kind for both engines. Each kind implements [`ElementLaw`] in its own file (the lumped
//! clutch and the one-way clutch in `clutch.rs`, the ideal gear in `ideal_gear.rs`, the
//! planetary set in `planetary.rs`, the gear mesh in `gear.rs`, the spring-damper in
//! `spring_damper.rs`, the resolved pack in `resolved_pack.rs`), and [`super::Coupling::law`]
//! is the one `match` on the kinds that hands it out. The engines and the layers above ask the
//! law, never the kind: its ports, its constraint row in a mode, its torque where the engines
//! share the formula, its state, its event guard and the stick/slip rule at an event, its
//! share of the energy audit, its co-simulation input and its kind's name, and what the layers
//! above show of it: the bodies it carries of its own (a resolved pack's discs and plates,
//! [`OwnBodies`]), the mode its session reports, its faces' normal force; and how a shift
//! schedule actuates it.
//!
//! What stays an engine's own is what the engines do differently: a gear mesh's contact events
//! (the law's memory, the impact peaks) and a resolved pack's session (its discs and plates),
//! which each engine builds from the kind ([`super::Coupling::mesh`],
//! [`super::Coupling::pack`]); and how an event's instant is found (the reference engine
//! locates it on its dense output, the multibody engine lands its step on it).
//!
//! Conventions: the ports are body indices in [`super::Network::bodies`], port 0 the coupling's
//! `a`, port 1 its `b` (a planetary set's port 2 its carrier); a two-port force element's
//! torque is the torque on port 0 (N m), the opposite acting on port 1; `w_rel = w_b - w_a`
//! (rad/s) as the clutch's.

use super::rows::Row;
use super::{Coupling, CouplingKind, Network, NetworkInput, NetworkProblem, Signal};
use serde::{Deserialize, Serialize};

/// The state of a friction element, a lumped clutch's (Modelica's `mode`: Free 2, Forward 1, Stuck 0, Backward -1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClutchMode {
    /// `fn <= 0`: no torque.
    Free,
    /// Slipping with `w_rel > 0` (`+1`) or `w_rel < 0` (`-1`).
    Slipping(i8),
    /// Locked: `w_rel = 0`, the torque is what holds the two bodies together.
    Locked,
}

impl ClutchMode {
    /// Modelica's integer for the mode (Free 2, Forward 1, Stuck 0, Backward -1), as in
    /// the MSL reference results' `clutchN.mode` columns.
    pub fn modelica_code(self) -> i8 {
        match self {
            ClutchMode::Free => 2,
            ClutchMode::Slipping(s) => s,
            ClutchMode::Locked => 0,
        }
    }

    /// A short name for tables: `free`, `slip+`, `slip-`, `locked`.
    pub fn label(self) -> &'static str {
        match self {
            ClutchMode::Free => "free",
            ClutchMode::Slipping(s) if s > 0 => "slip+",
            ClutchMode::Slipping(_) => "slip-",
            ClutchMode::Locked => "locked",
        }
    }
}

/// An element's mode: a clutch's [`ClutchMode`]; `None` for an element without modes.
pub type Mode = Option<ClutchMode>;

/// Where the counter an engine keeps for an element (the integral of its
/// [`ElementLaw::power_w`], J) goes in the run's energy audit
/// ([`super::NetworkEnergy`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnergyTerm {
    /// No counter (a rigid element does no work; a resolved pack books its own heat and
    /// loss in its session).
    None,
    /// A clutch's heat (`clutch_heat_j`).
    ClutchHeat,
    /// The work done on a gear mesh (`mesh_work_j`: its impact losses and the elastic energy
    /// of a contact still closed).
    MeshWork,
    /// A damper's loss (`damper_loss_j`; the spring's stored energy is
    /// [`ElementLaw::potential_change_j`]).
    DamperLoss,
}

/// How an engine found the end of a slip at an event (the input of the stick/slip rule,
/// [`super::friction::settled_mode`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlipEnd {
    /// The reference engine located the event: whether the element's guard crossed zero there
    /// (the slip is then the part of the guard that did, not its normal force).
    Located {
        /// The element's guard reached `<= 0` at the event.
        crossed: bool,
    },
    /// The multibody engine landed its step: the slip ended if it is within the engine's zero
    /// of slip (`1e-10 (1 + |w_a| + |w_b|)` rad/s).
    Landed,
}

/// A co-simulation input an element takes (the FMU's and the sdk's variable
/// `couplings.<name>.<suffix>`).
#[derive(Debug, Clone, Copy)]
pub struct InputSpec {
    /// The input of coupling `k` as the engines take it.
    pub input: fn(usize) -> NetworkInput,
    /// The last segment of its variable's name (`normal_force_n`).
    pub suffix: &'static str,
    /// Its unit as the FMU writes it (`N`, `Pa`).
    pub unit: &'static str,
    /// Its description, `{}` standing for the coupling's name.
    pub description: &'static str,
}

/// What a co-simulation output of an element gives ([`OutputSpec`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputQuantity {
    /// Its slip `w_b - w_a`, rad/s.
    Slip,
    /// Its mode as Modelica's `Clutch` numbers it ([`ClutchMode::modelica_code`]; a sample's
    /// mode `None` as free).
    Mode,
    /// Its heat since t = 0, J (the engine's `heat_j` of the coupling).
    Heat,
}

/// A co-simulation output an element gives (the variable `couplings.<name>.<suffix>`, after
/// its torque on body `a`, which every coupling gives).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputSpec {
    /// The last segment of its variable's name (`slip_rad_s`).
    pub suffix: &'static str,
    /// Its unit as the FMU writes it (`rad/s`, `1`, `J`).
    pub unit: &'static str,
    /// Its description, `{}` standing for the coupling's name.
    pub description: &'static str,
    /// What it gives.
    pub quantity: OutputQuantity,
}

/// The bodies an element carries of its own besides its ports, each engine's to integrate with
/// their tooth contacts (a resolved pack's friction discs, splined to port 0, and its
/// separator plates, splined to port 1): what the layers above name, count, draw, record and
/// summarise of them ([`ElementLaw::own_bodies`]). Indices run over the discs, then the plates,
/// as the engines number them.
#[derive(Debug, Clone, Copy)]
pub struct OwnBodies<'a> {
    /// The bodies on port 0 (friction discs), in order.
    pub discs: &'a [crate::DiscModel],
    /// The bodies on port 1 (separator plates), in order.
    pub plates: &'a [crate::DiscModel],
    /// Whether they are clamped in a stack (plate, disc, ..., plate along the axis).
    pub stacked: bool,
}

impl<'a> OwnBodies<'a> {
    /// How many: discs and plates.
    pub fn len(&self) -> usize {
        self.discs.len() + self.plates.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every body, the discs then the plates.
    pub fn iter(&self) -> impl Iterator<Item = &'a crate::DiscModel> {
        self.discs.iter().chain(self.plates)
    }

    /// Their names, in [`Self::iter`]'s order.
    pub fn names(&self) -> Vec<String> {
        self.iter().map(|d| d.name.clone()).collect()
    }

    /// The list body `i` is in, as outputs name it: `discs` or `plates`.
    pub fn role(&self, i: usize) -> &'static str {
        if i < self.discs.len() {
            "discs"
        } else {
            "plates"
        }
    }

    /// Body `i`'s level along the axis from the bottom (0, 1, ...): its place in the stack
    /// when they are stacked ([`crate::StackBody::position`]), else its index.
    pub fn level(&self, i: usize) -> usize {
        if !self.stacked {
            return i;
        }
        let nd = self.discs.len();
        let body = if i < nd {
            crate::StackBody::Disc(i)
        } else {
            crate::StackBody::Plate(i - nd)
        };
        body.position()
    }
}

/// The most ports an element has (a planetary set's sun, ring and carrier).
pub const MAX_PORTS: usize = 3;

/// An element's ports: the bodies it joins, by index in [`super::Network::bodies`] (2, or 3
/// for a planetary set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ports {
    ids: [usize; MAX_PORTS],
    len: usize,
}

impl Ports {
    /// The two ports `a`, `b`.
    pub fn two(a: usize, b: usize) -> Ports {
        Ports {
            ids: [a, b, 0],
            len: 2,
        }
    }

    /// The three ports `a`, `b`, `c`.
    pub fn three(a: usize, b: usize, c: usize) -> Ports {
        Ports {
            ids: [a, b, c],
            len: 3,
        }
    }
}

impl std::ops::Deref for Ports {
    type Target = [usize];
    fn deref(&self) -> &[usize] {
        &self.ids[..self.len]
    }
}

/// What one kind of element is, for both engines and every layer above (the module's docs).
/// Every method but [`Self::kind_name`] has the default of an element that does not have the
/// behaviour (no row, no torque, no state, no modes, no energy, no input).
pub trait ElementLaw {
    /// The kind's name in outputs and recordings (`clutch`, `one_way_clutch`, `ideal_gear`,
    /// `planetary`, `gear_mesh`, `spring_damper`, `pack`).
    fn kind_name(&self) -> &'static str;

    /// The element's ports (body indices) for the coupling's `a` and `b`: two, unless the
    /// element names a third body itself (a planetary set's carrier).
    fn ports(&self, a: usize, b: usize) -> Ports {
        Ports::two(a, b)
    }

    /// Its mode at t = 0, before the first settling (`Some(Free)` for a clutch; `None`: an
    /// element without modes).
    fn initial_mode(&self) -> Mode {
        None
    }

    /// Its constraint row as coupling `k` on the ports `ports` in the mode `mode`, when it is
    /// rigid there (MODEL.md section 8, [`super::rows`]): an ideal gear and a planetary set
    /// always, a clutch when locked; `None` for a force element.
    fn row(&self, _k: usize, _ports: &[usize], _mode: Mode) -> Option<Row> {
        None
    }

    /// The torque it puts on each of its ports per unit of its torque on port 0 (the samples'
    /// `torque_n_m`), by port (1 on port 0): a clutch's and a spring-damper's `-1` on port 1,
    /// an ideal gear's `-ratio`, a planetary set's ring and carrier coefficients over its
    /// sun's; `None` where its torque on port 0 does not give the others (a gear mesh's
    /// radii and contacts, a resolved pack's other side).
    fn torque_factors(&self, _ports: &[usize]) -> Option<[f64; MAX_PORTS]> {
        None
    }

    /// The `ratio` of a rigid two-port that always ties `w_a = ratio w_b` (an ideal gear), for
    /// the network's check of loops of such ties.
    fn fixed_ratio(&self) -> Option<f64> {
        None
    }

    /// A two-port force element's torque on port 0 at `t` (s) in the mode `mode`, N m (the
    /// opposite on port 1), at the twist `twist_rad` (`theta_a - theta_b`, rad: the engine's
    /// own state of it) and the speeds `w_a`, `w_b` (rad/s); `None` when it applies none
    /// that the engines share (a rigid element, a free or locked clutch, a gear mesh whose
    /// contacts are the engine's).
    fn port_torque_n_m(
        &self,
        _t_s: f64,
        _twist_rad: f64,
        _w_a_rad_s: f64,
        _w_b_rad_s: f64,
        _mode: Mode,
    ) -> Option<f64> {
        None
    }

    /// The scale of its own state (a spring's twist, rad; a mesh's displacement along its
    /// line of action, m): the adaptive engine's absolute tolerance is the tolerance times
    /// it. `None`: no state.
    fn state_scale(&self) -> Option<f64> {
        None
    }

    /// Its state at t = 0 (in the unit of [`Self::state_scale`]).
    fn initial_state(&self) -> f64 {
        0.0
    }

    /// Its state's rate at the ports' speeds `w_a`, `w_b` (rad/s).
    fn state_rate(&self, _w_a_rad_s: f64, _w_b_rad_s: f64) -> f64 {
        0.0
    }

    /// Where its counter goes in the energy audit.
    fn energy_term(&self) -> EnergyTerm {
        EnergyTerm::None
    }

    /// The power it takes from the bodies in the mode `mode`, W, under its torque
    /// `torque_n_m` on port 0 at the speeds `w_a`, `w_b` (rad/s): a slipping clutch's heat
    /// rate `tau (w_b - w_a)`, a damper's loss `d (w_a - w_b)^2`; `None` when the engine books
    /// it itself (a mesh's contact work) or there is none.
    fn power_w(&self, _mode: Mode, _torque_n_m: f64, _w_a: f64, _w_b: f64) -> Option<f64> {
        None
    }

    /// The loss over a step of `h` s (J) of the torque held over it, taken at the relative
    /// speed `w_rel_held` (`w_a - w_b`, rad/s), on the step's mean relative speed `w_rel_mean`
    /// (rad/s): a damper's `h d w_rel_held w_rel_mean` (the multibody engine's discrete energy
    /// identity); `None` for an element without a damper.
    fn damping_loss_j(&self, _h_s: f64, _w_rel_held: f64, _w_rel_mean: f64) -> Option<f64> {
        None
    }

    /// The change of its stored energy from a twist of 0 to `twist_rad` (rad), J; `None`: it
    /// stores none.
    fn potential_change_j(&self, _twist_rad: f64) -> Option<f64> {
        None
    }

    /// Every instant (s) where its own signal jumps or bends, pushed to `out` (the engines
    /// land a step on each).
    fn breakpoints(&self, _out: &mut Vec<f64>) {}

    /// Whether its actuation is on at `t` (s): a clutch's normal force above 0; `None`: it has
    /// none.
    fn engaged(&self, _t_s: f64) -> Option<bool> {
        None
    }

    /// The sense `s` (+1, -1) in the mode `mode` whose slip `s w_rel` reaching zero is an event
    /// (a slipping clutch's, a free one-way clutch's freewheel); `None`: none.
    fn slip_sense(&self, _mode: Mode) -> Option<i8> {
        None
    }

    /// Its event function at `t` (s) in the mode `mode` at the slip `w_rel` (rad/s) under the
    /// torque `held_n_m` (N m on port 0) that holds it when locked: positive while the mode
    /// holds, its crossing of zero an event (the reference engine's guard; 1 for an element
    /// without events of its own).
    fn guard(&self, _t_s: f64, _w_rel_rad_s: f64, _mode: Mode, _held_n_m: f64) -> f64 {
        1.0
    }

    /// The mode it enters at an event at `t` (s) from `before`, at the speeds `w_a`, `w_b`
    /// (rad/s), the slip's end found as `end` (the stick/slip rule,
    /// [`super::friction::settled_mode`]); an element without modes keeps `before`.
    fn settle(&self, _t_s: f64, before: Mode, _w_a: f64, _w_b: f64, _end: SlipEnd) -> Mode {
        before
    }

    /// How far the locked element is from breaking at `t` (s) under the torque `held_n_m` (N
    /// m on port 0) that holds it, N m (it breaks where this reaches 0); `None`: it does not
    /// break (a rigid gear).
    fn locked_margin_n_m(&self, _t_s: f64, _held_n_m: f64) -> Option<f64> {
        None
    }

    /// The mode a locked element that broke at `t` (s) under `held_n_m` (N m on port 0) is
    /// released to.
    fn released_mode(&self, _t_s: f64, _held_n_m: f64) -> Mode {
        None
    }

    /// Its parameters' problems and those it has in the network `net` as coupling `k` on the
    /// ports `ports` (all in the network), pushed to `out`; whether the element is sound
    /// enough for the network's checks of its rigid ties (an ideal gear with a good ratio
    /// between two turning bodies).
    fn problems(
        &self,
        _net: &Network,
        _k: usize,
        _ports: &[usize],
        _out: &mut Vec<NetworkProblem>,
    ) -> bool {
        true
    }

    /// The co-simulation input it takes, if any.
    fn input(&self) -> Option<InputSpec> {
        None
    }

    /// The value of its co-simulation input at `t` (s), in the input's unit.
    fn input_value(&self, _t_s: f64) -> f64 {
        0.0
    }

    /// The co-simulation outputs it gives besides its torque, in order.
    fn outputs(&self) -> &'static [OutputSpec] {
        &[]
    }

    /// This element as a shift schedule's normalized force `level` (0 open, 1 closed: what
    /// [`super::Transmission::schedule`] gives each element a gear closes) actuates it, as its
    /// coupling's new kind: a clutch's normal force follows the level (`fn_max` scales it), a
    /// stacked pack's piston pressure is the level times the pack's rated pressure
    /// ([`super::gears::pack_pressure`]); `Ok(None)` when the schedule leaves it as it is (an
    /// element no schedule actuates, a level of a kind it cannot follow); `Err` with its field
    /// and what is wrong (said of the element, after its name) when it cannot be actuated.
    fn scheduled(&self, _level: &Signal) -> Result<Option<CouplingKind>, (&'static str, String)> {
        Ok(None)
    }

    /// The bodies it carries of its own ([`OwnBodies`]: a resolved pack's discs and plates);
    /// `None` for an element that carries none.
    fn own_bodies(&self) -> Option<OwnBodies<'_>> {
        None
    }

    /// The mode at t = 0 of faces whose modes its own session reports rather than the
    /// engines' network equations (a resolved pack's faces: `Some(Free)`; their changes then
    /// come through [`crate::Observer::pack_faces`]), for the layers that follow
    /// modes (the recording's colours, an automatic's gear and shifts); `None` when its mode,
    /// if any, is the samples' ([`Self::initial_mode`]).
    fn session_mode(&self) -> Mode {
        None
    }

    /// The normal force on its friction faces at `t` (s), N, as the recording's coupling
    /// state carries it (a lumped clutch's `fn(t)`, as its signal gives it); `None` for an
    /// element without one there (the recording writes 0; a resolved pack's clamp forces are
    /// its session's).
    fn clamp_force_n(&self, _t_s: f64) -> Option<f64> {
        None
    }
}

/// A coupling's problem at its field `field`.
pub(super) fn problem(k: usize, field: &'static str, message: String) -> NetworkProblem {
    NetworkProblem::Coupling {
        index: k,
        field,
        message,
    }
}

impl Coupling {
    /// Its ports (body indices; [`ElementLaw::ports`]).
    pub fn ports(&self) -> Ports {
        self.law().ports(self.a, self.b)
    }

    /// Its constraint row as coupling `k` when it is rigid in the mode `mode`
    /// ([`ElementLaw::row`]): the one place that says which couplings are rigid, for both
    /// engines.
    pub fn row(&self, k: usize, mode: Mode) -> Option<Row> {
        self.law().row(k, &self.ports(), mode)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::{CouplingKind, LumpedClutch, PlanetarySet, Signal};
    use crate::spring::SpringDamper;

    fn clutch(one_way: bool) -> LumpedClutch {
        LumpedClutch {
            mu_table: vec![(0.0, 0.5)],
            peak: 1.1,
            cgeo_m: 1.0,
            fn_max_n: 20.0,
            force: Signal::Constant(0.5),
            one_way,
        }
    }

    fn spring() -> SpringDamper {
        SpringDamper {
            stiffness_n_m_per_rad: 400.0,
            damping_n_m_s_per_rad: 2.0,
            free_angle_rad: 0.1,
        }
    }

    fn planetary(double_pinion: bool) -> PlanetarySet {
        PlanetarySet {
            sun_teeth: 30,
            ring_teeth: 90,
            carrier: 2,
            double_pinion,
        }
    }

    /// One of every kind (the one-way clutch apart): each names itself, and no two the same
    /// (the summary's and the recording's `kind`).
    #[test]
    fn every_kind_has_its_own_name() {
        let kinds = [
            CouplingKind::Clutch(clutch(false)),
            CouplingKind::Clutch(clutch(true)),
            CouplingKind::ideal_gear(3.0),
            CouplingKind::GearMesh(crate::cases::dry_gear_mesh(false)),
            CouplingKind::SpringDamper(spring()),
            CouplingKind::Pack(Box::new(crate::cases::paper_pack(1e-5))),
            CouplingKind::Planetary(planetary(false)),
        ];
        let names: Vec<&str> = kinds.iter().map(|k| k.law().kind_name()).collect();
        assert_eq!(
            names,
            [
                "clutch",
                "one_way_clutch",
                "ideal_gear",
                "gear_mesh",
                "spring_damper",
                "pack",
                "planetary"
            ]
        );
    }

    /// A planetary set's ports are its sun, ring and carrier; its row is Willis' equation on
    /// them, and its torque factors do no work on any speeds that keep the row (the ideal
    /// set's power balance `sum_j f_j w_j = 0`, measured 0 to rounding: asserted 1e-12 of
    /// the speeds' scale), for a simple and a double-pinion set.
    #[test]
    fn planetary_ports_row_and_factors_agree() {
        for double_pinion in [false, true] {
            let p = planetary(double_pinion);
            let ports = p.ports(0, 1);
            assert_eq!(&*ports, &[0, 1, 2]);
            let row = ElementLaw::row(&p, 7, &ports, None).expect("always rigid");
            assert_eq!(row.coupling, 7);
            let (ws, wr) = (400.0, -120.0);
            let w = [ws, wr, p.carrier_speed_rad_s(ws, wr)];
            assert!(row.apply(&w).abs() < 1e-12 * 400.0, "{double_pinion}");
            let f = p.torque_factors(&ports).expect("rigid");
            assert_eq!(f[0], 1.0);
            let power: f64 = f.iter().zip(&w).map(|(f, w)| f * w).sum();
            assert!(power.abs() < 1e-12 * 400.0, "{double_pinion}: {power}");
        }
    }

    /// The force torques are the laws': a slipping clutch's `sign(w_rel) mu cgeo fn` on `a`,
    /// none when it is locked or free (a locked one is a row, `w_a - w_b = 0`); a
    /// spring-damper's `-T` on `a` at the twist given; an ideal gear a row `w_a - ratio w_b`.
    #[test]
    fn force_torques_and_rows_are_the_laws() {
        let c = clutch(false);
        let slip = c.port_torque_n_m(0.0, 0.0, 10.0, 4.0, Some(ClutchMode::Slipping(-1)));
        assert_eq!(slip, Some(-5.0));
        assert_eq!(
            c.port_torque_n_m(0.0, 0.0, 1.0, 1.0, Some(ClutchMode::Locked)),
            None
        );
        let locked = c.row(3, &[4, 5], Some(ClutchMode::Locked)).expect("a row");
        assert_eq!(locked.terms(), &[(4, 1.0), (5, -1.0)]);
        assert!(c.row(3, &[4, 5], Some(ClutchMode::Free)).is_none());
        let s = spring();
        let t = s
            .port_torque_n_m(0.0, 0.3, 5.0, 2.0, None)
            .expect("a torque");
        assert_eq!(t, -(400.0 * (0.3 - 0.1) + 2.0 * 3.0));
        assert_eq!(s.energy_term(), EnergyTerm::DamperLoss);
        let g = super::super::IdealGear { ratio: 3.5 };
        let row = g.row(0, &[1, 2], None).expect("always rigid");
        assert_eq!(row.terms(), &[(1, 1.0), (2, -3.5)]);
        assert_eq!(g.torque_factors(&[1, 2]), Some([1.0, -3.5, 0.0]));
    }

    /// What the layers above (recorder, sdk, CLI) ask through the law instead of the kind: a
    /// resolved pack carries its discs then its plates (the 3-disc brake's 3 and 4, named as
    /// the pack names them, stacked plate, disc, ..., plate: levels 1, 3, 5 and 0, 2, 4, 6),
    /// its faces start free in its session, and it has no lumped normal force; a clutch carries
    /// no bodies, its mode is the samples' and its normal force its signal's (0.5 of 20 N);
    /// a spring-damper has none of these.
    #[test]
    fn own_bodies_session_mode_and_clamp_force_are_the_kinds() {
        let pack = crate::cases::staggered_brake(3);
        let own = pack
            .own_bodies()
            .expect("a pack carries its discs and plates");
        assert_eq!((own.discs.len(), own.plates.len(), own.len()), (3, 4, 7));
        assert_eq!(own.names(), pack.body_names());
        let roles: Vec<&str> = (0..own.len()).map(|i| own.role(i)).collect();
        assert_eq!(
            roles,
            ["discs", "discs", "discs", "plates", "plates", "plates", "plates"]
        );
        let levels: Vec<usize> = (0..own.len()).map(|i| own.level(i)).collect();
        assert_eq!(levels, [1, 3, 5, 0, 2, 4, 6]);
        let loose = OwnBodies {
            stacked: false,
            ..own
        };
        assert_eq!(loose.level(4), 4);
        assert_eq!(pack.session_mode(), Some(ClutchMode::Free));
        assert_eq!(pack.initial_mode(), None);
        assert_eq!(pack.clamp_force_n(0.0), None);
        let c = clutch(false);
        assert!(c.own_bodies().is_none());
        assert_eq!(c.session_mode(), None);
        assert_eq!(c.clamp_force_n(0.0), Some(10.0));
        let s = spring();
        assert!(s.own_bodies().is_none() && s.session_mode().is_none());
        assert_eq!(s.clamp_force_n(0.0), None);
    }

    /// A schedule's level actuates each kind as its law says: a clutch's normal force follows
    /// it (0.25 of 20 N: 5 N), a stacked pack's pressure is it times the rated pressure (0.5
    /// of 2e5 Pa: 1e5 Pa), a released pack (rated 0 Pa) is refused at its `pack`, a pack
    /// without a stack and a spring-damper are left as they are.
    #[test]
    fn a_schedule_actuates_each_kind_through_its_law() {
        let level = Signal::Constant(0.25);
        let Ok(Some(CouplingKind::Clutch(c))) = clutch(false).scheduled(&level) else {
            panic!("a clutch takes the level");
        };
        assert_eq!(c.normal_force_n(1.0), 5.0);
        let mut pack = crate::cases::staggered_brake(3);
        let Err((field, why)) = pack.scheduled(&level) else {
            panic!("a released pack has no rated pressure");
        };
        assert_eq!(field, "pack");
        assert!(why.contains("rated pressure"), "{why}");
        let stack = pack.stack.as_mut().expect("stacked");
        stack.piston.pressure = crate::PressureProfile::Constant { pressure_pa: 2e5 };
        let Ok(Some(CouplingKind::Pack(p))) = pack.scheduled(&Signal::Constant(0.5)) else {
            panic!("a stacked pack takes the level");
        };
        let s = p.stack.as_ref().expect("stacked");
        assert_eq!(s.piston.pressure.pressure_pa(1.0), 1e5);
        pack.stack = None;
        assert!(matches!(pack.scheduled(&level), Ok(None)));
        assert!(matches!(spring().scheduled(&level), Ok(None)));
    }

    /// The two engines find a slip's end differently and the rule says how: a slipping clutch
    /// whose slip is within the engine's zero (1e-12 rad/s against a scale of 1e-10) locks
    /// when the multibody engine landed there, but stays slipping for the reference engine
    /// unless its guard crossed (it locates the zero as an event instead).
    #[test]
    fn a_slips_end_is_the_engines_own_finding() {
        let c = clutch(false);
        let before = Some(ClutchMode::Slipping(1));
        let (wa, wb) = (0.0, 1e-12);
        assert_eq!(
            c.settle(0.0, before, wa, wb, SlipEnd::Landed),
            Some(ClutchMode::Locked)
        );
        let located = |crossed| c.settle(0.0, before, wa, wb, SlipEnd::Located { crossed });
        assert_eq!(located(false), Some(ClutchMode::Slipping(1)));
        assert_eq!(located(true), Some(ClutchMode::Locked));
        // an element without modes keeps its (absent) mode
        assert_eq!(spring().settle(0.0, None, wa, wb, SlipEnd::Landed), None);
    }
}
