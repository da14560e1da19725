//! The pack part of the recorder ([`crate::Recorder`]): a pack run's samples, impacts,
//! interfaces, contact samples and temperatures on the topics of the crate documentation's
//! table, with the 3D view's scene updates and the run's `/summary`.

use crate::info::{num, utc_text, RunInfo};
use crate::sink::Sink;
use crate::summary::RecordedSummary;
use crate::view3d::{self, disc_frame};
use crate::write::{
    auto_chunk_size_bytes, log_time_ns, next_tick, quantize, unique_segments, RecordError,
    RecordOptions,
};
use crate::{proto, topics};
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, RunStats, Sample};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{SystemTime, UNIX_EPOCH};

struct Channels {
    tf: u16,
    scene: u16,
    shaft: u16,
    spline: Vec<u16>,
    teeth: Vec<u16>,
    interfaces: Vec<u16>,
    impacts: u16,
    summary: u16,
    /// `/scene/loads`: the load colours, every disc in each message
    scene_loads: u16,
    /// `/discs/<segment>/impacts`: each disc's impacts at their peak times
    disc_impacts: Vec<u16>,
    /// `/joints`: `sensor_msgs/msg/JointState`, for Rerun's plots
    joints: u16,
    /// `/discs/<segment>/load`: each disc's load at the samples and the contact samples
    /// (empty without [`RecordOptions::contact_samples`])
    load: Vec<u16>,
}

/// A thermal run's channels and colours, made at its first temperatures (an isothermal
/// recording has none of them).
struct ThermalChannels {
    /// `/discs/<segment>/temperature`, one per body
    bodies: Vec<u16>,
    /// `/oil/temperature`
    oil: u16,
    /// `/scene/temperatures`
    scene: u16,
    /// `(blue, red)` of the colours, K
    range_k: (f64, f64),
    /// colour level of each body last sent, in 1/32 (`u8::MAX`: none yet)
    levels: Vec<u8>,
}

/// The pack part of the [`crate::Recorder`]: a pack run's topics (the crate documentation's
/// table) streamed into its MCAP file.
pub(crate) struct PackPart {
    /// The file, its writer and the messages' bookkeeping (shared with the network part).
    pub(crate) sink: Sink,
    options: RecordOptions,
    info: RunInfo,
    frames: Vec<String>,
    names: Vec<String>,
    /// `/tf` message, updated in place each time
    tf: foxglove::schemas::FrameTransforms,
    ch: Channels,
    next_tf_s: f64,
    next_scene_s: f64,
    max_abs_since_scene: Vec<f64>,
    /// colour level of the load collar last sent per disc, in 1/16
    scene_levels: Vec<u8>,
    /// per disc, the largest `|load|` of each tooth since the last `/scene` (per-tooth only)
    tooth_max_since_scene: Vec<Vec<f64>>,
    /// per disc, the colour level last sent of each drawn tooth, in 1/16
    tooth_levels: Vec<Vec<u8>>,
    /// colour level (0..=1) of each disc's load ring as last sent, re-sent with every update
    ring_levels: Vec<f64>,
    /// per disc, the colour level (0..=1) of each drawn tooth as last sent (per-tooth only),
    /// re-sent with every update
    tooth_levels_sent: Vec<Vec<f64>>,
    /// `/joints` message buffer
    joint_buf: Vec<u8>,
    /// `/joints` values (position, velocity, effort per disc), reused
    joint_values: [Vec<f64>; 3],
    max_abs_run: f64,
    /// every impact peak, for the summary (bounded memory: long runs keep them on disk)
    peaks: clutchpack_analysis::PeakStats,
    /// impacts not yet written, in peak-time order (see `write_impact`)
    held_impacts: std::collections::BinaryHeap<std::cmp::Reverse<HeldImpact>>,
    /// per disc: the time of its last sample without a contact in progress, s
    last_free_t_s: Vec<f64>,
    last_t_s: f64,
    stats: Option<RunStats>,
    /// a thermal run's channels (from its first temperatures)
    thermal: Option<ThermalChannels>,
}

/// The chunk size of a pack's recording: the options' or [`auto_chunk_size_bytes`].
pub(crate) fn pack_chunk_size_bytes(info: &RunInfo, options: &RecordOptions) -> u64 {
    options
        .chunk_size_bytes
        .unwrap_or_else(|| auto_chunk_size_bytes(info.discs.len(), info.interfaces.len()))
}

