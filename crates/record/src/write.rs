//! Writing a recording: [`Recorder`], an [`Observer`] that streams an engine's samples and
//! impact events into an MCAP file.

use crate::info::{num, utc_text, RunInfo, META_STATS, SCENE_MEDIA_TYPE};
use crate::output::{PendingFile, Replace};
use crate::summary::RecordedSummary;
use crate::view3d::{self, disc_frame};
use crate::{proto, topic_segment, topics};
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, Observer, RunStats, Sample};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// How a run is recorded. `RecordOptions::default()` is what `clutchpack run` uses.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordOptions {
    /// Write no wall-clock data (no `recorded_at_utc`, `finished_at_utc`, `wall_s`, zero
    /// attachment `create_time`) and end chunks only on message count and size, never on the
    /// wall-clock timer, so that the same stream gives a byte-identical file. Default `false`.
    pub deterministic: bool,
    /// Also write `/discs/<name>/teeth` (per-tooth loads) for samples that carry them.
    /// Default `false`.
    pub per_tooth: bool,
    /// Longest wall time between two chunk flushes; a killed run loses at most about this
    /// much. Ignored when `deterministic`. Default 1 s.
    pub flush_interval: Duration,
    /// Flush the chunk after this many messages at most (deterministic). Default 1 000 000
    /// (the chunk size ends chunks first: about 200 000 messages in pack-8-brake's).
    pub flush_messages: usize,
    /// Target uncompressed chunk size in bytes: a chunk is ended once it is larger. `None`
    /// (the default): [`auto_chunk_size_bytes`] of the run's bodies and friction interfaces,
    /// 768 KiB each, between 4 and 64 MiB. The `mcap` writer keeps every chunk's index entry
    /// in memory until the summary section is written (and `finish` clones them all), and an
    /// entry holds one message-index offset per channel written in the chunk: about 1.2 kB
    /// of heap for pack-8-brake's 17 bodies and 16 interfaces. So the chunk count is what
    /// grows with a recorded run, and chunks that grow with the pack keep the index's heap
    /// per recorded byte the same for every pack: pack-8-brake (35 MB of file per simulated
    /// second) at 4 MiB chunks grew from 20 MB of peak RSS at 10 s to 73 MB at 600 s; at
    /// 24 MiB see docs/performance.md, "Memory of long runs" (and docs/DECISIONS.md).
    pub chunk_size_bytes: Option<u64>,
    /// zstd level (1..=19; 0 = zstd's default, 3). Default 1, zstd's fastest: on a 3 s
    /// paper-case run its file was 1.5 % larger than level 3's.
    pub compression_level: u32,
    /// Simulated time between two `/tf` messages in s; 0 writes one per sample. Default
    /// 2e-4 s: 50 poses per second of replay at `replay --serve`'s default speed of 0.01,
    /// smooth in the 3D view, while the exact angles are on the spline topics at every
    /// sample. `/tf` is the largest message: one per 0.1 ms made the recording thread's CPU
    /// time 90 % of the paper case engine's, one per 1 ms 56 %. Samples further apart than
    /// this get a `/tf` each.
    pub tf_interval_s: f64,
    /// Simulated time between two load-coloured `/scene` updates of the teeth in s (an
    /// update holds only the discs whose colour changed); 0 writes only the static scene at
    /// t = 0. Default 1e-3 s.
    pub scene_interval_s: f64,
    /// `|load_n|` in N drawn in full red in `/scene`; `None` uses the largest `|load_n|` seen
    /// so far in the run. Default `None`.
    pub load_color_scale_n: Option<f64>,
    /// Temperatures `(blue, red)` in K of a thermal run's `/scene/temperatures` colours;
    /// `None`: from the run's first temperature (the lowest body or oil) to 100 K above it.
    /// Default `None`.
    pub temperature_color_range_k: Option<(f64, f64)>,
    /// Write `/discs/<name>/load`: each disc's load at the engine's contact samples
    /// ([`Observer::contact_sample`]) and at the samples with a load (and the first; in
    /// between the load is 0), the series that shows the contact pulses and their peaks.
    /// Default `true`: on `pack-4-rattle` over 3 s it made the file 68 % larger (23.4 MB
    /// against 13.9 MB) and the run about 15 % longer (docs/DECISIONS.md).
    pub contact_samples: bool,
}

