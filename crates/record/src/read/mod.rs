//! Reading a recording: [`open`] and [`RecordingReader`].
//!
//! The file is read into memory and scanned once, record by record, from the start (the MCAP
//! "streaming" read), checking every chunk's CRC before using any of its messages, the data
//! section's CRC, the summary section's CRC and the message counts in the summary. Every
//! message of our own and of the two Foxglove schemas is decoded on the way, so a file that
//! opens cleanly decodes completely. The scan stops at the first error; what was read before
//! it (whole chunks only) stays usable and [`RecordingReader::damage`] says what happened, so
//! a run killed mid-way (no summary section) is still read message by message. Nothing in
//! here panics on bad input.

use crate::info::RunInfo;
use crate::proto;
use crate::summary::RunSummary;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

mod series;
use series::segment_of;
pub use series::{DiscSeries, InterfaceSeries, LoadHistory};

/// Why a recording could not be read (each variant displays as one line).
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is empty.
    #[error("{path} is empty (0 bytes): not an MCAP recording")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file does not start with the MCAP magic bytes.
    #[error("{path} is not an MCAP file: it starts with {start}")]
    NotMcap {
        /// The file.
        path: PathBuf,
        /// The first bytes, quoted.
        start: String,
    },
    /// The file is an MCAP file but truncated or corrupted (see [`Damage`]).
    #[error("{path}: {damage}")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What was read and what was not.
        damage: Damage,
    },
    /// An export file could not be written.
    #[error("cannot write {path}: {source}")]
    Export {
        /// The file being written.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// What kind of damage a recording has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DamageKind {
    /// The file ends early (a killed run, a partial copy): everything before is intact.
    Truncated,
    /// Bytes are wrong (a CRC mismatch, an unparsable record, an undecodable message).
    Corrupt,
}

/// What was read from a damaged recording, and what was not.
#[derive(Debug, Clone, PartialEq)]
pub struct Damage {
    /// Truncated or corrupt.
    pub kind: DamageKind,
    /// What went wrong, in words.
    pub reason: String,
    /// Bytes of the file read when the problem was found.
    pub at_byte: u64,
    /// Size of the file in bytes.
    pub file_bytes: u64,
    /// Messages recovered before the problem (whole chunks only).
    pub messages: u64,
    /// Topics with at least one recovered message.
    pub topics: usize,
    /// Log time of the last recovered message in s.
    pub last_t_s: Option<f64>,
}

impl fmt::Display for Damage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self.kind {
            DamageKind::Truncated => "truncated recording",
            DamageKind::Corrupt => "corrupted recording",
        };
        write!(
            f,
            "{what}: {} (at byte {} of {}); recovered {} messages on {} topics",
            self.reason, self.at_byte, self.file_bytes, self.messages, self.topics
        )?;
        match self.last_t_s {
            Some(t) => write!(f, " up to t = {t} s, the rest is unreadable"),
            None => write!(f, ", the rest is unreadable"),
        }
    }
}

/// One topic of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicInfo {
    /// Topic name.
    pub topic: String,
    /// Schema name (`foxglove.FrameTransforms`, `clutchpack.SplineState`, ...).
    pub schema_name: String,
    /// Schema encoding (`protobuf`).
    pub schema_encoding: String,
    /// Message encoding (`protobuf`).
    pub message_encoding: String,
    /// Channel metadata (for disc topics: `disc`, `disc_index`).
    pub metadata: BTreeMap<String, String>,
    /// Messages read.
    pub messages: u64,
    /// Log time of the first message in s (NaN without messages).
    pub first_s: f64,
    /// Log time of the last message in s (NaN without messages).
    pub last_s: f64,
}

/// One attachment of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct AttachmentInfo {
    /// Name (the scene's file name for ours).
    pub name: String,
    /// Media type (`application/toml` for the scene).
    pub media_type: String,
    /// Log time in ns.
    pub log_time_ns: u64,
    /// Creation time in ns since the Unix epoch (0 in deterministic recordings).
    pub create_time_ns: u64,
    /// The content.
    pub data: Vec<u8>,
}