/// Impacts held for ordering at most (about 5 MB): beyond, the earliest is written even if
/// an earlier peak may still come (a contact held for the whole run, e.g. a locked disc).
const MAX_HELD_IMPACTS: usize = 1 << 16;

/// An impact waiting to be written, ordered by peak time.
#[derive(Debug, Clone, Copy)]
struct HeldImpact(ImpactEvent);
impl PartialEq for HeldImpact {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o).is_eq()
    }
}
impl Eq for HeldImpact {}
impl PartialOrd for HeldImpact {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for HeldImpact {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0
            .t_peak_s
            .total_cmp(&o.0.t_peak_s)
            .then(self.0.disc.cmp(&o.0.disc))
    }
}

impl PackPart {
    /// Writes the channels and the static `/scene` of the pack `info` describes into `sink`
    /// (opened with [`pack_chunk_size_bytes`]), then flushes, so even a run killed at once
    /// leaves a valid prefix.
    pub fn start(
        mut sink: Sink,
        info: &RunInfo,
        options: &RecordOptions,
    ) -> Result<PackPart, RecordError> {
        let path = sink.path.clone();
        let write_err = |what: &str, cause| RecordError::Write {
            path: path.clone(),
            what: what.to_string(),
            cause,
        };
        // the writer is put back once the channels are added
        let Some(mut w) = sink.writer.take() else {
            return Err(sink.failed_err());
        };

        // schemas and channels
        let fds = proto::file_descriptor_set();
        let schema = |w: &mut mcap::Writer<_>, name: &str, data: &[u8]| {
            w.add_schema(name, "protobuf", data)
                .map_err(|e| write_err("schema", e))
        };
        use foxglove::Encode as _;
        let fx = |s: Option<foxglove::Schema>| s.map(|s| s.data.into_owned()).unwrap_or_default();
        let s_tf = schema(
            &mut w,
            "foxglove.FrameTransforms",
            &fx(foxglove::schemas::FrameTransforms::get_schema()),
        )?;
        let s_scene = schema(
            &mut w,
            "foxglove.SceneUpdate",
            &fx(foxglove::schemas::SceneUpdate::get_schema()),
        )?;
        let s_shaft = schema(&mut w, proto::SHAFT_STATE, &fds)?;
        let s_spline = schema(&mut w, proto::SPLINE_STATE, &fds)?;
        let s_teeth = schema(&mut w, proto::TOOTH_LOADS, &fds)?;
        let s_interface = if info.interfaces.is_empty() {
            None
        } else {
            Some(schema(&mut w, proto::INTERFACE_STATE, &fds)?)
        };
        let s_impact = schema(&mut w, proto::IMPACT, &fds)?;
        let s_summary = schema(&mut w, proto::RUN_SUMMARY, &fds)?;

        let channel = |w: &mut mcap::Writer<_>,
                       schema_id: u16,
                       topic: &str,
                       meta: BTreeMap<String, String>| {
            w.add_channel(schema_id, topic, "protobuf", &meta)
                .map_err(|e| write_err("channel", e))
        };
        let none = BTreeMap::new;
        let tf_ch = channel(&mut w, s_tf, topics::TF, none())?;
        let scene_ch = channel(&mut w, s_scene, topics::SCENE, none())?;
        let shaft = channel(&mut w, s_shaft, topics::SHAFT, none())?;
        let names = info.disc_names();
        let segments = unique_segments(&names);
        let mut spline = Vec::with_capacity(names.len());
        let mut teeth = Vec::new();
        for (i, (name, seg)) in names.iter().zip(&segments).enumerate() {
            let meta = || -> BTreeMap<String, String> {
                [
                    ("disc".to_string(), name.clone()),
                    ("disc_index".to_string(), i.to_string()),
                ]
                .into()
            };
            spline.push(channel(&mut w, s_spline, &topics::spline(seg), meta())?);
            if options.per_tooth {
                teeth.push(channel(&mut w, s_teeth, &topics::teeth(seg), meta())?);
            }
        }
        let mut interfaces = Vec::with_capacity(info.interfaces.len());
        if let Some(s_interface) = s_interface {
            // `<lower>__<upper>` is already topic-safe; repeats get `_<index>` as discs do
            let names: Vec<String> = info.interfaces.iter().map(|f| f.segment()).collect();
            for (m, (f, seg)) in info
                .interfaces
                .iter()
                .zip(unique_segments(&names))
                .enumerate()
            {
                let meta: BTreeMap<String, String> = [
                    ("lower".to_string(), f.lower.clone()),
                    ("upper".to_string(), f.upper.clone()),
                    ("interface_index".to_string(), m.to_string()),
                ]
                .into();
                interfaces.push(channel(
                    &mut w,
                    s_interface,
                    &topics::interface(&seg),
                    meta,
                )?);
            }
        }
        let impacts = channel(&mut w, s_impact, topics::IMPACTS, none())?;
        let summary = channel(&mut w, s_summary, topics::SUMMARY, none())?;
        // viewer channels, after the others so that those keep their ids
        let scene_loads = channel(&mut w, s_scene, topics::SCENE_LOADS, none())?;
        let mut disc_impacts = Vec::with_capacity(names.len());
        for (i, (name, seg)) in names.iter().zip(&segments).enumerate() {
            let meta: BTreeMap<String, String> = [
                ("disc".to_string(), name.clone()),
                ("disc_index".to_string(), i.to_string()),
            ]
            .into();
            disc_impacts.push(channel(&mut w, s_impact, &topics::disc_impacts(seg), meta)?);
        }
        // for Rerun, which maps these to its own archetypes (crate::ros2, view3d::pack_points)
        let s_joints = w
            .add_schema(
                crate::ros2::JOINT_STATE,
                "ros2msg",
                crate::ros2::JOINT_STATE_SCHEMA.as_bytes(),
            )
            .map_err(|e| write_err("schema", e))?;
        let joints = w
            .add_channel(s_joints, topics::JOINTS, "cdr", &none())
            .map_err(|e| write_err("channel", e))?;
        let s_cloud = schema(
            &mut w,
            "foxglove.PointCloud",
            &fx(foxglove::schemas::PointCloud::get_schema()),
        )?;
        let frames: Vec<String> = segments.iter().map(|s| disc_frame(s)).collect();
        let mut clouds = Vec::with_capacity(frames.len() + 1);
        for (frame, cloud) in view3d::pack_points(info, &frames) {
            clouds.push((
                channel(&mut w, s_cloud, &topics::pack(&frame), none())?,
                cloud,
            ));
        }
        // the dense load series, last so that every other channel keeps its id
        let mut load = Vec::new();
        if options.contact_samples {
            let s_load = schema(&mut w, proto::LOAD_SAMPLE, &fds)?;
            for (i, (name, seg)) in names.iter().zip(&segments).enumerate() {
                let meta: BTreeMap<String, String> = [
                    ("disc".to_string(), name.clone()),
                    ("disc_index".to_string(), i.to_string()),
                ]
                .into();
                load.push(channel(&mut w, s_load, &topics::load(seg), meta)?);
            }
        }
        let tf_discs: Vec<(String, f64, f64)> = frames
            .iter()
            .zip(&info.discs)
            .map(|(f, g)| (f.clone(), g.z_m, 0.0))
            .collect();
        let tf = view3d::frame_transforms(0, 0.0, &tf_discs);
        let n = names.len();
        sink.writer = Some(w);
        let mut rec = PackPart {
            sink,
            options: options.clone(),
            info: info.clone(),
            frames,
            names,
            tf,
            ch: Channels {
                tf: tf_ch,
                scene: scene_ch,
                shaft,
                spline,
                teeth,
                interfaces,
                impacts,
                summary,
                scene_loads,
                disc_impacts,
                joints,
                load,
            },
            next_tf_s: f64::NEG_INFINITY,
            next_scene_s: if options.scene_interval_s > 0.0 {
                next_tick(0.0, options.scene_interval_s)
            } else {
                f64::INFINITY
            },
            max_abs_since_scene: vec![0.0; n],
            scene_levels: vec![0; n],
            tooth_max_since_scene: vec![Vec::new(); n],
            tooth_levels: vec![Vec::new(); n],
            ring_levels: vec![0.0; n],
            tooth_levels_sent: vec![Vec::new(); n],
            joint_buf: Vec::with_capacity(256),
            joint_values: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            max_abs_run: 0.0,
            peaks: clutchpack_analysis::PeakStats::new(),
            // reserved whole (pages are touched only as it fills): grown by doubling, the
            // heap's last copy held the full old and half the new buffer at once, +3.7 MB of
            // peak memory once a contact held for the run (pack-8-brake's resting plates)
            // filled it, after 16 s simulated
            held_impacts: std::collections::BinaryHeap::with_capacity(MAX_HELD_IMPACTS + 1),
            last_free_t_s: vec![f64::NEG_INFINITY; n],
            last_t_s: 0.0,
            stats: None,
            thermal: None,
        };
        let static_scene = view3d::static_scene(&rec.info, &rec.frames);
        rec.sink.put(rec.ch.scene, 0, &static_scene, "/scene")?;
        let rings = view3d::load_scene(0, &rec.info, &rec.frames, &rec.all_rings());
        rec.sink
            .put(rec.ch.scene_loads, 0, &rings, "/scene/loads")?;
        for (ch, cloud) in clouds {
            rec.sink.put(ch, 0, &cloud, "/pack")?;
        }
        rec.sink.flush()?;
        Ok(rec)
    }

