//! The spline contact hook: tooth gaps, closing speeds and loads of one coupling from the
//! relative pose and velocity of its two bodies (MODEL.md sections 1, 2 and 5).
//!
//! # Theory
//! Work in the carrier's frame (the shaft's), origin on its axis in the disc's mid-plane.
//! Tooth `k` sits at angle `psi_k = 2 pi k / n` (plus its spacing error `eps_k`), with radial and
//! tangential unit vectors `r_k = (cos psi_k, sin psi_k)`, `t_k = (-sin psi_k, cos psi_k)`.
//! On flank `sigma` (`+1`: the shaft leads, `-1`: the disc leads) the tooth pushes the disc
//! along its line of action, tangent to the base circle `Rb = R cos(alpha)`:
//!
//! `u_k = sigma cos(alpha) t_k + sin(alpha) r_k`
//!
//! (the radial part points outward on both flanks: the shaft's external teeth are wedges that
//! push the disc's internal teeth outward). Its lever arm about the axis is exactly `Rb`:
//! `(R r_k) x u_k = sigma R cos(alpha) z`. With `phi = theta_s - theta_d`,
//! `dphi = omega_s - omega_d`, and `e`, `e'` the disc centre's offset from the axis and its
//! rate in the carrier frame, the penetration and closing speed of tooth `k` are, to first
//! order in the micrometre offset,
//!
//! `delta_k = (sigma (phi + eps_k) - g0) Rb - e . u_k`, `v_k = sigma dphi Rb - e' . u_k`
//!
//! (a disc pushed against the tooth, `-e . u_k > 0`, penetrates it). The first terms are the
//! model's [`SplineGeometry::kinematics`] at `phi + eps_k`, so with `e = 0` and no spacing
//! errors every tooth has the lumped `delta`, `v_n` and load: the `n` radial forces cancel and
//! the torque on the disc is `-n F Rb` (eq 5), the lumped law exactly. A disc offset towards
//! `+x` opens the gaps of the teeth near `+x` (`e . u_k = e sin(alpha) > 0`) and closes those
//! near `-x`, whose outward pushes drive it back: the spline centres itself.
//!
//! Each tooth keeps its own [`ContactState`] (the paper law's `dv` per contact event). The
//! event engages at the first evaluation with positive engagement depth, with `dv` the closing
//! speed interpolated linearly to the zero crossing of the depth between the last two
//! evaluations (MODEL.md: "dv the closing speed at the instant s crosses zero").

use clutchpack_model::{ContactState, Flank, SplineGeometry, ToothKinematics, ToothLaw};

/// The relative state of a coupling's two bodies, in the carrier's frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct RelativeState {
    /// `phi = theta_s - theta_d`, rad.
    pub phi: f64,
    /// `omega_s - omega_d` about the axis, rad/s.
    pub dphi: f64,
    /// The disc centre's offset from the carrier's axis, m (x, y of the carrier frame).
    pub offset: [f64; 2],
    /// Rate of the offset seen from the carrier frame, m/s.
    pub offset_rate: [f64; 2],
}

/// One tooth pair of a per-tooth coupling.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tooth {
    /// `r_k`, carrier frame.
    radial: [f64; 2],
    /// `t_k`, carrier frame.
    tangential: [f64; 2],
    /// Spacing error `eps_k`, rad (positive: the carrier tooth sits ahead).
    phase_error_rad: f64,
    /// The contact memory of this tooth.
    state: ContactState,
    /// Engagement depth and closing speed at the previous evaluation.
    prev: Option<(f64, f64)>,
    /// Signed load at the last evaluation, N.
    pub load_n: f64,
}

impl Tooth {
    /// The unit line of action `u_k = sigma cos(alpha) t_k + sin(alpha) r_k` on the flank of
    /// sign `sigma` (module docs), carrier frame, from the pressure angle's `(sin, cos)`.
    fn line_of_action(&self, sigma: f64, (sin_a, cos_a): (f64, f64)) -> [f64; 2] {
        [
            sigma * cos_a * self.tangential[0] + sin_a * self.radial[0],
            sigma * cos_a * self.tangential[1] + sin_a * self.radial[1],
        ]
    }
}

