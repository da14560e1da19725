//! Our own protobuf messages (package `clutchpack`), their descriptor, and the `.proto` text.
//!
//! The schema is defined once, in the tables of this module (`MESSAGES`, `ENUMS`); from
//! them come the `FileDescriptorProto` embedded in every recording (`file_descriptor_set`)
//! and the human-readable `proto/clutchpack.proto` (`proto_text`, checked by a test). The
//! encoders are the `prost`-derived structs below, whose tags a test checks against the tables.
//! No `protoc` and no build script are needed.
//!
//! Field names carry their unit (`load_n`, `t_s`), so a plot of `/discs/d1/spline.load_n`
//! says what it shows. Every message carries the simulated time `t_s` (also the MCAP log time,
//! in ns), because PlotJuggler and Rerun can plot against a field as well as the log time.
//!
//! Schema evolution: never renumber or retype a field; add new fields with new numbers.

use prost::Message as _;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{
    DescriptorProto, EnumDescriptorProto, EnumValueDescriptorProto, FieldDescriptorProto,
    FileDescriptorProto, FileDescriptorSet,
};

/// Protobuf package of our messages.
pub const PACKAGE: &str = "clutchpack";
/// File name of our messages inside the embedded `FileDescriptorSet`.
pub const FILE_NAME: &str = "clutchpack.proto";

/// Full schema name of [`ShaftState`] (topic `/shaft`).
pub const SHAFT_STATE: &str = "clutchpack.ShaftState";
/// Full schema name of [`SplineState`] (topics `/discs/<name>/spline`).
pub const SPLINE_STATE: &str = "clutchpack.SplineState";
/// Full schema name of [`ToothLoads`] (topics `/discs/<name>/teeth`).
pub const TOOTH_LOADS: &str = "clutchpack.ToothLoads";
/// Full schema name of [`InterfaceState`] (topics `/interfaces/<lower>__<upper>`).
pub const INTERFACE_STATE: &str = "clutchpack.InterfaceState";
/// Full schema name of [`Impact`] (topic `/impacts`).
pub const IMPACT: &str = "clutchpack.Impact";
/// Full schema name of [`SummaryMessage`] (topic `/summary`).
pub const RUN_SUMMARY: &str = "clutchpack.RunSummary";
/// Full schema name of [`LoadSample`] (topics `/discs/<name>/load`).
pub const LOAD_SAMPLE: &str = "clutchpack.LoadSample";
/// Full schema name of [`Temperature`] (topics `/discs/<name>/temperature`, `/oil/temperature`).
pub const TEMPERATURE: &str = "clutchpack.Temperature";
/// Full schema name of [`CouplingState`] (topics `/network/couplings/<name>` of a network
/// recording).
pub const COUPLING_STATE: &str = "clutchpack.CouplingState";

/// The shaft at one sample (topic `/shaft`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct ShaftState {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Shaft angle in rad.
    #[prost(double, tag = "2")]
    pub angle_rad: f64,
    /// Shaft speed in rad/s.
    #[prost(double, tag = "3")]
    pub speed_rad_s: f64,
}

/// One disc's spline coupling at one sample (topic `/discs/<name>/spline`); the fields of
/// [`clutchpack_model::DiscSample`] but the per-tooth loads.
#[derive(Clone, PartialEq, prost::Message)]
pub struct SplineState {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Relative angle `phi = theta_shaft - theta_disc` in rad (positive: the shaft leads).
    #[prost(double, tag = "2")]
    pub rel_angle_rad: f64,
    /// Closing speed along the line of action in m/s (positive closing).
    #[prost(double, tag = "3")]
    pub closing_speed_m_s: f64,
    /// Metal penetration along the line of action in m (negative: a gap).
    #[prost(double, tag = "4")]
    pub penetration_m: f64,
    /// Per-tooth load in N (negative when the shaft leads, Hu et al. eq (6)).
    #[prost(double, tag = "5")]
    pub load_n: f64,
    /// Spline torque on the disc in N m.
    #[prost(double, tag = "6")]
    pub torque_n_m: f64,
    /// Whether a contact event (film or metal) is in progress.
    #[prost(bool, tag = "7")]
    pub engaged: bool,
    /// Stiffness of the current contact event in N/m^1.5 (0 when not engaged).
    #[prost(double, tag = "8")]
    pub stiffness_n_m1_5: f64,
    /// Disc speed in rad/s.
    #[prost(double, tag = "9")]
    pub speed_rad_s: f64,
    /// Disc angle in rad.
    #[prost(double, tag = "10")]
    pub angle_rad: f64,
    /// Index of the disc in the scene, from 0.
    #[prost(uint32, tag = "11")]
    pub disc_index: u32,
}