    /// The summary of the impacts written so far (what `finish(None)` stores). Errors only
    /// when the peaks kept on disk (a long run, see `clutchpack_analysis::PeakStats`) cannot
    /// be read back.
    pub fn summary(&self) -> Result<RecordedSummary, RecordError> {
        let discs = self
            .peaks
            .stats(&self.names)
            .map_err(|source| RecordError::Write {
                path: self.sink.path.clone(),
                what: "the impact peaks kept in a temporary file".to_string(),
                cause: mcap::McapError::Io(source),
            })?;
        Ok(RecordedSummary {
            t_end_s: self.last_t_s,
            discs,
            fatigue: Vec::new(),
        })
    }

    /// Stores the engine's run statistics in the `clutchpack.stats` metadata written by
    /// [`Self::finish`].
    pub fn set_run_stats(&mut self, stats: &RunStats) {
        self.stats = Some(stats.clone());
    }

    /// Flushes when [`RecordOptions::flush_messages`] messages or (unless deterministic)
    /// [`RecordOptions::flush_interval`] of wall time have passed since the last flush.
    pub fn maybe_flush(&mut self) -> Result<(), RecordError> {
        if self.sink.since_flush == 0 {
            return Ok(());
        }
        let due = self.sink.since_flush >= self.options.flush_messages.max(1)
            || (!self.options.deterministic
                && self.sink.last_flush.elapsed() >= self.options.flush_interval);
        if due {
            self.sink.flush()?;
        }
        Ok(())
    }