impl Default for RecordOptions {
    fn default() -> Self {
        RecordOptions {
            deterministic: false,
            per_tooth: false,
            flush_interval: Duration::from_secs(1),
            flush_messages: 1_000_000,
            chunk_size_bytes: None,
            compression_level: 1,
            tf_interval_s: 2e-4,
            scene_interval_s: 1e-3,
            load_color_scale_n: None,
            temperature_color_range_k: None,
            contact_samples: true,
        }
    }
}

/// An error and its causes on one line ("a: b: c"). The I/O errors inside a
/// [`RecordError`] are its message's end rather than its `source()`, so that a reporter that
/// prints the whole chain (`anyhow`'s `{:#}`) says each cause once: with them as sources it
/// printed "I/O error from writing, or reading a compression stream" twice.
fn causes(e: &dyn std::error::Error) -> String {
    let mut out = e.to_string();
    let mut next = e.source();
    while let Some(c) = next {
        out.push_str(": ");
        out.push_str(&c.to_string());
        next = c.source();
    }
    out
}

/// Whether an I/O error says the disk is full or the quota exhausted (ENOSPC, EDQUOT).
pub fn is_disk_full(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        std::io::ErrorKind::StorageFull | std::io::ErrorKind::QuotaExceeded
    )
}

impl RecordError {
    /// Whether writing failed because the disk is full or the quota exhausted (ENOSPC, EDQUOT).
    pub fn is_disk_full(&self) -> bool {
        match self {
            RecordError::Create { cause, .. } | RecordError::Close { cause, .. } => {
                is_disk_full(cause)
            }
            RecordError::Write {
                cause: mcap::McapError::Io(cause),
                ..
            } => is_disk_full(cause),
            _ => false,
        }
    }
}

