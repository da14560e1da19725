//! The recorder on its own thread, so that encoding, compressing and writing a recording run
//! beside the engine rather than on its thread: the engine's thread copies each item into a
//! batch and hands full batches over a bounded channel.
//!
//! A [`ThreadedRecorder`] is fed by an engine's observer (`sample`, `impact`, `interfaces`,
//! `contact_sample`, and [`ThreadedRecorder::send`] at each progress call); [`ThreadedRecorder::join`] waits
//! for everything to be written and gives the [`Recorder`] back to be finished, with the
//! recording thread's CPU time.

use crate::Recorder;
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, Observer, Sample};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// What the engine's thread hands to the recording thread.
enum ToRecorder {
    Sample(Sample),
    Impact(ImpactEvent),
    Interfaces(f64, Vec<InterfaceSample>),
    /// `(disc, t s, state)` of a contact sample.
    Contact(usize, f64, DiscSample),
    /// `(t s, bodies K, oil K)` of a thermal run.
    Temperatures(f64, Vec<f64>, f64),
}

/// Items per batch handed to the recording thread. Handing over every sample on its own
/// woke the recording thread 10 000 times per simulated second (a futex call each), which
/// slowed the engine's thread more than the encoding did. Measured with `clutchpack bench`
/// on a 3 s paper case: the engine thread's CPU time grew by 7 % with batches of 32 and by
/// 3.5 % with 256; a batch is at most 2.6 ms of simulated time at 10 kHz, and a slow engine
/// hands over what it has at each progress call (every 1024 steps) anyway.
const BATCH: usize = 256;

/// Bytes of samples per batch at most (about): a batch is handed over at [`BATCH`] items or
/// this many bytes of their buffers, whichever comes first. A recorder that falls behind (a
/// starved machine) leaves up to [`QUEUED_BATCHES`] + 3 batches in flight, and their buffers
/// are kept for reuse: 256 samples of pack-8-brake's 17 bodies were about 870 kB a batch, so
/// a run `nice`d under a load of 7 peaked at 36 MB recorded against 29 MB unloaded. With 256
/// KiB a batch, at most about 3 MB are in flight whatever the pack; a 1-disc pack's batch
/// (about 50 kB) is still [`BATCH`] items, so its hand-overs stay as rare.
const BATCH_BYTES: usize = 256 << 10;

/// Full batches that may wait for the recording thread. When the engine outruns the
/// recorder (a long pack run: the recorder is the slower of the two), the queue fills and
/// holds this many batches for the rest of the run: 64 batches of a 4-disc pack's samples
/// were about 9 MB, which showed as memory that grew with the run length (15 MB at 3 s
/// simulated, 21-26 MB from 30 s on); 8 keep about 1 MB in flight and still smooth the
/// recorder's chunk writes.
const QUEUED_BATCHES: usize = 8;

/// The recorder on its own thread: the engine's thread only copies each sample into a batch
/// and hands full batches over a bounded channel, so encoding, compressing and writing run
/// beside the simulation. Emptied batches come back on a second channel and their samples'
/// buffers are reused, so the engine's thread neither allocates nor frees per sample.
pub struct ThreadedRecorder {
    tx: std::sync::mpsc::SyncSender<Vec<ToRecorder>>,
    back: std::sync::mpsc::Receiver<Vec<ToRecorder>>,
    batch: Vec<ToRecorder>,
    /// items of `batch` in use; those beyond are spare buffers
    len: usize,
    /// the bytes of the items in use (about: [`item_bytes`])
    bytes: usize,
    failed: Arc<AtomicBool>,
    /// the recorder's `Observer::wants_contact_samples`
    wants_contacts: bool,
    /// gives back the recorder and the thread's CPU time in s
    handle: std::thread::JoinHandle<(Recorder, f64)>,
}

/// The bytes an item holds (its own size and its buffers', about), for [`BATCH_BYTES`].
fn item_bytes(m: &ToRecorder) -> usize {
    let disc = |d: &DiscSample| {
        std::mem::size_of::<DiscSample>() + d.tooth_loads_n.len() * std::mem::size_of::<f64>()
    };
    std::mem::size_of::<ToRecorder>()
        + match m {
            ToRecorder::Sample(s) => s.discs.iter().map(disc).sum(),
            ToRecorder::Contact(_, _, d) => disc(d),
            ToRecorder::Interfaces(_, i) => i.len() * std::mem::size_of::<InterfaceSample>(),
            ToRecorder::Temperatures(_, b, _) => b.len() * std::mem::size_of::<f64>(),
            ToRecorder::Impact(_) => 0,
        }
}

/// Copies `src` into `dst` field by field, reusing `dst`'s buffers (a derived `clone_from`
/// would allocate anew). Destructured so that a new field of `Sample` fails to compile here.
fn copy_sample(dst: &mut Sample, src: &Sample) {
    let Sample {
        t_s,
        shaft_angle_rad,
        shaft_speed_rad_s,
        discs,
    } = src;
    dst.t_s = *t_s;
    dst.shaft_angle_rad = *shaft_angle_rad;
    dst.shaft_speed_rad_s = *shaft_speed_rad_s;
    dst.discs.truncate(discs.len());
    let n = dst.discs.len();
    for (d, s) in dst.discs.iter_mut().zip(discs) {
        let loads = std::mem::take(&mut d.tooth_loads_n);
        *d = DiscSample {
            tooth_loads_n: loads,
            ..*s
        };
        d.tooth_loads_n.clear();
        d.tooth_loads_n.extend_from_slice(&s.tooth_loads_n);
    }
    dst.discs.extend(discs[n..].iter().cloned());
}

