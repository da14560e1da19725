//! The gears of an automatic transmission from its topology alone (MODEL.md section 10): a
//! gear is the set of shift elements (clutches and brakes among the couplings) that are closed;
//! with their rows and the rows that always hold (ideal gears, planetary sets), the speeds the
//! rows allow are the null space of `C` (the fixed bodies held). In a gear the input's group
//! must keep exactly one degree of freedom, the output turning in it: every member's speed per
//! unit input speed follows, the ratio `w_in / w_out`, and the slip `w_b - w_a` of every open
//! element (its drag depends on it).
//!
//! A **shift schedule** (section 10's phases) is compiled here into each element's normalized
//! force: before the first shift the elements of the initial gear are closed (force 1), the
//! others open (0); a shift at `t0` from gear G to gear H opens the one element of G not in H
//! (the off-going) and closes the one of H not in G (the on-coming), the others holding:
//! - **fill** `[t0, t0 + t_f]`: the on-coming rises from 0 to its fill level (the kiss point);
//! - **torque phase** `[.., + t_t]`: the off-going falls from 1 to 0 while the on-coming rises
//!   to its torque-phase level (it takes over the torque);
//! - **inertia phase** `[.., + t_i]`: the on-coming rises to 1 (it pulls the input down to
//!   the new gear's speed and locks when its slip reaches zero).
//!
//! Each profile is linear between these instants (a [`Signal::Table`]), its corners
//! breakpoints the engines land on.
//!
//! A shift element is a lumped clutch (the signal is its normalized force) or a resolved pack
//! (its discs and plates on their splines): the pack's piston pressure is then the signal times
//! the pack's **rated pressure**, the largest pressure of its own pack file's profile
//! ([`rated_pressure_pa`], [`pack_pressure`]), the schedule replacing the profile's shape.
//!
//! The null space is taken from the projector `P = I - C^T (C C^T)^+ C` on the moving bodies
//! ([`super::rows::projected`] with unit inertias): rank one on the input's group means one
//! degree of freedom, and its column at the input is the speeds per unit input.

use super::rows::{self, Row};
use super::{ClutchMode, Network, Signal};
use crate::clutch::PressureProfile;
use serde::{Deserialize, Serialize};

/// One gear: the elements closed in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gear {
    /// Its name (`"1"`, `"R"`, ...).
    pub name: String,
    /// The couplings (indices in [`Network::couplings`], each a clutch or a brake) closed in it.
    pub closed: Vec<usize>,
}

/// Each shift element's normalized force over a schedule: `(coupling index, signal)`.
pub type ElementForces = Vec<(usize, Signal)>;

/// One shift of a schedule (the module's docs): when it starts, the gear it reaches and its
/// phases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Shift {
    /// Its start `t0`, s.
    pub at_s: f64,
    /// The gear it reaches (index in [`Transmission::gears`]).
    pub to: usize,
    /// The on-coming element's fill, s (> 0).
    pub fill_s: f64,
    /// The on-coming element's normalized force at the end of the fill (0..1).
    pub fill_level: f64,
    /// The torque phase, s (> 0).
    pub torque_phase_s: f64,
    /// The on-coming element's normalized force at the end of the torque phase (0..1).
    pub torque_level: f64,
    /// The inertia phase, s (> 0).
    pub inertia_phase_s: f64,
}

impl Shift {
    /// Its end, s: `t0 + t_f + t_t + t_i`.
    pub fn end_s(&self) -> f64 {
        self.at_s + self.fill_s + self.torque_phase_s + self.inertia_phase_s
    }
}

/// An automatic transmission on a network: its input and output bodies, its gears and,
/// optionally, a shift schedule from an initial gear.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Transmission {
    /// The input body (index in [`Network::bodies`]).
    pub input: usize,
    /// The output body.
    pub output: usize,
    /// The gears, in the order given.
    pub gears: Vec<Gear>,
    /// The gear engaged at t = 0 (index in [`Self::gears`]); with it the schedule sets every
    /// element's force ([`Self::schedule`]). `None`: the elements' own force signals.
    #[serde(default)]
    pub initial_gear: Option<usize>,
    /// The shifts, in time order, each starting after the one before has ended.
    #[serde(default)]
    pub shifts: Vec<Shift>,
}

