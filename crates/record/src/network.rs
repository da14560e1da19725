//! Recording a driveline network's run (MODEL.md section 8): the network part of the
//! [`crate::Recorder`] writes an MCAP file with every body's angle and speed, every coupling's torque (a clutch's slip,
//! mode and normal force too), the clutches' mode changes as log lines, the gear meshes'
//! impacts, and a 3D view of the bodies turning side by side with the couplings drawn between
//! them and coloured by mode. The file's header, scene attachment and metadata are the pack
//! recordings' ([`crate::sink::Sink`]), so `clutchpack replay` tells its provenance the
//! same way; `clutchpack.run` has `kind = network`, and `clutchpack.network` names the bodies
//! and couplings.
//!
//! Topics (log time = simulated time in ns):
//!
//! | topic | schema | when |
//! | --- | --- | --- |
//! | `/network/bodies/<segment>` | `clutchpack.ShaftState` | each sample |
//! | `/network/couplings/<segment>` | `clutchpack.CouplingState` | each sample |
//! | `/joints` (couplings: slip, torque), `/network/joints/bodies` (angle, speed) | `sensor_msgs/msg/JointState` | each sample (Rerun, Lichtblick) |
//! | `/network/packs/<segment>/joints` | `sensor_msgs/msg/JointState` | each sample: a resolved pack's discs and plates (angle, speed, per-tooth load) |
//! | `/network/packs/<segment>/temperature/<body>` | `clutchpack.Temperature` | a thermal pack's bodies and oil (`oil`), at t = 0 and each thermal window's end |
//! | `/network/events` | `foxglove.Log` | each clutch mode change, at its instant |
//! | `/network/impacts` | `clutchpack.Impact` | each gear-mesh impact and each tooth impact of a pack's disc or plate (`<pack>/discs/<disc>`, `<pack>/plates/<plate>`), logged when its contact closes (in time order; the message holds its peak's time) |
//! | `/network/contacts` | `clutchpack.Impact` | every [`OPEN_CONTACTS_EVERY_S`]: each contact still open, as it would close then (named as the impacts; superseded by its impact when it closes; what a killed run keeps of contacts that last) |
//! | `/tf` | `foxglove.FrameTransforms` | each sample: `world` -> `row/0` -> `row/1` ..., `row/<i>` -> `body/<segment>`; a pack's rings on their carrier's place; each planetary set's `planetary/<set>/set` (chained) -> its sun, ring and carrier -> its planets ([`crate::network_view`]) |
//! | `/scene` | `foxglove.SceneUpdate` | t = 0: every body as a disc with a marker and its name; the packs' rings; the planetary sets |
//! | `/scene/couplings` | `foxglove.SceneUpdate` | t = 0 and at each mode change: the couplings' diagram |
//! | `/scene/status` | `foxglove.SceneUpdate` | an automatic's gear and shift phase, at t = 0 and at each change (a scene with a `[transmission]`) |
//! | `/pack/body/<segment>`, `/pack/planetary/<set>/<part>`, `/pack/pack/<pack>/<body>` | `foxglove.PointCloud` | t = 0: each body, gearset part and pack ring as points, for Rerun |
//! | `/pack/network/couplings` | `foxglove.PointCloud` | the couplings' diagram as points (Rerun), with `/scene/couplings` |
//!
//! The summary of the run (the JSON of `run --summary-json`) is attached at the end as
//! `summary.json`.

use crate::info::{num, RunInfo};
use crate::network_view::{Status, View, DRAWN_THICKNESS_M};
use crate::sink::{MoreMetadata, Sink};
use crate::view3d::{entity, pose, rgba, timestamp, v3};
use crate::write::{unique_segments, RecordError, RecordOptions};
use crate::{log_time_ns, proto, ros2, topics};
use clutchpack_model::network::{
    ClutchEvent, ClutchMode, CouplingKind, Network, NetworkSample, Transmission,
};
use clutchpack_model::ImpactEvent;
use foxglove::schemas::{
    CubePrimitive, CylinderPrimitive, FrameTransforms, Log, SceneUpdate, TextPrimitive,
};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// How often a network recording logs its open tooth contacts (`/network/contacts`), s of
/// simulated time: a killed run's recording then holds every contact to within this of its
/// last sample (a locked pack's contacts last for the rest of the run; without them the
/// impacts of a run killed at 10 s ended where its last contact closed, 2.33 s into
/// `dct-upshift`). About 20 open contacts every 0.05 s: a percent of its samples' messages.
pub const OPEN_CONTACTS_EVERY_S: f64 = 0.05;