/// What the hook computed for one coupling at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CouplingForces {
    /// Lumped kinematics (the concentric tooth without spacing error).
    pub kin: ToothKinematics,
    /// Engagement depth of the coupling, m: the deepest tooth's.
    pub depth_m: f64,
    /// Mean signed per-tooth load, N (the per-tooth load of the lumped law).
    pub load_n: f64,
    /// Net force of the teeth on the disc, carrier frame, N.
    pub force: [f64; 2],
    /// Moment of the teeth's forces on the disc about the axis point in the disc's mid-plane,
    /// carrier frame, N m. Its z part is the spline torque on the disc.
    pub moment: [f64; 3],
    /// Stiffness `K` of the deepest engaged tooth's event, N/m^1.5 (0 when none).
    pub stiffness: f64,
    /// Elastic energy of the teeth, `sum (2/5) K s^2.5`, J (a potential only for `p = 0`).
    pub potential_j: f64,
    /// How much closer the closest tooth can be than the lumped gap, m (offset and spacing
    /// errors), and how much faster it can close, m/s: margins for the step controller.
    pub gap_margin_m: f64,
    /// See `gap_margin_m`.
    pub speed_margin_m_s: f64,
}

/// How far below zero (m) the deepest engagement depth a per-tooth coupling's teeth can
/// reach must be for its probes to skip the teeth ([`Coupling::none_can_touch`]): far above
/// the rounding of a depth (1e-19 m on a gap of 1e-4 m), far below any depth that loads a
/// tooth.
const PROBE_MARGIN_M: f64 = 1e-12;

/// A spline coupling between the carrier (shaft) and one disc.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Coupling {
    /// Geometry.
    pub spline: SplineGeometry,
    /// Tooth law.
    pub law: ToothLaw,
    /// Per-tooth state; empty for a lumped coupling.
    teeth: Vec<Tooth>,
    /// Contact memory of the lumped coupling.
    lumped: ContactState,
    /// Depth and closing speed of the lumped tooth at the previous evaluation.
    lumped_prev: Option<(f64, f64)>,
    /// Last lumped load, N.
    lumped_load_n: f64,
    /// Largest spacing error, rad.
    max_phase_error_rad: f64,
    /// The offset and its rate at the last evaluation (per-tooth couplings), for probes.
    last_offset: ([f64; 2], [f64; 2]),
    /// The base radius `Rb`, m, kept: the kinematics are evaluated millions of times and a
    /// cosine per call was the engine's largest single cost on the 16-disc brake pack (16 %
    /// of the run, perf).
    rb: f64,
    /// The half play `g0 = d / (2 R)`, rad, kept as `rb` (a division per call of the
    /// kinematics, four and more per multirate sub-step).
    g0: f64,
    /// The sine and cosine of the pressure angle (per-tooth lines of action).
    sin_cos_alpha: (f64, f64),
    /// Half a tooth pitch, `pi / n`, rad, kept as `rb` (the sub-steps check every relative
    /// angle against it: a division per sub-step).
    half_pitch_rad: f64,
}

/// The lumped tooth's kinematics at `(phi, dphi)` with the half play `g0` (rad) and the base
/// radius `rb` (m): [`SplineGeometry::kinematics_at`] to the bit, with both kept.
fn kinematics(g0: f64, rb: f64, phi_rad: f64, dphi_rad_s: f64) -> ToothKinematics {
    let flank = Flank::of(phi_rad);
    ToothKinematics {
        flank,
        delta_m: (phi_rad.abs() - g0) * rb,
        v_n_m_s: flank.phi_sign() * dphi_rad_s * rb,
    }
}

