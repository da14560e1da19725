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
use crate::summary::RecordedSummary;
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt;
use std::io::{BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

mod network;
mod scan;
mod series;
pub use network::{read_network, RecordedNetwork};
use scan::*;
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
    pub summary: Option<RecordedSummary>,
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
    pub fn summary(&self) -> Option<&RecordedSummary> {
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