/// Name of the `clutchpack.network` metadata record (bodies and couplings, in scene order).
pub const META_NETWORK: &str = "clutchpack.network";
/// Name of the attachment holding a network run's summary (JSON), written by
/// [`crate::Recorder::finish`] ([`crate::Recorder::set_summary_json`]).
pub const SUMMARY_ATTACHMENT: &str = "summary.json";

/// The name of a tooth impact on `/network/impacts`: a gear mesh's (`body` `None`) its
/// coupling's name; a pack's disc's or plate's (`body` its index in the pack, discs then
/// plates) `<pack>/discs/<disc>` or `<pack>/plates/<plate>`.
pub fn impact_name(net: &Network, coupling: usize, body: Option<usize>) -> String {
    let Some(c) = net.couplings.get(coupling) else {
        return format!("coupling {coupling}");
    };
    match (body, c.law().own_bodies()) {
        (Some(i), Some(own)) => {
            let body = own.iter().nth(i);
            format!(
                "{}/{}/{}",
                c.name,
                own.role(i),
                body.map_or("?", |d| d.name.as_str())
            )
        }
        _ => c.name.clone(),
    }
}

/// A coupling's kind as the summary names it.
pub fn coupling_kind_name(kind: &CouplingKind) -> &'static str {
    kind.law().kind_name()
}

/// The `clutchpack.network` metadata: `bodies`, `couplings` (counts), `body.<i>.name`,
/// `body.<i>.inertia_kg_m2`, `body.<i>.fixed`, `coupling.<k>.name`, `.kind`, `.a`, `.b`
/// (body names).
fn network_metadata(net: &Network) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("bodies".into(), net.bodies.len().to_string());
    m.insert("couplings".into(), net.couplings.len().to_string());
    for (i, b) in net.bodies.iter().enumerate() {
        m.insert(format!("body.{i}.name"), b.name.clone());
        m.insert(format!("body.{i}.inertia_kg_m2"), num(b.inertia_kg_m2));
        m.insert(format!("body.{i}.fixed"), b.is_fixed().to_string());
    }
    for (k, c) in net.couplings.iter().enumerate() {
        m.insert(format!("coupling.{k}.name"), c.name.clone());
        m.insert(
            format!("coupling.{k}.kind"),
            coupling_kind_name(&c.kind).into(),
        );
        m.insert(format!("coupling.{k}.a"), net.bodies[c.a].name.clone());
        m.insert(format!("coupling.{k}.b"), net.bodies[c.b].name.clone());
    }
    m
}

struct Channels {
    bodies: Vec<u16>,
    couplings: Vec<u16>,
    body_joints: u16,
    coupling_joints: u16,
    events: u16,
    impacts: u16,
    contacts: u16,
    tf: u16,
    scene: u16,
    scene_couplings: u16,
    /// The `foxglove.SceneUpdate` schema's id (for the status channel added later).
    scene_schema: u16,
    /// Per resolved pack (by coupling): its joints' channel and its bodies' names.
    pack_joints: BTreeMap<usize, (u16, Vec<String>)>,
    /// Per thermal resolved pack (by coupling): its bodies' temperature channels, then its
    /// oil's.
    pack_temperatures: BTreeMap<usize, Vec<u16>>,
}

/// The network part of the [`crate::Recorder`]: a network run streamed into an MCAP file
/// (its [`clutchpack_model::Observer`] methods call the `write_*` methods here), then
/// [`Self::finish`] (also after a stop or an engine error: the file then holds what ran).
pub(crate) struct NetworkPart {
    /// The file, its writer and the messages' bookkeeping (shared with the pack part).
    pub(crate) sink: Sink,
    net: Network,
    ch: Channels,
    body_names: Vec<String>,
    coupling_names: Vec<String>,
    /// the 3D view's layout, the couplings' diagram and the planetary sets
    view: View,
    /// an automatic's gear and shift phase, with the channel it goes on and the line last
    /// written
    status: Option<(Status, u16, String)>,
    /// the couplings' diagram as points (Rerun), redrawn with `/scene/couplings`
    diagram_points: u16,
    /// each resolved pack's faces' mode as last told ([`Self::set_pack_mode`]; `None` for
    /// another coupling), drawn and read for the gear as a clutch's
    pack_modes: Vec<Option<ClutchMode>>,
    /// the modes of the sample being written (a clutch's, else a pack's faces')
    modes_now: Vec<Option<ClutchMode>>,
    /// each body's frame (`body/<segment>`)
    frames: Vec<String>,
    tf: FrameTransforms,
    /// the resolved packs' discs and plates in 3D
    packs: crate::network_packs::PacksDrawing,
    /// the clutch modes last drawn in `/scene/couplings`
    drawn_modes: Vec<Option<ClutchMode>>,
    /// `/network/joints/*` values, reused: the bodies' angles and speeds, the couplings'
    /// slips and torques
    joint_values: [Vec<f64>; 4],
    last_t_s: f64,
    deterministic: bool,
    /// When the open tooth contacts are logged next, s ([`OPEN_CONTACTS_EVERY_S`]).
    open_contacts_at_s: f64,
    /// The run's summary (JSON) attached by [`Self::finish`], if given.
    pub(crate) summary_json: Option<Vec<u8>>,
}