/// Advances one tooth's contact memory to `kin` and returns its signed load (N) and engagement
/// depth (m). A new event holds the closing speed interpolated to the depth's zero crossing.
fn tooth_load(
    law: &ToothLaw,
    state: &mut ContactState,
    prev: &mut Option<(f64, f64)>,
    kin: &ToothKinematics,
) -> (f64, f64) {
    let depth = law.engagement_depth_m(kin);
    let load = if depth <= 0.0 {
        state.engagement = None;
        0.0
    } else {
        let e = match state.engagement {
            Some(e) if e.flank == kin.flank => e,
            _ => {
                let v_on = match *prev {
                    Some((d0, v0)) if d0 <= 0.0 => {
                        let w = -d0 / (depth - d0);
                        v0 + w * (kin.v_n_m_s - v0)
                    }
                    _ => kin.v_n_m_s,
                };
                law.engage(&ToothKinematics {
                    v_n_m_s: v_on,
                    ..*kin
                })
            }
        };
        state.engagement = Some(e);
        law.load_n(kin, &e)
    };
    *prev = Some((depth, kin.v_n_m_s));
    (load, depth)
}

/// One tooth's signed load (N) at `kin` as a probe takes it ([`Coupling::probe_torque`]):
/// zero unless engaged, else the law's with the tooth's event in progress `state` if it is on
/// the same flank, or an event engaging at `kin`; the contact memory is not advanced.
#[inline(always)]
fn probe_load(law: &ToothLaw, state: &ContactState, kin: &ToothKinematics) -> f64 {
    if law.engagement_depth_m(kin) <= 0.0 {
        return 0.0;
    }
    let e = match state.engagement {
        Some(e) if e.flank == kin.flank => e,
        _ => law.engage(kin),
    };
    law.load_n(kin, &e)
}

impl Coupling {
    /// The base radius `Rb`, m (kept: a cosine per call is dear in the inner loops).
    pub fn base_radius_m(&self) -> f64 {
        self.rb
    }

    /// The half play `g0`, rad ([`SplineGeometry::half_play_rad`], kept).
    pub fn half_play_rad(&self) -> f64 {
        self.g0
    }

    /// Half a tooth pitch, `pi / n`, rad (kept): the largest relative angle a coupling's
    /// state can have.
    pub fn half_pitch_rad(&self) -> f64 {
        self.half_pitch_rad
    }

    /// The lumped tooth's kinematics at `(phi, dphi)` ([`kinematics`]).
    fn kinematics(&self, phi_rad: f64, dphi_rad_s: f64) -> ToothKinematics {
        kinematics(self.g0, self.rb, phi_rad, dphi_rad_s)
    }