/// A gear's kinematics.
#[derive(Debug, Clone, PartialEq)]
pub struct GearKinematics {
    /// `w_in / w_out` (dimensionless; negative: the output turns backwards, a reverse gear).
    pub ratio: f64,
    /// Every body's speed per unit input speed (0 for a body that does not turn with the
    /// input, and for the fixed bodies).
    pub speeds_per_input: Vec<f64>,
    /// Each shift element open in this gear with its slip `w_b - w_a` per unit input speed:
    /// `(coupling index, slip)`.
    pub open_slips: Vec<(usize, f64)>,
}

/// The torque coupling `c` puts on body `body` per unit of its torque on its body `a` (the
/// samples' `torque_n_m`): 1 on `a`; on `b` -1 for a clutch, `-ratio` for an ideal gear, the
/// ring's and the carrier's coefficients over the sun's for a planetary set, -1 for a
/// spring-damper; 0 for a body it does not touch; `None` where the torque on `a` does not
/// give it (a gear mesh's, a resolved pack's other side).
pub fn torque_factor(c: &super::Coupling, body: usize) -> Option<f64> {
    let ports = c.ports();
    let Some(j) = ports.iter().position(|&p| p == body) else {
        return Some(0.0);
    };
    if j == 0 {
        return Some(1.0);
    }
    c.law().torque_factors(&ports).map(|f| f[j])
}

/// The constraint row of coupling `c` (index `k`) in a gear that closes it (`closed`) or
/// leaves it open: a clutch's or the gear sets' rows as [`super::Coupling::row`] gives them, and
/// a resolved pack closed in the gear as a locked clutch (its discs and plates turning with
/// each other, `w_a - w_b = 0`), so that a gear's kinematics does not depend on whether its
/// shift elements are lumped or resolved.
pub fn element_row(c: &super::Coupling, k: usize, closed: bool) -> Option<Row> {
    match c.kind {
        super::CouplingKind::Pack(_) if closed => Some(Row::two(k, (c.a, 1.0), (c.b, -1.0))),
        _ => c.row(k, closed.then_some(ClutchMode::Locked)),
    }
}

/// A pack's rated pressure (Pa): the largest pressure of `profile` (a constant's, a ramp's
/// final, a table's largest row), which a schedule's normalized level 1 stands for.
pub fn rated_pressure_pa(profile: &PressureProfile) -> f64 {
    match profile {
        PressureProfile::Constant { pressure_pa } | PressureProfile::Ramp { pressure_pa, .. } => {
            *pressure_pa
        }
        PressureProfile::Table(t) => t.y.iter().copied().fold(0.0, f64::max),
    }
}

/// The piston pressure (Pa) of a resolved pack that a schedule's normalized force `signal`
/// (0..1, a constant or a table: what [`Transmission::schedule`] gives) sets, with the pack's
/// rated pressure `rated_pa` (Pa): `p(t) = signal(t) rated_pa`, with the signal's breakpoints.
/// `None` for a signal of another kind.
pub fn pack_pressure(signal: &Signal, rated_pa: f64) -> Option<PressureProfile> {
    match signal {
        Signal::Constant(level) => Some(PressureProfile::Constant {
            pressure_pa: level * rated_pa,
        }),
        Signal::Table(t) => {
            let y = t.y.iter().map(|level| level * rated_pa).collect();
            let table = crate::drive::Table::new(t.t_s.clone(), y).ok()?;
            Some(PressureProfile::Table(table))
        }
        _ => None,
    }
}

/// One shift's hand-over: the off-going and on-coming elements (coupling indices) and its
/// phases' corners `t0 <= t1 <= t2 <= t3` (s: start, fill's end, torque phase's end, inertia
/// phase's end), and the gears it goes from and to (indices in [`Transmission::gears`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handover {
    /// The gear engaged before it.
    pub from: usize,
    /// The gear it reaches.
    pub to: usize,
    /// The element it opens.
    pub off_going: usize,
    /// The element it closes.
    pub on_coming: usize,
    /// `[t0, t1, t2, t3]`, s.
    pub corners_s: [f64; 4],
}

impl Transmission {
    /// The gear engaged (index in [`Self::gears`]) with the shift elements' modes `modes` (by
    /// coupling; a resolved pack's its faces', all locked: locked), if one is: the first gear
    /// whose every closed element is locked.
    pub fn engaged(&self, modes: &[Option<super::ClutchMode>]) -> Option<usize> {
        let locked = |k: usize| modes.get(k).copied().flatten() == Some(super::ClutchMode::Locked);
        self.gears
            .iter()
            .position(|g| g.closed.iter().all(|&k| locked(k)))
    }