impl NetworkPart {
    /// What a network's recording opens its [`Sink`] with: `info` with `kind = network`,
    /// the chunk size (`options`' or 1 MiB) and the `clutchpack.network` metadata of `net`.
    pub fn sink_setup(
        info: &RunInfo,
        net: &Network,
        options: &RecordOptions,
    ) -> (RunInfo, u64, MoreMetadata) {
        let mut kinds = info.clone();
        kinds.params.insert("kind".into(), "network".into());
        let chunk = options.chunk_size_bytes.unwrap_or(1 << 20);
        (
            kinds,
            chunk,
            vec![(META_NETWORK.to_string(), network_metadata(net))],
        )
    }

    /// Writes the channels and the static scene of `net` into `sink` (opened with
    /// [`Self::sink_setup`]); of `options` the determinism applies here.
    pub fn start(
        mut sink: Sink,
        net: &Network,
        options: &RecordOptions,
    ) -> Result<NetworkPart, RecordError> {
        let path = sink.path.clone();
        // the writer is put back once the channels are added
        let Some(mut w) = sink.writer.take() else {
            return Err(sink.failed_err());
        };
        let write_err = |what: &str, cause| RecordError::Write {
            path: path.clone(),
            what: what.to_string(),
            cause,
        };
        let fds = proto::file_descriptor_set();
        use foxglove::Encode as _;
        let fx = |s: Option<foxglove::Schema>| s.map(|s| s.data.into_owned()).unwrap_or_default();
        let schema = |w: &mut mcap::Writer<_>, name: &str, enc: &str, data: &[u8]| {
            w.add_schema(name, enc, data)
                .map_err(|e| write_err("schema", e))
        };
        let s_body = schema(&mut w, proto::SHAFT_STATE, "protobuf", &fds)?;
        let s_coupling = schema(&mut w, proto::COUPLING_STATE, "protobuf", &fds)?;
        let s_impact = schema(&mut w, proto::IMPACT, "protobuf", &fds)?;
        let s_log = schema(
            &mut w,
            "foxglove.Log",
            "protobuf",
            &fx(foxglove::schemas::Log::get_schema()),
        )?;
        let s_tf = schema(
            &mut w,
            "foxglove.FrameTransforms",
            "protobuf",
            &fx(FrameTransforms::get_schema()),
        )?;
        let s_scene = schema(
            &mut w,
            "foxglove.SceneUpdate",
            "protobuf",
            &fx(SceneUpdate::get_schema()),
        )?;
        let s_joints = schema(
            &mut w,
            ros2::JOINT_STATE,
            "ros2msg",
            ros2::JOINT_STATE_SCHEMA.as_bytes(),
        )?;
        let channel = |w: &mut mcap::Writer<_>,
                       schema_id: u16,
                       topic: &str,
                       enc: &str,
                       meta: BTreeMap<String, String>| {
            w.add_channel(schema_id, topic, enc, &meta)
                .map_err(|e| write_err("channel", e))
        };
        let body_names: Vec<String> = net.bodies.iter().map(|b| b.name.clone()).collect();
        let coupling_names: Vec<String> = net.couplings.iter().map(|c| c.name.clone()).collect();
        let body_segments = unique_segments(&body_names);
        let coupling_segments = unique_segments(&coupling_names);
        let mut bodies = Vec::with_capacity(body_names.len());
        for (i, (name, seg)) in body_names.iter().zip(&body_segments).enumerate() {
            let meta = [
                ("body".to_string(), name.clone()),
                ("body_index".to_string(), i.to_string()),
            ]
            .into();
            bodies.push(channel(
                &mut w,
                s_body,
                &topics::network_body(seg),
                "protobuf",
                meta,
            )?);
        }
        let mut couplings = Vec::with_capacity(coupling_names.len());
        for (k, (c, seg)) in net.couplings.iter().zip(&coupling_segments).enumerate() {
            let meta = [
                ("coupling".to_string(), c.name.clone()),
                ("coupling_index".to_string(), k.to_string()),
                ("kind".to_string(), coupling_kind_name(&c.kind).to_string()),
            ]
            .into();
            couplings.push(channel(
                &mut w,
                s_coupling,
                &topics::network_coupling(seg),
                "protobuf",
                meta,
            )?);
        }
        let none = BTreeMap::new;
        let mut pack_joints = BTreeMap::new();
        for (k, (c, seg)) in net.couplings.iter().zip(&coupling_segments).enumerate() {
            if let Some(own) = c.law().own_bodies() {
                let topic = topics::network_pack_joints(seg);
                let id = channel(&mut w, s_joints, &topic, "cdr", none())?;
                pack_joints.insert(k, (id, own.names()));
            }
        }
        let mut pack_temperatures = BTreeMap::new();
        if !net.pack_thermal.is_empty() {
            let s_temp = schema(&mut w, proto::TEMPERATURE, "protobuf", &fds)?;
            for (&k, seg) in net
                .pack_thermal
                .keys()
                .zip(net.pack_thermal.keys().map(|&k| &coupling_segments[k]))
            {
                let Some(own) = net.couplings[k].law().own_bodies() else {
                    continue;
                };
                let names = own.names();
                let mut ids = Vec::with_capacity(names.len() + 1);
                for body in unique_segments(&names)
                    .iter()
                    .map(String::as_str)
                    .chain(["oil"])
                {
                    let topic = topics::network_pack_temperature(seg, body);
                    ids.push(channel(&mut w, s_temp, &topic, "protobuf", none())?);
                }
                pack_temperatures.insert(k, ids);
            }
        }
        let ch = Channels {
            pack_temperatures,
            pack_joints,
            bodies,
            couplings,
            body_joints: channel(&mut w, s_joints, topics::NETWORK_BODY_JOINTS, "cdr", none())?,
            coupling_joints: channel(
                &mut w,
                s_joints,
                topics::NETWORK_COUPLING_JOINTS,
                "cdr",
                none(),
            )?,
            events: channel(&mut w, s_log, topics::NETWORK_EVENTS, "protobuf", none())?,
            impacts: channel(
                &mut w,
                s_impact,
                topics::NETWORK_IMPACTS,
                "protobuf",
                none(),
            )?,
            contacts: channel(
                &mut w,
                s_impact,
                topics::NETWORK_CONTACTS,
                "protobuf",
                none(),
            )?,
            tf: channel(&mut w, s_tf, topics::TF, "protobuf", none())?,
            scene: channel(&mut w, s_scene, topics::SCENE, "protobuf", none())?,
            scene_schema: s_scene,
            scene_couplings: channel(
                &mut w,
                s_scene,
                topics::NETWORK_SCENE_COUPLINGS,
                "protobuf",
                none(),
            )?,
        };
        let s_cloud = schema(
            &mut w,
            "foxglove.PointCloud",
            "protobuf",
            &fx(foxglove::schemas::PointCloud::get_schema()),
        )?;
        let mut clouds = Vec::with_capacity(body_segments.len());
        for seg in &body_segments {
            let topic = format!("{}{}", topics::PACK_PREFIX, body_frame(seg));
            clouds.push(channel(&mut w, s_cloud, &topic, "protobuf", none())?);
        }
        let view = View::new(net);
        let diagram_points = channel(
            &mut w,
            s_cloud,
            topics::NETWORK_DIAGRAM_POINTS,
            "protobuf",
            none(),
        )?;
        let mut set_clouds = Vec::new();
        let packs = crate::network_packs::PacksDrawing::new(net, &view.radii, DRAWN_THICKNESS_M);
        for (frame, c) in view.set_clouds().into_iter().chain(packs.clouds()) {
            let topic = format!("{}{frame}", topics::PACK_PREFIX);
            set_clouds.push((channel(&mut w, s_cloud, &topic, "protobuf", none())?, c));
        }
        let frames: Vec<String> = body_segments.iter().map(|s| body_frame(s)).collect();
        let mut tf = FrameTransforms::default();
        view.transforms(&frames, 0, &vec![0.0; frames.len()], &mut tf.transforms);
        let n = body_names.len();
        let m = coupling_names.len();
        sink.writer = Some(w);
        let mut rec = NetworkPart {
            packs,
            sink,
            net: net.clone(),
            ch,
            body_names,
            coupling_names,
            view,
            status: None,
            diagram_points,
            frames: frames.clone(),
            pack_modes: net
                .couplings
                .iter()
                .map(|c| c.law().session_mode())
                .collect(),
            modes_now: Vec::with_capacity(m),
            tf,
            drawn_modes: net
                .couplings
                .iter()
                .map(|c| c.law().initial_mode().or(c.law().session_mode()))
                .collect(),
            joint_values: [vec![0.0; n], vec![0.0; n], vec![0.0; m], vec![0.0; m]],
            last_t_s: 0.0,
            deterministic: options.deterministic,
            open_contacts_at_s: 0.0,
            summary_json: None,
        };
        let scene = rec.static_scene(&frames);
        rec.sink.put(rec.ch.scene, 0, &scene, "/scene")?;
        let radii = rec.view.radii.clone();
        for ((ch, frame), &r) in clouds.into_iter().zip(&frames).zip(&radii) {
            rec.sink.put(ch, 0, &body_points(frame, r), "body points")?;
        }
        for (ch, c) in set_clouds {
            rec.sink
                .put(ch, 0, &c, "planetary set and pack ring points")?;
        }
        rec.put_couplings(0)?;
        Ok(rec)
    }

