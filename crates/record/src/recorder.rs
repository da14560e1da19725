//! The one recorder: [`Recorder`] records either kind of run into an MCAP file, a pack's
//! (the crate documentation's topics, `crate::pack`) or a driveline network's
//! (`crate::network`), as the run's [`Observer`]; both parts write through one
//! `crate::sink::Sink` (header, scene attachment, metadata, messages, flushes, close).

use crate::network::NetworkPart;
use crate::output::Replace;
use crate::pack::{pack_chunk_size_bytes, PackPart};
use crate::sink::Sink;
use crate::summary::RecordedSummary;
use crate::write::{RecordError, RecordOptions};
use crate::RunInfo;
use clutchpack_model::network::{ClutchEvent, Network, NetworkSample, Transmission};
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, Observer, RunStats, Sample};
use std::path::{Path, PathBuf};

/// Streams a run into an MCAP file: a pack's run ([`Recorder::create`],
/// [`Recorder::create_output`]; the crate documentation's topics) or a driveline network's
/// ([`Recorder::create_network_output`]; MODEL.md section 8).
///
/// Use it as the engine's [`Observer`] (or, for a pack, call [`Self::write_sample`] and
/// [`Self::write_impact`]), then [`Self::finish`]. Errors met inside the observer methods are
/// kept (the first one) and returned by `finish`; after an error nothing more is written, and
/// [`Observer::progress`] returns `true` to stop the run. Dropping a recorder without
/// `finish` still closes the file with its summary section, but without `/summary` (a
/// network's: without its summary attachment); so call `finish` after an engine error or a
/// Ctrl-C stop as well, to keep the summary of what ran.
pub struct Recorder {
    part: Part,
    /// The first error met by the observer methods.
    error: Option<RecordError>,
}

/// What the recording is of.
enum Part {
    Pack(Box<PackPart>),
    Network(Box<NetworkPart>),
}

