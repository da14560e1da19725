//! Topic names. A disc's topics use its *segment*: the scene name with every character other
//! than `A-Z a-z 0-9 _ -` replaced by `_` (see [`crate::topic_segment`]).

/// Body poses, `foxglove.FrameTransforms`.
pub const TF: &str = "/tf";
/// The pack's static geometry, `foxglove.SceneUpdate`: one message at t = 0 and nothing
/// after it, so that "the latest message" of this topic is always the whole pack.
pub const SCENE: &str = "/scene";
/// Load colours over the teeth, `foxglove.SceneUpdate`: every message holds every disc's
/// colour, so that its latest message restores them all.
pub const SCENE_LOADS: &str = "/scene/loads";
/// The spline couplings as joints, `sensor_msgs/msg/JointState` (ROS 2, CDR), one message
/// per sample: one joint per disc, named by the disc; `position` = `rel_angle_rad`,
/// `velocity` = shaft minus disc speed in rad/s, `effort` = `load_n` (N per tooth). For
/// viewers that plot well-known messages without configuration (Rerun: a time series per
/// field, one line per disc).
pub const JOINTS: &str = "/joints";
/// Prefix of the point-cloud pack (`foxglove.PointCloud`, one per body, at t = 0), for
/// viewers that draw point clouds but not `foxglove.SceneUpdate` (Rerun).
pub const PACK_PREFIX: &str = "/pack/";

/// `/pack/<frame>`: the point cloud of the body whose frame is `frame` (`shaft`,
/// `disc/<segment>`).
pub fn pack(frame: &str) -> String {
    format!("{PACK_PREFIX}{frame}")
}

/// Shaft angle and speed, `clutchpack.ShaftState`.
pub const SHAFT: &str = "/shaft";
/// Impact events, `clutchpack.Impact`.
pub const IMPACTS: &str = "/impacts";
/// Per-disc summary of the run, `clutchpack.RunSummary`: written when the run ends, logged
/// at t = 0 so that a viewer shows it from the start.
pub const SUMMARY: &str = "/summary";
/// Prefix of the per-disc topics.
pub const DISCS_PREFIX: &str = "/discs/";

/// `/discs/<segment>/spline`, `clutchpack.SplineState`.
pub fn spline(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/spline")
}

/// `/discs/<segment>/impacts`, `clutchpack.Impact`: the disc's impacts, each logged at its
/// peak time `t_peak_s` with its exact located peak load `peak_n` (the same messages as on
/// [`IMPACTS`]), so that a plot of `peak_n` shows the true peaks that the sampled `load_n`
/// can miss (a contact lasts about as long as a sample interval).
pub fn disc_impacts(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/impacts")
}

/// `/discs/<segment>/load`, `clutchpack.LoadSample`: the disc's per-tooth load at the
/// engine's steps inside each contact (about 30 points per contact:
/// [`clutchpack_model::Observer::contact_sample`]) and at the samples with a load (and the
/// first; between contacts the load is 0), in time order: the one series whose plot shows
/// each contact pulse's shape and reaches its located peak (within 0.3 % on the paper case), where the sampled `load_n` of [`spline`] under-reads by 10-25 %. Written
/// unless the recording was made without contact samples
/// ([`crate::RecordOptions::contact_samples`]).
pub fn load(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/load")
}

/// `/discs/<segment>/temperature`, `clutchpack.Temperature`: a thermal run's body
/// temperature in K at the end of each thermal window (MODEL.md section 9).
pub fn temperature(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/temperature")
}

/// A thermal run's oil temperature in K, `clutchpack.Temperature`.
pub const OIL_TEMPERATURE: &str = "/oil/temperature";
/// A thermal run's temperature colours, `foxglove.SceneUpdate`: every message colours the
/// faces of every body and carries the legend (the range and the oil's temperature), so that
/// its latest message restores them all.
pub const SCENE_TEMPERATURES: &str = "/scene/temperatures";

/// `/discs/<segment>/teeth`, `clutchpack.ToothLoads`.
pub fn teeth(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/teeth")
}

/// Prefix of the friction interfaces' topics.
pub const INTERFACES_PREFIX: &str = "/interfaces/";

/// `/interfaces/<segment>`, `clutchpack.InterfaceState`; the segment of an interface is
/// `<lower>__<upper>` of its two bodies' segments (see [`crate::FrictionInterface`]).
pub fn interface(segment: &str) -> String {
    format!("{INTERFACES_PREFIX}{segment}")
}