    /// Every body as a disc in its frame, with a marker on its rim (so its rotation shows)
    /// and its name above it.
    fn static_scene(&self, frames: &[String]) -> SceneUpdate {
        let mut entities: Vec<_> = frames
            .iter()
            .zip(&self.view.radii)
            .zip(&self.net.bodies)
            .map(|((frame, &r), b)| {
                let mut e = entity(0, frame, frame);
                let grey = if b.is_fixed() { 0.35 } else { 0.62 };
                e.cylinders.push(CylinderPrimitive {
                    pose: pose(0.0, 0.0, 0.0, 0.0),
                    size: Some(v3(2.0 * r, 2.0 * r, DRAWN_THICKNESS_M)),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: rgba(grey, grey * 0.8, grey * 0.55, 1.0),
                });
                e.cubes.push(CubePrimitive {
                    pose: pose(0.8 * r, 0.0, 0.0, 0.0),
                    size: Some(v3(0.3 * r, 0.12 * r, DRAWN_THICKNESS_M * 1.5)),
                    color: rgba(0.1, 0.1, 0.1, 1.0),
                });
                e.texts.push(TextPrimitive {
                    pose: pose(0.0, 0.0, 0.05 + DRAWN_THICKNESS_M, 0.0),
                    billboard: true,
                    font_size: 14.0,
                    scale_invariant: true,
                    color: rgba(1.0, 1.0, 1.0, 1.0),
                    text: b.name.clone(),
                });
                e
            })
            .collect();
        entities.extend(self.packs.entities());
        entities.extend(self.view.set_entities());
        SceneUpdate {
            deletions: Vec::new(),
            entities,
        }
    }

