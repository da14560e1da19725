//! The MCAP file under every recording, a pack's or a network's ([`crate::Recorder`]): where
//! it is written (a temporary file moved into place at the end, [`PendingFile`]), the writer
//! opened with the header, scene attachment and metadata ([`open_mcap`]), the messages put on
//! their channels with their sequence numbers, the flushes, the first write error after which
//! nothing more is written, and the close with the `clutchpack.stats` record.

use crate::info::{num, utc_text, RunInfo, META_STATS, SCENE_MEDIA_TYPE};
use crate::output::{PendingFile, Replace};
use crate::write::{RecordError, RecordOptions};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Metadata records written after the run's own (`clutchpack.network`): each a name and its
/// key-value pairs.
pub(crate) type MoreMetadata = Vec<(String, BTreeMap<String, String>)>;

/// An MCAP file being written: the state both parts of the recorder share.
pub(crate) struct Sink {
    /// The file being written (the temporary file of an output written whole).
    pub path: PathBuf,
    /// Where [`Sink::close`] moves the file (an output written whole only).
    pub pending: Option<PendingFile>,
    pub writer: Option<mcap::Writer<BufWriter<File>>>,
    pub sequences: BTreeMap<u16, u32>,
    /// A message's bytes, reused: encoded into by [`Sink::put`], or by the caller before
    /// [`Sink::put_buf`].
    pub buf: Vec<u8>,
    /// Messages written so far.
    pub messages: u64,
    /// Messages written since the last flush.
    pub since_flush: usize,
    /// Whether a write failed (nothing more is written).
    pub failed: bool,
    pub last_flush: Instant,
    pub started: Instant,
}

impl Sink {
    /// Creates `target` as an output written whole (a temporary file beside it, see
    /// [`PendingFile`]) and opens the MCAP writer on it with `info`, `options`, chunks of
    /// `chunk_size_bytes` and `more_metadata` ([`open_mcap`]).
    pub fn create_output(
        target: &Path,
        replace: Replace,
        info: &RunInfo,
        options: &RecordOptions,
        chunk_size_bytes: u64,
        more_metadata: MoreMetadata,
    ) -> Result<Sink, RecordError> {
        let (pending, file) =
            PendingFile::create(target, replace).map_err(|cause| RecordError::Create {
                path: target.to_path_buf(),
                cause,
            })?;
        let path = pending.tmp_path().to_path_buf();
        Sink::open(
            path,
            file,
            Some(pending),
            info,
            options,
            chunk_size_bytes,
            more_metadata,
        )
    }

    /// Opens the MCAP writer on `file` (at `path`; moved into place by [`Sink::close`] when
    /// `pending`) as [`Sink::create_output`] does.
    pub fn open(
        path: PathBuf,
        file: File,
        pending: Option<PendingFile>,
        info: &RunInfo,
        options: &RecordOptions,
        chunk_size_bytes: u64,
        more_metadata: MoreMetadata,
    ) -> Result<Sink, RecordError> {
        let w = open_mcap(&path, file, info, options, chunk_size_bytes, more_metadata)?;
        Ok(Sink {
            path,
            pending,
            writer: Some(w),
            sequences: BTreeMap::new(),
            buf: Vec::with_capacity(4096),
            messages: 0,
            since_flush: 0,
            failed: false,
            last_flush: Instant::now(),
            started: Instant::now(),
        })
    }

    /// The error of a write after an earlier failure.
    pub fn failed_err(&self) -> RecordError {
        RecordError::AlreadyFailed {
            path: self.path.clone(),
        }
    }

    /// Encodes `msg` and writes it on `channel` at `log_time` (ns).
    pub fn put<M: prost::Message>(
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

    /// Writes the bytes in `self.buf` as a message on `channel` at `log_time` (ns); `what`
    /// names it in the error.
    pub fn put_buf(&mut self, channel: u16, log_time: u64, what: &str) -> Result<(), RecordError> {
        if self.failed {
            return Err(self.failed_err());
        }
        let Some(w) = self.writer.as_mut() else {
            return Err(self.failed_err());
        };
        if let Err(cause) = write_message(w, &mut self.sequences, channel, log_time, &self.buf) {
            self.failed = true;
            return Err(RecordError::Write {
                path: self.path.clone(),
                what: what.to_string(),
                cause,
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
            if let Err(cause) = w.flush() {
                self.failed = true;
                return Err(RecordError::Write {
                    path: self.path.clone(),
                    what: "flush".into(),
                    cause,
                });
            }
        }
        self.since_flush = 0;
        self.last_flush = Instant::now();
        Ok(())
    }

    /// Closes the file with the `clutchpack.stats` record `stats` ([`close_mcap`]) and moves
    /// an output written whole into place; returns its path. When the disk is full (or the
    /// quota exhausted) the temporary file is removed: what it holds cannot be completed, and
    /// leaving it would keep the space taken.
    pub fn close(&mut self, stats: BTreeMap<String, String>) -> Result<PathBuf, RecordError> {
        let Some(w) = self.writer.take().filter(|_| !self.failed) else {
            return Err(self.failed_err());
        };
        let r = close_mcap(w, &self.path.clone(), stats, &mut self.pending);
        self.discard_if_disk_full(&r);
        r
    }

    /// Removes the temporary file of an output written whole if `r` failed because the disk
    /// is full.
    pub fn discard_if_disk_full<T>(&mut self, r: &Result<T, RecordError>) {
        if r.as_ref().is_err_and(RecordError::is_disk_full) {
            if let Some(p) = self.pending.take() {
                p.discard();
            }
        }
    }
}

/// Opens an MCAP writer on `file` (at `path`, for messages) with the recorder's settings:
/// zstd chunks of `chunk_size_bytes`, the scene attached, and `info`'s metadata records
/// (with the recorder's options in `clutchpack.run`) followed by `more_metadata`. Shared by
/// both parts of the [`crate::Recorder`] (through [`Sink`]).
pub(crate) fn open_mcap(
    path: &Path,
    file: File,
    info: &RunInfo,
    options: &RecordOptions,
    chunk_size_bytes: u64,
    more_metadata: MoreMetadata,
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