/// What a recording holds (everything read before any damage).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecordingInfo {
    /// MCAP profile (empty for ours).
    pub profile: String,
    /// Writing library (`clutchpack_record ... (mcap-rs ...)` for ours).
    pub library: String,
    /// Topics in channel-id order.
    pub topics: Vec<TopicInfo>,
    /// Messages read.
    pub messages: u64,
    /// Log time of the earliest message in s.
    pub start_s: Option<f64>,
    /// Log time of the latest message in s.
    pub end_s: Option<f64>,
    /// Metadata records (name, key/values) in file order.
    pub metadata: Vec<(String, BTreeMap<String, String>)>,
    /// Attachments in file order.
    pub attachments: Vec<AttachmentInfo>,
    /// Chunks in the file, from the summary's statistics (`None` without a summary section).
    pub chunks: Option<u64>,
    /// Whether the file has a complete, verified summary section and footer.
    pub summary_section: bool,
    /// The stored `/summary` (the last one), if any.
    pub summary: Option<RunSummary>,
}

impl RecordingInfo {
    /// The metadata record named `name`.
    pub fn metadata(&self, name: &str) -> Option<&BTreeMap<String, String>> {
        self.metadata
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, m)| m)
    }

    /// The topic named `topic`.
    pub fn topic(&self, topic: &str) -> Option<&TopicInfo> {
        self.topics.iter().find(|t| t.topic == topic)
    }
}

/// One message as stored, handed to [`RecordingReader::for_each_message`].
#[derive(Debug, Clone, Copy)]
pub struct MessageView<'a> {
    /// Channel id in the file.
    pub channel_id: u16,
    /// Topic.
    pub topic: &'a str,
    /// Schema name.
    pub schema_name: &'a str,
    /// Schema encoding.
    pub schema_encoding: &'a str,
    /// Schema data (a `FileDescriptorSet` for protobuf).
    pub schema_data: &'a [u8],
    /// Message encoding.
    pub message_encoding: &'a str,
    /// Log time in ns (simulated time for ours).
    pub log_time_ns: u64,
    /// The encoded message.
    pub data: &'a [u8],
}

/// An opened recording. See [`open`].
#[derive(Debug)]
pub struct RecordingReader {
    path: PathBuf,
    bytes: Vec<u8>,
    info: RecordingInfo,
    damage: Option<Damage>,
}

#[derive(Debug, Clone)]
struct SchemaRec {
    name: String,
    encoding: String,
    data: Vec<u8>,
}

#[derive(Debug, Clone)]
struct ChannelRec {
    topic: String,
    schema_id: u16,
    message_encoding: String,
    metadata: BTreeMap<String, String>,
}

/// The outcome of one scan of the file.
struct Scan {
    info: RecordingInfo,
    schemas: BTreeMap<u16, SchemaRec>,
    channels: BTreeMap<u16, ChannelRec>,
    counts: BTreeMap<u16, (u64, u64, u64)>,
    error: Option<(DamageKind, String, u64)>,
}

/// Opens the recording at `path`.
///
/// Errors only when nothing can be read: the file cannot be read, is empty, or is not MCAP
/// (a foreign file). A truncated or corrupted MCAP file opens, with what could be read before
/// the damage, and [`RecordingReader::damage`] set; use [`RecordingReader::require_complete`]
/// (or [`open_complete`]) to treat that as an error.
pub fn open(path: impl AsRef<Path>) -> Result<RecordingReader, ReadError> {
    let path = path.as_ref().to_path_buf();
    let bytes = std::fs::read(&path).map_err(|source| ReadError::Io {
        path: path.clone(),
        source,
    })?;
    from_bytes(path, bytes)
}

/// [`open`], then [`RecordingReader::require_complete`].
pub fn open_complete(path: impl AsRef<Path>) -> Result<RecordingReader, ReadError> {
    let r = open(path)?;
    r.require_complete()?;
    Ok(r)
}

/// Reads a recording held in memory; `path` is only used in messages.
pub fn from_bytes(path: impl Into<PathBuf>, bytes: Vec<u8>) -> Result<RecordingReader, ReadError> {
    let path = path.into();
    if bytes.is_empty() {
        return Err(ReadError::Empty { path });
    }
    let magic = mcap::MAGIC;
    if bytes.len() < magic.len() && magic.starts_with(&bytes) {
        let damage = Damage {
            kind: DamageKind::Truncated,
            reason: format!(
                "the file holds only {} bytes of the MCAP magic",
                bytes.len()
            ),
            at_byte: bytes.len() as u64,
            file_bytes: bytes.len() as u64,
            messages: 0,
            topics: 0,
            last_t_s: None,
        };
        return Err(ReadError::Damaged { path, damage });
    }
    if !bytes.starts_with(magic) {
        return Err(ReadError::NotMcap {
            path,
            start: describe_start(&bytes),
        });
    }
    let scan = scan(&bytes, u64::MAX, &mut |v| validate(v));
    let damage = scan.error.as_ref().map(|(kind, reason, at)| Damage {
        kind: *kind,
        reason: reason.clone(),
        at_byte: *at,
        file_bytes: bytes.len() as u64,
        messages: scan.info.messages,
        topics: scan.info.topics.iter().filter(|t| t.messages > 0).count(),
        last_t_s: scan.info.end_s,
    });
    Ok(RecordingReader {
        path,
        bytes,
        info: scan.info,
        damage,
    })
}