    /// The couplings' diagram at `log_time_ns` as the modes last drawn: `/scene/couplings` and
    /// its points.
    fn put_couplings(&mut self, log_time_ns: u64) -> Result<(), RecordError> {
        let scene = self
            .view
            .coupling_scene(&self.net, &self.drawn_modes, log_time_ns);
        self.sink.put(
            self.ch.scene_couplings,
            log_time_ns,
            &scene,
            "/scene/couplings",
        )?;
        let mut points = self.view.coupling_points(&self.net, &self.drawn_modes);
        points.timestamp = Some(timestamp(log_time_ns));
        self.sink.put(
            self.diagram_points,
            log_time_ns,
            &points,
            "couplings' points",
        )
    }

    /// Shows `tr`'s gear and shift phase over the scene from now on (a scene with a
    /// `[transmission]`): a text on `/scene/status` and a line on `/network/events` at t = 0
    /// and whenever it changes.
    pub fn set_transmission(&mut self, tr: &Transmission) -> Result<(), RecordError> {
        let id = match self.sink.writer.as_mut() {
            Some(w) => {
                let s_scene = self.ch.scene_schema;
                w.add_channel(
                    s_scene,
                    topics::NETWORK_SCENE_STATUS,
                    "protobuf",
                    &BTreeMap::new(),
                )
                .map_err(|cause| RecordError::Write {
                    path: self.sink.path.clone(),
                    what: "channel".into(),
                    cause,
                })?
            }
            None => {
                return Err(RecordError::AlreadyFailed {
                    path: self.sink.path.clone(),
                })
            }
        };
        self.status = Some((Status::new(tr), id, String::new()));
        self.put_status(self.last_t_s)
    }

