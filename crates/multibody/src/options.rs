//! Engine options: how time advances, how teeth are resolved, and the bodies' shapes (which
//! the scene does not give: only each disc's inertia about the axis).

/// How the engine advances time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stepping {
    /// A fixed step: `t_k = k dt_s` (the last step is shortened to land on the end of the run).
    /// The check mode: every contact is resolved at the same `dt` whatever its duration.
    Fixed {
        /// Step length in s (> 0). The default is 1e-6 s: the tooth contact lasts about
        /// 60-70 us, so about 60 steps per contact.
        dt_s: f64,
    },
    /// Contact-aware adaptive steps (see [`AdaptiveStepping`]).
    Adaptive(AdaptiveStepping),
}

impl Stepping {
    /// Fixed steps of 1e-6 s.
    pub fn fixed_default() -> Stepping {
        Stepping::Fixed { dt_s: 1e-6 }
    }
}

impl Default for Stepping {
    fn default() -> Self {
        Stepping::Adaptive(AdaptiveStepping::default())
    }
}

/// Contact-aware adaptive stepping.
///
/// In free flight the teeth cross the backlash and only the drive and the drag act, so the
/// step can be long; during a contact it must resolve the Hertz impact. Each step the engine
/// predicts, for every flank of every coupling, the worst-case time to contact from the gap,
/// the closing speed and a bound on the relative acceleration, and steps a fraction of it;
/// once that time falls below one contact step it steps with the contact step, so a contact
/// onset is never stepped over: it always falls inside a contact-sized step.
///
/// The contact step is the predicted duration of the impact divided by
/// [`Self::steps_per_contact`]: for the per-tooth law `m s'' = -K s^1.5` with
/// `m = J / (n Rb^2)` and closing speed `v`, the Hertz impact lasts
/// `T = 2.943 (5 m / (4 K))^(2/5) v^(-1/5)` (Johnson, *Contact Mechanics*, 11.2), with `K`
/// raised by the impact damping factor `1 + p v`. During a contact the step is further bounded
/// by the local period of the linearised contact `2 pi / sqrt(1.5 K sqrt(s) / m)` over the same
/// number of steps, so that a sustained contact (a disc carried on one flank) stays resolved.
///
/// A contact that outlasts [`Self::sustained_after`] predicted impact durations is no impact
/// but a carried load (a locked pack transmitting torque, a disc dragged on one flank): from
/// then on its step is [`Self::sustained_steps_per_period`] steps per local period, which
/// resolves the slow load and its small vibration without the impact's resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveStepping {
    /// Longest step in s (free flight). Default 1e-4 s (the scene's `simulation.max_step_s`).
    pub max_step_s: f64,
    /// Steps per predicted contact duration (dimensionless, > 1). Default 128. The error of an
    /// impact falls as the cube of the step (`integrate.rs`): measured on the first 50 ms of
    /// the paper case against fixed 0.1 us steps, the worst peak differs by 0.3 % at 64 steps
    /// and 0.04 % at 128 (a grazing 34 N impact at h_o = 50 um; the rattle is chaotic, so
    /// the differences of the early impacts grow), 0.01 % and 0.001 % on the first ten.
    pub steps_per_contact: f64,
    /// The fraction of [`Self::steps_per_contact`] a coupling integrated alone against a
    /// carrier of known motion (a prescribed shaft, the fixed housing) takes in the multirate
    /// scheme, in (0, 1] (dimensionless; 1: the full count). Default 0.75 (96 steps per
    /// contact, the kinks' grading unchanged): the open brake packs' cost is their contacts'
    /// sub-steps (the 16-disc brake pack 16 % fewer instructions), and the cost in accuracy
    /// is measured against the reference engine, every cross-engine bound kept (the staggered
    /// 8-disc brake's worst onset over 50 ms 0.41 us against its bound of 1 us, 0.085 us at
    /// the full count; docs/DECISIONS.md, "Multirate scheme of the multibody engine"). The
    /// couplings integrated with an inertial carrier (a drum, an inertial shaft, a network's
    /// resolved packs) and the clamped stack keep the full count.
    pub alone_contact_fraction: f64,
    /// Fraction of the worst-case time to contact taken as one free-flight step, in (0, 1).
    /// Default 0.9: the approach to a contact takes a few geometrically shrinking steps.
    pub approach_fraction: f64,
    /// Smallest step in s; a smaller step means the controller failed and the run reports
    /// [`clutchpack_model::EngineError::Diverged`]. Default 1e-12 s.
    pub min_step_s: f64,
    /// Steps per local period of a sustained contact (dimensionless, more than pi for the
    /// symplectic step's stability; at most `steps_per_contact` to mean anything). Default
    /// 32: symplectic Euler then makes the period about 0.16 % short, `(2 pi / 32)^2 / 24`.
    pub sustained_steps_per_period: f64,
    /// Predicted impact durations after which a contact counts as sustained (dimensionless,
    /// greater than 1); `f64::INFINITY` never relaxes the step. Default 4: an impact, even a
    /// slow, damped one through the film, is over within about two.
    pub sustained_after: f64,
}