impl Recorder {
    /// Creates the recording of a pack run at `path` (its folder is created if missing; an
    /// existing file is replaced) and writes the header, the scene attachment, the metadata,
    /// the channels and the static `/scene`, then flushes, so even a run killed at once leaves
    /// a valid prefix.
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
        let file = std::fs::File::create(&path).map_err(create_err)?;
        let chunk = pack_chunk_size_bytes(info, options);
        let sink = Sink::open(path, file, None, info, options, chunk, Vec::new())?;
        let pack = PackPart::start(sink, info, options)?;
        Ok(Recorder::of(Part::Pack(Box::new(pack))))
    }

    /// Creates the recording of a pack run as an output written whole: into a new temporary
    /// file beside `target` (`<stem>.partial-<pid>-<k>.mcap`, see
    /// [`crate::PendingFile`]), moved into place by [`Self::finish`] (replacing an existing
    /// `target` only with [`Replace::Existing`]; with [`Replace::Never`] under the first free
    /// `<stem>-<k>.mcap`). A run killed before `finish` leaves the temporary file, readable
    /// up to its last flush.
    pub fn create_output(
        target: impl AsRef<Path>,
        replace: Replace,
        info: &RunInfo,
        options: &RecordOptions,
    ) -> Result<Recorder, RecordError> {
        let chunk = pack_chunk_size_bytes(info, options);
        let sink = Sink::create_output(target.as_ref(), replace, info, options, chunk, Vec::new())?;
        let pack = PackPart::start(sink, info, options)?;
        Ok(Recorder::of(Part::Pack(Box::new(pack))))
    }

    /// Creates the recording of a run of the network `net` as an output written whole (as
    /// [`Self::create_output`]). `info` gives the scene, engine and settings (its discs are
    /// empty); of `options` the compression, determinism and chunk size apply.
    pub fn create_network_output(
        target: impl AsRef<Path>,
        replace: Replace,
        info: &RunInfo,
        net: &Network,
        options: &RecordOptions,
    ) -> Result<Recorder, RecordError> {
        let (info, chunk, meta) = NetworkPart::sink_setup(info, net, options);
        let sink = Sink::create_output(target.as_ref(), replace, &info, options, chunk, meta)?;
        let part = NetworkPart::start(sink, net, options)?;
        Ok(Recorder::of(Part::Network(Box::new(part))))
    }

    fn of(part: Part) -> Recorder {
        Recorder { part, error: None }
    }

    fn sink(&self) -> &Sink {
        match &self.part {
            Part::Pack(p) => &p.sink,
            Part::Network(n) => &n.sink,
        }
    }

    fn sink_mut(&mut self) -> &mut Sink {
        match &mut self.part {
            Part::Pack(p) => &mut p.sink,
            Part::Network(n) => &mut n.sink,
        }
    }

    /// The pack part, or the error of a pack's `what` given to a network's recording.
    fn pack(&mut self, what: &str) -> Result<&mut PackPart, RecordError> {
        match &mut self.part {
            Part::Pack(p) => Ok(p),
            Part::Network(n) => Err(RecordError::NotAPack {
                path: n.sink.path.clone(),
                what: what.to_string(),
            }),
        }
    }

    /// The recording's path (the temporary file of an output until [`Self::finish`]).
    pub fn path(&self) -> &Path {
        &self.sink().path
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.sink().messages
    }

    /// Whether the recording is deterministic ([`RecordOptions::deterministic`]: no wall
    /// times, so that two runs give the same bytes).
    pub fn deterministic(&self) -> bool {
        match &self.part {
            Part::Pack(p) => p.deterministic(),
            Part::Network(n) => n.deterministic(),
        }
    }

    /// The first error met by the [`Observer`] methods, if any (also returned by `finish`).
    pub fn error(&self) -> Option<&RecordError> {
        self.error.as_ref()
    }

    /// The first error met by the [`Observer`] methods, taken (nothing more is written;
    /// `finish` then reports the recording failed).
    pub fn take_error(&mut self) -> Option<RecordError> {
        self.error.take()
    }

    /// A pack recording's summary of the impacts written so far (what `finish(None)` stores).
    /// Errors only when the peaks kept on disk (a long run, see
    /// `clutchpack_analysis::PeakStats`) cannot be read back, or for a network's recording.
    pub fn summary(&self) -> Result<RecordedSummary, RecordError> {
        match &self.part {
            Part::Pack(p) => p.summary(),
            Part::Network(n) => Err(RecordError::NotAPack {
                path: n.sink.path.clone(),
                what: "summary".into(),
            }),
        }
    }

    /// Stores the engine's run statistics in the `clutchpack.stats` metadata written by
    /// [`Self::finish`] (a pack's recording; a network's keeps its own).
    pub fn set_run_stats(&mut self, stats: &RunStats) {
        if let Part::Pack(p) = &mut self.part {
            p.set_run_stats(stats);
        }
    }

    /// A network's run summary (the JSON of `run --summary-json`), attached by
    /// [`Self::finish`] as [`crate::SUMMARY_ATTACHMENT`] (a pack's recording stores its own
    /// `/summary` instead and ignores it).
    pub fn set_summary_json(&mut self, json: Vec<u8>) {
        if let Part::Network(n) = &mut self.part {
            n.summary_json = Some(json);
        }
    }

    /// Shows `tr`'s gear and shift phase over a network's scene from now on (a scene with a
    /// `[transmission]`): a text on `/scene/status` and a line on `/network/events` at t = 0
    /// and whenever it changes. Nothing for a pack's recording.
    pub fn set_transmission(&mut self, tr: &Transmission) -> Result<(), RecordError> {
        match &mut self.part {
            Part::Network(n) => n.set_transmission(tr),
            Part::Pack(_) => Ok(()),
        }
    }

    /// Ends the current chunk and flushes it to the file (it survives a SIGKILL from now on).
    pub fn flush(&mut self) -> Result<(), RecordError> {
        self.sink_mut().flush()
    }

    /// Writes one pack sample: `/shaft`, each disc's `/discs/<name>/spline` (and `teeth` when
    /// asked for), `/tf` and `/scene` when due. Log time = `sample.t_s` in ns.
    pub fn write_sample(&mut self, sample: &Sample) -> Result<(), RecordError> {
        self.pack("sample")?.write_sample(sample)
    }

    /// Writes one pack impact on `/impacts`, logged at its peak time `t_peak_s`.
    pub fn write_impact(&mut self, e: &ImpactEvent) -> Result<(), RecordError> {
        self.pack("impact")?.write_impact(e)
    }

    /// Writes the state of a pack's friction interfaces at `t_s` (s).
    pub fn write_interfaces(
        &mut self,
        t_s: f64,
        interfaces: &[InterfaceSample],
    ) -> Result<(), RecordError> {
        self.pack("interfaces")?.write_interfaces(t_s, interfaces)
    }

    /// Writes the state of a pack's disc `disc` at `t_s` (s) inside a contact
    /// ([`Observer::contact_sample`]).
    pub fn write_contact_sample(
        &mut self,
        disc: usize,
        t_s: f64,
        state: &DiscSample,
    ) -> Result<(), RecordError> {
        self.pack("contact sample")?
            .write_contact_sample(disc, t_s, state)
    }

    /// Writes a thermal pack run's temperatures at `t_s` (s): its bodies' and the oil's, K.
    pub fn write_temperatures(
        &mut self,
        t_s: f64,
        bodies_k: &[f64],
        oil_k: f64,
    ) -> Result<(), RecordError> {
        self.pack("temperatures")?
            .write_temperatures(t_s, bodies_k, oil_k)
    }

    /// Closes the file, moving an output into place, and returns its path, or the first
    /// error met while recording (the file is then closed as well as it can be). A pack's
    /// recording first writes `/summary` (`summary`, or [`Self::summary`] when `None`) and
    /// the run statistics if set; a network's attaches its summary JSON if set
    /// ([`Self::set_summary_json`]). Call it after a stop or an engine error too: the file
    /// then holds what ran.
    ///
    /// When the disk is full (or the quota exhausted) the temporary file is removed: what it
    /// holds cannot be completed, and leaving it would keep the space taken.
    pub fn finish(mut self, summary: Option<RecordedSummary>) -> Result<PathBuf, RecordError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        match self.part {
            Part::Pack(p) => p.finish(summary),
            Part::Network(n) => n.finish(),
        }
    }

    /// Keeps the first error of `r` (after which nothing more is written).
    fn keep(&mut self, r: Result<(), RecordError>) {
        if let Err(e) = r {
            if self.error.is_none() {
                self.error = Some(e);
            }
            self.sink_mut().failed = true;
        }
    }

    /// Runs `write` on the network part, unless writing failed; keeps its first error.
    fn network(&mut self, write: impl FnOnce(&mut NetworkPart) -> Result<(), RecordError>) {
        if let Part::Network(n) = &mut self.part {
            if !n.sink.failed {
                let r = write(n);
                self.keep(r);
            }
        }
    }

    /// Runs `write` on the pack part, unless writing failed; keeps its first error.
    fn on_pack(&mut self, write: impl FnOnce(&mut PackPart) -> Result<(), RecordError>) {
        if let Part::Pack(p) = &mut self.part {
            if !p.sink.failed {
                let r = write(p);
                self.keep(r);
            }
        }
    }
}