    /// Each shift's hand-over, in order, or the index of the first shift that is not a
    /// clutch-to-clutch shift from the gear engaged before it, with the reason; `None` without
    /// an initial gear.
    pub fn handovers(&self) -> Option<Result<Vec<Handover>, (usize, String)>> {
        let mut gear = self.initial_gear?;
        let mut out = Vec::new();
        let mut free_from = 0.0;
        for (i, sh) in self.shifts.iter().enumerate() {
            let (from, to) = (&self.gears[gear], &self.gears[sh.to]);
            if sh.to == gear {
                return Some(Err((
                    i,
                    format!("gear \"{}\" is already engaged then", to.name),
                )));
            }
            if sh.at_s < free_from {
                return Some(Err((
                    i,
                    format!(
                        "starts at {} s, before the shift before it ends ({free_from} s)",
                        sh.at_s
                    ),
                )));
            }
            let off: Vec<usize> = from
                .closed
                .iter()
                .copied()
                .filter(|k| !to.closed.contains(k))
                .collect();
            let on: Vec<usize> = to
                .closed
                .iter()
                .copied()
                .filter(|k| !from.closed.contains(k))
                .collect();
            if off.len() != 1 || on.len() != 1 {
                return Some(Err((
                    i,
                    format!(
                        "from gear \"{}\" to \"{}\" opens {} and closes {} elements: a shift hands over from one element to one other (shift through the gears between)",
                        from.name,
                        to.name,
                        off.len(),
                        on.len()
                    ),
                )));
            }
            let t1 = sh.at_s + sh.fill_s;
            let t2 = t1 + sh.torque_phase_s;
            let t3 = t2 + sh.inertia_phase_s;
            out.push(Handover {
                from: gear,
                to: sh.to,
                off_going: off[0],
                on_coming: on[0],
                corners_s: [sh.at_s, t1, t2, t3],
            });
            gear = sh.to;
            free_from = t3;
        }
        Some(Ok(out))
    }

    /// Each element's normalized force over the schedule (the module's docs):
    /// `(coupling index, signal)` for every element, or the index of the first shift that is
    /// not a clutch-to-clutch shift from the gear engaged before it, with the reason. `None`
    /// without an initial gear.
    pub fn schedule(&self) -> Option<Result<ElementForces, (usize, String)>> {
        let gear = self.initial_gear?;
        let handovers = match self.handovers()? {
            Ok(h) => h,
            Err(e) => return Some(Err(e)),
        };
        let elements = self.elements();
        // each element's corners (t, force)
        let mut knots: Vec<Vec<(f64, f64)>> = elements
            .iter()
            .map(|k| {
                vec![(
                    0.0,
                    f64::from(u8::from(self.gears[gear].closed.contains(k))),
                )]
            })
            .collect();
        for (h, sh) in handovers.iter().zip(&self.shifts) {
            let [t0, t1, t2, t3] = h.corners_s;
            for (e, k) in elements.iter().enumerate() {
                let corners: &[(f64, f64)] = if *k == h.off_going {
                    &[(t1, 1.0), (t2, 0.0)]
                } else if *k == h.on_coming {
                    &[
                        (t0, 0.0),
                        (t1, sh.fill_level),
                        (t2, sh.torque_level),
                        (t3, 1.0),
                    ]
                } else {
                    &[]
                };
                for &(t, y) in corners {
                    // a corner at the instant of the one before replaces it (a shift at 0 s)
                    match knots[e].last_mut() {
                        Some(last) if last.0 >= t => last.1 = y,
                        _ => knots[e].push((t, y)),
                    }
                }
            }
        }
        let mut signals = Vec::new();
        for (k, path) in elements.iter().zip(knots) {
            let signal = if path.len() == 1 {
                Signal::Constant(path[0].1)
            } else {
                let (t, y): (Vec<f64>, Vec<f64>) = path.into_iter().unzip();
                match crate::drive::Table::new(t, y) {
                    Ok(table) => Signal::Table(table),
                    Err(e) => {
                        let last = self.shifts.len().saturating_sub(1);
                        return Some(Err((
                            last,
                            format!("its phases give no force profile: {e}"),
                        )));
                    }
                }
            };
            signals.push((*k, signal));
        }
        Some(Ok(signals))
    }

