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
use crate::topics;
use clutchpack_model::{DiscSample, Flank, ImpactEvent, Sample};
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

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

/// One disc's recorded spline states (`/discs/<name>/spline`), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscSeries {
    /// Disc name.
    pub name: String,
    /// Topic segment (`/discs/<segment>/spline`).
    pub segment: String,
    /// Index of the disc in the scene.
    pub index: usize,
    /// The decoded messages.
    pub states: Vec<proto::SplineState>,
    /// Per-tooth loads, if they were recorded.
    pub teeth: Vec<proto::ToothLoads>,
}

/// One friction interface's recorded states (`/interfaces/<segment>`), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceSeries {
    /// The body below the interface (channel metadata `lower`).
    pub lower: String,
    /// The body above it (channel metadata `upper`).
    pub upper: String,
    /// Topic segment (`/interfaces/<segment>`).
    pub segment: String,
    /// Index of the interface along the stack.
    pub index: usize,
    /// The decoded messages.
    pub states: Vec<proto::InterfaceState>,
}

/// One disc's per-tooth load history: what `plot` draws and `compare` needs.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadHistory {
    /// Disc name.
    pub name: String,
    /// Sample times in s.
    pub t_s: Vec<f64>,
    /// Per-tooth load in N at each time (negative when the shaft leads).
    pub load_n: Vec<f64>,
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

    /// What the file holds, as text for `clutchpack replay`: the file and its state, the run
    /// (program, engine, scene and its hash, overrides), the topics with their schemas,
    /// message counts and time spans, and the per-disc summary (stored, or recomputed from
    /// the recovered impacts and marked so). Lines end with `\n`.
    pub fn describe(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let i = &self.info;
        let state = match &self.damage {
            None => "complete".to_string(),
            Some(d) => d.to_string(),
        };
        let _ = writeln!(
            s,
            "{} ({} bytes): {state}",
            self.path.display(),
            self.bytes.len()
        );
        if let Some(run) = self.info.metadata(crate::info::META_RUN) {
            let g = |k: &str| run.get(k).map(String::as_str).unwrap_or("?");
            let sha = g("scene_sha256");
            let _ = writeln!(
                s,
                "run: {} {}, engine {}, scene {} ({}, sha256 {}), overrides {}",
                g("program"),
                g("program_version"),
                g("engine"),
                g("scene_name"),
                g("scene_file"),
                sha.chars().take(12).collect::<String>(),
                g("overrides")
            );
        }
        match (i.start_s, i.end_s) {
            (Some(a), Some(b)) => {
                let _ = writeln!(
                    s,
                    "{} messages on {} topics, t = {} .. {} s",
                    i.messages,
                    i.topics.len(),
                    short(a),
                    short(b)
                );
            }
            _ => {
                let _ = writeln!(s, "no messages, {} topics", i.topics.len());
            }
        }
        let w = i
            .topics
            .iter()
            .map(|t| t.topic.len())
            .max()
            .unwrap_or(5)
            .max(5);
        let ws = i
            .topics
            .iter()
            .map(|t| t.schema_name.len())
            .max()
            .unwrap_or(6)
            .max(6);
        let _ = writeln!(
            s,
            "  {:<w$}  {:<ws$}  {:>9}  span (s)",
            "topic", "schema", "messages"
        );
        for t in &i.topics {
            let span = if t.messages > 0 {
                format!("{} .. {}", short(t.first_s), short(t.last_s))
            } else {
                "-".into()
            };
            let _ = writeln!(
                s,
                "  {:<w$}  {:<ws$}  {:>9}  {span}",
                t.topic, t.schema_name, t.messages
            );
        }
        let (summary, note) = match self.summary() {
            Some(x) => (x.clone(), "stored"),
            None => (
                self.summary_or_recomputed(),
                "recomputed from the recovered impacts",
            ),
        };
        if !summary.discs.is_empty() {
            let _ = writeln!(
                s,
                "summary ({note}; per-tooth loads in N, t_end = {} s):",
                short(summary.t_end_s)
            );
            let wd = summary
                .discs
                .iter()
                .map(|d| d.name.len())
                .max()
                .unwrap_or(4)
                .max(4);
            let _ = writeln!(
                s,
                "  {:<wd$}  {:>12}  {:>12}  {:>12}  {:>8}  {:>14}",
                "disc", "max_positive", "max_negative", "p99_abs", "impacts", "mean_top10_abs"
            );
            for d in &summary.discs {
                let _ = writeln!(
                    s,
                    "  {:<wd$}  {:>12.1}  {:>12.1}  {:>12.1}  {:>8}  {:>14.1}",
                    d.name,
                    d.max_positive_n,
                    d.max_negative_n,
                    d.p99_abs_n,
                    d.impacts,
                    d.mean_top10_abs_n
                );
            }
            if summary.discs.iter().any(|d| d.fatigue.is_some()) {
                let _ = writeln!(
                    s,
                    "fatigue of the spline teeth (stored; MODEL.md section 7, at this duty):"
                );
                let _ = writeln!(
                    s,
                    "  {:<wd$}  {:>12}  {:>10}  {:>10}  {:>12}  {:>16}",
                    "disc", "damage [1/h]", "life [h]", "S_eq [N]", "max sigma_F", "worst tooth"
                );
                let life =
                    |h: Option<f64>| h.map_or("unlimited".to_string(), |h| format!("{h:.3e}"));
                for d in &summary.discs {
                    let Some(f) = &d.fatigue else { continue };
                    let worst = f
                        .worst_tooth
                        .map_or("-".to_string(), |(k, l, _)| format!("{k}: {} h", life(l)));
                    let _ = writeln!(
                        s,
                        "  {:<wd$}  {:>12.4e}  {:>10}  {:>10.1}  {:>8.1} MPa  {:>16}",
                        d.name,
                        f.damage_rate_per_h,
                        life(f.life_h),
                        f.eq_load_range_n,
                        f.max_root_stress_pa * 1e-6,
                        worst
                    );
                }
            }
        }
        let interfaces = self.interface_stats();
        if !interfaces.is_empty() {
            let _ = writeln!(s, "friction interfaces (from the piston side):");
            let table = clutchpack_analysis::interface_table(
                &interfaces,
                clutchpack_analysis::TableFormat::Text,
            );
            for line in table.lines() {
                let _ = writeln!(s, "  {line}");
            }
        }
        s
    }

    /// What each friction interface did over the recorded run ([`InterfaceStats`]), in
    /// stack order; named `<lower>__<upper>`.
    ///
    /// [`InterfaceStats`]: clutchpack_analysis::InterfaceStats
    pub fn interface_stats(&self) -> Vec<clutchpack_analysis::InterfaceStats> {
        self.interface_series()
            .iter()
            .map(|f| {
                let name = crate::FrictionInterface {
                    lower: f.lower.clone(),
                    upper: f.upper.clone(),
                }
                .name();
                let mut st = clutchpack_analysis::InterfaceStats::new(name);
                for m in &f.states {
                    st.update(m.t_s, &m.to_sample());
                }
                st
            })
            .collect()
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

    /// The shaft states (`/shaft`) in file order.
    pub fn shaft_states(&self) -> Vec<proto::ShaftState> {
        let mut out = Vec::new();
        self.for_each_message(|v| {
            if v.schema_name == proto::SHAFT_STATE {
                if let Ok(m) = proto::ShaftState::decode(v.data) {
                    out.push(m);
                }
            }
        });
        out
    }

    /// Every friction interface's states, in stack order (empty for a pack without a stack).
    pub fn interface_series(&self) -> Vec<InterfaceSeries> {
        let mut by_topic: BTreeMap<&str, InterfaceSeries> = BTreeMap::new();
        for t in &self.info.topics {
            if t.schema_name == proto::INTERFACE_STATE {
                let meta = |k: &str| t.metadata.get(k).cloned().unwrap_or_default();
                let segment = t
                    .topic
                    .strip_prefix(topics::INTERFACES_PREFIX)
                    .unwrap_or(&t.topic)
                    .to_string();
                by_topic.insert(
                    &t.topic,
                    InterfaceSeries {
                        lower: meta("lower"),
                        upper: meta("upper"),
                        segment,
                        index: meta("interface_index").parse().unwrap_or(usize::MAX),
                        states: Vec::new(),
                    },
                );
            }
        }
        self.for_each_message(|v| {
            if v.schema_name == proto::INTERFACE_STATE {
                if let (Some(series), Ok(m)) = (
                    by_topic.get_mut(v.topic),
                    proto::InterfaceState::decode(v.data),
                ) {
                    series.states.push(m);
                }
            }
        });
        let mut out: Vec<InterfaceSeries> = by_topic.into_values().collect();
        out.sort_by_key(|s| s.index);
        out
    }

    /// Every disc's spline states (and per-tooth loads when recorded), in disc-index order.
    pub fn disc_series(&self) -> Vec<DiscSeries> {
        let names = self.disc_names();
        let mut by_index: BTreeMap<u32, DiscSeries> = BTreeMap::new();
        fn get<'m>(
            by_index: &'m mut BTreeMap<u32, DiscSeries>,
            names: &[String],
            i: u32,
            topic: &str,
        ) -> &'m mut DiscSeries {
            by_index.entry(i).or_insert_with(|| DiscSeries {
                name: names
                    .get(i as usize)
                    .cloned()
                    .unwrap_or_else(|| segment_of(topic).to_string()),
                segment: segment_of(topic).to_string(),
                index: i as usize,
                states: Vec::new(),
                teeth: Vec::new(),
            })
        }
        self.for_each_message(|v| match v.schema_name {
            proto::SPLINE_STATE => {
                if let Ok(m) = proto::SplineState::decode(v.data) {
                    get(&mut by_index, &names, m.disc_index, v.topic)
                        .states
                        .push(m);
                }
            }
            proto::TOOTH_LOADS => {
                if let Ok(m) = proto::ToothLoads::decode(v.data) {
                    get(&mut by_index, &names, m.disc_index, v.topic)
                        .teeth
                        .push(m);
                }
            }
            _ => {}
        });
        by_index.into_values().collect()
    }

    /// Each disc's per-tooth load history (t in s, load in N), in disc-index order.
    pub fn load_histories(&self) -> Vec<LoadHistory> {
        self.disc_series()
            .into_iter()
            .map(|d| LoadHistory {
                name: d.name,
                t_s: d.states.iter().map(|s| s.t_s).collect(),
                load_n: d.states.iter().map(|s| s.load_n).collect(),
            })
            .collect()
    }

    /// The impact events (`/impacts`) in file order (the order they closed).
    pub fn impacts(&self) -> Vec<ImpactEvent> {
        let mut out = Vec::new();
        self.for_each_message(|v| {
            if v.schema_name == proto::IMPACT {
                if let Ok(m) = proto::Impact::decode(v.data) {
                    out.push(ImpactEvent {
                        disc: m.disc_index as usize,
                        t_on_s: m.t_on_s,
                        t_peak_s: m.t_peak_s,
                        t_off_s: m.t_off_s,
                        flank: match proto::Flank::try_from(m.flank) {
                            Ok(proto::Flank::DiscLeads) => Flank::DiscLeads,
                            Ok(proto::Flank::ShaftLeads) => Flank::ShaftLeads,
                            // unset: the sign of the load says it (eq (6))
                            _ => {
                                if m.peak_n > 0.0 {
                                    Flank::DiscLeads
                                } else {
                                    Flank::ShaftLeads
                                }
                            }
                        },
                        v_on_m_s: m.v_on_m_s,
                        peak_n: m.peak_n,
                    });
                }
            }
        });
        out
    }

    /// The stored summary, or (for a run that did not finish) the summary of the recovered
    /// impacts up to the last recovered message.
    pub fn summary_or_recomputed(&self) -> RunSummary {
        if let Some(s) = self.summary() {
            return s.clone();
        }
        RunSummary::from_impacts(
            &self.disc_names(),
            &self.impacts(),
            self.info.end_s.unwrap_or(0.0),
        )
    }

    /// The samples, rebuilt from `/shaft` and the disc topics (the k-th message of each makes
    /// the k-th sample). A sample only partly recovered (cut by a truncation) is left out;
    /// `tooth_loads_n` is empty unless per-tooth loads were recorded.
    pub fn samples(&self) -> Vec<Sample> {
        let shaft = self.shaft_states();
        let discs = self.disc_series();
        let mut out = Vec::with_capacity(shaft.len());
        let mut tooth_cursor = vec![0usize; discs.len()];
        'samples: for (k, sh) in shaft.iter().enumerate() {
            let mut sample = Sample {
                t_s: sh.t_s,
                shaft_angle_rad: sh.angle_rad,
                shaft_speed_rad_s: sh.speed_rad_s,
                discs: Vec::with_capacity(discs.len()),
            };
            for (d, c) in discs.iter().zip(tooth_cursor.iter_mut()) {
                let Some(s) = d.states.get(k) else {
                    break 'samples;
                };
                if s.t_s != sh.t_s {
                    break 'samples;
                }
                while d.teeth.get(*c).is_some_and(|t| t.t_s < sh.t_s) {
                    *c += 1;
                }
                let tooth_loads_n = match d.teeth.get(*c) {
                    Some(t) if t.t_s == sh.t_s => t.loads_n.clone(),
                    _ => Vec::new(),
                };
                sample.discs.push(DiscSample {
                    angle_rad: s.angle_rad,
                    speed_rad_s: s.speed_rad_s,
                    rel_angle_rad: s.rel_angle_rad,
                    penetration_m: s.penetration_m,
                    closing_speed_m_s: s.closing_speed_m_s,
                    load_n: s.load_n,
                    torque_n_m: s.torque_n_m,
                    engaged: s.engaged,
                    stiffness: s.stiffness_n_m1_5,
                    tooth_loads_n,
                });
            }
            out.push(sample);
        }
        out
    }
}

/// A time in s with at most 9 decimals, trailing zeros dropped (`0.00399`, not
/// `0.0039900000000000005`).
fn short(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// The `<segment>` of `/discs/<segment>/...`.
fn segment_of(topic: &str) -> &str {
    let rest = topic.strip_prefix(topics::DISCS_PREFIX).unwrap_or(topic);
    rest.split('/').next().unwrap_or(rest)
}