/// Per-tooth loads of one disc at one sample (topic `/discs/<name>/teeth`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct ToothLoads {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Load of each tooth in N, signed as `load_n`.
    #[prost(double, repeated, tag = "2")]
    pub loads_n: Vec<f64>,
    /// Index of the disc in the scene, from 0.
    #[prost(uint32, tag = "3")]
    pub disc_index: u32,
}

/// One friction interface of the stack at one sample (topic `/interfaces/<lower>__<upper>`);
/// the fields of [`clutchpack_model::InterfaceSample`].
#[derive(Clone, PartialEq, prost::Message)]
pub struct InterfaceState {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Slip speed `omega_upper - omega_lower` in rad/s.
    #[prost(double, tag = "2")]
    pub slip_rad_s: f64,
    /// Slip speed at the effective radius in m/s (same sign).
    #[prost(double, tag = "3")]
    pub slip_m_s: f64,
    /// Friction coefficient in use (dimensionless; 0 for an open interface).
    #[prost(double, tag = "4")]
    pub mu: f64,
    /// Clamp force in N (0: open).
    #[prost(double, tag = "5")]
    pub clamp_n: f64,
    /// Torque of the interface on its upper body about +z in N m (the lower body gets the
    /// opposite).
    #[prost(double, tag = "6")]
    pub torque_n_m: f64,
    /// Whether the faces are locked together (no slip).
    #[prost(bool, tag = "7")]
    pub locked: bool,
    /// Index of the interface along the stack, from 0 (between stack bodies `m` and `m + 1`).
    #[prost(uint32, tag = "8")]
    pub interface_index: u32,
    /// Energy the interface has dissipated since t = 0 in J (>= 0).
    #[prost(double, tag = "9")]
    pub dissipated_j: f64,
}

impl InterfaceState {
    /// The model's view of this message (the index and the time are left out).
    pub fn to_sample(&self) -> clutchpack_model::InterfaceSample {
        clutchpack_model::InterfaceSample {
            slip_rad_s: self.slip_rad_s,
            slip_m_s: self.slip_m_s,
            mu: self.mu,
            clamp_n: self.clamp_n,
            torque_n_m: self.torque_n_m,
            locked: self.locked,
            dissipated_j: self.dissipated_j,
        }
    }
}

/// Which flank is in contact (wire form of [`clutchpack_model::Flank`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum Flank {
    /// Not set (never written).
    Unspecified = 0,
    /// The shaft leads; the load is negative.
    ShaftLeads = 1,
    /// The disc leads; the load is positive.
    DiscLeads = 2,
}

/// One impact (topic `/impacts`), logged at its peak time `t_peak_s`.
#[derive(Clone, PartialEq, prost::Message)]
pub struct Impact {
    /// Disc name.
    #[prost(string, tag = "1")]
    pub disc: String,
    /// Index of the disc in the scene, from 0.
    #[prost(uint32, tag = "2")]
    pub disc_index: u32,
    /// Onset in s.
    #[prost(double, tag = "3")]
    pub t_on_s: f64,
    /// Time of the peak load in s.
    #[prost(double, tag = "4")]
    pub t_peak_s: f64,
    /// Separation in s.
    #[prost(double, tag = "5")]
    pub t_off_s: f64,
    /// Flank in contact.
    #[prost(enumeration = "Flank", tag = "6")]
    pub flank: i32,
    /// Closing speed at onset in m/s.
    #[prost(double, tag = "7")]
    pub v_on_m_s: f64,
    /// Signed peak per-tooth load in N.
    #[prost(double, tag = "8")]
    pub peak_n: f64,
}

impl Impact {
    /// The message of the impact `e` of the body (or gear mesh) named `name`.
    pub fn of(e: &clutchpack_model::ImpactEvent, name: String) -> Impact {
        Impact {
            disc: name,
            disc_index: e.disc as u32,
            t_on_s: e.t_on_s,
            t_peak_s: e.t_peak_s,
            t_off_s: e.t_off_s,
            flank: match e.flank {
                clutchpack_model::Flank::ShaftLeads => Flank::ShaftLeads,
                clutchpack_model::Flank::DiscLeads => Flank::DiscLeads,
            } as i32,
            v_on_m_s: e.v_on_m_s,
            peak_n: e.peak_n,
        }
    }
}

