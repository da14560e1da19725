//! A pack's thermal model as a scene gives it (`[thermal]`, MODEL.md section 9): the oil's
//! viscosity law as its fitted points, the reference temperature of the tooth film, the
//! lumped capacities and conductances of the bodies and the oil, and the thermal window on
//! which an engine advances the temperatures; and what a thermal run reports
//! ([`ThermalReport`]). Data only: the scene crate validates it, the engines integrate it.

use super::friction::{FrictionMap, FrictionMapError};
use super::viscosity::{Viscosity, ViscosityError, ViscosityTable, Vogel, Walther};
use serde::{Deserialize, Serialize};

/// The oil's viscosity law as the points it is fitted through (validated: its fit succeeds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViscosityLaw {
    /// Walther (ASTM D341) through two kinematic viscosities.
    Walther {
        /// Two increasing temperatures, K.
        temperatures_k: [f64; 2],
        /// The kinematic viscosities there, m^2/s (decreasing, above 0.3e-6).
        kinematic_m2_s: [f64; 2],
        /// Density for `eta = nu rho`, kg/m^3 (> 0).
        density_kg_m3: f64,
    },
    /// Vogel through three dynamic viscosities.
    Vogel {
        /// Three increasing temperatures, K.
        temperatures_k: [f64; 3],
        /// The dynamic viscosities there, Pa s (decreasing, `ln eta` strictly convex).
        viscosities_pa_s: [f64; 3],
    },
    /// A table, `ln eta` linear in `T` between rows, held beyond its ends.
    Table {
        /// Increasing temperatures, K (at least two).
        temperatures_k: Vec<f64>,
        /// The dynamic viscosities there, Pa s (decreasing).
        viscosities_pa_s: Vec<f64>,
    },
}

impl ViscosityLaw {
    /// The fitted law ([`Viscosity`]); the error says which point is bad.
    pub fn fit(&self) -> Result<Viscosity, ViscosityError> {
        Ok(match self {
            ViscosityLaw::Walther {
                temperatures_k: t,
                kinematic_m2_s: nu,
                density_kg_m3,
            } => Viscosity::Walther(Walther::through(
                [(t[0], nu[0]), (t[1], nu[1])],
                *density_kg_m3,
            )?),
            ViscosityLaw::Vogel {
                temperatures_k: t,
                viscosities_pa_s: e,
            } => Viscosity::Vogel(Vogel::through([(t[0], e[0]), (t[1], e[1]), (t[2], e[2])])?),
            ViscosityLaw::Table {
                temperatures_k,
                viscosities_pa_s,
            } => Viscosity::Table(ViscosityTable::new(
                temperatures_k.clone(),
                viscosities_pa_s.clone(),
            )?),
        })
    }
}

/// The faces' friction coefficient against slip speed and temperature, `mu(v, T)`, as the
/// points a scene gives (`[thermal.friction]`; validated: [`FrictionTable::fit`] succeeds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrictionTable {
    /// Slip speeds at the effective radius, m/s (from >= 0, strictly increasing).
    pub speeds_m_s: Vec<f64>,
    /// Temperatures, K (strictly increasing).
    pub temperatures_k: Vec<f64>,
    /// `mu[i][j]` at `speeds_m_s[i]` and `temperatures_k[j]` (dimensionless, >= 0).
    pub mu: Vec<Vec<f64>>,
}

impl FrictionTable {
    /// The fitted map ([`FrictionMap`]: bilinear, held at its edges); the error names the
    /// bad value.
    pub fn fit(&self) -> Result<FrictionMap, FrictionMapError> {
        FrictionMap::new(
            self.speeds_m_s.clone(),
            self.temperatures_k.clone(),
            self.mu.clone(),
        )
    }
}

/// What viscosity the open gaps' drag (MODEL.md section 5) takes in a thermal run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GapViscosity {
    /// The law's absolute `eta(T_oil)` (MODEL.md section 9).
    #[default]
    Absolute,
    /// The scene's `stack.open_gap.viscosity_pa_s` times the film scale `eta(T_oil) /
    /// eta(T_ref)`: for a gap viscosity that is itself a calibrated, effective value.
    Scaled,
}

/// One lumped body (a friction disc or a separator plate).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThermalBody {
    /// Heat capacity `m c`, J/K (> 0).
    pub capacity_j_k: f64,
    /// Effusivity of its friction faces' material `sqrt(k rho c)`, W s^0.5 / (m^2 K) (> 0):
    /// steel for a plate, the lining for a disc.
    pub face_effusivity: f64,
    /// Conductance to the oil `sum h A` over its two faces, W/K (>= 0; 0: adiabatic).
    pub conductance_w_k: f64,
}

/// The oil volume (a sump or the cooling flow through the pack).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThermalOil {
    /// Heat capacity, J/K (> 0).
    pub capacity_j_k: f64,
    /// The cooler's capacity rate `m_dot c_p`, W/K (>= 0; 0: no cooler).
    pub flow_capacity_w_k: f64,
    /// Temperature of the oil entering from the cooler, K.
    pub inlet_k: f64,
}

