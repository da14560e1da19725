//! Reading a recording: [`open`] and [`RecordingReader`].
//!
//! The file is scanned once, record by record, from the start (the MCAP "streaming" read),
//! checking every chunk's CRC before using any of its messages, the data section's CRC, the
//! summary section's CRC and the message counts in the summary. Every message of our own and
//! of the two Foxglove schemas is decoded on the way, so a file that opens cleanly decodes
//! completely. At the first error [`RecordingReader::damage`] records what happened (strict
//! readers refuse the file on it), and the scan resynchronises: it seeks back to the last good
//! record and searches forward, one block at a time, for the next chunk record (a chunk header
//! whose lengths agree with each other and with the file, then the chunk's CRC) and reads on
//! from there, so a flipped bit in the scene attachment or in one chunk loses only that
//! record, not every chunk after it. Schemas and channels come from the summary section too
//! when the footer is intact, so messages of a chunk whose channel was defined in a lost chunk
//! still decode. Whole chunks only are used; [`Damage`] says how many regions and bytes were
//! skipped. A run killed mid-way (no summary section) is read up to its last complete chunk.
//! Nothing in here panics on bad input.
//!
//! # Memory
//!
//! The file is never held: the scan feeds the MCAP linear reader from a buffered file in
//! blocks ([`ReadOptions::block_bytes`], 1 MiB), so memory is bounded by the largest record
//! (a chunk, compressed and decompressed: at most about 4 MiB for ours) plus what the scan
//! reports (topics, metadata, the scene attachment), whatever the file's size. A damaged
//! record length can make the reader buffer up to the rest of the file before the record is
//! found bad; the record length limit is the file's size (at least 256 MiB). The reader keeps
//! the path and size, and every pass over the messages
//! ([`RecordingReader::for_each_message`]) reads the file again, as it was at open (bytes
//! appended since are not read). A file shortened, removed or rewritten in between is
//! reported, never a panic: [`RecordingReader::try_for_each_message`] returns
//! [`ReadError::Reread`]; [`RecordingReader::for_each_message`] keeps it for
//! [`RecordingReader::reread_error`]. What the series methods return is held whole
//! ([`RecordingReader::samples`] holds every sample); [`crate::export_csv`] and
//! [`RecordingReader::interface_stats`] stream. [`from_bytes`] reads a recording held in
//! memory (tests) and keeps it.

use crate::info::RunInfo;
use crate::proto;
use crate::summary::RunSummary;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt;
use std::io::{BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

mod series;
pub(crate) use series::impact_event;
pub(crate) use series::segment_of;
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
    /// The path is not a regular file (a FIFO, a device, a socket).
    #[error(
        "{path} is not a regular file (a FIFO, device or socket): a recording is read from a file"
    )]
    NotAFile {
        /// The path.
        path: PathBuf,
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
        /// What was read and what was not (boxed: it is large next to the other errors).
        damage: Box<Damage>,
    },
    /// The file could not be read again after it was opened (it was removed, shortened or
    /// rewritten): see [`RecordingReader::reread_error`].
    #[error("{path}: {reason}")]
    Reread {
        /// The file.
        path: PathBuf,
        /// What went wrong, in words.
        reason: String,
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
    /// Damaged regions skipped by resynchronising on the next chunk (0: the scan stopped at
    /// the damage).
    pub skipped_regions: u64,
    /// Bytes skipped in those regions.
    pub skipped_bytes: u64,
    /// Messages lost, when the file's summary section (its message count) could be read.
    pub lost_messages: Option<u64>,
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
        if let Some(t) = self.last_t_s {
            write!(f, " up to t = {t} s")?;
        }
        if self.skipped_regions == 0 {
            write!(f, ", the rest is unreadable")?;
        } else {
            write!(
                f,
                ", reading on past {} damaged region(s) ({} bytes skipped)",
                self.skipped_regions, self.skipped_bytes
            )?;
        }
        if let Some(n) = self.lost_messages {
            write!(f, "; {n} messages lost")?;
        }
        Ok(())
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

/// How a recording is read: the size of the blocks read from the file at a time.
///
/// The defaults suit every use; a small block is for tests (it exercises the reassembly of
/// records from many reads and the windowed search of the resynchronisation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadOptions {
    /// Bytes read from the file at a time (at least 1), and the window of the forward search
    /// for the next chunk after damage. Default 1 MiB.
    pub block_bytes: usize,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            block_bytes: 1 << 20,
        }
    }
}