/// Statistics of one disc's impact peaks (wire form of `clutchpack_analysis::DiscStats`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct DiscSummary {
    /// Disc name.
    #[prost(string, tag = "1")]
    pub name: String,
    /// Index of the disc in the scene, from 0.
    #[prost(uint32, tag = "2")]
    pub index: u32,
    /// Largest positive peak in N (0 if none).
    #[prost(double, tag = "3")]
    pub max_positive_n: f64,
    /// Most negative peak in N (<= 0; 0 if none).
    #[prost(double, tag = "4")]
    pub max_negative_n: f64,
    /// 99th percentile of |peak| in N.
    #[prost(double, tag = "5")]
    pub p99_abs_n: f64,
    /// Number of impacts.
    #[prost(uint64, tag = "6")]
    pub impacts: u64,
    /// Impacts with a positive peak.
    #[prost(uint64, tag = "7")]
    pub positive_impacts: u64,
    /// Impacts with a negative peak.
    #[prost(uint64, tag = "8")]
    pub negative_impacts: u64,
    /// Mean of the 10 largest |peak| in N.
    #[prost(double, tag = "9")]
    pub mean_top10_abs_n: f64,
    /// Whether the fatigue fields 11.. are set (false in files written before them).
    #[prost(bool, tag = "10")]
    pub fatigue: bool,
    /// Damage per hour of the simulated duty, 1/h (MODEL.md section 7).
    #[prost(double, tag = "11")]
    pub damage_rate_per_h: f64,
    /// Life in hours at this duty; 0 when unlimited (no damage).
    #[prost(double, tag = "12")]
    pub life_h: f64,
    /// Damage-equivalent load range for one hour at the knee's cycles, N.
    #[prost(double, tag = "13")]
    pub eq_load_range_n: f64,
    /// Largest tooth-root bending stress, Pa.
    #[prost(double, tag = "14")]
    pub max_root_stress_pa: f64,
    /// Number of resolved teeth (0: the engine did not resolve teeth).
    #[prost(uint32, tag = "15")]
    pub teeth: u32,
    /// Index of the most damaged resolved tooth.
    #[prost(uint32, tag = "16")]
    pub worst_tooth: u32,
    /// Life of the most damaged resolved tooth in hours; 0 when unlimited.
    #[prost(double, tag = "17")]
    pub worst_tooth_life_h: f64,
}

/// The run's summary (topic `/summary`, one message at the end of the run).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SummaryMessage {
    /// Simulated time at the end of the run in s.
    #[prost(double, tag = "1")]
    pub t_end_s: f64,
    /// One entry per disc, in scene order.
    #[prost(message, repeated, tag = "2")]
    pub discs: Vec<DiscSummary>,
}

/// One disc's per-tooth load at one instant (topic `/discs/<name>/load`): at the engine's
/// steps inside each contact (see [`clutchpack_model::Observer::contact_sample`]) and at the
/// regular samples with a load (the first sample too; between contacts the load is 0), in
/// time order, so that one plot line shows each contact pulse's shape and its peak.
#[derive(Clone, PartialEq, prost::Message)]
pub struct LoadSample {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Per-tooth load in N (negative when the shaft leads, Hu et al. eq (6)).
    #[prost(double, tag = "2")]
    pub load_n: f64,
    /// Relative angle `phi = theta_shaft - theta_disc` in rad (positive: the shaft leads).
    #[prost(double, tag = "3")]
    pub rel_angle_rad: f64,
    /// `true` for a step inside a contact, `false` for a regular sample (the same instant as
    /// the spline topic's message).
    #[prost(bool, tag = "4")]
    pub contact_step: bool,
    /// Index of the disc in the scene, from 0.
    #[prost(uint32, tag = "5")]
    pub disc_index: u32,
}

/// A body's or the oil's temperature in a thermal run, at the end of each thermal window
/// (topics `/discs/<name>/temperature`, `/oil/temperature`; MODEL.md section 9).
#[derive(Clone, PartialEq, prost::Message)]
pub struct Temperature {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Temperature in K.
    #[prost(double, tag = "2")]
    pub temperature_k: f64,
    /// Index of the body in the scene (the discs, then the plates), from 0; the oil's is the
    /// number of bodies.
    #[prost(uint32, tag = "3")]
    pub body_index: u32,
}