/// The first bytes of a foreign file, for the error message.
fn describe_start(bytes: &[u8]) -> String {
    let head = &bytes[..bytes.len().min(24)];
    let text = head
        .iter()
        .all(|&b| b == b'\n' || b == b'\r' || b == b'\t' || (0x20..0x7f).contains(&b));
    if text {
        let s = String::from_utf8_lossy(head);
        format!(
            "the text {:?} (expected the MCAP magic \\x89MCAP0\\r\\n)",
            s.as_ref()
        )
    } else {
        let hex: Vec<String> = head.iter().take(8).map(|b| format!("{b:02x}")).collect();
        format!(
            "the bytes {} (expected the MCAP magic 89 4d 43 41 50 30 0d 0a)",
            hex.join(" ")
        )
    }
}

/// Decodes one message of a known schema; the error says why not.
fn validate(v: &MessageView<'_>) -> Result<(), String> {
    if v.message_encoding != "protobuf" || v.schema_encoding != "protobuf" {
        return Ok(());
    }
    let r = match v.schema_name {
        proto::SHAFT_STATE => proto::ShaftState::decode(v.data).map(drop),
        proto::SPLINE_STATE => proto::SplineState::decode(v.data).map(drop),
        proto::TOOTH_LOADS => proto::ToothLoads::decode(v.data).map(drop),
        proto::INTERFACE_STATE => proto::InterfaceState::decode(v.data).map(drop),
        proto::IMPACT => proto::Impact::decode(v.data).map(drop),
        proto::RUN_SUMMARY => proto::RunSummary::decode(v.data).map(drop),
        "foxglove.FrameTransforms" => foxglove::schemas::FrameTransforms::decode(v.data).map(drop),
        "foxglove.SceneUpdate" => foxglove::schemas::SceneUpdate::decode(v.data).map(drop),
        _ => Ok(()),
    };
    r.map_err(|e| {
        format!(
            "a message on {} at t = {} s does not decode as {}: {e}",
            v.topic,
            v.log_time_ns as f64 * 1e-9,
            v.schema_name
        )
    })
}

fn describe_mcap_error(e: &mcap::McapError, data_end: bool) -> (DamageKind, String) {
    use mcap::McapError as E;
    match e {
        E::UnexpectedEof if !data_end => (
            DamageKind::Truncated,
            "the file ends inside the data section (no summary section: the run did not finish, or the copy is partial)".into(),
        ),
        E::UnexpectedEof => (
            DamageKind::Truncated,
            "the file ends inside the summary section".into(),
        ),
        E::BadChunkCrc { saved, calculated } => (
            DamageKind::Corrupt,
            format!("a chunk's CRC does not match (stored {saved:08x}, computed {calculated:08x})"),
        ),
        E::BadDataCrc { saved, calculated } => (
            DamageKind::Corrupt,
            format!("the data section's CRC does not match (stored {saved:08x}, computed {calculated:08x})"),
        ),
        E::BadSummaryCrc { saved, calculated } => (
            DamageKind::Corrupt,
            format!("the summary section's CRC does not match (stored {saved:08x}, computed {calculated:08x})"),
        ),
        E::DecompressionError(m) => (DamageKind::Corrupt, format!("a chunk does not decompress: {m}")),
        other => (DamageKind::Corrupt, format!("{other}").replace('\n', " ")),
    }
}