impl AdaptiveStepping {
    /// The settings a coupling alone against a carrier of known motion steps by in the
    /// multirate scheme: these with [`Self::steps_per_contact`] times
    /// [`Self::alone_contact_fraction`].
    pub(crate) fn alone(&self) -> AdaptiveStepping {
        AdaptiveStepping {
            steps_per_contact: self.steps_per_contact * self.alone_contact_fraction,
            ..*self
        }
    }
}

impl Default for AdaptiveStepping {
    fn default() -> Self {
        AdaptiveStepping {
            max_step_s: 1e-4,
            steps_per_contact: 128.0,
            alone_contact_fraction: 0.75,
            approach_fraction: 0.9,
            min_step_s: 1e-12,
            sustained_steps_per_period: 32.0,
            sustained_after: 4.0,
        }
    }
}

/// How the spline contact hook resolves the teeth of a coupling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToothResolution {
    /// Lumped where that is exact (concentric disc, no spacing errors: all teeth carry the
    /// same load), per tooth otherwise. The default.
    #[default]
    Auto,
    /// One tooth evaluated and multiplied by `n` (MODEL.md section 1): exact for a concentric
    /// coupling without spacing errors.
    Lumped,
    /// Every tooth evaluated at its own contact point, its force applied along its own line of
    /// action (MODEL.md section 5).
    PerTooth,
}

/// Shapes of the bodies. The scene gives only each disc's inertia about the axis; the engine
/// needs a mass and transverse inertia too, and places the discs along the shaft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyShapes {
    /// Density of the discs and the shaft in kg/m^3. Default 7850 (steel).
    pub density_kg_m3: f64,
    /// Disc thickness in m. Default 3 mm.
    pub disc_thickness_m: f64,
    /// Axial distance between the mid-planes of neighbouring discs in m. Default 6 mm.
    pub disc_pitch_m: f64,
}

impl Default for BodyShapes {
    fn default() -> Self {
        BodyShapes {
            density_kg_m3: 7850.0,
            disc_thickness_m: 3e-3,
            disc_pitch_m: 6e-3,
        }
    }
}