/// One coupling of a driveline network at one sample (topics `/network/couplings/<name>`;
/// MODEL.md section 8). A network's bodies use [`ShaftState`] (`/network/bodies/<name>`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct CouplingState {
    /// Simulated time in s.
    #[prost(double, tag = "1")]
    pub t_s: f64,
    /// Torque of the coupling on its body `a` in N m (positive along the positive rotation;
    /// body `b` gets the opposite, through the ratio for a gear).
    #[prost(double, tag = "2")]
    pub torque_n_m: f64,
    /// A clutch's slip `w_rel = omega_b - omega_a` in rad/s (the network's convention,
    /// Modelica's: positive in mode `slip+`; 0 for other kinds).
    #[prost(double, tag = "3")]
    pub slip_rad_s: f64,
    /// A clutch's mode: `free`, `slip+`, `slip-` or `locked` (empty for other kinds).
    #[prost(string, tag = "4")]
    pub mode: String,
    /// Whether a clutch is locked (false for other kinds).
    #[prost(bool, tag = "5")]
    pub locked: bool,
    /// A clutch's normal force in N (>= 0; 0 for other kinds).
    #[prost(double, tag = "6")]
    pub normal_force_n: f64,
    /// Index of the coupling in the scene, from 0.
    #[prost(uint32, tag = "7")]
    pub coupling_index: u32,
}

/// Field type in the schema tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FieldType {
    /// `double`
    Double,
    /// `bool`
    Bool,
    /// `uint32`
    Uint32,
    /// `uint64`
    Uint64,
    /// `string`
    String,
    /// An enum of this package, by short name.
    Enum(&'static str),
    /// A message of this package, by short name.
    Message(&'static str),
}

/// One field of a message in the schema tables.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FieldDef {
    /// Field name (with its unit).
    pub name: &'static str,
    /// Field number (never changes).
    pub number: i32,
    /// Type.
    pub ty: FieldType,
    /// `repeated`.
    pub repeated: bool,
    /// One-line comment for the `.proto` text.
    pub doc: &'static str,
}

/// One message in the schema tables.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MessageDef {
    /// Short name (`SplineState`).
    pub name: &'static str,
    /// Comment for the `.proto` text.
    pub doc: &'static str,
    /// Fields in number order.
    pub fields: &'static [FieldDef],
}

/// One enum in the schema tables.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EnumDef {
    /// Short name.
    pub name: &'static str,
    /// Comment.
    pub doc: &'static str,
    /// Values (name, number).
    pub values: &'static [(&'static str, i32)],
}

const fn f(name: &'static str, number: i32, ty: FieldType, doc: &'static str) -> FieldDef {
    FieldDef {
        name,
        number,
        ty,
        repeated: false,
        doc,
    }
}

const fn rep(name: &'static str, number: i32, ty: FieldType, doc: &'static str) -> FieldDef {
    FieldDef {
        name,
        number,
        ty,
        repeated: true,
        doc,
    }
}

use FieldType::{Bool, Double, Uint32, Uint64};

/// The enums of package `clutchpack`.
pub(crate) const ENUMS: &[EnumDef] = &[EnumDef {
    name: "Flank",
    doc: "Which flank is in contact.",
    values: &[
        ("FLANK_UNSPECIFIED", 0),
        ("SHAFT_LEADS", 1),
        ("DISC_LEADS", 2),
    ],
}];