/// Scans `bytes` (which start with the MCAP magic), calling `on_message` for each of the
/// first `limit` messages; stops at the first error of the file or of `on_message`.
fn scan(
    bytes: &[u8],
    limit: u64,
    on_message: &mut dyn FnMut(&MessageView<'_>) -> Result<(), String>,
) -> Scan {
    let mut s = Scan {
        info: RecordingInfo::default(),
        schemas: BTreeMap::new(),
        channels: BTreeMap::new(),
        counts: BTreeMap::new(),
        error: None,
    };
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(bytes.len().max(256 << 20)),
    );
    let mut pos = 0usize;
    let mut data_end = false;
    let mut footer = false;
    let mut stats: Option<mcap::records::Statistics> = None;
    loop {
        let event = match reader.next_event() {
            None => break,
            Some(Ok(e)) => e,
            Some(Err(e)) => {
                let (kind, reason) = describe_mcap_error(&e, data_end);
                s.error = Some((kind, reason, pos as u64));
                break;
            }
        };
        match event {
            LinearReadEvent::ReadRequest(n) => {
                let take = n.min(bytes.len() - pos);
                reader.insert(take).copy_from_slice(&bytes[pos..pos + take]);
                reader.notify_read(take);
                pos += take;
            }
            LinearReadEvent::Record { opcode, data } => {
                let record = match mcap::parse_record(opcode, data) {
                    Ok(r) => r,
                    Err(e) => {
                        let (kind, reason) = describe_mcap_error(&e, data_end);
                        s.error = Some((
                            kind,
                            format!("a record (opcode {opcode:#04x}) does not parse: {reason}"),
                            pos as u64,
                        ));
                        break;
                    }
                };
                if data_end {
                    // the summary section repeats schemas and channels; keep its statistics
                    match record {
                        Record::Statistics(st) => stats = Some(st),
                        Record::Footer(_) => footer = true,
                        _ => {}
                    }
                    continue;
                }
                if let Err(reason) = on_record(&mut s, record, limit, on_message) {
                    s.error = Some((DamageKind::Corrupt, reason, pos as u64));
                    break;
                }
                if opcode == mcap::records::op::DATA_END {
                    data_end = true;
                }
            }
        }
    }
    if s.error.is_none() {
        if !footer {
            s.error = Some((
                DamageKind::Truncated,
                "the file has no footer".into(),
                pos as u64,
            ));
        } else if let Some(st) = &stats {
            if st.message_count != s.info.messages && limit == u64::MAX {
                s.error = Some((
                    DamageKind::Corrupt,
                    format!(
                        "the summary counts {} messages but the data section holds {}",
                        st.message_count, s.info.messages
                    ),
                    pos as u64,
                ));
            }
        }
    }
    s.info.summary_section = s.error.is_none() && footer;
    if s.info.summary_section {
        s.info.chunks = stats.as_ref().map(|st| u64::from(st.chunk_count));
    }
    // topics
    for (id, ch) in &s.channels {
        let (n, first, last) = s.counts.get(id).copied().unwrap_or((0, 0, 0));
        let schema = s.schemas.get(&ch.schema_id);
        s.info.topics.push(TopicInfo {
            topic: ch.topic.clone(),
            schema_name: schema.map(|x| x.name.clone()).unwrap_or_default(),
            schema_encoding: schema.map(|x| x.encoding.clone()).unwrap_or_default(),
            message_encoding: ch.message_encoding.clone(),
            metadata: ch.metadata.clone(),
            messages: n,
            first_s: if n > 0 { first as f64 * 1e-9 } else { f64::NAN },
            last_s: if n > 0 { last as f64 * 1e-9 } else { f64::NAN },
        });
    }
    s
}