/// How a disc is held on the shaft axis (rotation about it and the axial slide free).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DiscMount {
    /// [`DiscMount::LockedAxes`] when the multirate scheme runs the pack, the
    /// [`DiscMount::Joint`] on the shared step ([`DiscMount::for_scheme`]). The default.
    ///
    /// In the multirate scheme the couplings integrate their own motion and the rapier world
    /// only carries each body from one world step to the next (each body driven to its mean
    /// speed over the step, its speed set at the step's end): the joints' constraints hold
    /// nothing there but cost a third of a brake pack's run. Measured: every shipped scene the
    /// multirate scheme runs gives the same impacts and summary to the bit on either mount
    /// (docs/DECISIONS.md, "Multirate scheme of the multibody engine").
    #[default]
    Auto,
    /// A generic impulse joint to the shaft locking the two radial translations and the two
    /// tilts (ARCHITECTURE.md).
    Joint,
    /// Rapier's per-body locked axes (world x, y translations and rotations), no constraint
    /// to solve. The same motion whenever the shaft's axis stays on the world z axis, which
    /// it does here (a kinematic shaft, or a dynamic one on a revolute joint to the housing);
    /// measured about 1.9x faster per step for 8 discs. A floating disc then has only its
    /// tilts locked; an eccentric disc that does not float always gets a joint (its offset
    /// turns with the shaft).
    LockedAxes,
}

impl DiscMount {
    /// The mount a run builds its world with: [`DiscMount::Auto`] resolved for the scheme
    /// (`multirate`: the multirate scheme runs the pack), any other as asked.
    pub fn for_scheme(self, multirate: bool) -> DiscMount {
        match self {
            DiscMount::Auto if multirate => DiscMount::LockedAxes,
            DiscMount::Auto => DiscMount::Joint,
            m => m,
        }
    }
}

/// Options of the multibody engine.
#[derive(Debug, Clone, PartialEq)]
pub struct MultibodyOptions {
    /// Rate of the samples handed to the observer, Hz (> 0). Default 1e4 (the scenes'
    /// `simulation.record_rate_hz` default).
    pub record_rate_hz: f64,
    /// How time advances. Default: adaptive, with `max_step_s` from the scene.
    pub stepping: Stepping,
    /// How teeth are resolved. Default [`ToothResolution::Auto`].
    pub teeth: ToothResolution,
    /// Whether samples carry every tooth's load (`DiscSample::tooth_loads_n`). Default off:
    /// `n` numbers per disc per sample.
    pub record_tooth_loads: bool,
    /// Shapes of the bodies.
    pub shapes: BodyShapes,
    /// How the discs are held on the axis.
    pub mount: DiscMount,
    /// Which time-stepping scheme runs. Default [`Scheme::Auto`].
    pub scheme: Scheme,
}

/// The engine's time-stepping scheme (crate docs, "Theory").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheme {
    /// The multirate scheme wherever it applies (adaptive steps, a prescribed shaft, friction
    /// discs only, concentric lumped couplings), the shared step otherwise. The default.
    #[default]
    Auto,
    /// Every body on one shared contact-aware step (the shortest any coupling needs).
    Shared,
    /// The multirate scheme, or an error for a pack it cannot run.
    Multirate,
}

impl Default for MultibodyOptions {
    fn default() -> Self {
        MultibodyOptions {
            record_rate_hz: 1e4,
            stepping: Stepping::default(),
            teeth: ToothResolution::default(),
            record_tooth_loads: false,
            shapes: BodyShapes::default(),
            mount: DiscMount::default(),
            scheme: Scheme::default(),
        }
    }
}

impl MultibodyOptions {
    /// These options with samples at `record_rate_hz` (Hz).
    pub fn with_record_rate(self, record_rate_hz: f64) -> MultibodyOptions {
        MultibodyOptions {
            record_rate_hz,
            ..self
        }
    }

    /// The default options with a run's settings (what a scene's `[simulation]` gives):
    /// samples at `record_rate_hz` (Hz), adaptive steps of at most `max_step_s` (s), every
    /// tooth's load in the samples if `record_tooth_loads`.
    pub fn with_settings(
        record_rate_hz: f64,
        max_step_s: f64,
        record_tooth_loads: bool,
    ) -> MultibodyOptions {
        MultibodyOptions {
            record_rate_hz,
            record_tooth_loads,
            stepping: Stepping::Adaptive(AdaptiveStepping {
                max_step_s,
                ..AdaptiveStepping::default()
            }),
            ..MultibodyOptions::default()
        }
    }
}