/// The messages of package `clutchpack`, in file order.
pub(crate) const MESSAGES: &[MessageDef] = &[
    MessageDef {
        name: "ShaftState",
        doc: "The shaft at one sample. Topic /shaft.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f("angle_rad", 2, Double, "shaft angle, rad"),
            f("speed_rad_s", 3, Double, "shaft speed, rad/s"),
        ],
    },
    MessageDef {
        name: "SplineState",
        doc: "One disc's spline coupling at one sample. Topic /discs/<name>/spline.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f(
                "rel_angle_rad",
                2,
                Double,
                "phi = theta_shaft - theta_disc, rad (positive: the shaft leads)",
            ),
            f(
                "closing_speed_m_s",
                3,
                Double,
                "closing speed along the line of action, m/s (positive closing)",
            ),
            f(
                "penetration_m",
                4,
                Double,
                "metal penetration along the line of action, m (negative: a gap)",
            ),
            f(
                "load_n",
                5,
                Double,
                "per-tooth load, N (negative when the shaft leads)",
            ),
            f("torque_n_m", 6, Double, "spline torque on the disc, N m"),
            f(
                "engaged",
                7,
                Bool,
                "a contact event (film or metal) is in progress",
            ),
            f(
                "stiffness_n_m1_5",
                8,
                Double,
                "stiffness of the current contact event, N/m^1.5 (0 when not engaged)",
            ),
            f("speed_rad_s", 9, Double, "disc speed, rad/s"),
            f("angle_rad", 10, Double, "disc angle, rad"),
            f(
                "disc_index",
                11,
                Uint32,
                "index of the disc in the scene, from 0",
            ),
        ],
    },
    MessageDef {
        name: "ToothLoads",
        doc: "Per-tooth loads of one disc at one sample. Topic /discs/<name>/teeth.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            rep(
                "loads_n",
                2,
                Double,
                "load of each tooth, N (negative when the shaft leads)",
            ),
            f(
                "disc_index",
                3,
                Uint32,
                "index of the disc in the scene, from 0",
            ),
        ],
    },
    MessageDef {
        name: "InterfaceState",
        doc:
            "One friction interface of the stack at one sample. Topic /interfaces/<lower>__<upper>.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f(
                "slip_rad_s",
                2,
                Double,
                "slip speed omega_upper - omega_lower, rad/s",
            ),
            f(
                "slip_m_s",
                3,
                Double,
                "slip speed at the effective radius, m/s (same sign)",
            ),
            f(
                "mu",
                4,
                Double,
                "friction coefficient in use (0 for an open interface)",
            ),
            f("clamp_n", 5, Double, "clamp force, N (0: open)"),
            f(
                "torque_n_m",
                6,
                Double,
                "torque on the upper body about +z, N m (the lower body gets the opposite)",
            ),
            f("locked", 7, Bool, "the faces are locked together (no slip)"),
            f(
                "interface_index",
                8,
                Uint32,
                "index of the interface along the stack, from 0",
            ),
            f(
                "dissipated_j",
                9,
                Double,
                "energy the interface has turned into heat since t = 0, J (>= 0)",
            ),
        ],
    },
    MessageDef {
        name: "Impact",
        doc: "One impact, logged at its peak time. Topic /impacts.",
        fields: &[
            f("disc", 1, FieldType::String, "disc name"),
            f(
                "disc_index",
                2,
                Uint32,
                "index of the disc in the scene, from 0",
            ),
            f("t_on_s", 3, Double, "onset, s"),
            f("t_peak_s", 4, Double, "time of the peak load, s"),
            f("t_off_s", 5, Double, "separation, s"),
            f("flank", 6, FieldType::Enum("Flank"), "flank in contact"),
            f("v_on_m_s", 7, Double, "closing speed at onset, m/s"),
            f("peak_n", 8, Double, "signed peak per-tooth load, N"),
        ],
    },
    MessageDef {
        name: "DiscSummary",
        doc: "Statistics of one disc's impact peaks.",
        fields: &[
            f("name", 1, FieldType::String, "disc name"),
            f("index", 2, Uint32, "index of the disc in the scene, from 0"),
            f(
                "max_positive_n",
                3,
                Double,
                "largest positive peak, N (0 if none)",
            ),
            f(
                "max_negative_n",
                4,
                Double,
                "most negative peak, N (<= 0; 0 if none)",
            ),
            f(
                "p99_abs_n",
                5,
                Double,
                "99th percentile of |peak|, N (numpy's linear definition)",
            ),
            f("impacts", 6, Uint64, "number of impacts"),
            f(
                "positive_impacts",
                7,
                Uint64,
                "impacts with a positive peak (disc leads)",
            ),
            f(
                "negative_impacts",
                8,
                Uint64,
                "impacts with a negative peak (shaft leads)",
            ),
            f(
                "mean_top10_abs_n",
                9,
                Double,
                "mean of the 10 largest |peak|, N",
            ),
            f(
                "fatigue",
                10,
                Bool,
                "whether the fatigue fields 11.. are set",
            ),
            f(
                "damage_rate_per_h",
                11,
                Double,
                "tooth damage per hour of the simulated duty, 1/h",
            ),
            f("life_h", 12, Double, "life at this duty, h (0: unlimited)"),
            f(
                "eq_load_range_n",
                13,
                Double,
                "damage-equivalent load range for one hour at N_D cycles, N",
            ),
            f(
                "max_root_stress_pa",
                14,
                Double,
                "largest tooth-root bending stress, Pa",
            ),
            f("teeth", 15, Uint32, "resolved teeth (0: none)"),
            f(
                "worst_tooth",
                16,
                Uint32,
                "index of the most damaged resolved tooth",
            ),
            f(
                "worst_tooth_life_h",
                17,
                Double,
                "life of the most damaged resolved tooth, h (0: unlimited)",
            ),
        ],
    },
    MessageDef {
        name: "RunSummary",
        doc: "The run's per-disc summary, one message at the end of the run. Topic /summary.",
        fields: &[
            f(
                "t_end_s",
                1,
                Double,
                "simulated time at the end of the run, s",
            ),
            rep(
                "discs",
                2,
                FieldType::Message("DiscSummary"),
                "one entry per disc, in scene order",
            ),
        ],
    },
    MessageDef {
        name: "LoadSample",
        doc: "One disc's per-tooth load at a regular sample or a step inside a contact, in time order. Topic /discs/<name>/load.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f(
                "load_n",
                2,
                Double,
                "per-tooth load, N (negative when the shaft leads)",
            ),
            f(
                "rel_angle_rad",
                3,
                Double,
                "phi = theta_shaft - theta_disc, rad (positive: the shaft leads)",
            ),
            f(
                "contact_step",
                4,
                Bool,
                "true: a step inside a contact; false: a regular sample",
            ),
            f(
                "disc_index",
                5,
                Uint32,
                "index of the disc in the scene, from 0",
            ),
        ],
    },
    MessageDef {
        name: "Temperature",
        doc: "A body's or the oil's temperature in a thermal run, at the end of each thermal window. Topics /discs/<name>/temperature, /oil/temperature.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f("temperature_k", 2, Double, "temperature, K"),
            f(
                "body_index",
                3,
                Uint32,
                "index of the body in the scene (the discs, then the plates), from 0; the oil's is the number of bodies",
            ),
        ],
    },
    MessageDef {
        name: "CouplingState",
        doc: "One coupling of a driveline network at one sample. Topics /network/couplings/<name>.",
        fields: &[
            f("t_s", 1, Double, "simulated time, s"),
            f(
                "torque_n_m",
                2,
                Double,
                "torque on its body a, N m (body b gets the opposite, through the ratio for a gear)",
            ),
            f(
                "slip_rad_s",
                3,
                Double,
                "a clutch's slip w_rel = omega_b - omega_a, rad/s (positive in mode slip+; 0 for other kinds)",
            ),
            f(
                "mode",
                4,
                FieldType::String,
                "a clutch's mode: free, slip+, slip- or locked (empty for other kinds)",
            ),
            f("locked", 5, Bool, "whether a clutch is locked"),
            f(
                "normal_force_n",
                6,
                Double,
                "a clutch's normal force, N (0 for other kinds)",
            ),
            f(
                "coupling_index",
                7,
                Uint32,
                "index of the coupling in the scene, from 0",
            ),
        ],
    },
];