fn on_record(
    s: &mut Scan,
    record: Record<'_>,
    limit: u64,
    on_message: &mut dyn FnMut(&MessageView<'_>) -> Result<(), String>,
) -> Result<(), String> {
    match record {
        Record::Header(h) => {
            s.info.profile = h.profile;
            s.info.library = h.library;
        }
        Record::Schema { header, data } => {
            if header.id == 0 {
                return Err("a schema has the invalid id 0".into());
            }
            let rec = SchemaRec {
                name: header.name,
                encoding: header.encoding,
                data: data.into_owned(),
            };
            if let Some(old) = s.schemas.get(&header.id) {
                if old.name != rec.name || old.encoding != rec.encoding || old.data != rec.data {
                    return Err(format!(
                        "schema {} is defined twice, differently",
                        header.id
                    ));
                }
            } else {
                s.schemas.insert(header.id, rec);
            }
        }
        Record::Channel(c) => {
            if c.schema_id != 0 && !s.schemas.contains_key(&c.schema_id) {
                return Err(format!(
                    "channel {} ({}) refers to the unknown schema {}",
                    c.id, c.topic, c.schema_id
                ));
            }
            s.channels.entry(c.id).or_insert(ChannelRec {
                topic: c.topic,
                schema_id: c.schema_id,
                message_encoding: c.message_encoding,
                metadata: c.metadata,
            });
        }
        Record::Message { header, data } => {
            if s.info.messages >= limit {
                return Ok(());
            }
            let Some(ch) = s.channels.get(&header.channel_id) else {
                return Err(format!(
                    "a message refers to the unknown channel {}",
                    header.channel_id
                ));
            };
            let empty = SchemaRec {
                name: String::new(),
                encoding: String::new(),
                data: Vec::new(),
            };
            let schema = s.schemas.get(&ch.schema_id).unwrap_or(&empty);
            let view = MessageView {
                channel_id: header.channel_id,
                topic: &ch.topic,
                schema_name: &schema.name,
                schema_encoding: &schema.encoding,
                schema_data: &schema.data,
                message_encoding: &ch.message_encoding,
                log_time_ns: header.log_time,
                data: &data,
            };
            on_message(&view)?;
            if view.schema_name == proto::RUN_SUMMARY {
                if let Ok(m) = proto::RunSummary::decode(view.data) {
                    s.info.summary = Some(RunSummary::from_proto(m));
                }
            }
            let lt = header.log_time;
            let c = s.counts.entry(header.channel_id).or_insert((0, lt, lt));
            c.0 += 1;
            c.1 = c.1.min(lt);
            c.2 = c.2.max(lt);
            s.info.messages += 1;
            let t = lt as f64 * 1e-9;
            s.info.start_s = Some(s.info.start_s.map_or(t, |x| x.min(t)));
            s.info.end_s = Some(s.info.end_s.map_or(t, |x| x.max(t)));
        }
        Record::Metadata(m) => s.info.metadata.push((m.name, m.metadata)),
        Record::Attachment { header, data, .. } => s.info.attachments.push(AttachmentInfo {
            name: header.name,
            media_type: header.media_type,
            log_time_ns: header.log_time,
            create_time_ns: header.create_time,
            data: data.into_owned(),
        }),
        _ => {}
    }
    Ok(())
}

impl RecordingReader {
    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's size in bytes.
    pub fn file_bytes(&self) -> u64 {
        self.bytes.len() as u64
    }

    /// What the recording holds (as far as it could be read).
    pub fn info(&self) -> &RecordingInfo {
        &self.info
    }

    /// The damage found, if the file is truncated or corrupted.
    pub fn damage(&self) -> Option<&Damage> {
        self.damage.as_ref()
    }

    /// Whether the file was read to its end with every check passing.
    pub fn is_complete(&self) -> bool {
        self.damage.is_none()
    }

    /// `Err(ReadError::Damaged)` (one line: what was read, what was not, why) unless the file
    /// is complete.
    pub fn require_complete(&self) -> Result<(), ReadError> {
        match &self.damage {
            None => Ok(()),
            Some(d) => Err(ReadError::Damaged {
                path: self.path.clone(),
                damage: d.clone(),
            }),
        }
    }

    /// The stored `/summary`, if the run finished.
    pub fn summary(&self) -> Option<&RunSummary> {
        self.info.summary.as_ref()
    }

    /// The run's description (program, engine, scene text, overrides, solver, geometry), or
    /// `None` for a file not written by this crate.
    pub fn run_info(&self) -> Option<RunInfo> {
        let run = self.info.metadata(crate::info::META_RUN)?;
        let scene_file = run.get("scene_file").cloned().unwrap_or_default();
        let scene = self
            .info
            .attachments
            .iter()
            .find(|a| a.name == scene_file)
            .map(|a| String::from_utf8_lossy(&a.data).into_owned());
        RunInfo::from_metadata(&self.info.metadata, scene.as_deref())
    }

    /// The disc names in scene order: from the run info, else from the spline topics.
    pub fn disc_names(&self) -> Vec<String> {
        if let Some(info) = self.run_info() {
            if !info.discs.is_empty() {
                return info.disc_names();
            }
        }
        let mut by_index: BTreeMap<usize, String> = BTreeMap::new();
        for t in &self.info.topics {
            if t.schema_name == proto::SPLINE_STATE {
                let i = t
                    .metadata
                    .get("disc_index")
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(by_index.len());
                let name = t
                    .metadata
                    .get("disc")
                    .cloned()
                    .unwrap_or_else(|| segment_of(&t.topic).to_string());
                by_index.insert(i, name);
            }
        }
        by_index.into_values().collect()
    }

    /// Calls `f` for every message read at open, in file order.
    pub fn for_each_message(&self, mut f: impl FnMut(&MessageView<'_>)) {
        let _ = scan(&self.bytes, self.info.messages, &mut |v| {
            f(v);
            Ok(())
        });
    }
}
