//! The equations of motion of a shaft and a set of its discs (Hu et al. eqs 3-5), in the
//! state layout the integrator advances; for a whole pack also the separator plates on the
//! housing or the drum, the drum (MODEL.md section 5) and the open stack's oil gaps.

use clutchpack_model::{
    DiscModel, DiscSample, Engagement, InterfaceSample, PackModel, Sample, Shaft, StackBody,
    ToothKinematics,
};

/// What a coupling's spline ties its body to.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Carrier {
    /// The shaft (friction discs).
    Shaft,
    /// The output drum (separator plates of a clutch).
    Drum,
    /// The fixed housing (separator plates of a brake): angle and speed 0.
    Housing,
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
/// (rad/s) when there is a drum, then the heat (J) each open interface has dissipated.
pub(crate) struct System<'a> {
    pub pack: &'a PackModel,
    /// Index of the first disc state: 0 for a prescribed shaft, 2 for an inertial one.
    pub off: usize,
    /// Global coupling index of each slot.
    pub ids: Vec<usize>,
    /// Number of friction discs of the pack.
    nd: usize,
    /// Open-gap damping `c = pi eta (Ro^4 - Ri^4) / (2 h)` of every interface, N m s/rad (0
    /// without a stack or its oil gap; MODEL.md section 5).
    c_gap: f64,
}

impl<'a> System<'a> {
    /// The shaft and the couplings `ids` of `pack`. A pack with plates, a drum or a stack
    /// needs every coupling in order (`ids = 0..N + P`).
    pub fn new(pack: &'a PackModel, ids: Vec<usize>) -> System<'a> {
        let off = if matches!(pack.shaft, Shaft::Inertial { .. }) {
            2
        } else {
            0
        };
        let c_gap = pack
            .stack
            .as_ref()
            .map_or(0.0, |s| -s.open_gap_torque_n_m(1.0));
        let sys = System {
            pack,
            off,
            ids,
            nd: pack.discs.len(),
            c_gap,
        };
        debug_assert!(
            !sys.is_whole() || sys.ids == (0..sys.nd + pack.plates.len()).collect::<Vec<_>>()
        );
        sys
    }

    /// Whether the pack has plates, a drum or a stack (the whole-pack layout).
    pub fn is_whole(&self) -> bool {
        !self.pack.plates.is_empty() || self.pack.drum.is_some() || self.pack.stack.is_some()
    }

    /// Index of the drum's angle in the state (its speed follows).
    fn drum_at(&self) -> usize {
        self.off + 2 * self.ids.len()
    }

    /// Index of the first interface's heat in the state.
    fn heat_at(&self) -> usize {
        self.drum_at() + if self.pack.drum.is_some() { 2 } else { 0 }
    }

    /// Number of friction interfaces (`2N` with a stack).
    pub fn interfaces(&self) -> usize {
        if self.pack.stack.is_some() {
            2 * self.nd
        } else {
            0
        }
    }

    pub fn dim(&self) -> usize {
        self.heat_at() + self.interfaces()
    }

    /// The coupling with global index `id`: disc `id`, or plate `id - N`.
    fn coupling(&self, id: usize) -> &'a DiscModel {
        if id < self.nd {
            &self.pack.discs[id]
        } else {
            &self.pack.plates[id - self.nd]
        }
    }