    /// Writes the status line at `t_s` if it changed.
    fn put_status(&mut self, t_s: f64) -> Result<(), RecordError> {
        let Some((status, id, last)) = &self.status else {
            return Ok(());
        };
        let label = status.label(t_s, &self.drawn_modes);
        if label == *last {
            return Ok(());
        }
        let id = *id;
        let ns = log_time_ns(t_s);
        let y = self.view.lanes_y_m();
        let z = self.view.bottom_m(self.net.couplings.len()) - 0.35;
        let scene = Status::scene(&label, y, z, ns);
        self.sink.put(id, ns, &scene, "/scene/status")?;
        let log = Log {
            timestamp: Some(timestamp(ns)),
            level: foxglove::schemas::log::Level::Info as i32,
            message: label.clone(),
            name: "clutchpack".into(),
            file: String::new(),
            line: 0,
        };
        self.sink.put(self.ch.events, ns, &log, "/network/events")?;
        if let Some((_, _, last)) = &mut self.status {
            *last = label;
        }
        Ok(())
    }

    /// A resolved pack's faces changed mode (as a clutch's: all locked, some clamped, none):
    /// from the next sample its wire is coloured so and the automatic's gear reads it.
    pub fn set_pack_mode(&mut self, coupling: usize, mode: ClutchMode) {
        if let Some(m) = self.pack_modes.get_mut(coupling) {
            *m = Some(mode);
        }
    }

    /// Whether the recording is deterministic (`RecordOptions::deterministic`: no wall times,
    /// so that two runs give the same bytes).
    pub fn deterministic(&self) -> bool {
        self.deterministic
    }

    /// Writes one sample: each body's and coupling's topic, the joints, `/tf`.
    pub fn write_sample(&mut self, s: &NetworkSample) -> Result<(), RecordError> {
        let t = s.t_s;
        let ns = log_time_ns(t);
        self.last_t_s = t;
        for i in 0..self.ch.bodies.len() {
            let msg = proto::ShaftState {
                t_s: t,
                angle_rad: s.angle_rad[i],
                speed_rad_s: s.speed_rad_s[i],
            };
            self.sink.put(self.ch.bodies[i], ns, &msg, "body state")?;
        }
        for k in 0..self.ch.couplings.len() {
            let c = &self.net.couplings[k];
            let mode = s.mode[k];
            let msg = proto::CouplingState {
                t_s: t,
                torque_n_m: s.torque_n_m[k],
                slip_rad_s: clutch_slip_rad_s(s, c, k),
                mode: mode.map(|m| m.label().to_string()).unwrap_or_default(),
                locked: mode == Some(ClutchMode::Locked),
                normal_force_n: c.law().clamp_force_n(t).unwrap_or(0.0),
                coupling_index: k as u32,
            };
            self.sink
                .put(self.ch.couplings[k], ns, &msg, "coupling state")?;
        }
        let [angles, speeds, _, _] = &mut self.joint_values;
        angles.copy_from_slice(&s.angle_rad);
        speeds.copy_from_slice(&s.speed_rad_s);
        ros2::joint_state(
            &mut self.sink.buf,
            ns,
            &self.body_names,
            angles,
            speeds,
            &[],
        );
        self.sink.put_buf(self.ch.body_joints, ns, "body joints")?;
        let [_, _, slips, torques] = &mut self.joint_values;
        for (k, c) in self.net.couplings.iter().enumerate() {
            slips[k] = clutch_slip_rad_s(s, c, k);
        }
        torques.copy_from_slice(&s.torque_n_m);
        ros2::joint_state(
            &mut self.sink.buf,
            ns,
            &self.coupling_names,
            &[],
            slips,
            torques,
        );
        self.sink
            .put_buf(self.ch.coupling_joints, ns, "coupling joints")?;
        self.view
            .transforms(&self.frames, ns, &s.angle_rad, &mut self.tf.transforms);
        let tf = std::mem::take(&mut self.tf);
        let r = self.sink.put(self.ch.tf, ns, &tf, "/tf");
        self.tf = tf;
        r?;
        self.modes_now.clear();
        let packs = &self.pack_modes;
        self.modes_now
            .extend(s.mode.iter().zip(packs).map(|(m, p)| m.or(*p)));
        if self.modes_now != self.drawn_modes {
            self.drawn_modes.clone_from(&self.modes_now);
            self.put_couplings(ns)?;
        }
        self.put_status(t)
    }

