//! The equations of motion of a shaft and a set of its discs (Hu et al. eqs 3-5), in the
//! state layout the integrator advances.

use clutchpack_model::{
    DiscModel, DiscSample, Engagement, PackModel, Sample, Shaft, ToothKinematics,
};

/// The shaft and the discs in `ids` (global indices into `pack.discs`, in slots 0, 1, ...).
///
/// State layout: for an inertial shaft `y[0] = theta_s` (rad), `y[1] = omega_s` (rad/s), then
/// per slot `j` at `off + 2 j` the relative angle `phi = theta_s - theta_d` (rad) and the
/// relative speed `psi = omega_s - omega_d` (rad/s); for a prescribed shaft `off = 0` and the
/// shaft comes from its profile.
pub(crate) struct System<'a> {
    pub pack: &'a PackModel,
    /// Index of the first disc state: 0 for a prescribed shaft, 2 for an inertial one.
    pub off: usize,
    /// Global disc index of each slot.
    pub ids: Vec<usize>,
}

impl<'a> System<'a> {
    /// The shaft and the discs `ids` of `pack`.
    pub fn new(pack: &'a PackModel, ids: Vec<usize>) -> System<'a> {
        let off = if matches!(pack.shaft, Shaft::Inertial { .. }) {
            2
        } else {
            0
        };
        System { pack, off, ids }
    }

    pub fn dim(&self) -> usize {
        self.off + 2 * self.ids.len()
    }

    pub fn disc(&self, slot: usize) -> &'a DiscModel {
        &self.pack.discs[self.ids[slot]]
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
        let mut shaft_torque = 0.0;
        let (omega_s, alpha_prescribed) = match &self.pack.shaft {
            Shaft::Prescribed(p) => (p.speed(t), p.acceleration(t)),
            Shaft::Inertial { .. } => (y[1], 0.0),
        };
        // Per-disc loads first: an inertial shaft needs their sum.
        let mut alpha_s = alpha_prescribed;
        if let Shaft::Inertial {
            inertia_kg_m2,
            damping_n_m_s_rad,
            ..
        } = &self.pack.shaft
        {
            for slot in 0..self.ids.len() {
                let d = self.disc(slot);
                let f = self.load(slot, y, &modes[slot]);
                // Hu et al. eq (4): the spline reaction n F Rb acts back on the shaft
                shaft_torque += d.spline.teeth as f64 * f * d.spline.base_radius_m();
            }
            alpha_s = (self.pack.shaft.drive_torque_n_m(t) + shaft_torque
                - damping_n_m_s_rad * omega_s)
                / inertia_kg_m2;
            dy[0] = omega_s;
            dy[1] = alpha_s;
        }
        for slot in 0..self.ids.len() {
            let d = self.disc(slot);
            let k = self.off + 2 * slot;
            let f = self.load(slot, y, &modes[slot]);
            let omega_d = omega_s - y[k + 1];
            // Hu et al. eq (5)
            let alpha_d =
                (d.spline.disc_torque_n_m(f) - d.drag_n_m_s_rad * omega_d) / d.inertia_kg_m2;
            dy[k] = y[k + 1];
            dy[k + 1] = alpha_s - alpha_d;
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
        let (theta_s, omega_s) = self.shaft(t, y);
        let k = self.off + 2 * slot;
        disc_sample(self.disc(slot), theta_s, omega_s, y[k], y[k + 1], mode)
    }

    /// The sample of the whole system at `t` (every disc of the pack in its slot: only for a
    /// system of all the pack's discs in order).
    pub fn sample(&self, t: f64, y: &[f64], modes: &[Option<Engagement>]) -> Sample {
        let (theta_s, omega_s) = self.shaft(t, y);
        let discs = (0..self.ids.len())
            .map(|slot| {
                let k = self.off + 2 * slot;
                disc_sample(
                    self.disc(slot),
                    theta_s,
                    omega_s,
                    y[k],
                    y[k + 1],
                    &modes[slot],
                )
            })
            .collect();
        Sample {
            t_s: t,
            shaft_angle_rad: theta_s,
            shaft_speed_rad_s: omega_s,
            discs,
        }
    }
}

/// The sample of disc `d` with the shaft at `theta_s` (rad), `omega_s` (rad/s), relative
/// angle `phi` (rad), relative speed `psi` (rad/s) and contact mode `mode`.
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
