//! The loaded samples of one coupling that no closed impact has claimed yet, in memory that
//! does not grow with the run: the newest [`PENDING_IN_MEMORY`] in memory, the older ones in
//! an unnamed temporary file (as [`crate::PeakStats`] keeps its peaks).
//!
//! A contact that never opens holds no samples, but one that stays closed (a plate resting
//! on its flank under the gaps' drag, a locked pack) holds every sample of its load until it
//! separates, which may be the end of the run: its history is counted from those samples with
//! the located peak merged in at its time ([`crate::cycles::impact_history`]), and the peak's
//! time is known only when the contact closes, so no sample can be counted or dropped before.

use std::io::{BufReader, Read, Seek, SeekFrom};

/// Loaded samples of one coupling held in memory before the older ones go to its temporary
/// file: 16 bytes each, 64 kB per coupling (a contact of 0.4 s at 10 kHz).
pub const PENDING_IN_MEMORY: usize = 4_096;

/// Bytes of one (t s f64, load N f64) record of the temporary file.
const RECORD_BYTES: usize = 16;

/// Loaded samples `(t s, load N)` in time order: those in the file first, then `held`.
#[derive(Debug, Default)]
pub(super) struct PendingSamples {
    /// the oldest samples, when more than [`PENDING_IN_MEMORY`] were pending
    file: Option<std::fs::File>,
    /// the newest samples (after those in the file)
    held: Vec<(f64, f64)>,
    /// the file could not be created or written: everything stays in memory
    in_memory_only: bool,
    /// the first error reading the file back (the samples after it were lost)
    error: Option<String>,
}

impl PendingSamples {
    /// Adds the next sample (time order).
    pub(super) fn push(&mut self, t_s: f64, load_n: f64) {
        self.held.push((t_s, load_n));
        if self.held.len() >= PENDING_IN_MEMORY && !self.in_memory_only && self.spill().is_err() {
            // no temporary space: keep the samples in memory rather than lose them
            self.in_memory_only = true;
        }
    }

    /// Samples held in memory.
    pub(super) fn held(&self) -> usize {
        self.held.len()
    }

    /// Why some samples could not be read back from the temporary file, if they could not.
    pub(super) fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn spill(&mut self) -> std::io::Result<()> {
        let mut bytes = Vec::with_capacity(self.held.len() * RECORD_BYTES);
        for &(t, x) in &self.held {
            bytes.extend_from_slice(&t.to_le_bytes());
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        crate::stats::append_to_temp(&mut self.file, &bytes)?;
        self.held.clear();
        Ok(())
    }

    /// Every sample in time order to `visit`, the file's first; stops reading the file at
    /// its first error (returned), then visits the held samples.
    fn each(&self, mut visit: impl FnMut((f64, f64))) -> std::io::Result<()> {
        let mut result = Ok(());
        if let Some(mut f) = self.file.as_ref() {
            result = (|| {
                f.seek(SeekFrom::Start(0))?;
                let mut r = BufReader::with_capacity(1 << 16, f);
                let mut rec = [0u8; RECORD_BYTES];
                loop {
                    match r.read_exact(&mut rec) {
                        Ok(()) => {}
                        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
                        Err(e) => return Err(e),
                    }
                    let (t, x) = rec.split_at(8);
                    let t = f64::from_le_bytes(t.try_into().unwrap_or_default());
                    let x = f64::from_le_bytes(x.try_into().unwrap_or_default());
                    visit((t, x));
                }
            })();
        }
        for &s in &self.held {
            visit(s);
        }
        result
    }

    /// Hands the samples strictly inside `(t_on_s, t_off_s)` to `visit` in time order and
    /// keeps only those after `t_off_s` (a closed impact claims its samples; those before
    /// it belong to no contact that can still close).
    pub(super) fn claim(&mut self, t_on_s: f64, t_off_s: f64, mut visit: impl FnMut((f64, f64))) {
        if self.file.is_none() {
            for &s in &self.held {
                if s.0 > t_on_s && s.0 < t_off_s {
                    visit(s);
                }
            }
            self.held.retain(|s| s.0 > t_off_s);
            return;
        }
        let mut rest = PendingSamples {
            in_memory_only: self.in_memory_only,
            error: self.error.take(),
            ..PendingSamples::default()
        };
        let read = self.each(|s| {
            if s.0 > t_on_s && s.0 < t_off_s {
                visit(s);
            }
            if s.0 > t_off_s {
                rest.push(s.0, s.1);
            }
        });
        if let Err(e) = read {
            rest.error.get_or_insert_with(|| {
                format!("loaded samples kept in a temporary file could not be read back ({e})")
            });
        }
        *self = rest;
    }
}

impl Clone for PendingSamples {
    /// An independent copy: the samples in the temporary file are copied to a new one (or,
    /// failing that, read into memory).
    fn clone(&self) -> PendingSamples {
        let copy = |f: &std::fs::File| -> std::io::Result<std::fs::File> {
            let mut from = f;
            from.seek(SeekFrom::Start(0))?;
            let mut to = tempfile::tempfile()?;
            std::io::copy(&mut from, &mut to)?;
            Ok(to)
        };
        let mut c = PendingSamples {
            file: None,
            held: self.held.clone(),
            in_memory_only: self.in_memory_only,
            error: self.error.clone(),
        };
        if let Some(f) = self.file.as_ref() {
            match copy(f) {
                Ok(to) => c.file = Some(to),
                Err(_) => {
                    let mut all = Vec::new();
                    if let Err(e) = self.each(|s| all.push(s)) {
                        c.error.get_or_insert_with(|| {
                            format!(
                                "loaded samples kept in a temporary file could not be read back ({e})"
                            )
                        });
                    }
                    c.held = all;
                    c.in_memory_only = true;
                }
            }
        }
        c
    }
}