/// Prefix of a network recording's topics (MODEL.md section 8).
pub const NETWORK_PREFIX: &str = "/network/";

/// `/network/bodies/<segment>`, `clutchpack.ShaftState`: a network body's angle and speed at
/// each sample (every body of a driveline is a shaft).
pub fn network_body(segment: &str) -> String {
    format!("{NETWORK_PREFIX}bodies/{segment}")
}

/// `/network/couplings/<segment>`, `clutchpack.CouplingState`: a coupling's torque, and a
/// clutch's slip, mode and normal force, at each sample.
pub fn network_coupling(segment: &str) -> String {
    format!("{NETWORK_PREFIX}couplings/{segment}")
}

/// `/network/packs/<segment>/joints`, `sensor_msgs/msg/JointState` (ROS 2, CDR): a resolved
/// pack's discs and plates at each sample, one joint per body named as in its pack file
/// (discs, then plates): `position` = its angle (rad, absolute), `velocity` = its speed
/// (rad/s), `effort` = its per-tooth spline load (N, signed as the impacts'), so that the
/// viewers plot every disc's load as they plot a pack run's [`JOINTS`].
pub fn network_pack_joints(segment: &str) -> String {
    format!("{NETWORK_PREFIX}packs/{segment}/joints")
}

/// `/network/packs/<segment>/temperature/<body>`, `clutchpack.Temperature`: a thermal
/// resolved pack's body's temperature in K (`<body>` its segment; the oil's is `oil`) at t = 0
/// and at the end of each thermal window (MODEL.md section 9).
pub fn network_pack_temperature(pack: &str, body: &str) -> String {
    format!("{NETWORK_PREFIX}packs/{pack}/temperature/{body}")
}

/// A network's clutch mode changes, `foxglove.Log` (one line each, at its instant:
/// `K2: slip+ -> locked`).
pub const NETWORK_EVENTS: &str = "/network/events";
/// A network's gear-mesh tooth impacts, `clutchpack.Impact` (`disc` = the mesh's name,
/// `disc_index` = its coupling index), each at its peak time.
pub const NETWORK_IMPACTS: &str = "/network/impacts";
/// A network's tooth contacts still open, `clutchpack.Impact` named as on
/// [`NETWORK_IMPACTS`], each as it would close at the instant it is logged (`t_off_s`, its
/// peak so far), every [`crate::OPEN_CONTACTS_EVERY_S`] of simulated time: what a run cut
/// short (a kill) keeps of contacts that last (a locked pack's teeth carry its torque for
/// seconds); a contact's closed impact supersedes them (`read_network`).
pub const NETWORK_CONTACTS: &str = "/network/contacts";
/// A network's bodies as joints, `sensor_msgs/msg/JointState` (ROS 2, CDR), one message per
/// sample: `position` = angle (rad), `velocity` = speed (rad/s), for Rerun.
pub const NETWORK_BODY_JOINTS: &str = "/network/joints/bodies";
/// A network's couplings as joints, `sensor_msgs/msg/JointState`: `velocity` = a clutch's
/// slip `omega_b - omega_a` (rad/s), `effort` = the torque on body `a` (N m). The same topic as a pack's
/// [`JOINTS`] (a coupling is the joint between its two bodies, as a disc's spline is), so
/// that the viewers' ready plots of `/joints` show the couplings' torques.
pub const NETWORK_COUPLING_JOINTS: &str = JOINTS;
/// The couplings drawn between the bodies, `foxglove.SceneUpdate`: at t = 0, then whenever a
/// clutch changes mode (each message draws every coupling, coloured by its mode).
pub const NETWORK_SCENE_COUPLINGS: &str = "/scene/couplings";
/// An automatic's status over the scene, `foxglove.SceneUpdate`: the gear engaged and, during
/// a shift, its phase (`gear 1 · shift 1 -> 2: torque phase`), at t = 0 and whenever it
/// changes (the same line goes to [`NETWORK_EVENTS`]). Only in a recording of a scene with a
/// `[transmission]`.
pub const NETWORK_SCENE_STATUS: &str = "/scene/status";
/// The couplings' diagram as points in the world frame, `foxglove.PointCloud`, for Rerun
/// (which does not draw scene updates): at t = 0 and with each [`NETWORK_SCENE_COUPLINGS`].
pub const NETWORK_DIAGRAM_POINTS: &str = "/pack/network/couplings";