fn json_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// The `FileDescriptorProto` of `clutchpack.proto` (proto3, package `clutchpack`, no imports).
pub(crate) fn file_descriptor() -> FileDescriptorProto {
    let message_type = MESSAGES
        .iter()
        .map(|m| DescriptorProto {
            name: Some(m.name.to_string()),
            field: m
                .fields
                .iter()
                .map(|fd| {
                    let (ty, type_name) = match fd.ty {
                        Double => (Type::Double, None),
                        Bool => (Type::Bool, None),
                        Uint32 => (Type::Uint32, None),
                        Uint64 => (Type::Uint64, None),
                        FieldType::String => (Type::String, None),
                        FieldType::Enum(n) => (Type::Enum, Some(format!(".{PACKAGE}.{n}"))),
                        FieldType::Message(n) => (Type::Message, Some(format!(".{PACKAGE}.{n}"))),
                    };
                    FieldDescriptorProto {
                        name: Some(fd.name.to_string()),
                        number: Some(fd.number),
                        label: Some(if fd.repeated {
                            Label::Repeated
                        } else {
                            Label::Optional
                        } as i32),
                        r#type: Some(ty as i32),
                        type_name,
                        json_name: Some(json_name(fd.name)),
                        ..Default::default()
                    }
                })
                .collect(),
            ..Default::default()
        })
        .collect();
    let enum_type = ENUMS
        .iter()
        .map(|e| EnumDescriptorProto {
            name: Some(e.name.to_string()),
            value: e
                .values
                .iter()
                .map(|&(n, v)| EnumValueDescriptorProto {
                    name: Some(n.to_string()),
                    number: Some(v),
                    options: None,
                })
                .collect(),
            ..Default::default()
        })
        .collect();
    FileDescriptorProto {
        name: Some(FILE_NAME.to_string()),
        package: Some(PACKAGE.to_string()),
        message_type,
        enum_type,
        syntax: Some("proto3".to_string()),
        ..Default::default()
    }
}

