//! `export --csv DIR`: one CSV file per topic of ours (see [`export_csv`]).

use crate::output::{PendingFile, Replace};
use crate::proto;
use crate::read::{impact_event, segment_of, MessageView, ReadError, RecordingReader};
use crate::summary::RecordedSummary;
use crate::topics;
use clutchpack_analysis::csv_field;
use clutchpack_model::Flank;
use prost::Message as _;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufRead as _, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Writes one CSV file per topic of ours into `dir` (created if missing) and returns their
/// paths.
///
/// | file | topic | columns |
/// | --- | --- | --- |
/// | `shaft.csv` | `/shaft` | `t_s,angle_rad,speed_rad_s` |
/// | `spline_<segment>.csv` | `/discs/<segment>/spline` | `t_s,rel_angle_rad,closing_speed_m_s,penetration_m,load_n,torque_n_m,engaged,stiffness_n_m1_5,speed_rad_s,angle_rad` |
/// | `teeth_<segment>.csv` | `/discs/<segment>/teeth` | `t_s,tooth_0_n,tooth_1_n,...` |
/// | `load_<segment>.csv` | `/discs/<segment>/load` | `t_s,load_n,rel_angle_rad,contact_step` |
/// | `interface_<segment>.csv` | `/interfaces/<segment>` | `t_s,slip_rad_s,slip_m_s,mu,clamp_n,torque_n_m,locked,dissipated_j` |
/// | `impacts.csv` | `/impacts` | `disc,disc_index,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n` |
/// | `summary.csv` | `/summary` | `disc,max_positive_n,max_negative_n,p99_abs_n,impacts,positive_impacts,negative_impacts,mean_top10_abs_n` |
///
/// Numbers are written in Rust's shortest round-trip form (read back exactly); `engaged` is
/// 0 or 1, as is `locked`; `flank` is `shaft_leads` or `disc_leads`. `summary.csv` holds the stored summary,
/// or for a run that did not finish the one recomputed from the recovered impacts.
/// Files of topics without messages are not written (but for the shaft, impacts and summary).
pub fn export_csv(
    reader: &RecordingReader,
    dir: impl AsRef<Path>,
) -> Result<Vec<PathBuf>, ReadError> {
    export_csv_until(reader, dir, &AtomicBool::new(false))
}

/// [`export_csv`] that stops once `stop` is set (a signal): the files committed until then
/// are complete (each is written to a temporary sibling and renamed into place) and returned;
/// the others are removed.
///
/// The recording is read once, and every row goes to its file as its message is read: memory
/// does not grow with the recording (but for the impacts kept to recompute the summary of a
/// run that did not finish). The per-tooth rows go to a temporary file first, because the
/// header names as many teeth as the longest row has.
pub fn export_csv_until(
    reader: &RecordingReader,
    dir: impl AsRef<Path>,
    stop: &AtomicBool,
) -> Result<Vec<PathBuf>, ReadError> {
    let dir = dir.as_ref();
    std::fs::create_dir_all(dir).map_err(|source| ReadError::Export {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut out = Export::new(reader, dir)?;
    let read = reader.for_each_message_until(Some(stop), |v| {
        if out.error.is_none() {
            if let Err(e) = out.message(v) {
                out.error = Some(e);
            }
        }
    });
    let result = match (read, out.error.take()) {
        (_, Some(e)) | (Err(e), None) => Err(e),
        (Ok(()), None) => Ok(()),
    };
    if let Err(e) = result {
        out.discard();
        return Err(e);
    }
    if stop.load(Ordering::SeqCst) {
        out.discard();
        return Ok(Vec::new());
    }
    out.finish(reader, stop)
}

/// One CSV file being written: rows go to a temporary sibling of the target.
struct Csv {
    pending: PendingFile,
    w: BufWriter<File>,
}

impl Csv {
    fn create(target: &Path, header: &str) -> Result<Csv, ReadError> {
        let (pending, f) =
            PendingFile::create(target, Replace::Existing).map_err(|source| ReadError::Export {
                path: target.to_path_buf(),
                source,
            })?;
        let mut csv = Csv {
            pending,
            w: BufWriter::with_capacity(64 << 10, f),
        };
        csv.w
            .write_all(header.as_bytes())
            .map_err(|e| csv.error(e))?;
        Ok(csv)
    }

    /// The CSV in `slot`, created at `target()` with `header` on first use (a per-disc or
    /// per-interface file exists only if its topic has a message).
    fn lazy<'a>(
        slot: &'a mut Option<Csv>,
        target: impl FnOnce() -> PathBuf,
        header: &str,
    ) -> Result<&'a mut Csv, ReadError> {
        let c = match slot.take() {
            Some(c) => c,
            None => Csv::create(&target(), header)?,
        };
        Ok(slot.insert(c))
    }

    fn error(&self, source: std::io::Error) -> ReadError {
        ReadError::Export {
            path: self.pending.target().to_path_buf(),
            source,
        }
    }

    /// Flushes and closes the temporary file (not yet renamed into place).
    fn close(self) -> Result<PendingFile, ReadError> {
        let Csv { pending, w } = self;
        match w.into_inner() {
            Ok(f) => {
                drop(f);
                Ok(pending)
            }
            Err(e) => {
                let err = ReadError::Export {
                    path: pending.target().to_path_buf(),
                    source: e.into_error(),
                };
                pending.discard();
                Err(err)
            }
        }
    }
}