    /// A coupling; `per_tooth` resolves every tooth, with spacing errors `phase_errors_rad`
    /// (one per tooth, or empty for none).
    pub fn new(
        spline: SplineGeometry,
        law: ToothLaw,
        per_tooth: bool,
        phase_errors_rad: &[f64],
    ) -> Coupling {
        let n = spline.teeth as usize;
        let teeth = if per_tooth {
            (0..n)
                .map(|k| {
                    let psi = std::f64::consts::TAU * k as f64 / n as f64;
                    let (s, c) = psi.sin_cos();
                    Tooth {
                        radial: [c, s],
                        tangential: [-s, c],
                        phase_error_rad: phase_errors_rad.get(k).copied().unwrap_or(0.0),
                        state: ContactState::default(),
                        prev: None,
                        load_n: 0.0,
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        Coupling {
            rb: spline.base_radius_m(),
            g0: spline.half_play_rad(),
            sin_cos_alpha: spline.pressure_angle_rad.sin_cos(),
            half_pitch_rad: std::f64::consts::PI / spline.teeth as f64,
            spline,
            law,
            teeth,
            lumped: ContactState::default(),
            lumped_prev: None,
            lumped_load_n: 0.0,
            max_phase_error_rad: phase_errors_rad
                .iter()
                .fold(0.0, |m: f64, e| m.max(e.abs())),
            last_offset: ([0.0; 2], [0.0; 2]),
        }
    }

    /// Signed loads of every tooth at the last evaluation, N (the lumped load `n` times for a
    /// lumped coupling).
    pub fn tooth_loads_n(&self) -> Vec<f64> {
        if self.teeth.is_empty() {
            vec![self.lumped_load_n; self.spline.teeth as usize]
        } else {
            self.teeth.iter().map(|t| t.load_n).collect()
        }
    }

    /// The teeth's torque on the disc about the axis, N m, at a relative angle and speed
    /// other than the evaluated one (the disc's offset held at its last value), without
    /// advancing the contact memories: each tooth's event in progress if it is on the same
    /// flank, else an event engaging at `dphi`. Used to integrate the teeth's torque along a
    /// step (`integrate.rs`).
    ///
    /// Inlined where it is called (the multirate sub-steps probe a lumped coupling three
    /// times a step: the call and the registers it spilled were a third of a probe's cost);
    /// a per-tooth coupling's loop is its own function, [`Self::probe_torque_per_tooth`].
    #[inline(always)]
    pub fn probe_torque(&self, phi: f64, dphi: f64) -> f64 {
        if self.teeth.is_empty() {
            let kin = self.kinematics(phi, dphi);
            return self.disc_torque_n_m(probe_load(&self.law, &self.lumped, &kin));
        }
        self.probe_torque_per_tooth(phi, dphi)
    }

    /// [`Self::probe_torque`] of a per-tooth coupling.
    fn probe_torque_per_tooth(&self, phi: f64, dphi: f64) -> f64 {
        let load = |state: &ContactState, kin: &ToothKinematics| probe_load(&self.law, state, kin);
        let r = self.spline.pitch_radius_m;
        let ([ex, ey], [ex_dot, ey_dot]) = self.last_offset;
        if self.none_can_touch(phi, (ex * ex + ey * ey).sqrt()) {
            return 0.0;
        }
        let mut moment = 0.0;
        for tooth in &self.teeth {
            let k0 = self.kinematics(phi + tooth.phase_error_rad, dphi);
            let u = tooth.line_of_action(k0.flank.phi_sign(), self.sin_cos_alpha);
            let k = ToothKinematics {
                flank: k0.flank,
                delta_m: k0.delta_m - (ex * u[0] + ey * u[1]),
                v_n_m_s: k0.v_n_m_s - (ex_dot * u[0] + ey_dot * u[1]),
            };
            let f = load(&tooth.state, &k).abs();
            moment += r * f * (tooth.radial[0] * u[1] - tooth.radial[1] * u[0]);
        }
        moment
    }

    /// Whether no tooth of a per-tooth coupling can be engaged at the relative angle `phi`
    /// (rad) with the disc's centre `offset` (m) off the axis: the deepest engagement depth
    /// any tooth can have, `(|phi| + max |eps_k| - g0) Rb + |e| + h_o` (each tooth's is
    /// `(|phi + eps_k| - g0) Rb - e . u_k + h_o` with `u_k` a unit vector, module docs), is
    /// below zero by more than rounding ([`PROBE_MARGIN_M`]). Every tooth's load is then
    /// zero, and so are the sums over them: the probes skip the loop (measured on
    /// `eccentric-disc.toml`: the probes were 40 % of the run, most of them in free flight).
    fn none_can_touch(&self, phi: f64, offset_m: f64) -> bool {
        let reach = (phi.abs() + self.max_phase_error_rad - self.g0) * self.rb
            + offset_m
            + self.law.engagement_offset_m();
        reach < -PROBE_MARGIN_M
    }

    /// The deepest tooth's engagement depth less the lumped one on `flank`, m: the deepest
    /// engagement depth of the coupling at a relative angle `phi` on that flank is
    /// `(sigma phi - g0) Rb + h_o` plus this, `max_k (sigma eps_k Rb - e . u_k)` (module
    /// docs) with the disc's offset `e` of the last evaluation; 0 for a lumped coupling. The
    /// multirate sub-steps land on its zero crossings, the coupling's onsets and separations
    /// (`engine/substep.rs`); exact while the offset does not move, as for a disc that does
    /// not float radially.
    pub fn deepest_tooth_shift_m(&self, flank: Flank) -> f64 {
        if self.teeth.is_empty() {
            return 0.0;
        }
        let sigma = flank.phi_sign();
        let [ex, ey] = self.last_offset.0;
        self.teeth
            .iter()
            .map(|tooth| {
                let u = tooth.line_of_action(sigma, self.sin_cos_alpha);
                sigma * tooth.phase_error_rad * self.rb - (ex * u[0] + ey * u[1])
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Torque on the disc from a signed per-tooth load, N m: `-n F Rb` (eq 5), as
    /// [`SplineGeometry::disc_torque_n_m`] with the kept `Rb`.
    fn disc_torque_n_m(&self, load_n: f64) -> f64 {
        -(self.spline.teeth as f64) * load_n * self.rb
    }

    /// Evaluates the tooth law for the relative state `rel`, advancing the contact memories.
    pub fn evaluate(&mut self, rel: &RelativeState) -> CouplingForces {
        let kin = self.kinematics(rel.phi, rel.dphi);
        if self.teeth.is_empty() {
            self.evaluate_lumped(kin)
        } else {
            self.evaluate_per_tooth(kin, rel)
        }
    }

    /// One tooth, times `n` (MODEL.md section 1).
    fn evaluate_lumped(&mut self, kin: ToothKinematics) -> CouplingForces {
        let (load, depth) = tooth_load(&self.law, &mut self.lumped, &mut self.lumped_prev, &kin);
        self.lumped_load_n = load;
        let (stiffness, potential) = match self.lumped.engagement {
            Some(e) if depth > 0.0 => (
                e.stiffness,
                self.spline.teeth as f64 * 0.4 * e.stiffness * depth * depth * depth.sqrt(),
            ),
            _ => (0.0, 0.0),
        };
        CouplingForces {
            kin,
            depth_m: depth,
            load_n: load,
            force: [0.0, 0.0],
            moment: [0.0, 0.0, self.disc_torque_n_m(load)],
            stiffness,
            potential_j: potential,
            gap_margin_m: 0.0,
            speed_margin_m_s: 0.0,
        }
    }

    /// Every tooth at its own contact point, along its own line of action (MODEL.md 5).
    fn evaluate_per_tooth(&mut self, kin: ToothKinematics, rel: &RelativeState) -> CouplingForces {
        let (g0, rb) = (self.g0, self.rb);
        let r = self.spline.pitch_radius_m;
        let [ex, ey] = rel.offset;
        let [ex_dot, ey_dot] = rel.offset_rate;
        self.last_offset = (rel.offset, rel.offset_rate);
        let mut force = [0.0; 2];
        let mut moment = [0.0; 3];
        let mut sum_load = 0.0;
        let mut depth_max = f64::NEG_INFINITY;
        let mut stiffness = 0.0;
        let mut potential = 0.0;
        for tooth in &mut self.teeth {
            let k0 = kinematics(g0, rb, rel.phi + tooth.phase_error_rad, rel.dphi);
            let u = tooth.line_of_action(k0.flank.phi_sign(), self.sin_cos_alpha);
            let k = ToothKinematics {
                flank: k0.flank,
                delta_m: k0.delta_m - (ex * u[0] + ey * u[1]),
                v_n_m_s: k0.v_n_m_s - (ex_dot * u[0] + ey_dot * u[1]),
            };
            let (load, depth) = tooth_load(&self.law, &mut tooth.state, &mut tooth.prev, &k);
            tooth.load_n = load;
            sum_load += load;
            if depth > depth_max {
                depth_max = depth;
                if depth > 0.0 {
                    stiffness = tooth.state.engagement.map(|e| e.stiffness).unwrap_or(0.0);
                }
            }
            if load != 0.0 {
                let f = load.abs();
                force[0] += f * u[0];
                force[1] += f * u[1];
                // (R r_k) x f, about the axis point of the mid-plane: only a z part. Written
                // as `probe_torque` writes it, so that a probe of the state just evaluated
                // gives this torque to the bit (the multirate sub-steps take it as their first
                // stage, `engine/substep.rs`).
                moment[2] += r * f * (tooth.radial[0] * u[1] - tooth.radial[1] * u[0]);
                if let Some(e) = tooth.state.engagement {
                    potential += 0.4 * e.stiffness * depth * depth * depth.sqrt();
                }
            }
        }
        let n = self.teeth.len() as f64;
        let offset = (ex * ex + ey * ey).sqrt();
        let offset_rate = (ex_dot * ex_dot + ey_dot * ey_dot).sqrt();
        CouplingForces {
            kin,
            depth_m: depth_max,
            load_n: sum_load / n,
            force,
            moment,
            stiffness,
            potential_j: potential,
            gap_margin_m: offset + self.max_phase_error_rad * self.rb,
            speed_margin_m_s: offset_rate,
        }
    }
}

/// The flank's sign helper for the step controller: both flanks in a fixed order.
pub(crate) const FLANKS: [Flank; 2] = [Flank::ShaftLeads, Flank::DiscLeads];

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::LawKind;

    fn paper_spline() -> SplineGeometry {
        SplineGeometry {
            teeth: 154,
            pitch_radius_m: 0.231,
            pressure_angle_rad: 20f64.to_radians(),
            backlash_m: 0.75e-3,
        }
    }

    /// The paper's law (Table 2), from the model's named cases.
    fn law(kind: LawKind, h_o: f64) -> ToothLaw {
        clutchpack_model::cases::paper_law(kind, h_o)
    }

    /// MODEL.md 5: with a concentric disc and no spacing errors the per-tooth hook is the
    /// lumped law exactly: the same per-tooth load on every tooth, the lumped torque `-n F Rb`
    /// to rounding (1e-12 relative: a sum of 154 terms), and no net radial force (1e-12 of
    /// `n |F|`). Checked along a sequence of states through a contact on each flank, so the
    /// paper law's held `dv` is exercised too.
    #[test]
    fn per_tooth_equals_lumped_when_concentric() {
        for (kind, h_o) in [(LawKind::Dry, 0.0), (LawKind::Paper, 25e-6)] {
            let g = paper_spline();
            let mut lumped = Coupling::new(g, law(kind, h_o), false, &[]);
            let mut teeth = Coupling::new(g, law(kind, h_o), true, &[]);
            let g0 = g.half_play_rad();
            let mut saw_contact = 0;
            for i in 0..400 {
                let s = (i as f64 / 400.0 * std::f64::consts::TAU).sin();
                let rel = RelativeState {
                    phi: (g0 + 3e-6 / g.base_radius_m()) * s,
                    dphi: 3.0 * (i as f64 * 0.05).cos(),
                    ..Default::default()
                };
                let a = lumped.evaluate(&rel);
                let b = teeth.evaluate(&rel);
                assert_eq!(a.load_n.to_bits() == 0, b.load_n.to_bits() == 0);
                assert!(
                    (a.load_n - b.load_n).abs() <= 1e-12 * a.load_n.abs(),
                    "{a:?} {b:?}"
                );
                assert!((a.moment[2] - b.moment[2]).abs() <= 1e-12 * a.moment[2].abs());
                let n_f = 154.0 * a.load_n.abs();
                assert!(b.force[0].abs() <= 1e-12 * n_f && b.force[1].abs() <= 1e-12 * n_f);
                assert!(teeth.tooth_loads_n().iter().all(|&f| f == a.load_n));
                assert_eq!(a.depth_m, b.depth_m);
                if a.load_n != 0.0 {
                    saw_contact += 1;
                }
            }
            assert!(saw_contact > 10, "the sequence must reach both flanks");
        }
    }

    /// MODEL.md 5, involute splines centre themselves: a disc offset radially under a torque
    /// that holds one flank closed is pushed back towards the axis (the net radial force is
    /// opposite to the offset), and the teeth on the side of the offset carry less.
    #[test]
    fn offset_disc_is_pushed_back() {
        let g = paper_spline();
        let mut c = Coupling::new(g, law(LawKind::Dry, 0.0), true, &[]);
        let phi = g.half_play_rad() + 2e-6 / g.base_radius_m();
        let rel = RelativeState {
            phi,
            dphi: 0.0,
            offset: [0.5e-6, 0.0],
            offset_rate: [0.0, 0.0],
        };
        let f = c.evaluate(&rel);
        assert!(f.force[0] < 0.0, "pushed back towards -x: {:?}", f.force);
        assert!(f.force[1].abs() < 1e-6 * f.force[0].abs() * 154.0 + 1e-3);
        let loads = c.tooth_loads_n();
        // tooth 0 sits at +x (gap opened), tooth n/2 at -x (gap closed); loads are negative
        // (the shaft leads), so "carries less" is a smaller magnitude.
        assert!(loads[0].abs() < loads[77].abs());
    }
}