/// The encoded `FileDescriptorSet` holding [`file_descriptor`]: the schema data of every
/// `clutchpack.*` schema in a recording (MCAP schema encoding `protobuf`).
pub(crate) fn file_descriptor_set() -> Vec<u8> {
    FileDescriptorSet {
        file: vec![file_descriptor()],
    }
    .encode_to_vec()
}

/// The `.proto` text of our messages, generated from the tables (the content of
/// `crates/record/proto/clutchpack.proto`).
// Only the test that keeps `proto/clutchpack.proto` in step calls it.
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) fn proto_text() -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "// clutchpack recording messages. GENERATED from crates/record/src/proto.rs by its tests;\n\
         // edit the tables there, then run `UPDATE_PROTO=1 cargo test -p clutchpack_record`.\n\
         // Units are in the field names; times are simulated seconds.\n\
         syntax = \"proto3\";\n\npackage {PACKAGE};"
    );
    for e in ENUMS {
        let _ = writeln!(s, "\n// {}\nenum {} {{", e.doc, e.name);
        for (n, v) in e.values {
            let _ = writeln!(s, "  {n} = {v};");
        }
        s.push_str("}\n");
    }
    for m in MESSAGES {
        let _ = writeln!(s, "\n// {}\nmessage {} {{", m.doc, m.name);
        for fd in m.fields {
            let ty = match fd.ty {
                Double => "double",
                Bool => "bool",
                Uint32 => "uint32",
                Uint64 => "uint64",
                FieldType::String => "string",
                FieldType::Enum(n) | FieldType::Message(n) => n,
            };
            let label = if fd.repeated { "repeated " } else { "" };
            let _ = writeln!(
                s,
                "  {label}{ty} {} = {}; // {}",
                fd.name, fd.number, fd.doc
            );
        }
        s.push_str("}\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Splits an encoded message into its (field number, wire type) keys, top level only.
    fn keys(mut b: &[u8]) -> Vec<(u64, u64)> {
        fn varint(b: &mut &[u8]) -> u64 {
            let mut v = 0u64;
            let mut shift = 0;
            loop {
                let byte = b[0];
                *b = &b[1..];
                v |= u64::from(byte & 0x7f) << shift;
                if byte & 0x80 == 0 {
                    return v;
                }
                shift += 7;
            }
        }
        let mut out = Vec::new();
        while !b.is_empty() {
            let key = varint(&mut b);
            let (num, wt) = (key >> 3, key & 7);
            match wt {
                0 => {
                    varint(&mut b);
                }
                1 => b = &b[8..],
                2 => {
                    let n = varint(&mut b) as usize;
                    b = &b[n..];
                }
                5 => b = &b[4..],
                _ => panic!("unexpected wire type {wt}"),
            }
            out.push((num, wt));
        }
        out
    }

    fn wire_type(fd: &FieldDef) -> u64 {
        if fd.repeated {
            return 2; // packed scalars and messages are length-delimited
        }
        match fd.ty {
            Double => 1,
            Bool | Uint32 | Uint64 | FieldType::Enum(_) => 0,
            FieldType::String | FieldType::Message(_) => 2,
        }
    }

    fn check(name: &str, encoded: Vec<u8>) {
        let def = MESSAGES.iter().find(|m| m.name == name).unwrap();
        let got = keys(&encoded);
        let want: Vec<(u64, u64)> = def
            .fields
            .iter()
            .map(|fd| (fd.number as u64, wire_type(fd)))
            .collect();
        assert_eq!(
            got, want,
            "prost struct {name} disagrees with its descriptor table"
        );
    }

    /// The prost-derived encoders put every field of the descriptor tables under the same
    /// number and wire type (all fields set to non-default values, so all are encoded), so a
    /// decoder that trusts the embedded descriptor reads what we wrote.
    #[test]
    fn encoders_match_the_descriptor_tables() {
        check(
            "ShaftState",
            ShaftState {
                t_s: 1.0,
                angle_rad: 2.0,
                speed_rad_s: 3.0,
            }
            .encode_to_vec(),
        );
        check(
            "SplineState",
            SplineState {
                t_s: 1.0,
                rel_angle_rad: 2.0,
                closing_speed_m_s: 3.0,
                penetration_m: 4.0,
                load_n: 5.0,
                torque_n_m: 6.0,
                engaged: true,
                stiffness_n_m1_5: 8.0,
                speed_rad_s: 9.0,
                angle_rad: 10.0,
                disc_index: 11,
            }
            .encode_to_vec(),
        );
        check(
            "ToothLoads",
            ToothLoads {
                t_s: 1.0,
                loads_n: vec![1.0, 2.0],
                disc_index: 3,
            }
            .encode_to_vec(),
        );
        check(
            "InterfaceState",
            InterfaceState {
                t_s: 1.0,
                slip_rad_s: 2.0,
                slip_m_s: 3.0,
                mu: 4.0,
                clamp_n: 5.0,
                torque_n_m: 6.0,
                locked: true,
                interface_index: 8,
                dissipated_j: 9.0,
            }
            .encode_to_vec(),
        );
        check(
            "Impact",
            Impact {
                disc: "a".into(),
                disc_index: 2,
                t_on_s: 3.0,
                t_peak_s: 4.0,
                t_off_s: 5.0,
                flank: Flank::DiscLeads as i32,
                v_on_m_s: 7.0,
                peak_n: 8.0,
            }
            .encode_to_vec(),
        );
        check(
            "LoadSample",
            LoadSample {
                t_s: 1.0,
                load_n: 2.0,
                rel_angle_rad: 3.0,
                contact_step: true,
                disc_index: 5,
            }
            .encode_to_vec(),
        );
        check(
            "Temperature",
            Temperature {
                t_s: 1.0,
                temperature_k: 2.0,
                body_index: 3,
            }
            .encode_to_vec(),
        );
        check(
            "CouplingState",
            CouplingState {
                t_s: 1.0,
                torque_n_m: 2.0,
                slip_rad_s: 3.0,
                mode: "locked".into(),
                locked: true,
                normal_force_n: 6.0,
                coupling_index: 7,
            }
            .encode_to_vec(),
        );
        let ds = DiscSummary {
            name: "a".into(),
            index: 2,
            max_positive_n: 3.0,
            max_negative_n: -4.0,
            p99_abs_n: 5.0,
            impacts: 6,
            positive_impacts: 7,
            negative_impacts: 8,
            mean_top10_abs_n: 9.0,
            fatigue: true,
            damage_rate_per_h: 11.0,
            life_h: 12.0,
            eq_load_range_n: 13.0,
            max_root_stress_pa: 14.0,
            teeth: 15,
            worst_tooth: 16,
            worst_tooth_life_h: 17.0,
        };
        check("DiscSummary", ds.encode_to_vec());
        check(
            "RunSummary",
            SummaryMessage {
                t_end_s: 1.0,
                discs: vec![ds],
            }
            .encode_to_vec(),
        );
    }

    /// Every message and enum of the tables is in the descriptor, with full type names that
    /// resolve inside the file (a decoder builds its pool from this file alone).
    #[test]
    fn descriptor_is_self_contained() {
        let fd = file_descriptor();
        assert_eq!(fd.message_type.len(), MESSAGES.len());
        let known: Vec<String> = MESSAGES
            .iter()
            .map(|m| m.name)
            .chain(ENUMS.iter().map(|e| e.name))
            .map(|n| format!(".{PACKAGE}.{n}"))
            .collect();
        for m in &fd.message_type {
            for field in &m.field {
                if let Some(t) = &field.type_name {
                    assert!(known.contains(t), "{t} does not resolve");
                }
            }
        }
        let set = FileDescriptorSet::decode(file_descriptor_set().as_slice()).unwrap();
        assert_eq!(set.file, vec![fd]);
        for name in [
            SHAFT_STATE,
            SPLINE_STATE,
            TOOTH_LOADS,
            INTERFACE_STATE,
            IMPACT,
            RUN_SUMMARY,
            LOAD_SAMPLE,
            TEMPERATURE,
            COUPLING_STATE,
        ] {
            let short = name.strip_prefix("clutchpack.").unwrap();
            assert!(MESSAGES.iter().any(|m| m.name == short), "{name}");
        }
    }

    /// `proto/clutchpack.proto` is the text generated from the tables (set `UPDATE_PROTO=1`
    /// to rewrite it after a deliberate schema change).
    #[test]
    fn proto_file_is_up_to_date() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/proto/clutchpack.proto");
        let text = proto_text();
        if std::env::var_os("UPDATE_PROTO").is_some() {
            std::fs::write(path, &text).unwrap();
        }
        let on_disk = std::fs::read_to_string(path).unwrap_or_default();
        assert_eq!(on_disk, text, "{path} is stale: run with UPDATE_PROTO=1");
    }
}