/// One disc's files: spline states and per-tooth loads (the rows first, the header after).
struct DiscFiles {
    segment: String,
    spline: Option<Csv>,
    teeth: Option<Csv>,
    /// The dense load series (samples with a load and contact samples).
    load: Option<Csv>,
    /// The most and fewest teeth of a per-tooth row.
    teeth_n: (usize, usize),
}

/// The files of an export being written.
struct Export<'a> {
    dir: &'a Path,
    names: Vec<String>,
    shaft: Option<Csv>,
    discs: BTreeMap<u32, DiscFiles>,
    /// By topic: the interface's index along the stack, its segment, its file once a state
    /// came.
    interfaces: BTreeMap<String, (usize, String, Option<Csv>)>,
    impacts: Option<Csv>,
    /// A network recording's files by topic (`network_body_<segment>.csv`,
    /// `network_coupling_<segment>.csv`), in topic order, once a message came.
    network: BTreeMap<String, Option<Csv>>,
    /// The impacts, kept only when the summary has to be recomputed from them.
    recompute: Option<Vec<clutchpack_model::ImpactEvent>>,
    error: Option<ReadError>,
}

impl<'a> Export<'a> {
    fn new(reader: &RecordingReader, dir: &'a Path) -> Result<Export<'a>, ReadError> {
        let interfaces = reader
            .info()
            .topics
            .iter()
            .filter(|t| t.schema_name == proto::INTERFACE_STATE)
            .map(|t| {
                let segment = t
                    .topic
                    .strip_prefix(topics::INTERFACES_PREFIX)
                    .unwrap_or(&t.topic)
                    .to_string();
                let index = t
                    .metadata
                    .get("interface_index")
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(usize::MAX);
                (t.topic.clone(), (index, segment, None))
            })
            .collect();
        let mut e = Export {
            dir,
            names: reader.disc_names(),
            shaft: None,
            discs: BTreeMap::new(),
            interfaces,
            impacts: None,
            network: BTreeMap::new(),
            // a network recording's summary is its attachment, not recomputed from impacts
            recompute: (reader.summary().is_none()
                && reader.info().metadata(crate::META_NETWORK).is_none())
            .then(Vec::new),
            error: None,
        };
        // a network recording has no shaft of a pack: its bodies go to files of their own
        if reader.info().metadata(crate::META_NETWORK).is_none() {
            let shaft = Csv::create(&dir.join("shaft.csv"), "t_s,angle_rad,speed_rad_s\n");
            e.shaft = Some(shaft?);
        }
        let impacts = Csv::create(
            &dir.join("impacts.csv"),
            "disc,disc_index,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n\n",
        );
        match impacts {
            Ok(c) => e.impacts = Some(c),
            Err(err) => {
                e.discard();
                return Err(err);
            }
        }
        Ok(e)
    }

    /// Writes the row of one message, if it is one of ours.
    fn message(&mut self, v: &MessageView<'_>) -> Result<(), ReadError> {
        if v.topic.starts_with(&topics::network_body(""))
            || v.topic.starts_with(&topics::network_coupling(""))
        {
            return self.network_message(v);
        }
        match v.schema_name {
            proto::SHAFT_STATE => {
                let (Ok(m), Some(c)) = (proto::ShaftState::decode(v.data), self.shaft.as_mut())
                else {
                    return Ok(());
                };
                writeln!(c.w, "{:?},{:?},{:?}", m.t_s, m.angle_rad, m.speed_rad_s)
                    .map_err(|e| c.error(e))
            }
            proto::SPLINE_STATE => {
                let Ok(m) = proto::SplineState::decode(v.data) else {
                    return Ok(());
                };
                let dir = self.dir;
                let d = self.disc(m.disc_index, v.topic);
                let segment = &d.segment;
                let c = Csv::lazy(
                    &mut d.spline,
                    || dir.join(format!("spline_{segment}.csv")),
                    "t_s,rel_angle_rad,closing_speed_m_s,penetration_m,load_n,torque_n_m,engaged,stiffness_n_m1_5,speed_rad_s,angle_rad\n",
                )?;
                writeln!(
                    c.w,
                    "{:?},{:?},{:?},{:?},{:?},{:?},{},{:?},{:?},{:?}",
                    m.t_s,
                    m.rel_angle_rad,
                    m.closing_speed_m_s,
                    m.penetration_m,
                    m.load_n,
                    m.torque_n_m,
                    u8::from(m.engaged),
                    m.stiffness_n_m1_5,
                    m.speed_rad_s,
                    m.angle_rad
                )
                .map_err(|e| c.error(e))
            }
            proto::LOAD_SAMPLE => {
                let Ok(m) = proto::LoadSample::decode(v.data) else {
                    return Ok(());
                };
                let dir = self.dir;
                let d = self.disc(m.disc_index, v.topic);
                let segment = &d.segment;
                let c = Csv::lazy(
                    &mut d.load,
                    || dir.join(format!("load_{segment}.csv")),
                    "t_s,load_n,rel_angle_rad,contact_step\n",
                )?;
                writeln!(
                    c.w,
                    "{:?},{:?},{:?},{}",
                    m.t_s,
                    m.load_n,
                    m.rel_angle_rad,
                    u8::from(m.contact_step)
                )
                .map_err(|e| c.error(e))
            }
            proto::TOOTH_LOADS => {
                let Ok(m) = proto::ToothLoads::decode(v.data) else {
                    return Ok(());
                };
                let dir = self.dir;
                let d = self.disc(m.disc_index, v.topic);
                if d.teeth.is_none() {
                    // the rows only: the header is written when the number of teeth is known
                    let path = dir.join(format!("teeth_{}.csv", d.segment));
                    d.teeth = Some(Csv::create(&path, "")?);
                    d.teeth_n = (m.loads_n.len(), m.loads_n.len());
                }
                d.teeth_n.0 = d.teeth_n.0.max(m.loads_n.len());
                d.teeth_n.1 = d.teeth_n.1.min(m.loads_n.len());
                let Some(c) = d.teeth.as_mut() else {
                    return Ok(());
                };
                let mut row = format!("{:?}", m.t_s);
                for x in &m.loads_n {
                    let _ = write!(row, ",{x:?}");
                }
                row.push('\n');
                c.w.write_all(row.as_bytes()).map_err(|e| c.error(e))
            }
            proto::INTERFACE_STATE => {
                let Some((_, segment, file)) = self.interfaces.get_mut(v.topic) else {
                    return Ok(());
                };
                let Ok(m) = proto::InterfaceState::decode(v.data) else {
                    return Ok(());
                };
                let dir = self.dir;
                let c = Csv::lazy(
                    file,
                    || dir.join(format!("interface_{segment}.csv")),
                    "t_s,slip_rad_s,slip_m_s,mu,clamp_n,torque_n_m,locked,dissipated_j\n",
                )?;
                writeln!(
                    c.w,
                    "{:?},{:?},{:?},{:?},{:?},{:?},{},{:?}",
                    m.t_s,
                    m.slip_rad_s,
                    m.slip_m_s,
                    m.mu,
                    m.clamp_n,
                    m.torque_n_m,
                    u8::from(m.locked),
                    m.dissipated_j
                )
                .map_err(|e| c.error(e))
            }
            // `/discs/<segment>/impacts` repeat these per disc for plots
            proto::IMPACT if v.topic == topics::IMPACTS => {
                let Ok(m) = proto::Impact::decode(v.data) else {
                    return Ok(());
                };
                let e = impact_event(&m);
                if let Some(all) = self.recompute.as_mut() {
                    all.push(e);
                }
                let Some(c) = self.impacts.as_mut() else {
                    return Ok(());
                };
                let name = self
                    .names
                    .get(e.disc)
                    .cloned()
                    .unwrap_or_else(|| format!("disc {}", e.disc));
                let flank = match e.flank {
                    Flank::ShaftLeads => "shaft_leads",
                    Flank::DiscLeads => "disc_leads",
                };
                writeln!(
                    c.w,
                    "{},{},{:?},{:?},{:?},{flank},{:?},{:?}",
                    csv_field(&name),
                    e.disc,
                    e.t_on_s,
                    e.t_peak_s,
                    e.t_off_s,
                    e.v_on_m_s,
                    e.peak_n
                )
                .map_err(|err| c.error(err))
            }
            _ => Ok(()),
        }
    }

    /// The files of disc `index` (its segment from the first topic it appears on).
    fn disc(&mut self, index: u32, topic: &str) -> &mut DiscFiles {
        self.discs.entry(index).or_insert_with(|| DiscFiles {
            segment: segment_of(topic).to_string(),
            spline: None,
            teeth: None,
            load: None,
            teeth_n: (0, 0),
        })
    }

    /// Writes the row of a network recording's body or coupling message into its file
    /// (`network_body_<segment>.csv`, `network_coupling_<segment>.csv`).
    fn network_message(&mut self, v: &MessageView<'_>) -> Result<(), ReadError> {
        let dir = self.dir;
        let segment = |prefix: &str| v.topic.strip_prefix(prefix).map(str::to_string);
        let body = segment(&topics::network_body(""));
        let coupling = segment(&topics::network_coupling(""));
        let slot = self.network.entry(v.topic.to_string()).or_default();
        match (v.schema_name, body, coupling) {
            (proto::SHAFT_STATE, Some(seg), _) => {
                let Ok(m) = proto::ShaftState::decode(v.data) else {
                    return Ok(());
                };
                let c = Csv::lazy(
                    slot,
                    || dir.join(format!("network_body_{seg}.csv")),
                    "t_s,angle_rad,speed_rad_s\n",
                )?;
                writeln!(c.w, "{:?},{:?},{:?}", m.t_s, m.angle_rad, m.speed_rad_s)
                    .map_err(|e| c.error(e))
            }
            (proto::COUPLING_STATE, _, Some(seg)) => {
                let Ok(m) = proto::CouplingState::decode(v.data) else {
                    return Ok(());
                };
                let c = Csv::lazy(
                    slot,
                    || dir.join(format!("network_coupling_{seg}.csv")),
                    "t_s,torque_n_m,slip_rad_s,mode,locked,normal_force_n\n",
                )?;
                writeln!(
                    c.w,
                    "{:?},{:?},{:?},{},{},{:?}",
                    m.t_s,
                    m.torque_n_m,
                    m.slip_rad_s,
                    csv_field(&m.mode),
                    u8::from(m.locked),
                    m.normal_force_n
                )
                .map_err(|e| c.error(e))
            }
            _ => Ok(()),
        }
    }

    /// Every open file, in the order of the export's list.
    fn into_files(self) -> Vec<Csv> {
        let mut files: Vec<Csv> = self.shaft.into_iter().collect();
        files.extend(self.network.into_values().flatten());
        for d in self.discs.into_values() {
            files.extend(d.spline);
            files.extend(d.teeth);
            files.extend(d.load);
        }
        let mut interfaces: Vec<(usize, Csv)> = self
            .interfaces
            .into_values()
            .filter_map(|(i, _, f)| f.map(|f| (i, f)))
            .collect();
        interfaces.sort_by_key(|(i, _)| *i);
        files.extend(interfaces.into_iter().map(|(_, f)| f));
        files.extend(self.impacts);
        files
    }

    /// Removes every temporary file.
    fn discard(self) {
        for f in self.into_files() {
            if let Ok(p) = f.close() {
                p.discard();
            }
        }
    }

    /// Completes the per-tooth files and the summary, then renames every file into place
    /// in order, checking `stop` before each.
    fn finish(
        mut self,
        reader: &RecordingReader,
        stop: &AtomicBool,
    ) -> Result<Vec<PathBuf>, ReadError> {
        // the per-tooth files: header, then the rows (padded if some are shorter)
        let mut teeth = Vec::new();
        for (&i, d) in self.discs.iter_mut() {
            if let Some(body) = d.teeth.take() {
                teeth.push((i, d.segment.clone(), d.teeth_n, body));
            }
        }
        let mut fail = None;
        for (i, segment, n, body) in teeth {
            if fail.is_some() {
                if let Ok(p) = body.close() {
                    p.discard();
                }
                continue;
            }
            match teeth_file(self.dir, &segment, n, body) {
                Ok(c) => {
                    if let Some(d) = self.discs.get_mut(&i) {
                        d.teeth = Some(c);
                    }
                }
                Err(e) => fail = Some(e),
            }
        }
        let summary = match &self.recompute {
            None => reader.summary().cloned(),
            Some(impacts) => Some(RecordedSummary::from_impacts(
                &self.names,
                impacts,
                reader.info().end_s.unwrap_or(0.0),
            )),
        };
        let dir = self.dir;
        let mut files = self.into_files();
        if let Some(e) = fail {
            for f in files {
                if let Ok(p) = f.close() {
                    p.discard();
                }
            }
            return Err(e);
        }
        let mut s = String::from(
            "disc,max_positive_n,max_negative_n,p99_abs_n,impacts,positive_impacts,negative_impacts,mean_top10_abs_n\n",
        );
        for d in summary.map(|s| s.discs).unwrap_or_default() {
            let _ = writeln!(
                s,
                "{},{:?},{:?},{:?},{},{},{},{:?}",
                csv_field(&d.name),
                d.max_positive_n,
                d.max_negative_n,
                d.p99_abs_n,
                d.impacts,
                d.positive_impacts,
                d.negative_impacts,
                d.mean_top10_abs_n
            );
        }
        match Csv::create(&dir.join("summary.csv"), &s) {
            Ok(c) => files.push(c),
            Err(e) => {
                for f in files {
                    if let Ok(p) = f.close() {
                        p.discard();
                    }
                }
                return Err(e);
            }
        }
        let mut written = Vec::new();
        let mut result = Ok(());
        for f in files {
            if result.is_err() || stop.load(Ordering::SeqCst) {
                if let Ok(p) = f.close() {
                    p.discard();
                }
                continue;
            }
            let target = f.pending.target().to_path_buf();
            match f.close().and_then(|p| {
                p.commit().map_err(|source| ReadError::Export {
                    path: target.clone(),
                    source,
                })
            }) {
                Ok(path) => written.push(path),
                Err(e) => result = Err(e),
            }
        }
        result.map(|()| written)
    }
}

/// `teeth_<segment>.csv`: the header naming `n.0` teeth (the longest row), then the rows
/// written to `body`, each padded with empty fields to `n.0` teeth when `n.1` (the shortest
/// row) says some are shorter.
fn teeth_file(dir: &Path, segment: &str, n: (usize, usize), body: Csv) -> Result<Csv, ReadError> {
    let mut header = String::from("t_s");
    for i in 0..n.0 {
        let _ = write!(header, ",tooth_{i}_n");
    }
    header.push('\n');
    let body = body.close()?;
    let mut c = match Csv::create(&dir.join(format!("teeth_{segment}.csv")), &header) {
        Ok(c) => c,
        Err(e) => {
            body.discard();
            return Err(e);
        }
    };
    let copied = File::open(body.tmp_path()).and_then(|f| {
        let mut r = BufReader::new(f);
        if n.0 == n.1 {
            std::io::copy(&mut r, &mut c.w).map(drop)
        } else {
            let mut line = String::new();
            loop {
                line.clear();
                if r.read_line(&mut line)? == 0 {
                    break Ok(());
                }
                let row = line.trim_end_matches('\n');
                let fields = row.matches(',').count();
                c.w.write_all(row.as_bytes())?;
                for _ in fields..n.0 {
                    c.w.write_all(b",")?;
                }
                c.w.write_all(b"\n")?;
            }
        }
    });
    body.discard();
    match copied {
        Ok(()) => Ok(c),
        Err(e) => {
            let err = c.error(e);
            if let Ok(p) = c.close() {
                p.discard();
            }
            Err(err)
        }
    }
}