/// Why a recording could not be written.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file (or its folder) could not be created.
    #[error("cannot create the recording {path}: {}", causes(cause))]
    Create {
        /// The recording's path.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// Writing failed (disk full, I/O error); the file is readable up to the last flush.
    #[error("cannot write the recording {path} ({what}): {}", causes(cause))]
    Write {
        /// The recording's path.
        path: PathBuf,
        /// What was being written.
        what: String,
        /// The MCAP writer's error.
        cause: mcap::McapError,
    },
    /// The final flush of the file failed.
    #[error("cannot close the recording {path}: {}", causes(cause))]
    Close {
        /// The recording's path.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// A sample does not fit the run info it was created with.
    #[error("sample at t = {t_s} s has {got} discs, but the recording {path} was created for {expected}")]
    DiscCount {
        /// The recording's path.
        path: PathBuf,
        /// Time of the sample in s.
        t_s: f64,
        /// Discs in the sample.
        got: usize,
        /// Discs in the run info.
        expected: usize,
    },
    /// The engine reports a different number of friction interfaces than the run info has.
    #[error("interface sample at t = {t_s} s has {got} interfaces, but the recording {path} was created for {expected}")]
    InterfaceCount {
        /// The recording's path.
        path: PathBuf,
        /// Time of the sample in s.
        t_s: f64,
        /// Interfaces in the sample.
        got: usize,
        /// Interfaces in the run info.
        expected: usize,
    },
    /// A write after an earlier error (the first error is returned by `finish`).
    #[error("the recording {path} failed earlier; nothing more is written")]
    AlreadyFailed {
        /// The recording's path.
        path: PathBuf,
    },
}

/// The default recording path `dir/<scene>-<UTC time to the millisecond>.mcap`, e.g.
/// `recordings/paper-20261122T022900.250Z.mcap` for `now` = 2026-11-22 02:29:00.25 UTC; the
/// scene name is made file-safe as a topic segment ([`topic_segment`](crate::topic_segment)).
/// Two runs in the same millisecond get the same name here: write default names with
/// [`Recorder::create_output`] and [`Replace::Never`], which takes the next free
/// `<name>-2.mcap`, ... atomically.
pub fn default_path(dir: impl AsRef<Path>, scene_name: &str, now: SystemTime) -> PathBuf {
    let since = now.duration_since(UNIX_EPOCH).unwrap_or_default();
    // 2026-11-22T02:29:00.250Z -> 20261122T022900.250Z
    let t: String = utc_text(since)
        .chars()
        .take(23)
        .filter(|c| c.is_ascii_digit() || *c == 'T' || *c == '.')
        .collect();
    dir.as_ref()
        .join(format!("{}-{t}Z.mcap", topic_segment(scene_name)))
}

/// The first multiple of `interval` (s) after `t` (s), less a hair, so that samples on the
/// grid (`k dt` with rounding) land on their tick; `t` itself for a zero interval.
fn next_tick(t: f64, interval: f64) -> f64 {
    if interval > 0.0 {
        let k = (t / interval + 1e-6).floor() + 1.0;
        k * interval - 1e-6 * interval
    } else {
        t
    }
}

/// The chunk size of a recording of `bodies` discs and plates and `interfaces` friction
/// interfaces, bytes: 768 KiB each, at least 4 MiB and at most 64 MiB
/// ([`RecordOptions::chunk_size_bytes`]).
pub fn auto_chunk_size_bytes(bodies: usize, interfaces: usize) -> u64 {
    let n = (bodies + interfaces) as u64;
    (n * (768 << 10)).clamp(4 << 20, 64 << 20)
}

/// A colour level (0..=1) in steps of 1/16: a colour is sent again only when this changes.
fn quantize(level: f64) -> u8 {
    (level * 16.0).round() as u8
}

/// Simulated time `t_s` (s) as an MCAP log time in ns (negative and NaN times give 0).
pub fn log_time_ns(t_s: f64) -> u64 {
    if t_s.is_nan() || t_s <= 0.0 {
        0
    } else {
        (t_s * 1e9).round().min(u64::MAX as f64) as u64
    }
}

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

/// Streams a run into an MCAP file. See the crate documentation for the topics.
///
/// Use it as the engine's [`Observer`] (or call [`Self::write_sample`] and
/// [`Self::write_impact`]), then [`Self::finish`]. Errors met inside the observer methods are
/// kept (the first one) and returned by `finish`; after an error nothing more is written, and
/// [`Observer::progress`] returns `true` to stop the run. Dropping a recorder without
/// `finish` still closes the file with its summary section, but without `/summary`; so call
/// `finish` after an engine error or a Ctrl-C stop as well, to keep the summary of what ran.
pub struct Recorder {
    /// The file being written (the temporary file of an output made with `create_output`).
    path: PathBuf,
    /// Where `finish` moves the file (`create_output` only).
    pending: Option<PendingFile>,
    writer: Option<mcap::Writer<BufWriter<File>>>,
    options: RecordOptions,
    info: RunInfo,
    frames: Vec<String>,
    names: Vec<String>,
    /// `/tf` message, updated in place each time
    tf: foxglove::schemas::FrameTransforms,
    ch: Channels,
    sequences: BTreeMap<u16, u32>,
    buf: Vec<u8>,
    error: Option<RecordError>,
    failed: bool,
    last_flush: Instant,
    started: Instant,
    since_flush: usize,
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
    messages: u64,
    stats: Option<RunStats>,
    /// a thermal run's channels (from its first temperatures)
    thermal: Option<ThermalChannels>,
}

/// Opens an MCAP writer on `file` (at `path`, for messages) with the recorder's settings:
/// zstd chunks of `chunk_size_bytes`, the scene attached, and `info`'s metadata records
/// (with the recorder's options in `clutchpack.run`) followed by `more_metadata`. Shared by
/// the pack [`Recorder`] and the network recorder ([`crate::NetworkRecorder`]).
pub(crate) fn open_mcap(
    path: &Path,
    file: File,
    info: &RunInfo,
    options: &RecordOptions,
    chunk_size_bytes: u64,
    more_metadata: Vec<(String, BTreeMap<String, String>)>,
) -> Result<mcap::Writer<BufWriter<File>>, RecordError> {
    let write_err = |what: &str, cause| RecordError::Write {
        path: path.to_path_buf(),
        what: what.to_string(),
        cause,
    };
    let opts = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .compression_level(options.compression_level)
        // zstd in the writing thread itself (no worker): the recorder already runs beside
        // the engine (the CLI's recording thread), and a zstd worker made a third busy
        // thread on a 2-core machine plus a mutex round trip for each of the 7 small
        // writes of every MCAP message record. Single-threaded zstd output is the same on
        // every machine, which keeps deterministic recordings byte-identical.
        .compression_threads(0)
        .chunk_size(Some(chunk_size_bytes.max(1)))
        .library(format!(
            "clutchpack_record {} (mcap-rs {})",
            env!("CARGO_PKG_VERSION"),
            mcap::VERSION
        ))
        // Chunks are compressed straight into the file and their headers written in
        // place once complete (the writer seeks back). Building each chunk in memory
        // instead (`disable_seeking`) held a buffer of the chunk's size, which is what
        // kept chunks at 1 MiB and so the chunk index growing with the run. A killed
        // run still leaves every flushed chunk readable: what follows the last one is a
        // chunk record whose length is a placeholder, which the readers find to run past
        // the end of the file (`killed_mid_chunk_keeps_the_flushed_chunks`).
        .disable_seeking(false);
    let mut w = opts
        .create(BufWriter::with_capacity(1 << 16, file))
        .map_err(|e| write_err("header", e))?;

    let wall_ns = if options.deterministic {
        0
    } else {
        SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(0)
    };
    w.attach(&mcap::Attachment {
        log_time: 0,
        create_time: wall_ns,
        name: info.scene_file_name().to_string(),
        media_type: SCENE_MEDIA_TYPE.to_string(),
        data: Cow::Borrowed(info.scene_text.as_bytes()),
    })
    .map_err(|e| write_err("scene attachment", e))?;

    let mut extra = vec![
        (
            "deterministic".to_string(),
            options.deterministic.to_string(),
        ),
        ("per_tooth".to_string(), options.per_tooth.to_string()),
        (
            "contact_samples".to_string(),
            options.contact_samples.to_string(),
        ),
        ("tf_interval_s".to_string(), num(options.tf_interval_s)),
        (
            "scene_interval_s".to_string(),
            num(options.scene_interval_s),
        ),
    ];
    if !options.deterministic {
        extra.push((
            "recorded_at_utc".to_string(),
            utc_text(Duration::from_nanos(wall_ns)),
        ));
    }
    for (name, metadata) in info.to_metadata(&extra).into_iter().chain(more_metadata) {
        w.write_metadata(&mcap::records::Metadata { name, metadata })
            .map_err(|e| write_err("metadata", e))?;
    }
    Ok(w)
}

/// Writes `data` as the next message on `channel` at `log_time` (ns, also its publish time),
/// numbered by the channel's count in `sequences`: every message of both recorders goes
/// through it.
pub(crate) fn write_message(
    w: &mut mcap::Writer<BufWriter<File>>,
    sequences: &mut BTreeMap<u16, u32>,
    channel: u16,
    log_time: u64,
    data: &[u8],
) -> Result<(), mcap::McapError> {
    let seq = sequences.entry(channel).or_insert(0);
    *seq = seq.wrapping_add(1);
    let header = mcap::records::MessageHeader {
        channel_id: channel,
        sequence: *seq,
        log_time,
        publish_time: log_time,
    };
    w.write_to_known_channel(&header, data)
}

/// Ends an MCAP file opened by [`open_mcap`]: the `clutchpack.stats` metadata record `stats`,
/// the summary section, the flush, and the move into place of an output written whole
/// (`pending` is taken only then: after an error the caller may still discard it).
pub(crate) fn close_mcap(
    mut w: mcap::Writer<BufWriter<File>>,
    path: &Path,
    stats: BTreeMap<String, String>,
    pending: &mut Option<PendingFile>,
) -> Result<PathBuf, RecordError> {
    let write_err = |what: &str, cause| RecordError::Write {
        path: path.to_path_buf(),
        what: what.to_string(),
        cause,
    };
    w.write_metadata(&mcap::records::Metadata {
        name: META_STATS.into(),
        metadata: stats,
    })
    .map_err(|e| write_err("stats metadata", e))?;
    w.finish().map_err(|e| write_err("summary section", e))?;
    let mut inner = w.into_inner();
    inner.flush().map_err(|cause| RecordError::Close {
        path: path.to_path_buf(),
        cause,
    })?;
    drop(inner);
    match pending.take() {
        Some(p) => p.commit().map_err(|cause| RecordError::Close {
            path: path.to_path_buf(),
            cause,
        }),
        None => Ok(path.to_path_buf()),
    }
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

impl Recorder {
    /// Creates the recording at `path` (its folder is created if missing; an existing file is
    /// replaced) and writes the header, the scene attachment, the metadata, the channels and
    /// the static `/scene`, then flushes, so even a run killed at once leaves a valid prefix.
    pub fn create(
        path: impl AsRef<Path>,
        info: &RunInfo,
        options: &RecordOptions,
    ) -> Result<Recorder, RecordError> {
        let path = path.as_ref().to_path_buf();
        let create_err = |cause| RecordError::Create {
            path: path.clone(),
            cause,
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(create_err)?;
        }
        let file = File::create(&path).map_err(create_err)?;
        Recorder::start(path, file, None, info, options)
    }

    /// Creates the recording as an output written whole: into a new temporary file beside
    /// `target` (`<stem>.partial-<pid>-<k>.mcap`, see [`PendingFile`]), moved into place by
    /// [`Self::finish`] (replacing an existing `target` only with [`Replace::Existing`];
    /// with [`Replace::Never`] under the first free `<stem>-<k>.mcap`). A run killed before
    /// `finish` leaves the temporary file, readable up to its last flush.
    pub fn create_output(
        target: impl AsRef<Path>,
        replace: Replace,
        info: &RunInfo,
        options: &RecordOptions,
    ) -> Result<Recorder, RecordError> {
        let target = target.as_ref();
        let (pending, file) =
            PendingFile::create(target, replace).map_err(|cause| RecordError::Create {
                path: target.to_path_buf(),
                cause,
            })?;
        let path = pending.tmp_path().to_path_buf();
        Recorder::start(path, file, Some(pending), info, options)
    }

    fn start(
        path: PathBuf,
        file: File,
        pending: Option<PendingFile>,
        info: &RunInfo,
        options: &RecordOptions,
    ) -> Result<Recorder, RecordError> {
        let write_err = |what: &str, cause| RecordError::Write {
            path: path.clone(),
            what: what.to_string(),
            cause,
        };
        let chunk = options
            .chunk_size_bytes
            .unwrap_or_else(|| auto_chunk_size_bytes(info.discs.len(), info.interfaces.len()));
        let mut w = open_mcap(&path, file, info, options, chunk, Vec::new())?;

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
        let mut rec = Recorder {
            path,
            pending,
            writer: Some(w),
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
            sequences: BTreeMap::new(),
            buf: Vec::with_capacity(4096),
            error: None,
            failed: false,
            last_flush: Instant::now(),
            started: Instant::now(),
            since_flush: 0,
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
            messages: 0,
            stats: None,
            thermal: None,
        };
        let static_scene = view3d::static_scene(&rec.info, &rec.frames);
        rec.put(rec.ch.scene, 0, &static_scene, "/scene")?;
        let rings = view3d::load_scene(0, &rec.info, &rec.frames, &rec.all_rings());
        rec.put(rec.ch.scene_loads, 0, &rings, "/scene/loads")?;
        for (ch, cloud) in clouds {
            rec.put(ch, 0, &cloud, "/pack")?;
        }
        rec.flush()?;
        Ok(rec)
    }

    /// The recording's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// The first error met by the [`Observer`] methods, if any (also returned by `finish`).
    pub fn error(&self) -> Option<&RecordError> {
        self.error.as_ref()
    }

    /// The summary of the impacts written so far (what `finish(None)` stores). Errors only
    /// when the peaks kept on disk (a long run, see `clutchpack_analysis::PeakStats`) cannot
    /// be read back.
    pub fn summary(&self) -> Result<RecordedSummary, RecordError> {
        let discs = self
            .peaks
            .stats(&self.names)
            .map_err(|source| RecordError::Write {
                path: self.path.clone(),
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

    fn failed_err(&self) -> RecordError {
        RecordError::AlreadyFailed {
            path: self.path.clone(),
        }
    }

    /// Encodes `msg` and writes it on `channel` at `log_time` (ns).
    fn put<M: prost::Message>(
        &mut self,
        channel: u16,
        log_time: u64,
        msg: &M,
        what: &str,
    ) -> Result<(), RecordError> {
        self.buf.clear();
        // encoding into a Vec cannot run out of space
        let _ = msg.encode(&mut self.buf);
        self.put_buf(channel, log_time, what)
    }

    /// Writes the bytes in `self.buf` as a message on `channel` at `log_time` (ns).
    fn put_buf(&mut self, channel: u16, log_time: u64, what: &str) -> Result<(), RecordError> {
        if self.failed {
            return Err(self.failed_err());
        }
        let Some(w) = self.writer.as_mut() else {
            return Err(self.failed_err());
        };
        if let Err(source) = write_message(w, &mut self.sequences, channel, log_time, &self.buf) {
            self.failed = true;
            return Err(RecordError::Write {
                path: self.path.clone(),
                what: what.to_string(),
                cause: source,
            });
        }
        self.messages += 1;
        self.since_flush += 1;
        Ok(())
    }

    /// Ends the current chunk and flushes it to the file (it survives a SIGKILL from now on).
    pub fn flush(&mut self) -> Result<(), RecordError> {
        if self.failed {
            return Err(self.failed_err());
        }
        if let Some(w) = self.writer.as_mut() {
            if let Err(source) = w.flush() {
                self.failed = true;
                return Err(RecordError::Write {
                    path: self.path.clone(),
                    what: "flush".into(),
                    cause: source,
                });
            }
        }
        self.since_flush = 0;
        self.last_flush = Instant::now();
        Ok(())
    }

    fn maybe_flush(&mut self) -> Result<(), RecordError> {
        if self.since_flush == 0 {
            return Ok(());
        }
        let due = self.since_flush >= self.options.flush_messages.max(1)
            || (!self.options.deterministic
                && self.last_flush.elapsed() >= self.options.flush_interval);
        if due {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes one sample: `/shaft`, each disc's `/discs/<name>/spline` (and `teeth` when
    /// asked for), `/tf` and `/scene` when due. Log time = `sample.t_s` in ns.
    pub fn write_sample(&mut self, sample: &Sample) -> Result<(), RecordError> {
        if self.failed {
            return Err(self.failed_err());
        }
        let n = self.names.len();
        if sample.discs.len() != n {
            return Err(RecordError::DiscCount {
                path: self.path.clone(),
                t_s: sample.t_s,
                got: sample.discs.len(),
                expected: n,
            });
        }
        let t = sample.t_s;
        let lt = log_time_ns(t);
        self.last_t_s = self.last_t_s.max(t);
        self.put(
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
            self.put(self.ch.spline[i], lt, &msg, "spline")?;
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
                self.put(ch, lt, &msg, "load")?;
            }
            if self.options.per_tooth && !d.tooth_loads_n.is_empty() {
                let msg = proto::ToothLoads {
                    t_s: t,
                    loads_n: d.tooth_loads_n.clone(),
                    disc_index: i as u32,
                };
                self.put(self.ch.teeth[i], lt, &msg, "teeth")?;
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
            let r = self.put(self.ch.tf, lt, &tf, "/tf");
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
                self.put(self.ch.scene_loads, lt, &update, "/scene/loads")?;
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
        ch.and_then(|c| self.sequences.get(c)).copied().unwrap_or(0)
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
        if self.failed {
            return Err(self.failed_err());
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
        self.put(ch, log_time_ns(t_s), &msg, "load")?;
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
        std::mem::swap(&mut self.buf, &mut buf);
        let r = self.put_buf(self.ch.joints, lt, "/joints");
        std::mem::swap(&mut self.buf, &mut buf);
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
        if self.failed {
            return Err(self.failed_err());
        }
        if interfaces.len() != self.ch.interfaces.len() {
            return Err(RecordError::InterfaceCount {
                path: self.path.clone(),
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
            self.put(self.ch.interfaces[m], lt, &msg, "interface")?;
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
        if self.failed {
            return Err(self.failed_err());
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
            self.put(ch, lt, &msg, "temperature")?;
        }
        if changed {
            let update =
                view3d::temperature_scene(lt, &self.info, &self.frames, bodies_k, oil_k, range_k);
            self.put(scene, lt, &update, "/scene/temperatures")?;
        }
        self.maybe_flush()
    }

    /// Makes a thermal run's channels ([`Self::write_temperatures`]).
    fn thermal_channels(&mut self, range_k: (f64, f64)) -> Result<ThermalChannels, RecordError> {
        let path = self.path.clone();
        let err = |what: &str, cause| RecordError::Write {
            path: path.clone(),
            what: what.to_string(),
            cause,
        };
        let Some(w) = self.writer.as_mut() else {
            return Err(self.failed_err());
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
        if self.failed {
            return Err(self.failed_err());
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
        self.put(self.ch.impacts, log_time_ns(e.t_peak_s), &msg, "/impacts")?;
        if let Some(&ch) = self.ch.disc_impacts.get(e.disc) {
            self.put(ch, log_time_ns(e.t_peak_s), &msg, "impacts")?;
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
        if let Err(e) = &result {
            if e.is_disk_full() {
                if let Some(p) = self.pending.take() {
                    p.discard();
                }
            }
        }
        result
    }

    fn finish_inner(&mut self, summary: Option<RecordedSummary>) -> Result<PathBuf, RecordError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.failed {
            return Err(self.failed_err());
        }
        self.release_impacts(f64::INFINITY)?;
        let summary = match summary {
            Some(s) => s,
            None => self.summary()?,
        };
        // logged at t = 0 although written last: viewers open a file at its start and show
        // the latest message of each topic, so the summary is there from the first frame
        self.put(self.ch.summary, 0, &summary.to_proto(), "/summary")?;
        let path = self.path.clone();
        let Some(w) = self.writer.take() else {
            return Err(self.failed_err());
        };
        let mut meta = BTreeMap::new();
        if let Some(s) = &self.stats {
            meta.insert("simulated_s".into(), num(s.simulated_s));
            meta.insert("steps".into(), s.steps.to_string());
            meta.insert("rejected_steps".into(), s.rejected_steps.to_string());
            meta.insert("rhs_evals".into(), s.rhs_evals.to_string());
            meta.insert("stopped_early".into(), s.stopped_early.to_string());
        }
        meta.insert("messages".into(), self.messages.to_string());
        if !self.options.deterministic {
            meta.insert("wall_s".into(), num(self.started.elapsed().as_secs_f64()));
            if let Ok(now) = SystemTime::now().duration_since(UNIX_EPOCH) {
                meta.insert("finished_at_utc".into(), utc_text(now));
            }
        }
        close_mcap(w, &path, meta, &mut self.pending)
    }

    fn keep(&mut self, r: Result<(), RecordError>) {
        if let Err(e) = r {
            if self.error.is_none() {
                self.error = Some(e);
            }
            self.failed = true;
        }
    }
}

impl Observer for Recorder {
    fn sample(&mut self, sample: &Sample) {
        if !self.failed {
            let r = self.write_sample(sample);
            self.keep(r);
        }
    }

    fn impact(&mut self, event: &ImpactEvent) {
        if !self.failed {
            let r = self.write_impact(event);
            self.keep(r);
        }
    }

    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        if !self.failed {
            let r = self.write_interfaces(t_s, interfaces);
            self.keep(r);
        }
    }

    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        if !self.failed {
            let r = self.write_contact_sample(disc, t_s, state);
            self.keep(r);
        }
    }

    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        if !self.failed {
            let r = self.write_temperatures(t_s, bodies_k, oil_k);
            self.keep(r);
        }
    }

    /// With [`RecordOptions::contact_samples`].
    fn wants_contact_samples(&self) -> bool {
        self.options.contact_samples
    }

    /// Flushes when the wall-clock interval has passed; returns `true` (stop the run) once
    /// writing has failed.
    fn progress(&mut self, _t_s: f64) -> bool {
        if !self.failed {
            let r = self.maybe_flush();
            self.keep(r);
        }
        self.failed
    }
}

/// Topic segments of `names` ([`topic_segment`]), made unique by appending `_<index>` to
/// repeats.
pub(crate) fn unique_segments(names: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(names.len());
    for (i, n) in names.iter().enumerate() {
        let mut s = topic_segment(n);
        if out.contains(&s) {
            s = format!("{s}_{i}");
        }
        out.push(s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A known instant gives a known, file-safe name.
    #[test]
    fn default_path_is_scene_and_utc_time() {
        let now = UNIX_EPOCH + Duration::from_secs(1_795_314_540);
        let p = default_path("recordings", "paper case", now);
        assert_eq!(
            p,
            PathBuf::from("recordings/paper_case-20261122T022900.000Z.mcap")
        );
        let p = default_path("r", "x", now + Duration::from_millis(250));
        assert_eq!(p, PathBuf::from("r/x-20261122T022900.250Z.mcap"));
    }

    /// Issue 36: a recorded run's memory grew with the chunk count (the `mcap` writer keeps
    /// an index entry per chunk with one offset per channel written in it: 1.24 kB for
    /// pack-8-brake's). The chunk size follows the bodies and interfaces, so the entries per
    /// recorded byte stay the same for every pack: pack-8-brake's 17 bodies and 16 interfaces
    /// get 24.75 MiB chunks (measured 1.20x peak RSS from 10 to 600 s, against 3.3x at
    /// 4 MiB); small packs keep 4 MiB, and no pack gets more than 64 MiB.
    #[test]
    fn chunks_grow_with_the_pack() {
        assert_eq!(auto_chunk_size_bytes(1, 0), 4 << 20);
        assert_eq!(auto_chunk_size_bytes(4, 0), 4 << 20);
        assert_eq!(auto_chunk_size_bytes(17, 16), 33 * (768 << 10));
        assert_eq!(auto_chunk_size_bytes(13, 12), 25 * (768 << 10));
        assert_eq!(auto_chunk_size_bytes(200, 199), 64 << 20);
        assert_eq!(RecordOptions::default().chunk_size_bytes, None);
    }

    /// Log times: simulated seconds to ns, rounded; nothing negative.
    #[test]
    fn log_times() {
        assert_eq!(log_time_ns(1.5e-6), 1500);
        assert_eq!(log_time_ns(-1.0), 0);
        assert_eq!(log_time_ns(f64::NAN), 0);
        assert_eq!(log_time_ns(0.1 + 0.2), 300_000_000);
    }
}