    /// Writes a clutch's mode change as a log line on `/network/events`.
    pub fn write_clutch_event(&mut self, e: &ClutchEvent) -> Result<(), RecordError> {
        let ns = log_time_ns(e.t_s);
        let msg = Log {
            timestamp: Some(timestamp(ns)),
            level: foxglove::schemas::log::Level::Info as i32,
            message: format!(
                "{}: {} -> {} at t = {:.6} s",
                self.coupling_names
                    .get(e.coupling)
                    .map_or("?", String::as_str),
                e.from.label(),
                e.to.label(),
                e.t_s
            ),
            name: "clutchpack".into(),
            file: String::new(),
            line: 0,
        };
        self.sink.put(self.ch.events, ns, &msg, "/network/events")
    }

    /// Writes the tooth impact of a resolved pack's disc or plate on `/network/impacts`,
    /// logged when its contact closes (the message holds its peak), named
    /// `<pack>/discs/<disc>` or `<pack>/plates/<plate>` (`coupling` the pack's index; `disc`
    /// of the event the body's index in the pack, its discs then its plates).
    pub fn write_pack_impact(
        &mut self,
        coupling: usize,
        e: &ImpactEvent,
    ) -> Result<(), RecordError> {
        let msg = proto::Impact::of(e, impact_name(&self.net, coupling, Some(e.disc)));
        self.sink.put(
            self.ch.impacts,
            log_time_ns(e.t_off_s),
            &msg,
            "/network/impacts",
        )
    }

    /// Writes the resolved pack that is coupling `coupling` at `t_s` (s), its discs' then
    /// plates' angles `angle_rad` (rad), speeds `speed_rad_s` (rad/s) and per-tooth loads
    /// `load_n` (N): its joints, and its rings' frames on `/tf`.
    pub fn write_pack_sample(
        &mut self,
        coupling: usize,
        t_s: f64,
        angle_rad: &[f64],
        speed_rad_s: &[f64],
        load_n: &[f64],
    ) -> Result<(), RecordError> {
        let ns = log_time_ns(t_s);
        if let Some((id, names)) = self.ch.pack_joints.get(&coupling) {
            let id = *id;
            ros2::joint_state(
                &mut self.sink.buf,
                ns,
                names,
                angle_rad,
                speed_rad_s,
                load_n,
            );
            self.sink.put_buf(id, ns, "pack joints")?;
        }
        match self.packs.transforms(coupling, ns, angle_rad) {
            Some(tf) => self.sink.put(self.ch.tf, ns, &tf, "/tf"),
            None => Ok(()),
        }
    }

    /// Writes a thermal resolved pack's temperatures at `t_s` (s), K: its discs', its
    /// plates', then its oil's, each on its own topic
    /// ([`topics::network_pack_temperature`]).
    pub fn write_pack_temperatures(
        &mut self,
        coupling: usize,
        t_s: f64,
        temperatures_k: &[f64],
    ) -> Result<(), RecordError> {
        let Some(ids) = self.ch.pack_temperatures.get(&coupling).cloned() else {
            return Ok(());
        };
        let ns = log_time_ns(t_s);
        for (i, (id, &temperature_k)) in ids.into_iter().zip(temperatures_k).enumerate() {
            let msg = proto::Temperature {
                t_s,
                temperature_k,
                body_index: i as u32,
            };
            self.sink.put(id, ns, &msg, "pack temperature")?;
        }
        Ok(())
    }

    /// Writes the tooth contacts open at `t_s` (s) on `/network/contacts`, each `(coupling,
    /// body in a pack, event as it would close at t_s)` and named as its impact will be
    /// ([`impact_name`]).
    pub fn write_open_contacts(
        &mut self,
        t_s: f64,
        open: &[(usize, Option<usize>, ImpactEvent)],
    ) -> Result<(), RecordError> {
        let ns = log_time_ns(t_s);
        for (coupling, body, e) in open {
            let msg = proto::Impact::of(e, impact_name(&self.net, *coupling, *body));
            self.sink
                .put(self.ch.contacts, ns, &msg, "/network/contacts")?;
        }
        Ok(())
    }