impl Observer for Recorder {
    fn sample(&mut self, sample: &Sample) {
        self.on_pack(|p| p.write_sample(sample));
    }

    fn impact(&mut self, event: &ImpactEvent) {
        self.on_pack(|p| p.write_impact(event));
    }

    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.on_pack(|p| p.write_interfaces(t_s, interfaces));
    }

    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        self.on_pack(|p| p.write_contact_sample(disc, t_s, state));
    }

    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.on_pack(|p| p.write_temperatures(t_s, bodies_k, oil_k));
    }

    /// A pack's recording with [`RecordOptions::contact_samples`].
    fn wants_contact_samples(&self) -> bool {
        match &self.part {
            Part::Pack(p) => p.wants_contact_samples(),
            Part::Network(_) => false,
        }
    }

    fn network_sample(&mut self, sample: &NetworkSample) {
        self.network(|n| n.write_sample(sample));
    }

    fn clutch_event(&mut self, event: &ClutchEvent) {
        self.network(|n| n.write_clutch_event(event));
    }

    fn mesh_impact(&mut self, impact: &ImpactEvent) {
        self.network(|n| n.write_mesh_impact(impact));
    }

    fn pack_impact(&mut self, coupling: usize, impact: &ImpactEvent) {
        self.network(|n| n.write_pack_impact(coupling, impact));
    }

    fn pack_sample(
        &mut self,
        coupling: usize,
        t_s: f64,
        angle_rad: &[f64],
        speed_rad_s: &[f64],
        load_n: &[f64],
    ) {
        self.network(|n| n.write_pack_sample(coupling, t_s, angle_rad, speed_rad_s, load_n));
    }

    fn pack_temperatures(&mut self, coupling: usize, t_s: f64, temperatures_k: &[f64]) {
        self.network(|n| n.write_pack_temperatures(coupling, t_s, temperatures_k));
    }

    fn pack_faces(
        &mut self,
        coupling: usize,
        _t_s: f64,
        locked: usize,
        clamped: usize,
        faces: usize,
    ) {
        self.network(|n| {
            n.pack_faces(coupling, locked, clamped, faces);
            Ok(())
        });
    }

    /// A network's recording, on the grid of [`crate::OPEN_CONTACTS_EVERY_S`].
    fn wants_open_contacts(&mut self, t_s: f64) -> bool {
        match &self.part {
            Part::Network(n) => n.wants_open_contacts(t_s),
            Part::Pack(_) => false,
        }
    }

    fn open_contacts(&mut self, t_s: f64, open: &[(usize, Option<usize>, ImpactEvent)]) {
        self.network(|n| n.open_contacts(t_s, open));
    }

    /// A pack's recording flushes when its interval has passed; either returns `true` (stop
    /// the run) once writing has failed.
    fn progress(&mut self, _t_s: f64) -> bool {
        self.on_pack(|p| p.maybe_flush());
        self.sink().failed
    }
}