    pub fn disc(&self, slot: usize) -> &'a DiscModel {
        self.coupling(self.ids[slot])
    }

    fn carrier(&self, slot: usize) -> Carrier {
        if self.ids[slot] < self.nd {
            Carrier::Shaft
        } else if self.pack.drum.is_some() {
            Carrier::Drum
        } else {
            Carrier::Housing
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
            Shaft::Prescribed(p) => (p.angle(t), p.speed(t)),
            Shaft::Inertial { .. } => (y[0], y[1]),
        }
    }

    pub fn kin(&self, slot: usize, y: &[f64]) -> ToothKinematics {
        let k = self.off + 2 * slot;
        self.disc(slot).spline.kinematics(y[k], y[k + 1])
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

    /// `dy = f(t, y)` with the slots' contact modes `modes`.
    pub fn rhs(&self, t: f64, y: &[f64], modes: &[Option<Engagement>], dy: &mut [f64]) {
        let (omega_s, alpha_prescribed) = match &self.pack.shaft {
            Shaft::Prescribed(p) => (p.speed(t), p.acceleration(t)),
            Shaft::Inertial { .. } => (y[1], 0.0),
        };
        // The carriers first: an inertial shaft and a drum need their couplings' reactions.
        let mut alpha_s = alpha_prescribed;
        let inertial = matches!(self.pack.shaft, Shaft::Inertial { .. });
        let (mut shaft_torque, mut drum_torque) = (0.0, 0.0);
        if inertial || self.pack.drum.is_some() {
            for slot in 0..self.ids.len() {
                let d = self.disc(slot);
                let f = self.load(slot, y, &modes[slot]);
                // Hu et al. eq (4): the spline reaction n F Rb acts back on the carrier
                let reaction = d.spline.teeth as f64 * f * d.spline.base_radius_m();
                match self.carrier(slot) {
                    Carrier::Shaft => shaft_torque += reaction,
                    Carrier::Drum => drum_torque += reaction,
                    Carrier::Housing => {}
                }
            }
        }
        if let Shaft::Inertial {
            inertia_kg_m2,
            damping_n_m_s_rad,
            ..
        } = &self.pack.shaft
        {
            alpha_s = (self.pack.shaft.drive_torque_n_m(t) + shaft_torque
                - damping_n_m_s_rad * omega_s)
                / inertia_kg_m2;
            dy[0] = omega_s;
            dy[1] = alpha_s;
        }
        let (mut omega_r, mut alpha_r) = (0.0, 0.0);
        if let Some(drum) = &self.pack.drum {
            // the drum: its load, its drag and the plates' spline reactions (MODEL.md section 5)
            let r = self.drum_at();
            omega_r = y[r + 1];
            alpha_r = (drum.load_torque_n_m + drum_torque - drum.drag_n_m_s_rad * omega_r)
                / drum.inertia_kg_m2;
            dy[r] = omega_r;
            dy[r + 1] = alpha_r;
        }
        for slot in 0..self.ids.len() {
            let d = self.disc(slot);
            let k = self.off + 2 * slot;
            let f = self.load(slot, y, &modes[slot]);
            let (omega_c, alpha_c) = match self.carrier(slot) {
                Carrier::Shaft => (omega_s, alpha_s),
                Carrier::Drum => (omega_r, alpha_r),
                Carrier::Housing => (0.0, 0.0),
            };
            let omega_b = omega_c - y[k + 1];
            let stack = self.stack_torque_n_m(slot, y, omega_s, omega_r);
            // Hu et al. eq (5), with the open gaps' drag on a whole pack
            let alpha_b = (d.spline.disc_torque_n_m(f) - d.drag_n_m_s_rad * omega_b + stack)
                / d.inertia_kg_m2;
            dy[k] = y[k + 1];
            dy[k + 1] = alpha_c - alpha_b;
        }
        let h = self.heat_at();
        for m in 0..self.interfaces() {
            // heat rate of an open gap: c slip^2 (>= 0)
            let slip = self.stack_speed(m + 1, y, omega_s, omega_r)
                - self.stack_speed(m, y, omega_s, omega_r);
            dy[h + m] = self.c_gap * slip * slip;
        }
    }

    /// Speed (rad/s) of the body at stack position `b` (whole pack: slot = coupling index),
    /// with the shaft at `omega_s` and the drum at `omega_r` (rad/s).
    fn stack_speed(&self, b: usize, y: &[f64], omega_s: f64, omega_r: f64) -> f64 {
        let slot = StackBody::at(b).body_index(self.nd);
        let omega_c = match self.carrier(slot) {
            Carrier::Shaft => omega_s,
            Carrier::Drum => omega_r,
            Carrier::Housing => 0.0,
        };
        omega_c - y[self.off + 2 * slot + 1]
    }

    /// Torque of the open stack's gaps on the body in `slot`, N m: the Couette drag `-c slip`
    /// of each interface it shares with a neighbour (MODEL.md section 5).
    fn stack_torque_n_m(&self, slot: usize, y: &[f64], omega_s: f64, omega_r: f64) -> f64 {
        if self.interfaces() == 0 {
            return 0.0;
        }
        let id = self.ids[slot];
        let b = if id < self.nd {
            StackBody::Disc(id)
        } else {
            StackBody::Plate(id - self.nd)
        }
        .position();
        let me = self.stack_speed(b, y, omega_s, omega_r);
        let mut torque = 0.0;
        if b > 0 {
            torque -= self.c_gap * (me - self.stack_speed(b - 1, y, omega_s, omega_r));
        }
        if b < 2 * self.nd {
            torque -= self.c_gap * (me - self.stack_speed(b + 1, y, omega_s, omega_r));
        }
        torque
    }

    /// The open interfaces' states at `t` for state `y` (empty without a stack).
    pub fn interface_samples(&self, t: f64, y: &[f64]) -> Vec<InterfaceSample> {
        let Some(stack) = &self.pack.stack else {
            return Vec::new();
        };
        let omega_s = self.shaft(t, y).1;
        let omega_r = self.pack.drum.map_or(0.0, |_| y[self.drum_at() + 1]);
        let r_eff = stack.effective_radius_m();
        (0..self.interfaces())
            .map(|m| {
                let slip = self.stack_speed(m + 1, y, omega_s, omega_r)
                    - self.stack_speed(m, y, omega_s, omega_r);
                InterfaceSample {
                    slip_rad_s: slip,
                    slip_m_s: slip * r_eff,
                    mu: 0.0,
                    clamp_n: 0.0,
                    torque_n_m: -self.c_gap * slip,
                    locked: false,
                    dissipated_j: y[self.heat_at() + m],
                }
            })
            .collect()
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
        if let Some(drum) = &self.pack.drum {
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
        let (theta_s, omega_s) = self.shaft(t, y);
        let discs = (0..self.ids.len())
            .map(|slot| self.disc_sample(t, slot, y, &modes[slot]))
            .collect();
        Sample {
            t_s: t,
            shaft_angle_rad: theta_s,
            shaft_speed_rad_s: omega_s,
            discs,
        }
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
        pack
    }

    /// At states with some couplings in contact and every gap slipping, the right-hand side
    /// conserves angular momentum exactly (`sum J alpha = 0`: every spline reaction and gap
    /// torque is paired) and power (`sum J omega alpha = sum n F Rb psi - sum heat rates`:
    /// the teeth's power is what their potential gives up, the gaps' is the heat they make).
    #[test]
    fn whole_pack_rhs_conserves_momentum_and_power() {
        let pack = free_pack();
        let sys = System::new(&pack, (0..5).collect());
        assert_eq!(sys.dim(), 2 + 2 * 5 + 2 + 4);
        let g0 = pack.discs[0].spline.half_play_rad();
        for (k, contact) in [
            [0.3, 1.02, -0.7, -1.01, 0.2],
            [1.01, 0.1, 1.03, -0.5, -1.02],
        ]
        .iter()
        .enumerate()
        {
            let mut y = sys.initial_state();
            y[1] = 100.0 + k as f64;
            for slot in 0..5 {
                y[2 + 2 * slot] = contact[slot] * g0;
                y[2 + 2 * slot + 1] = 3.0 - 1.7 * slot as f64 + k as f64;
            }
            y[sys.drum_at() + 1] = -4.0;
            let modes: Vec<Option<Engagement>> = (0..5)
                .map(|slot| {
                    (sys.depth(slot, &y) > 0.0)
                        .then(|| sys.disc(slot).law.engage(&sys.kin(slot, &y)))
                })
                .collect();
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
                let (psi, j) = (y[2 + 2 * slot + 1], sys.disc(slot).inertia_kg_m2);
                let (w_b, a_b) = (w_c - psi, a_c - dy[2 + 2 * slot + 1]);
                momentum += j * a_b;
                scale += (j * a_b).abs();
                power += j * w_b * a_b;
                let d = sys.disc(slot);
                teeth += d.spline.teeth as f64
                    * sys.load(slot, &y, &modes[slot])
                    * d.spline.base_radius_m()
                    * psi;
            }
            let heat: f64 = dy[sys.heat_at()..].iter().sum();
            assert!(heat > 0.0);
            assert!(momentum.abs() <= 1e-12 * scale, "{momentum} of {scale}");
            let p_scale = teeth.abs() + heat;
            assert!(
                (power - teeth + heat).abs() <= 1e-11 * p_scale,
                "{power} {teeth} {heat}"
            );
        }
    }
}