/// A pack's thermal model (`[thermal]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThermalModel {
    /// The oil's viscosity against temperature.
    pub viscosity: ViscosityLaw,
    /// Temperature at which the scene's tooth film viscosities (`oil.viscosity_pa_s`, Hu et
    /// al. eqs 7-8) hold, K: the film scale is `eta(T_oil) / eta(T_ref)`.
    pub reference_k: f64,
    /// The open gaps' viscosity.
    pub gap_viscosity: GapViscosity,
    /// The thermal window, s (> 0): the temperatures and the viscosity-dependent parameters
    /// advance once per window (operator splitting).
    pub step_s: f64,
    /// Temperature of every body and the oil at t = 0, K.
    pub initial_k: f64,
    /// The friction discs, in scene order.
    pub discs: Vec<ThermalBody>,
    /// The separator plates, in scene order.
    pub plates: Vec<ThermalBody>,
    /// The oil.
    pub oil: ThermalOil,
    /// The faces' `mu(v, T)`, taken at each window's end at each face's temperature (the
    /// hotter of its two bodies; docs/DECISIONS.md, "Friction against temperature");
    /// `None`: the stack's own `mu(v)` all the run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionTable>,
}

/// Fewest seconds the fastest time constant of a thermal model may have (the scene crate
/// refuses a model below it; docs/DECISIONS.md, "Plausibility bounds"): the windows' RK4
/// sub-steps are a twentieth of it, so a window of `step_s` takes at most
/// `step_s / (0.05 MIN_TIME_CONSTANT_S)` of them (2e5 for the longest window, 10 s). The
/// thinnest real plate on the thinnest oil gap (1 mm of steel, 10 um of oil) is about 0.04 s.
pub const MIN_TIME_CONSTANT_S: f64 = 1e-3;

/// Most RK4 sub-steps one advance of the temperatures may take (a window and the engine's
/// step past its end, `ThermalWindows::close_windows`); beyond it the run stops with
/// [`crate::EngineError::Diverged`] rather than spend minutes in one window (issue 48,
/// item 3). A model that validates needs at most 2e5 per window (see
/// [`MIN_TIME_CONSTANT_S`]); 1e6 sub-steps of a 20-body pack take about half a second.
pub const MAX_SUB_STEPS: f64 = 1e6;

/// Which capacity sets a thermal model's fastest time constant
/// ([`ThermalModel::fastest_time_constant_s`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FastestBody {
    /// A friction disc (every disc has the same capacity and conductance).
    Disc,
    /// A separator plate.
    Plate,
    /// The oil, against the bodies' conductances and the cooler.
    Oil,
}

impl ThermalModel {
    /// The fastest time constant of the lumped equations, s (infinite: every body adiabatic
    /// and no cooler), and which capacity sets it: each body's `C / G` (MODEL.md section 9,
    /// [`super::time_constant_s`]) and the oil's `C_oil / (sum G + m_dot c_p)`. The windows'
    /// sub-steps are a twentieth of it.
    pub fn fastest_time_constant_s(&self) -> (f64, FastestBody) {
        let mut tau = f64::INFINITY;
        let mut which = FastestBody::Oil;
        let mut g_sum = 0.0;
        for (b, kind) in self
            .discs
            .iter()
            .map(|b| (b, FastestBody::Disc))
            .chain(self.plates.iter().map(|b| (b, FastestBody::Plate)))
        {
            if b.conductance_w_k > 0.0 {
                let t = b.capacity_j_k / b.conductance_w_k;
                if t < tau {
                    (tau, which) = (t, kind);
                }
            }
            g_sum += b.conductance_w_k;
        }
        if g_sum + self.oil.flow_capacity_w_k > 0.0 {
            let t = self.oil.capacity_j_k / (g_sum + self.oil.flow_capacity_w_k);
            if t < tau {
                (tau, which) = (t, FastestBody::Oil);
            }
        }
        (tau, which)
    }
}

/// What a thermal run reports at its end (MODEL.md section 9's checks). Bodies: the discs,
/// then the plates, as the engines number them. Temperatures in K, heats in J (>= 0).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ThermalReport {
    /// Each body's temperature at the end, K.
    pub final_k: Vec<f64>,
    /// Each body's highest temperature at a window's end, K.
    pub max_k: Vec<f64>,
    /// The oil's temperature at the end, K.
    pub oil_final_k: f64,
    /// The oil's highest temperature at a window's end, K.
    pub oil_max_k: f64,
    /// Heat of the slipping faces, J (split between their two bodies by effusivity).
    pub friction_heat_j: f64,
    /// Heat of the open gaps' drag, J (into the oil).
    pub gap_heat_j: f64,
    /// Heat of the tooth impacts (the tooth forces' work on the relative motion), J (into
    /// the oil).
    pub impact_heat_j: f64,
    /// Heat stored in the bodies, `sum C (T - T_0)`, J.
    pub stored_bodies_j: f64,
    /// Heat stored in the oil, `C_oil (T_oil - T_0)`, J.
    pub stored_oil_j: f64,
    /// Heat the cooler took, J.
    pub cooler_j: f64,
    /// Thermal windows taken.
    pub windows: u64,
    /// Windows after which the viscosity-dependent parameters changed.
    pub updates: u64,
}

impl ThermalReport {
    /// Heat generated, J: friction, gaps and impacts.
    pub fn generated_j(&self) -> f64 {
        self.friction_heat_j + self.gap_heat_j + self.impact_heat_j
    }

    /// Heat accounted for, J: stored in bodies and oil plus taken by the cooler.
    pub fn accounted_j(&self) -> f64 {
        self.stored_bodies_j + self.stored_oil_j + self.cooler_j
    }
}