/// An opened recording. See [`open`].
///
/// It holds what the first scan found ([`RecordingInfo`], [`Damage`]) and the file's path and
/// size, not the file: [`RecordingReader::for_each_message`] (and every series built on it)
/// reads the file again. A reader made by [`from_bytes`] keeps its bytes instead.
#[derive(Debug)]
pub struct RecordingReader {
    path: PathBuf,
    file_bytes: u64,
    /// The recording given to [`from_bytes`] (`None`: read from `path`).
    memory: Option<Vec<u8>>,
    options: ReadOptions,
    info: RecordingInfo,
    damage: Option<Damage>,
    /// Why the last [`RecordingReader::for_each_message`] could not read the file again.
    reread_error: Mutex<Option<String>>,
}

/// A byte source the scan reads from: the file ([`open`]) or memory ([`from_bytes`]).
trait Source: Read + Seek {}
impl<T: Read + Seek> Source for T {}

/// A source with its size (as at open: nothing after it is read) and the block size.
struct Input<'a> {
    src: &'a mut dyn Source,
    len: u64,
    block: usize,
    /// Stops the scan after the record being read once set (a signal).
    stop: Option<&'a AtomicBool>,
}

impl Input<'_> {
    fn seek(&mut self, at: u64) -> std::io::Result<()> {
        self.src.seek(SeekFrom::Start(at)).map(drop)
    }

    /// Fills `buf` from the current position; fewer bytes only at the end of the source.
    fn fill(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let mut n = 0;
        while n < buf.len() {
            match self.src.read(&mut buf[n..]) {
                Ok(0) => break,
                Ok(k) => n += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        Ok(n)
    }

    /// Up to `n` bytes at `at` (fewer at the end of the source).
    fn read_at(&mut self, at: u64, n: usize) -> std::io::Result<Vec<u8>> {
        let n = n.min(self.len.saturating_sub(at).try_into().unwrap_or(usize::MAX));
        let mut buf = vec![0; n];
        self.seek(at)?;
        let got = self.fill(&mut buf)?;
        buf.truncate(got);
        Ok(buf)
    }
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
    /// Damaged regions skipped and their bytes.
    skipped: (u64, u64),
    /// The message count of the summary section's statistics, if read.
    expected_messages: Option<u64>,
}

/// Where one pass of the linear reader ended.
struct PassEnd {
    /// The error that stopped it, if any: kind, reason, bytes read.
    error: Option<(DamageKind, String, u64)>,
    /// File offset just after the last record that was read whole (where the damage starts).
    last_good: u64,
    /// Whether the message limit was reached (the rest of the file is not wanted).
    done: bool,
}

/// What a pass carries over to the next one.
#[derive(Default)]
struct PassState {
    data_end: bool,
    footer: bool,
    stats: Option<mcap::records::Statistics>,
}

/// Opens the recording at `path` and scans it once (see the module documentation).
///
/// Errors only when nothing can be read: the file cannot be read, is not a regular file (a
/// FIFO, device or socket: it could not be read twice), is empty, or is not MCAP (a foreign
/// file). A truncated or corrupted MCAP file opens, with what could be read before the
/// damage, and [`RecordingReader::damage`] set; use [`RecordingReader::require_complete`]
/// (or [`open_complete`]) to treat that as an error. Memory does not grow with the file: it
/// is read in blocks, and only its largest record (a chunk, decompressed) is held at once.
pub fn open(path: impl AsRef<Path>) -> Result<RecordingReader, ReadError> {
    open_with(path, &ReadOptions::default())
}

/// [`open`] with explicit [`ReadOptions`].
pub fn open_with(
    path: impl AsRef<Path>,
    options: &ReadOptions,
) -> Result<RecordingReader, ReadError> {
    let path = path.as_ref().to_path_buf();
    let io = |source| ReadError::Io {
        path: path.clone(),
        source,
    };
    let meta = std::fs::metadata(&path).map_err(io)?;
    if !meta.is_file() && !meta.is_dir() {
        // a FIFO would block (or be consumed by the first read), a device never ends
        return Err(ReadError::NotAFile { path });
    }
    let file = std::fs::File::open(&path).map_err(io)?;
    // a folder opens on Linux and fails at the first read: the error names it
    let len = file.metadata().map_err(io)?.len();
    let mut src = BufReader::with_capacity(options.block_bytes.clamp(1, 64 << 10), file);
    read_source(path, &mut src, len, options)
}

/// [`open`], then [`RecordingReader::require_complete`].
pub fn open_complete(path: impl AsRef<Path>) -> Result<RecordingReader, ReadError> {
    let r = open(path)?;
    r.require_complete()?;
    Ok(r)
}

/// Reads a recording held in memory (kept by the reader); `path` is only used in messages.
pub fn from_bytes(path: impl Into<PathBuf>, bytes: Vec<u8>) -> Result<RecordingReader, ReadError> {
    from_bytes_with(path, bytes, &ReadOptions::default())
}

/// [`from_bytes`] with explicit [`ReadOptions`].
pub fn from_bytes_with(
    path: impl Into<PathBuf>,
    bytes: Vec<u8>,
    options: &ReadOptions,
) -> Result<RecordingReader, ReadError> {
    let path = path.into();
    let len = bytes.len() as u64;
    let mut src = Cursor::new(bytes);
    let mut r = read_source(path, &mut src, len, options)?;
    r.memory = Some(src.into_inner());
    Ok(r)
}

/// The first scan of a recording: checks its start, then scans it whole.
fn read_source(
    path: PathBuf,
    src: &mut dyn Source,
    len: u64,
    options: &ReadOptions,
) -> Result<RecordingReader, ReadError> {
    let io = |source| ReadError::Io {
        path: path.clone(),
        source,
    };
    let mut input = Input {
        src,
        len,
        block: options.block_bytes.max(1),
        stop: None,
    };
    let head = input.read_at(0, 24).map_err(io)?;
    if head.is_empty() {
        return Err(ReadError::Empty { path });
    }
    let magic = mcap::MAGIC;
    if head.len() < magic.len() && magic.starts_with(&head) {
        let damage = Damage {
            kind: DamageKind::Truncated,
            reason: format!("the file holds only {} bytes of the MCAP magic", head.len()),
            at_byte: head.len() as u64,
            file_bytes: len,
            messages: 0,
            topics: 0,
            last_t_s: None,
            skipped_regions: 0,
            skipped_bytes: 0,
            lost_messages: None,
        };
        return Err(ReadError::Damaged {
            path,
            damage: Box::new(damage),
        });
    }
    if !head.starts_with(magic) {
        return Err(ReadError::NotMcap {
            path,
            start: describe_start(&head),
        });
    }
    let scan = scan(&mut input, u64::MAX, &mut |v| validate(v)).map_err(io)?;
    let damage = scan.error.as_ref().map(|(kind, reason, at)| Damage {
        kind: *kind,
        reason: reason.clone(),
        at_byte: *at,
        file_bytes: len,
        messages: scan.info.messages,
        topics: scan.info.topics.iter().filter(|t| t.messages > 0).count(),
        last_t_s: scan.info.end_s,
        skipped_regions: scan.skipped.0,
        skipped_bytes: scan.skipped.1,
        lost_messages: scan
            .expected_messages
            .map(|n| n.saturating_sub(scan.info.messages)),
    });
    Ok(RecordingReader {
        path,
        file_bytes: len,
        memory: None,
        options: *options,
        info: scan.info,
        damage,
        reread_error: Mutex::new(None),
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

/// Scans `input` (which starts with the MCAP magic), calling `on_message` for each of the
/// first `limit` messages. The first error of the file or of `on_message` is kept in
/// `Scan::error`; the scan then resynchronises on the next intact chunk (see the module
/// documentation) and reads on. With a finite `limit` it stops once it has handed over that
/// many messages. Errors only when the source cannot be read.
fn scan(
    input: &mut Input<'_>,
    limit: u64,
    on_message: &mut dyn FnMut(&MessageView<'_>) -> Result<(), String>,
) -> std::io::Result<Scan> {
    let mut s = Scan {
        info: RecordingInfo::default(),
        schemas: BTreeMap::new(),
        channels: BTreeMap::new(),
        counts: BTreeMap::new(),
        error: None,
        skipped: (0, 0),
        expected_messages: None,
    };
    let mut st = PassState::default();
    let mut start = 0u64;
    let mut pos = 0u64;
    let len = input.len;
    loop {
        let end = scan_pass(input, start, &mut s, &mut st, limit, on_message)?;
        pos = pos.max(end.last_good);
        if end.done {
            return Ok(s);
        }
        let Some(err) = end.error else { break };
        if s.error.is_none() {
            s.error = Some(err.clone());
            // the summary section (if the footer is intact) knows every schema and channel
            // and how many messages there are
            preload_summary(input, &mut s)?;
        }
        if st.data_end {
            break; // damage in the summary section: no data after it
        }
        // resynchronise on the next plausible chunk (or metadata record) after the last good
        // record (strictly after this pass's start, so that every pass makes progress); a
        // pass that fails at once on it moves the search on by a byte
        match next_chunk(input, end.last_good.max(start + 1))? {
            Some(o) => {
                if o > end.last_good {
                    s.skipped.0 += 1;
                    s.skipped.1 += o - end.last_good;
                }
                start = o;
            }
            None => {
                // nothing intact after the damage: the rest of the file is skipped
                if end.last_good < len && s.skipped.0 > 0 {
                    s.skipped.1 += len - end.last_good;
                }
                break;
            }
        }
    }
    let footer = st.footer;
    let stats = st.stats;
    if let (Some(st), true) = (&stats, s.error.is_some()) {
        s.expected_messages = Some(st.message_count);
    }
    if s.error.is_none() {
        if !footer {
            s.error = Some((DamageKind::Truncated, "the file has no footer".into(), pos));
        } else if let Some(st) = &stats {
            if st.message_count != s.info.messages && limit == u64::MAX {
                s.error = Some((
                    DamageKind::Corrupt,
                    format!(
                        "the summary counts {} messages but the data section holds {}",
                        st.message_count, s.info.messages
                    ),
                    pos,
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
    Ok(s)
}

/// One pass of the linear reader over the input from `start` (0: the whole file, with its
/// magic; otherwise the offset of a chunk record found by [`next_chunk`]), fed in blocks of
/// at most `input.block` bytes: the reader holds one record (a chunk, decompressed) at a
/// time, never the file.
fn scan_pass(
    input: &mut Input<'_>,
    start: u64,
    s: &mut Scan,
    st: &mut PassState,
    limit: u64,
    on_message: &mut dyn FnMut(&MessageView<'_>) -> Result<(), String>,
) -> std::io::Result<PassEnd> {
    let resumed = start > 0;
    let len = input.len;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(resumed)
            .with_prevalidate_chunk_crcs(true)
            .with_validate_chunk_crcs(true)
            // the data section's CRC covers it from its start: not checkable after a skip
            .with_validate_data_section_crc(!resumed)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(usize::try_from(len).unwrap_or(usize::MAX).max(256 << 20)),
    );
    input.seek(start)?;
    let mut pos = start;
    let mut last_good = start;
    let fail = |kind, reason, pos: u64, last_good| {
        Ok(PassEnd {
            error: Some((kind, reason, pos)),
            last_good,
            done: false,
        })
    };
    loop {
        let event = match reader.next_event() {
            None => break,
            Some(Ok(e)) => e,
            Some(Err(e)) => {
                let (kind, reason) = if chunk_runs_past_end(input, last_good)? {
                    (
                        DamageKind::Truncated,
                        "the file ends inside a chunk (no summary section: the run did not finish, or the copy is partial)".into(),
                    )
                } else {
                    describe_mcap_error(&e, st.data_end)
                };
                return fail(kind, reason, pos, last_good);
            }
        };
        match event {
            LinearReadEvent::ReadRequest(n) => {
                // never past the size at open (a file still being written grows)
                let rest = usize::try_from(len.saturating_sub(pos)).unwrap_or(usize::MAX);
                let take = n.min(input.block).min(rest);
                let got = input.fill(reader.insert(take))?;
                reader.notify_read(got);
                pos += got as u64;
            }
            LinearReadEvent::Record { opcode, data } => {
                let record = match mcap::parse_record(opcode, data) {
                    Ok(r) => r,
                    Err(e) => {
                        let (kind, reason) = describe_mcap_error(&e, st.data_end);
                        let reason =
                            format!("a record (opcode {opcode:#04x}) does not parse: {reason}");
                        return fail(kind, reason, pos, last_good);
                    }
                };
                if st.data_end {
                    // the summary section repeats schemas and channels; keep its statistics
                    match record {
                        Record::Statistics(x) => st.stats = Some(x),
                        Record::Footer(_) => st.footer = true,
                        _ => {}
                    }
                    last_good = pos;
                    continue;
                }
                if let Err(reason) = on_record(s, record, limit, on_message) {
                    return fail(DamageKind::Corrupt, reason, pos, last_good);
                }
                if opcode == mcap::records::op::DATA_END {
                    st.data_end = true;
                }
                last_good = pos;
                let stopped = input.stop.is_some_and(|x| x.load(Ordering::SeqCst));
                if stopped || (limit != u64::MAX && s.info.messages >= limit) {
                    return Ok(PassEnd {
                        error: None,
                        last_good,
                        done: true,
                    });
                }
            }
        }
    }
    Ok(PassEnd {
        error: None,
        last_good: pos,
        done: false,
    })
}

/// The most bytes [`plausible_chunk`] looks at: opcode, record length, the fixed chunk
/// header, a compression name of at most 4 bytes and the compressed size.
const CHUNK_PROBE: usize = 9 + 32 + 4 + 8;

/// Whether a chunk record starts at `at` whose stated length runs past the end of the file:
/// the chunk a killed run was writing (the recorder writes a chunk in place, its length a
/// placeholder until the chunk ends) or the last chunk of a partial copy.
fn chunk_runs_past_end(input: &mut Input<'_>, at: u64) -> std::io::Result<bool> {
    let head = input.read_at(at, 9)?;
    Ok(match head.split_first() {
        Some((&op, len)) if op == mcap::records::op::CHUNK && len.len() == 8 => {
            let mut b = [0u8; 8];
            b.copy_from_slice(len);
            let record_len = u64::from_le_bytes(b);
            at.saturating_add(9).saturating_add(record_len) > input.len
        }
        _ => false,
    })
}

/// The offset of the first plausible chunk or metadata record at or after `from`. A chunk:
/// the chunk opcode, then a record length that fits in the file and agrees with the chunk
/// header's compression name (none, `zstd` or `lz4`) and compressed size; its CRC is checked
/// when it is read. A metadata record (the run's statistics follow the last chunk): a length
/// that fits and agrees with its name's and its map's lengths. The file is searched in
/// windows of one block (plus the few bytes a candidate's header needs).
fn next_chunk(input: &mut Input<'_>, from: u64) -> std::io::Result<Option<u64>> {
    use mcap::records::op;
    let len = input.len;
    let w = input.block;
    let mut o = from;
    while o < len {
        let win = input.read_at(o, w + CHUNK_PROBE)?;
        if win.is_empty() {
            break; // the source is shorter than at open
        }
        let scan_to = win.len().min(w);
        let mut i = 0;
        while i < scan_to {
            let Some(k) = win[i..scan_to]
                .iter()
                .position(|&b| b == op::CHUNK || b == op::METADATA)
            else {
                break;
            };
            i += k;
            let at = o + i as u64;
            let head = &win[i..];
            let avail = len - at;
            let ok = if head[0] == op::CHUNK {
                plausible_chunk(head, avail)
            } else {
                plausible_metadata(input, at, head, avail)?
            };
            if ok {
                return Ok(Some(at));
            }
            i += 1;
        }
        o += scan_to as u64;
    }
    Ok(None)
}

/// Whether the record at `at` (whose first bytes are `head`, `avail` bytes left in the file)
/// is a metadata record whose lengths agree (see [`next_chunk`]).
fn plausible_metadata(
    input: &mut Input<'_>,
    at: u64,
    head: &[u8],
    avail: u64,
) -> std::io::Result<bool> {
    let le32 = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64;
    if avail < 9 + 8 || head.len() < 9 + 8 {
        return Ok(false);
    }
    let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
    if len < 8 || len > avail - 9 {
        return Ok(false);
    }
    let name = le32(&head[9..13]);
    if name > len - 8 {
        return Ok(false);
    }
    // the map's length follows the name: in the window, or read from the file
    let map_at = 9 + 4 + name as usize;
    let map_len = if head.len() >= map_at + 4 {
        le32(&head[map_at..map_at + 4])
    } else {
        let b = input.read_at(at + map_at as u64, 4)?;
        if b.len() < 4 {
            return Ok(false);
        }
        le32(&b)
    };
    Ok(4 + name + 4 + map_len == len)
}

/// Whether `head` (at least [`CHUNK_PROBE`] bytes, or all `avail` bytes left in the file)
/// starts with a chunk record whose lengths agree (see [`next_chunk`]).
fn plausible_chunk(head: &[u8], avail: u64) -> bool {
    let le64 = |b: &[u8]| u64::from_le_bytes(b.try_into().unwrap_or([0xff; 8]));
    // opcode, record length, then the fixed chunk header: start, end, uncompressed size and
    // CRC, compression name length
    if avail < 9 + 32 || head.len() < 9 + 32 {
        return false;
    }
    let len = le64(&head[1..9]);
    if len > avail - 9 {
        return false;
    }
    let h = &head[9..];
    let clen = u32::from_le_bytes([h[28], h[29], h[30], h[31]]) as usize;
    if clen > 4 || avail - 9 < (32 + clen + 8) as u64 || h.len() < 32 + clen + 8 {
        return false;
    }
    if !matches!(&h[32..32 + clen], b"" | b"zstd" | b"lz4") {
        return false;
    }
    let csize = le64(&h[32 + clen..40 + clen]);
    (40 + clen as u64).checked_add(csize) == Some(len)
}

/// Reads the schemas, channels and statistics of the summary section, if the footer at the
/// end of the file is intact, into `s` (what the data section defined is kept), so that a
/// resynchronised scan decodes chunks whose channels were defined in a lost one, and knows
/// how many messages were lost. The section is read record by record.
fn preload_summary(input: &mut Input<'_>, s: &mut Scan) -> std::io::Result<()> {
    use mcap::records::op;
    let n = input.len;
    // footer record: opcode, length 20, summary start, summary offset start, CRC; then magic
    let footer_len = 9 + 20;
    let tail_len = (footer_len + mcap::MAGIC.len()) as u64;
    if n < mcap::MAGIC.len() as u64 + tail_len {
        return Ok(());
    }
    let f = n - tail_len;
    let tail = input.read_at(f, tail_len as usize)?;
    if tail.len() as u64 != tail_len || !tail.ends_with(mcap::MAGIC) || tail[0] != op::FOOTER {
        return Ok(());
    }
    let mut p = u64::from_le_bytes(tail[9..17].try_into().unwrap_or([0; 8]));
    if p == 0 || p >= f {
        return Ok(());
    }
    input.seek(p)?;
    let mut body = Vec::new();
    while p + 9 <= f {
        let mut head = [0u8; 9];
        if input.fill(&mut head)? < 9 {
            return Ok(());
        }
        let len = u64::from_le_bytes(head[1..9].try_into().unwrap_or([0xff; 8]));
        let Some(end) = (p + 9).checked_add(len) else {
            return Ok(());
        };
        if end > f {
            return Ok(());
        }
        // bounded by the summary section (checked just above)
        body.resize(len as usize, 0);
        if input.fill(&mut body)? < body.len() {
            return Ok(());
        }
        match mcap::parse_record(head[0], &body) {
            Ok(Record::Schema { header, data }) if header.id != 0 => {
                s.schemas.entry(header.id).or_insert(SchemaRec {
                    name: header.name,
                    encoding: header.encoding,
                    data: data.into_owned(),
                });
            }
            Ok(Record::Channel(c)) => {
                if c.schema_id == 0 || s.schemas.contains_key(&c.schema_id) {
                    s.channels.entry(c.id).or_insert(ChannelRec {
                        topic: c.topic,
                        schema_id: c.schema_id,
                        message_encoding: c.message_encoding,
                        metadata: c.metadata,
                    });
                }
            }
            Ok(Record::Statistics(st)) => s.expected_messages = Some(st.message_count),
            Ok(_) => {}
            Err(_) => return Ok(()),
        }
        p = end;
    }
    Ok(())
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
        self.file_bytes
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
                damage: Box::new(d.clone()),
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

    /// Calls `f` for every message read at open, in file order, reading the file again.
    ///
    /// The file is read as at open: the messages recovered then, the damaged regions
    /// skipped as then. It may have grown since (a run still recording appends whole chunks);
    /// if it cannot be read again (removed, shortened, rewritten so that fewer messages are
    /// recovered), `f` sees the messages up to the problem and the reason is kept for
    /// [`RecordingReader::reread_error`] (which commands that must not give partial results
    /// check), rather than returned: the series built on this method stay plain vectors.
    /// Use [`RecordingReader::try_for_each_message`] to get the error at once.
    pub fn for_each_message(&self, f: impl FnMut(&MessageView<'_>)) {
        let result = self.try_for_each_message(f);
        if let Err(e) = result {
            let reason = match e {
                ReadError::Reread { reason, .. } => reason,
                other => other.to_string(),
            };
            if let Ok(mut slot) = self.reread_error.lock() {
                slot.get_or_insert(reason);
            }
        }
    }

    /// [`RecordingReader::for_each_message`] that returns [`ReadError::Reread`] (naming the
    /// file) when the file cannot be read again as it was at open; `f` has then seen the
    /// messages up to the problem.
    pub fn try_for_each_message(&self, f: impl FnMut(&MessageView<'_>)) -> Result<(), ReadError> {
        self.for_each_message_until(None, f)
    }

    /// [`RecordingReader::try_for_each_message`] that stops after the message being handed
    /// over once `stop` is set (a signal; not an error).
    pub(crate) fn for_each_message_until(
        &self,
        stop: Option<&AtomicBool>,
        mut f: impl FnMut(&MessageView<'_>),
    ) -> Result<(), ReadError> {
        let fail = |reason: String| ReadError::Reread {
            path: self.path.clone(),
            reason,
        };
        let want = self.info.messages;
        if want == 0 {
            return Ok(());
        }
        let mut seen = 0u64;
        let mut on_message = |v: &MessageView<'_>| {
            seen += 1;
            f(v);
            Ok(())
        };
        let block = self.options.block_bytes.max(1);
        let mut src: Box<dyn Source + '_> = match &self.memory {
            Some(bytes) => Box::new(Cursor::new(bytes.as_slice())),
            None => {
                let file = std::fs::File::open(&self.path)
                    .map_err(|e| fail(format!("cannot read the file again: {e}")))?;
                let now = file
                    .metadata()
                    .map_err(|e| fail(format!("cannot read the file again: {e}")))?
                    .len();
                if now < self.file_bytes {
                    return Err(fail(format!(
                        "the file changed since it was opened: it holds {now} bytes, {} at open",
                        self.file_bytes
                    )));
                }
                Box::new(BufReader::with_capacity(block.min(64 << 10), file))
            }
        };
        let mut input = Input {
            src: &mut *src,
            len: self.file_bytes,
            block,
            stop,
        };
        let scanned = scan(&mut input, want, &mut on_message);
        scanned.map_err(|e| fail(format!("cannot read the file again: {e}")))?;
        let stopped = stop.is_some_and(|x| x.load(Ordering::SeqCst));
        if seen < want && !stopped {
            return Err(fail(format!(
                "the file changed since it was opened: {seen} of its {want} messages read again"
            )));
        }
        Ok(())
    }

    /// Why a [`RecordingReader::for_each_message`] (or a series built on it:
    /// [`RecordingReader::samples`], [`RecordingReader::impacts`], ...) could not read the
    /// file again, as [`ReadError::Reread`] naming the file; `None` if every re-read was
    /// whole. Commands check it before they report, so that a file changed under them is an
    /// error rather than a partial result.
    pub fn reread_error(&self) -> Option<ReadError> {
        let slot = self.reread_error.lock().ok()?;
        slot.as_ref().map(|reason| ReadError::Reread {
            path: self.path.clone(),
            reason: reason.clone(),
        })
    }
}
