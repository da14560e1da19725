//! What every recording shares: its options ([`RecordOptions`]), its errors ([`RecordError`]),
//! its default path and log times; the MCAP file itself is `crate::sink`, the pack's and the
//! network's topics `crate::pack` and `crate::network`, the one recorder `crate::recorder`.

use crate::info::utc_text;
use crate::topic_segment;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

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
    /// ([`clutchpack_model::Observer::contact_sample`]) and at the samples with a load (and the first; in
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
    /// A pack's record (a sample, an impact, ...) given to a network's recording.
    #[error("the recording {path} is a network's: it takes no pack {what}")]
    NotAPack {
        /// The recording's path.
        path: PathBuf,
        /// What was given.
        what: String,
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
/// [`crate::Recorder::create_output`] and [`crate::Replace::Never`], which takes the next free
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
pub(crate) fn next_tick(t: f64, interval: f64) -> f64 {
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
pub(crate) fn quantize(level: f64) -> u8 {
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