    /// Writes a gear mesh's tooth impact on `/network/impacts`, logged when its contact
    /// closes (`disc` of the event is the coupling's index).
    pub fn write_mesh_impact(&mut self, e: &ImpactEvent) -> Result<(), RecordError> {
        let msg = proto::Impact::of(e, impact_name(&self.net, e.disc, None));
        self.sink.put(
            self.ch.impacts,
            log_time_ns(e.t_off_s),
            &msg,
            "/network/impacts",
        )
    }

    /// Whether it wants the open tooth contacts at `t_s` (s): on the grid of
    /// [`OPEN_CONTACTS_EVERY_S`], whatever the steps.
    pub fn wants_open_contacts(&self, t_s: f64) -> bool {
        t_s >= self.open_contacts_at_s
    }

    /// [`Self::write_open_contacts`], and the next time the open contacts are due.
    pub fn open_contacts(
        &mut self,
        t_s: f64,
        open: &[(usize, Option<usize>, ImpactEvent)],
    ) -> Result<(), RecordError> {
        let every = OPEN_CONTACTS_EVERY_S;
        self.open_contacts_at_s = ((t_s / every).floor() + 1.0) * every;
        self.write_open_contacts(t_s, open)
    }

    /// A resolved pack's faces changed mode at `t_s` (s): `locked` of its `faces` friction
    /// faces are locked, `clamped` are clamped; drawn and read as a clutch's mode (all
    /// locked: locked; some clamped: slipping; none: free) from the next sample.
    pub fn pack_faces(&mut self, coupling: usize, locked: usize, clamped: usize, faces: usize) {
        let mode = if locked == faces {
            ClutchMode::Locked
        } else if clamped > 0 {
            ClutchMode::Slipping(1)
        } else {
            ClutchMode::Free
        };
        self.set_pack_mode(coupling, mode);
    }

    /// Attaches the run's summary (JSON, if given: [`Self::summary_json`]) and closes the
    /// file, moving it into place. Call it after a stop or an engine error too: the file then
    /// holds what ran.
    pub fn finish(mut self) -> Result<PathBuf, RecordError> {
        let r = self.finish_inner();
        self.sink.discard_if_disk_full(&r);
        r
    }

    fn finish_inner(&mut self) -> Result<PathBuf, RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        if let (Some(json), Some(w)) = (&self.summary_json, self.sink.writer.as_mut()) {
            w.attach(&mcap::Attachment {
                log_time: log_time_ns(self.last_t_s),
                create_time: 0,
                name: SUMMARY_ATTACHMENT.into(),
                media_type: "application/json".into(),
                data: Cow::Borrowed(json),
            })
            .map_err(|cause| RecordError::Write {
                path: self.sink.path.clone(),
                what: "summary attachment".into(),
                cause,
            })?;
        }
        let mut stats = BTreeMap::new();
        stats.insert("simulated_s".into(), num(self.last_t_s));
        stats.insert("messages".into(), self.sink.messages.to_string());
        if !self.deterministic {
            stats.insert(
                "wall_s".into(),
                num(self.sink.started.elapsed().as_secs_f64()),
            );
        }
        self.sink.close(stats)
    }
}

/// A body drawn as points in its frame `frame` (for Rerun, which does not draw scene
/// updates): an annulus from `0.2 r` to `r` (m) with a dark sector, so that it turns visibly.
fn body_points(frame: &str, r: f64) -> foxglove::schemas::PointCloud {
    let mut data = Vec::new();
    crate::view3d::annulus_points(
        &mut data,
        0.2 * r,
        r,
        DRAWN_THICKNESS_M,
        [158, 122, 82, 255],
    );
    for k in 0..8 {
        let x = r * (0.65 + 0.04 * f64::from(k));
        for y in [-0.03 * r, 0.0, 0.03 * r] {
            crate::view3d::push_point(&mut data, x, y, 0.6 * DRAWN_THICKNESS_M, [20, 20, 20, 255]);
        }
    }
    crate::view3d::cloud(frame, data)
}

/// A clutch's slip `w_rel = omega_b - omega_a` in `s`, rad/s (the network's sign convention,
/// MODEL.md section 8 and `clutchpack_model::network::clutch`: positive in mode `slip+`; 0 for
/// another kind of coupling).
fn clutch_slip_rad_s(s: &NetworkSample, c: &clutchpack_model::network::Coupling, k: usize) -> f64 {
    if s.mode[k].is_some() {
        s.speed_rad_s[c.b] - s.speed_rad_s[c.a]
    } else {
        0.0
    }
}

/// The frame of the network body whose topic segment is `segment` (`body/<segment>`).
pub fn body_frame(segment: &str) -> String {
    format!("body/{segment}")
}