impl ThreadedRecorder {
    /// Starts the recording thread that writes into `rec`.
    pub fn start(mut rec: Recorder) -> ThreadedRecorder {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<ToRecorder>>(QUEUED_BATCHES);
        let (back_tx, back) = std::sync::mpsc::channel::<Vec<ToRecorder>>();
        let failed = Arc::new(AtomicBool::new(false));
        let wants_contacts = rec.wants_contact_samples();
        let flag = failed.clone();
        let worker = move || {
            let cpu = cpu_time::ThreadTime::try_now().ok();
            for batch in rx {
                let mut t_s = None;
                for m in &batch {
                    match m {
                        ToRecorder::Sample(s) => {
                            rec.sample(s);
                            t_s = Some(s.t_s);
                        }
                        ToRecorder::Impact(e) => rec.impact(e),
                        ToRecorder::Interfaces(t, i) => rec.interfaces(*t, i),
                        ToRecorder::Contact(i, t, d) => rec.contact_sample(*i, *t, d),
                        ToRecorder::Temperatures(t, b, oil) => rec.temperatures(*t, b, *oil),
                    }
                }
                // the wall-clock flush is checked once per batch
                if rec.progress(t_s.unwrap_or(0.0)) {
                    flag.store(true, Ordering::SeqCst);
                }
                // the engine's thread may be gone already; the batch is then dropped here
                let _ = back_tx.send(batch);
            }
            let cpu_s = cpu
                .and_then(|c| c.try_elapsed().ok())
                .map_or(0.0, |d| d.as_secs_f64());
            (rec, cpu_s)
        };
        let handle = std::thread::Builder::new()
            .name("recorder".into())
            .spawn(worker)
            .expect("spawning the recorder thread");
        ThreadedRecorder {
            tx,
            back,
            batch: Vec::with_capacity(BATCH),
            len: 0,
            bytes: 0,
            failed,
            wants_contacts,
            handle,
        }
    }

    /// Hands an impact to the recording thread (batched).
    pub fn push_impact(&mut self, e: &ImpactEvent) {
        self.push(ToRecorder::Impact(*e));
    }

    /// Hands the friction interfaces' states at `t_s` (s) to the recording thread (batched).
    pub fn push_interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.push(ToRecorder::Interfaces(t_s, interfaces.to_vec()));
    }

    /// Hands a thermal run's temperatures at `t_s` (s) to the recording thread (batched;
    /// [`Observer::temperatures`]: the bodies' and the oil's, K).
    pub fn push_temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.push(ToRecorder::Temperatures(t_s, bodies_k.to_vec(), oil_k));
    }

    /// Whether the recorder takes contact samples ([`RecordOptions::contact_samples`]).
    ///
    /// [`RecordOptions::contact_samples`]: crate::RecordOptions::contact_samples
    pub fn wants_contact_samples(&self) -> bool {
        self.wants_contacts
    }

    /// Hands disc `disc`'s contact sample at `t_s` (s) to the recording thread (batched;
    /// [`Observer::contact_sample`]).
    pub fn push_contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        match self.slot() {
            Some(ToRecorder::Contact(i, t, dst)) => {
                *i = disc;
                *t = t_s;
                let loads = std::mem::take(&mut dst.tooth_loads_n);
                *dst = DiscSample {
                    tooth_loads_n: loads,
                    ..*state
                };
                dst.tooth_loads_n.clear();
                dst.tooth_loads_n.extend_from_slice(&state.tooth_loads_n);
            }
            Some(other) => *other = ToRecorder::Contact(disc, t_s, state.clone()),
            None => self
                .batch
                .push(ToRecorder::Contact(disc, t_s, state.clone())),
        }
        self.send_if_full();
    }

    /// Whether writing failed (the recorder's own error is given by `finish` after
    /// [`ThreadedRecorder::join`]); a run should stop then.
    pub fn failed(&self) -> bool {
        self.failed.load(Ordering::SeqCst)
    }

    /// The next free slot of the batch: a spare one (to be overwritten) or a new one.
    fn slot(&mut self) -> Option<&mut ToRecorder> {
        let i = self.len;
        self.len += 1;
        self.batch.get_mut(i)
    }

    /// Hands a copy of `s` to the recording thread (batched).
    pub fn push_sample(&mut self, s: &Sample) {
        match self.slot() {
            Some(ToRecorder::Sample(dst)) => copy_sample(dst, s),
            Some(other) => *other = ToRecorder::Sample(s.clone()),
            None => self.batch.push(ToRecorder::Sample(s.clone())),
        }
        self.send_if_full();
    }

    fn push(&mut self, m: ToRecorder) {
        match self.slot() {
            Some(slot) => *slot = m,
            None => self.batch.push(m),
        }
        self.send_if_full();
    }

    fn send_if_full(&mut self) {
        if let Some(m) = self.len.checked_sub(1).and_then(|i| self.batch.get(i)) {
            self.bytes += item_bytes(m);
        }
        if self.len >= BATCH || self.bytes >= BATCH_BYTES {
            self.send();
        }
    }

    /// Hands what is pending to the recording thread now, without waiting for a full batch
    /// (an engine's progress call does this, so a slow engine's samples reach the file).
    pub fn send(&mut self) {
        if self.len == 0 {
            return;
        }
        self.batch.truncate(self.len);
        let next = self
            .back
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH));
        let full = std::mem::replace(&mut self.batch, next);
        self.len = 0;
        self.bytes = 0;
        // A closed channel means the thread ended; join() reports why.
        let _ = self.tx.send(full);
    }

    /// Waits for everything pushed to be written and returns the recorder to finish it, and
    /// the recording thread's CPU time in s.
    pub fn join(mut self) -> (Recorder, f64) {
        self.send();
        drop(self.tx);
        match self.handle.join() {
            Ok(r) => r,
            Err(p) => std::panic::resume_unwind(p),
        }
    }
}