    /// Writes one sample: `/shaft`, each disc's `/discs/<name>/spline` (and `teeth` when
    /// asked for), `/tf` and `/scene` when due. Log time = `sample.t_s` in ns.
    pub fn write_sample(&mut self, sample: &Sample) -> Result<(), RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        let n = self.names.len();
        if sample.discs.len() != n {
            return Err(RecordError::DiscCount {
                path: self.sink.path.clone(),
                t_s: sample.t_s,
                got: sample.discs.len(),
                expected: n,
            });
        }
        let t = sample.t_s;
        let lt = log_time_ns(t);
        self.last_t_s = self.last_t_s.max(t);
        self.sink.put(
            self.ch.shaft,
            lt,
            &proto::ShaftState {
                t_s: t,
                angle_rad: sample.shaft_angle_rad,
                speed_rad_s: sample.shaft_speed_rad_s,
            },
            "/shaft",
        )?;
        for (i, d) in sample.discs.iter().enumerate() {
            let msg = proto::SplineState {
                t_s: t,
                rel_angle_rad: d.rel_angle_rad,
                closing_speed_m_s: d.closing_speed_m_s,
                penetration_m: d.penetration_m,
                load_n: d.load_n,
                torque_n_m: d.torque_n_m,
                engaged: d.engaged,
                stiffness_n_m1_5: d.stiffness,
                speed_rad_s: d.speed_rad_s,
                angle_rad: d.angle_rad,
                disc_index: i as u32,
            };
            self.sink.put(self.ch.spline[i], lt, &msg, "spline")?;
            // the samples with a load (or in a contact) and the first: in between the load
            // is 0, which the series' line draws from a contact's closing point (0 N) to
            // the next onset (0 N) without them
            let first = t <= 0.0 || self.messages_on(self.ch.load.get(i)) == 0;
            if let (Some(&ch), true) = (self.ch.load.get(i), first || d.engaged || d.load_n != 0.0)
            {
                let msg = proto::LoadSample {
                    t_s: t,
                    load_n: d.load_n,
                    rel_angle_rad: d.rel_angle_rad,
                    contact_step: false,
                    disc_index: i as u32,
                };
                self.sink.put(ch, lt, &msg, "load")?;
            }
            if self.options.per_tooth && !d.tooth_loads_n.is_empty() {
                let msg = proto::ToothLoads {
                    t_s: t,
                    loads_n: d.tooth_loads_n.clone(),
                    disc_index: i as u32,
                };
                self.sink.put(self.ch.teeth[i], lt, &msg, "teeth")?;
            }
            let a = d
                .tooth_loads_n
                .iter()
                .fold(d.load_n.abs(), |m, x| m.max(x.abs()));
            if a.is_finite() {
                self.max_abs_since_scene[i] = self.max_abs_since_scene[i].max(a);
                self.max_abs_run = self.max_abs_run.max(a);
            }
            if self.options.per_tooth && !d.tooth_loads_n.is_empty() {
                let m = &mut self.tooth_max_since_scene[i];
                m.resize(d.tooth_loads_n.len(), 0.0);
                for (m, x) in m.iter_mut().zip(&d.tooth_loads_n) {
                    if x.is_finite() {
                        *m = m.max(x.abs());
                    }
                }
            }
        }
        self.write_joints(lt, sample)?;
        if t >= self.next_tf_s {
            self.next_tf_s = next_tick(t, self.options.tf_interval_s);
            view3d::update_transforms(
                &mut self.tf,
                lt,
                sample.shaft_angle_rad,
                sample
                    .discs
                    .iter()
                    .map(|d| (d.angle_rad, d.center_offset_m)),
            );
            let tf = std::mem::take(&mut self.tf);
            let r = self.sink.put(self.ch.tf, lt, &tf, "/tf");
            self.tf = tf;
            r?;
        }
        if t >= self.next_scene_s {
            self.next_scene_s = next_tick(t, self.options.scene_interval_s);
            let scale = self
                .options
                .load_color_scale_n
                .unwrap_or(self.max_abs_run)
                .max(f64::MIN_POSITIVE);
            let mut changed = false;
            for (i, a) in self.max_abs_since_scene.iter_mut().enumerate() {
                let level = (*a / scale).clamp(0.0, 1.0);
                let q = quantize(level);
                if self.scene_levels.get(i) != Some(&q) {
                    changed = true;
                    if let Some(l) = self.scene_levels.get_mut(i) {
                        *l = q;
                    }
                    if let Some(l) = self.ring_levels.get_mut(i) {
                        *l = level;
                    }
                }
                *a = 0.0;
            }
            // per-tooth colours: drawn tooth k shows the largest load of the teeth it stands
            // for (all of them when the disc has no more teeth than are drawn)
            let mut teeth: Vec<(usize, Vec<f64>)> = Vec::new();
            for (i, maxima) in self.tooth_max_since_scene.iter_mut().enumerate() {
                let Some(d) = self.info.discs.get(i) else {
                    continue;
                };
                if maxima.is_empty() {
                    continue;
                }
                let drawn = view3d::drawn_teeth(d) as usize;
                let n = maxima.len();
                let levels: Vec<f64> = (0..drawn)
                    .map(|k| {
                        let (lo, hi) =
                            (k * n / drawn, ((k + 1) * n / drawn).max(k * n / drawn + 1));
                        let m = maxima[lo.min(n - 1)..hi.min(n)]
                            .iter()
                            .fold(0.0_f64, |m, x| m.max(*x));
                        (m / scale).clamp(0.0, 1.0)
                    })
                    .collect();
                let q: Vec<u8> = levels.iter().map(|&l| quantize(l)).collect();
                if self.tooth_levels[i] != q {
                    self.tooth_levels[i] = q;
                    teeth.push((i, levels));
                }
                maxima.iter_mut().for_each(|m| *m = 0.0);
            }
            if changed || !teeth.is_empty() {
                // every disc's ring and teeth, so that the latest message restores all colours
                let mut update =
                    view3d::load_scene(lt, &self.info, &self.frames, &self.all_rings());
                for (i, levels) in teeth {
                    self.tooth_levels_sent[i] = levels;
                }
                let refs: Vec<(usize, &[f64])> = self
                    .tooth_levels_sent
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| !l.is_empty())
                    .map(|(i, l)| (i, l.as_slice()))
                    .collect();
                update
                    .entities
                    .extend(view3d::teeth_scene(lt, &self.info, &self.frames, &refs).entities);
                self.sink
                    .put(self.ch.scene_loads, lt, &update, "/scene/loads")?;
            }
        }
        for (free, d) in self.last_free_t_s.iter_mut().zip(&sample.discs) {
            if !d.engaged {
                *free = t;
            }
        }
        self.release_impacts(self.safe_impact_time_s())
    }

    /// Messages written so far on channel `ch` (0 for `None`).
    fn messages_on(&self, ch: Option<&u16>) -> u32 {
        ch.and_then(|c| self.sink.sequences.get(c))
            .copied()
            .unwrap_or(0)
    }

    /// Writes disc `disc`'s state `d` at `t_s` (s), a step inside one of its contacts
    /// ([`Observer::contact_sample`]), on `/discs/<segment>/load` (nothing without
    /// [`RecordOptions::contact_samples`]); its `|load_n|` also counts for the load colours
    /// of `/scene/loads`. The engine sends each disc's contact samples and samples in time
    /// order together, so the topic's log times never decrease.
    pub fn write_contact_sample(
        &mut self,
        disc: usize,
        t_s: f64,
        d: &DiscSample,
    ) -> Result<(), RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        let Some(&ch) = self.ch.load.get(disc) else {
            return Ok(());
        };
        let msg = proto::LoadSample {
            t_s,
            load_n: d.load_n,
            rel_angle_rad: d.rel_angle_rad,
            contact_step: true,
            disc_index: disc as u32,
        };
        self.sink.put(ch, log_time_ns(t_s), &msg, "load")?;
        let a = d.load_n.abs();
        if a.is_finite() {
            if let Some(m) = self.max_abs_since_scene.get_mut(disc) {
                *m = m.max(a);
            }
            self.max_abs_run = self.max_abs_run.max(a);
        }
        self.maybe_flush()
    }

    /// Writes `/joints` for a sample: per disc the relative angle (rad), the shaft's minus
    /// the disc's speed (rad/s) and the tooth load (N).
    fn write_joints(&mut self, lt: u64, sample: &Sample) -> Result<(), RecordError> {
        let [pos, vel, eff] = &mut self.joint_values;
        for (i, d) in sample.discs.iter().enumerate().take(pos.len()) {
            pos[i] = d.rel_angle_rad;
            vel[i] = sample.shaft_speed_rad_s - d.speed_rad_s;
            eff[i] = d.load_n;
        }
        let mut buf = std::mem::take(&mut self.joint_buf);
        crate::ros2::joint_state(&mut buf, lt, &self.names, pos, vel, eff);
        std::mem::swap(&mut self.sink.buf, &mut buf);
        let r = self.sink.put_buf(self.ch.joints, lt, "/joints");
        std::mem::swap(&mut self.sink.buf, &mut buf);
        self.joint_buf = buf;
        r
    }

    /// `(disc index, level)` of every disc's load ring as last sent.
    fn all_rings(&self) -> Vec<(usize, f64)> {
        self.ring_levels.iter().copied().enumerate().collect()
    }

    /// Writes the stack's friction interfaces at `t_s` (s), one `/interfaces/<segment>`
    /// message each, in the order of [`RunInfo::interfaces`].
    pub fn write_interfaces(
        &mut self,
        t_s: f64,
        interfaces: &[InterfaceSample],
    ) -> Result<(), RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        if interfaces.len() != self.ch.interfaces.len() {
            return Err(RecordError::InterfaceCount {
                path: self.sink.path.clone(),
                t_s,
                got: interfaces.len(),
                expected: self.ch.interfaces.len(),
            });
        }
        let lt = log_time_ns(t_s);
        for (m, f) in interfaces.iter().enumerate() {
            let msg = proto::InterfaceState {
                t_s,
                slip_rad_s: f.slip_rad_s,
                slip_m_s: f.slip_m_s,
                mu: f.mu,
                clamp_n: f.clamp_n,
                torque_n_m: f.torque_n_m,
                locked: f.locked,
                interface_index: m as u32,
                dissipated_j: f.dissipated_j,
            };
            self.sink
                .put(self.ch.interfaces[m], lt, &msg, "interface")?;
        }
        self.maybe_flush()
    }

    /// Writes a thermal run's temperatures at `t_s` (s): `bodies_k` (K, in the order of the
    /// run info's discs: the discs, then the plates) on `/discs/<segment>/temperature`,
    /// `oil_k` (K) on `/oil/temperature`, and, when a body's colour level changed (steps of
    /// 1/32 of the range), every body's colour and the legend on `/scene/temperatures`. The
    /// channels are made at the first call.
    pub fn write_temperatures(
        &mut self,
        t_s: f64,
        bodies_k: &[f64],
        oil_k: f64,
    ) -> Result<(), RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        if self.thermal.is_none() {
            let lo = bodies_k.iter().copied().fold(oil_k, f64::min);
            let range_k = self
                .options
                .temperature_color_range_k
                .unwrap_or((lo, lo + 100.0));
            self.thermal = Some(self.thermal_channels(range_k)?);
        }
        let Some(th) = self.thermal.as_mut() else {
            return Ok(());
        };
        let lt = log_time_ns(t_s);
        let (lo, hi) = th.range_k;
        let span = (hi - lo).max(f64::MIN_POSITIVE);
        let mut changed = false;
        let mut puts = Vec::with_capacity(bodies_k.len() + 1);
        for (i, &t_k) in bodies_k.iter().enumerate() {
            if let Some(&ch) = th.bodies.get(i) {
                puts.push((ch, i, t_k));
            }
            let q = ((t_k - lo) / span * 32.0).round().clamp(0.0, 32.0) as u8;
            if let Some(l) = th.levels.get_mut(i) {
                changed |= *l != q;
                *l = q;
            }
        }
        puts.push((th.oil, bodies_k.len(), oil_k));
        let (scene, range_k) = (th.scene, th.range_k);
        for (ch, i, t_k) in puts {
            let msg = proto::Temperature {
                t_s,
                temperature_k: t_k,
                body_index: i as u32,
            };
            self.sink.put(ch, lt, &msg, "temperature")?;
        }
        if changed {
            let update =
                view3d::temperature_scene(lt, &self.info, &self.frames, bodies_k, oil_k, range_k);
            self.sink.put(scene, lt, &update, "/scene/temperatures")?;
        }
        self.maybe_flush()
    }

    /// Makes a thermal run's channels ([`Self::write_temperatures`]).
    fn thermal_channels(&mut self, range_k: (f64, f64)) -> Result<ThermalChannels, RecordError> {
        let path = self.sink.path.clone();
        let err = |what: &str, cause| RecordError::Write {
            path: path.clone(),
            what: what.to_string(),
            cause,
        };
        let Some(w) = self.sink.writer.as_mut() else {
            return Err(self.sink.failed_err());
        };
        let none = BTreeMap::new();
        use foxglove::Encode as _;
        let scene_schema = foxglove::schemas::SceneUpdate::get_schema()
            .map(|s| s.data.into_owned())
            .unwrap_or_default();
        let s_scene = w
            .add_schema("foxglove.SceneUpdate", "protobuf", &scene_schema)
            .map_err(|e| err("schema", e))?;
        let s_temp = w
            .add_schema(
                proto::TEMPERATURE,
                "protobuf",
                &proto::file_descriptor_set(),
            )
            .map_err(|e| err("schema", e))?;
        let segments = unique_segments(&self.names);
        let mut bodies = Vec::with_capacity(segments.len());
        for (i, (name, seg)) in self.names.iter().zip(&segments).enumerate() {
            let meta: BTreeMap<String, String> = [
                ("body".to_string(), name.clone()),
                ("body_index".to_string(), i.to_string()),
            ]
            .into();
            bodies.push(
                w.add_channel(s_temp, &topics::temperature(seg), "protobuf", &meta)
                    .map_err(|e| err("channel", e))?,
            );
        }
        let oil = w
            .add_channel(s_temp, topics::OIL_TEMPERATURE, "protobuf", &none)
            .map_err(|e| err("channel", e))?;
        let scene = w
            .add_channel(s_scene, topics::SCENE_TEMPERATURES, "protobuf", &none)
            .map_err(|e| err("channel", e))?;
        Ok(ThermalChannels {
            bodies,
            oil,
            scene,
            range_k,
            levels: vec![u8::MAX; self.names.len()],
        })
    }

    /// Writes one impact on `/impacts`, logged at its peak time `t_peak_s`.
    pub fn write_impact(&mut self, e: &ImpactEvent) -> Result<(), RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        if e.disc < self.names.len() + crate::summary::MAX_EXTRA_DISCS {
            self.peaks.push(e.disc, e.peak_n);
        }
        // Impacts are logged at their peak but handed over when their contact closes, so a
        // long contact's impact comes after shorter ones that peaked later; written as they
        // come, `/impacts` went back in time across chunks (Rerun's `mcap check` reports
        // that). They wait here until no earlier peak can come, at most MAX_HELD_IMPACTS.
        self.held_impacts.push(std::cmp::Reverse(HeldImpact(*e)));
        let mut until = self.safe_impact_time_s();
        if self.held_impacts.len() > MAX_HELD_IMPACTS {
            until = until.max(self.held_impacts.peek().map_or(until, |h| h.0 .0.t_peak_s));
        }
        self.release_impacts(until)
    }

    /// The latest peak time up to which no impact can still arrive: engines hand over an
    /// impact when its contact closes, after the samples before that, so a later impact peaks
    /// after the last sample, or inside a contact already in progress, which began after its
    /// disc's last free sample.
    fn safe_impact_time_s(&self) -> f64 {
        self.last_free_t_s
            .iter()
            .fold(self.last_t_s, |m, &t| m.min(t))
    }

    /// Writes the held impacts that peak at or before `until_s` (s), in peak-time order.
    fn release_impacts(&mut self, until_s: f64) -> Result<(), RecordError> {
        while self
            .held_impacts
            .peek()
            .is_some_and(|h| h.0 .0.t_peak_s <= until_s)
        {
            if let Some(std::cmp::Reverse(HeldImpact(e))) = self.held_impacts.pop() {
                self.put_impact(&e)?;
            }
        }
        self.maybe_flush()
    }

    /// Writes one impact on `/impacts` and its disc's topic, logged at its peak time.
    fn put_impact(&mut self, e: &ImpactEvent) -> Result<(), RecordError> {
        let name = self
            .names
            .get(e.disc)
            .cloned()
            .unwrap_or_else(|| format!("disc {}", e.disc));
        let msg = proto::Impact::of(e, name);
        self.sink
            .put(self.ch.impacts, log_time_ns(e.t_peak_s), &msg, "/impacts")?;
        if let Some(&ch) = self.ch.disc_impacts.get(e.disc) {
            self.sink
                .put(ch, log_time_ns(e.t_peak_s), &msg, "impacts")?;
        }
        Ok(())
    }

    /// Writes `/summary` (the given one, or [`Self::summary`] when `None`), the run
    /// statistics if set, and the summary section, then closes the file. Returns its path, or
    /// the first error met while recording (the file is then closed as well as it can be).
    ///
    /// When the disk is full (or the quota exhausted) the temporary file is removed: what it
    /// holds cannot be completed, and leaving it would keep the space taken.
    pub fn finish(mut self, summary: Option<RecordedSummary>) -> Result<PathBuf, RecordError> {
        let result = self.finish_inner(summary);
        self.sink.discard_if_disk_full(&result);
        result
    }

    fn finish_inner(&mut self, summary: Option<RecordedSummary>) -> Result<PathBuf, RecordError> {
        if self.sink.failed {
            return Err(self.sink.failed_err());
        }
        self.release_impacts(f64::INFINITY)?;
        let summary = match summary {
            Some(s) => s,
            None => self.summary()?,
        };
        // logged at t = 0 although written last: viewers open a file at its start and show
        // the latest message of each topic, so the summary is there from the first frame
        self.sink
            .put(self.ch.summary, 0, &summary.to_proto(), "/summary")?;
        let mut meta = BTreeMap::new();
        if let Some(s) = &self.stats {
            meta.insert("simulated_s".into(), num(s.simulated_s));
            meta.insert("steps".into(), s.steps.to_string());
            meta.insert("rejected_steps".into(), s.rejected_steps.to_string());
            meta.insert("rhs_evals".into(), s.rhs_evals.to_string());
            meta.insert("stopped_early".into(), s.stopped_early.to_string());
        }
        meta.insert("messages".into(), self.sink.messages.to_string());
        if !self.options.deterministic {
            meta.insert(
                "wall_s".into(),
                num(self.sink.started.elapsed().as_secs_f64()),
            );
            if let Ok(now) = SystemTime::now().duration_since(UNIX_EPOCH) {
                meta.insert("finished_at_utc".into(), utc_text(now));
            }
        }
        self.sink.close(meta)
    }

    /// Whether the recording is deterministic ([`RecordOptions::deterministic`]).
    pub fn deterministic(&self) -> bool {
        self.options.deterministic
    }

    /// Whether it takes contact samples ([`RecordOptions::contact_samples`]).
    pub fn wants_contact_samples(&self) -> bool {
        self.options.contact_samples
    }
}