    /// Every body's speed at t = 0 (rad/s) with the initial gear engaged and the input at
    /// `w_in` (rad/s): the input's group at the gear's speeds per unit input, the other bodies
    /// at `others` (their own). `None` without an initial gear or when it is no gear.
    pub fn initial_speeds_rad_s(
        &self,
        net: &Network,
        w_in: f64,
        others: &[f64],
    ) -> Option<Vec<f64>> {
        let k = self.kinematics(net, self.initial_gear?).ok()?;
        let moving: Vec<bool> = net.bodies.iter().map(|b| !b.is_fixed()).collect();
        let rows: Vec<Row> = net
            .couplings
            .iter()
            .enumerate()
            .filter_map(|(c, cp)| {
                let closed = self.gears[self.initial_gear?].closed.contains(&c);
                element_row(cp, c, closed)
            })
            .collect();
        let of = rows::groups(&rows, &moving);
        Some(
            (0..net.bodies.len())
                .map(|i| {
                    if of[i] == of[self.input] {
                        k.speeds_per_input[i] * w_in
                    } else {
                        others[i]
                    }
                })
                .collect(),
        )
    }

    /// The shift elements: every coupling closed in some gear, in the couplings' order.
    pub fn elements(&self) -> Vec<usize> {
        let mut out: Vec<usize> = self.gears.iter().flat_map(|g| g.closed.clone()).collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The kinematics of gear `gear` (index in [`Self::gears`]) on `net`, or why it has none
    /// (the message names the element or the bodies at fault).
    pub fn kinematics(&self, net: &Network, gear: usize) -> Result<GearKinematics, String> {
        let g = &self.gears[gear];
        let n = net.bodies.len();
        let rows: Vec<Row> = net
            .couplings
            .iter()
            .enumerate()
            .filter_map(|(k, c)| element_row(c, k, g.closed.contains(&k)))
            .collect();
        // a prescribed body moves as a free one here: its speed is imposed but not zero, and
        // the ratio is the kinematics of the closed elements whatever drives them (a rig's
        // motor at the input, a dynamometer at the output); held as the fixed body's, a
        // prescribed input would read as held still
        let inv: Vec<f64> = net
            .bodies
            .iter()
            .map(|b| if b.is_fixed() { 0.0 } else { 1.0 })
            .collect();
        if let Some(r) = rows::redundant(&rows, &inv).first() {
            return Err(format!(
                "over-constrains the transmission: \"{}\" ties members the elements and gear sets before it already tie",
                net.couplings[rows[*r].coupling].name
            ));
        }
        let (p, _) = rows::projected(&rows, &inv);
        let (i, o) = (self.input, self.output);
        let pin = p[i * n + i];
        if pin <= 1e-12 {
            return Err(format!(
                "holds the input \"{}\" still: its elements lock the transmission",
                net.bodies[i].name
            ));
        }
        let moving: Vec<bool> = net.bodies.iter().map(|b| !b.is_fixed()).collect();
        let of = rows::groups(&rows, &moving);
        let members: Vec<usize> = (0..n).filter(|&j| of[j] == of[i]).collect();
        let v: Vec<f64> = (0..n).map(|j| p[j * n + i] / pin).collect();
        // one degree of freedom: P = v v^T P_in,in on the input's group
        let one = members.iter().all(|&a| {
            members
                .iter()
                .all(|&b| (p[a * n + b] - v[a] * v[b] * pin).abs() <= 1e-9 * (1.0 + pin))
        });
        if !one {
            return Err(format!(
                "leaves the input \"{}\" more than one degree of freedom: close more elements (or fewer gear sets turn freely)",
                net.bodies[i].name
            ));
        }
        if of[o] != of[i] || v[o].abs() <= 1e-12 {
            return Err(format!(
                "the output \"{}\" does not turn with the input \"{}\"",
                net.bodies[o].name, net.bodies[i].name
            ));
        }
        let open_slips = self
            .elements()
            .into_iter()
            .filter(|k| !g.closed.contains(k))
            .map(|k| {
                let c = &net.couplings[k];
                (k, v[c.b] - v[c.a])
            })
            .collect();
        Ok(GearKinematics {
            ratio: 1.0 / v[o],
            speeds_per_input: v,
            open_slips,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::cases::eight_speed;

    /// The 8HP's nine gears from its topology alone: each ratio is the published exact
    /// fraction (MODEL.md section 10) to 1e-12 relative (measured: 4e-15 and below, the
    /// elimination's rounding); in 6th every member turns with the input; in 1st the open
    /// elements D and E slip.
    #[test]
    fn eight_speed_ratios_are_the_exact_fractions() {
        let (net, tr) = eight_speed();
        let want = [
            -1744.0 / 529.0,
            108.0 / 23.0,
            72.0 / 23.0,
            162.0 / 77.0,
            5.0 / 3.0,
            8826.0 / 6871.0,
            1.0,
            120.0 / 143.0,
            2.0 / 3.0,
        ];
        for (g, w) in want.iter().enumerate() {
            let k = tr.kinematics(&net, g).unwrap();
            assert!(
                (k.ratio - w).abs() < 1e-12 * w.abs(),
                "gear {}: {} against {w}",
                tr.gears[g].name,
                k.ratio
            );
        }
        let sixth = tr.kinematics(&net, 6).unwrap();
        assert!(
            sixth.speeds_per_input[..8]
                .iter()
                .all(|v| (v - 1.0).abs() < 1e-12),
            "{sixth:?}"
        );
        let first = tr.kinematics(&net, 1).unwrap();
        assert_eq!(first.open_slips.len(), 2);
        assert!(
            first.open_slips.iter().all(|(_, s)| s.abs() > 0.01),
            "{first:?}"
        );
    }

    /// A prescribed body is moving to the gear check, not given as the fixed body is: the
    /// 8HP with its input (a rig's motor) or its output (a dynamometer) at a prescribed speed
    /// has every gear's ratio, speeds per input and open slips of the free one, bit for bit
    /// (held like the fixed body, a prescribed input reads as "holds the input still").
    #[test]
    fn a_prescribed_input_or_output_keeps_every_gears_kinematics() {
        let (net, tr) = eight_speed();
        let free: Vec<_> = (0..tr.gears.len())
            .map(|g| tr.kinematics(&net, g).unwrap())
            .collect();
        for body in [tr.input, tr.output] {
            let mut rig = net.clone();
            rig.bodies[body].motion =
                crate::network::Motion::Prescribed(crate::SpeedProfile::sine(100.0, 5.0, 30.0));
            for (g, k) in free.iter().enumerate() {
                assert_eq!(tr.kinematics(&rig, g).as_ref(), Ok(k), "gear {g}");
            }
        }
    }

    /// A gear of two elements leaves a degree of freedom too many, one of four holds the input
    /// still (eight rows on eight moving bodies), each refused with the reason.
    #[test]
    fn gears_that_are_no_gear_are_refused_with_the_reason() {
        let (net, mut tr) = eight_speed();
        tr.gears[1].closed = vec![4, 5];
        assert!(tr
            .kinematics(&net, 1)
            .unwrap_err()
            .contains("more than one degree of freedom"));
        tr.gears[1].closed = vec![4, 5, 6, 7];
        assert!(tr
            .kinematics(&net, 1)
            .unwrap_err()
            .contains("holds the input"));
    }

    /// A 1 -> 2 shift at 1 s (A B C to A B E): C, the off-going, holds through the fill and
    /// falls to 0 over the torque phase; E, the on-coming, fills to 0.1, rises to 0.6 over the
    /// torque phase and to 1 over the inertia phase; A and B hold. A shift to the engaged gear,
    /// one that swaps two elements, or one that starts before the last ends is refused.
    #[test]
    fn a_schedule_sets_a_packs_pressure_from_its_rated_pressure() {
        use super::{pack_pressure, rated_pressure_pa, Shift};
        use crate::clutch::PressureProfile;
        use crate::drive::Table;
        // the rated pressure: a table's largest row, a ramp's final, a constant
        let table = Table::new(vec![0.0, 0.1, 0.2], vec![0.0, 2e6, 1.5e6]).unwrap();
        assert_eq!(rated_pressure_pa(&PressureProfile::Table(table)), 2e6);
        let ramp = PressureProfile::Ramp {
            start_s: 0.0,
            rise_s: 0.1,
            pressure_pa: 1e6,
        };
        assert_eq!(rated_pressure_pa(&ramp), 1e6);
        // the on-coming element E's schedule times 2 MPa, with the schedule's corners
        let (net, mut tr) = eight_speed();
        tr.initial_gear = Some(1);
        tr.shifts = vec![Shift {
            at_s: 1.0,
            to: 2,
            fill_s: 0.05,
            fill_level: 0.1,
            torque_phase_s: 0.1,
            torque_level: 0.6,
            inertia_phase_s: 0.2,
        }];
        let e = net.couplings.iter().position(|c| c.name == "E").unwrap();
        let sched = tr.schedule().unwrap().unwrap();
        let signal = &sched.iter().find(|(c, _)| *c == e).unwrap().1;
        let p = pack_pressure(signal, 2e6).unwrap();
        for (t, want) in [
            (0.5, 0.0),
            (1.05, 0.2e6),
            (1.15, 1.2e6),
            (1.25, 1.6e6),
            (2.0, 2e6),
        ] {
            let got = p.pressure_pa(t);
            assert!(
                (got - want).abs() < 1e-6,
                "at {t} s: {got} Pa against {want}"
            );
        }
        let mut corners = Vec::new();
        p.breakpoints(&mut corners);
        assert_eq!(corners.len(), 5, "{corners:?}");
        // an element closed throughout: a constant
        let a = net.couplings.iter().position(|c| c.name == "A").unwrap();
        let signal = &sched.iter().find(|(c, _)| *c == a).unwrap().1;
        assert_eq!(
            pack_pressure(signal, 2e6),
            Some(PressureProfile::Constant { pressure_pa: 2e6 })
        );
    }

    /// A closed resolved pack ties its carriers as a locked clutch does: the gears' rows are
    /// the same whichever kind the element is.
    #[test]
    fn a_closed_pack_is_a_locked_element() {
        use super::element_row;
        let (net, _) = eight_speed();
        let c = net.couplings.iter().position(|c| c.name == "C").unwrap();
        let mut pack = net.couplings[c].clone();
        pack.kind = super::super::CouplingKind::Pack(Box::new(crate::cases::paper_pack(0.0)));
        for closed in [false, true] {
            assert_eq!(
                element_row(&pack, c, closed),
                element_row(&net.couplings[c], c, closed)
            );
        }
    }

    #[test]
    fn a_schedule_compiles_into_each_elements_force() {
        use super::Shift;
        let (net, mut tr) = eight_speed();
        tr.initial_gear = Some(1);
        let shift = |at_s: f64, to: usize| Shift {
            at_s,
            to,
            fill_s: 0.05,
            fill_level: 0.1,
            torque_phase_s: 0.1,
            torque_level: 0.6,
            inertia_phase_s: 0.2,
        };
        tr.shifts = vec![shift(1.0, 2)];
        let sched = tr.schedule().unwrap().unwrap();
        let force = |name: &str, t: f64| {
            let k = net.couplings.iter().position(|c| c.name == name).unwrap();
            sched.iter().find(|(c, _)| *c == k).unwrap().1.value(t)
        };
        let close = |name: &str, t: f64, want: f64| {
            let got = force(name, t);
            assert!(
                (got - want).abs() < 1e-12,
                "{name} at {t} s: {got} against {want}"
            );
        };
        close("A", 2.0, 1.0);
        close("B", 2.0, 1.0);
        close("D", 2.0, 0.0);
        close("C", 1.05, 1.0);
        close("C", 1.1, 0.5);
        close("C", 1.151, 0.0);
        close("E", 1.0, 0.0);
        close("E", 1.05, 0.1);
        close("E", 1.15, 0.6);
        close("E", 1.25, 0.8);
        close("E", 1.36, 1.0);
        tr.shifts = vec![shift(1.0, 1)];
        assert!(tr
            .schedule()
            .unwrap()
            .unwrap_err()
            .1
            .contains("already engaged"));
        tr.shifts = vec![shift(1.0, 4)];
        assert!(tr
            .schedule()
            .unwrap()
            .unwrap_err()
            .1
            .contains("opens 2 and closes 2"));
        tr.shifts = vec![shift(1.0, 2), shift(1.2, 3)];
        assert_eq!(tr.schedule().unwrap().unwrap_err().0, 1);
    }
}
