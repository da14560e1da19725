//! The resynchronising scan of a recording (see the parent module's documentation): one
//! pass of the MCAP linear reader over the file in blocks, checking and decoding every record;
//! at an error, the search for the next intact chunk and the next pass from there.

use super::*;

/// A byte source the scan reads from: the file ([`open`]) or memory ([`from_bytes`]).
pub(super) trait Source: Read + Seek {}
impl<T: Read + Seek> Source for T {}

/// A source with its size (as at open: nothing after it is read) and the block size.
pub(super) struct Input<'a> {
    pub(super) src: &'a mut dyn Source,
    pub(super) len: u64,
    pub(super) block: usize,
    /// Stops the scan after the record being read once set (a signal).
    pub(super) stop: Option<&'a AtomicBool>,
}

impl Input<'_> {
    pub(super) fn seek(&mut self, at: u64) -> std::io::Result<()> {
        self.src.seek(SeekFrom::Start(at)).map(drop)
    }

    /// Fills `buf` from the current position; fewer bytes only at the end of the source.
    pub(super) fn fill(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
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
    pub(super) fn read_at(&mut self, at: u64, n: usize) -> std::io::Result<Vec<u8>> {
        let n = n.min(self.len.saturating_sub(at).try_into().unwrap_or(usize::MAX));
        let mut buf = vec![0; n];
        self.seek(at)?;
        let got = self.fill(&mut buf)?;
        buf.truncate(got);
        Ok(buf)
    }
}

#[derive(Debug, Clone)]
pub(super) struct SchemaRec {
    pub(super) name: String,
    pub(super) encoding: String,
    pub(super) data: Vec<u8>,
}

#[derive(Debug, Clone)]
pub(super) struct ChannelRec {
    pub(super) topic: String,
    pub(super) schema_id: u16,
    pub(super) message_encoding: String,
    pub(super) metadata: BTreeMap<String, String>,
}

/// The outcome of one scan of the file.
pub(super) struct Scan {
    pub(super) info: RecordingInfo,
    pub(super) schemas: BTreeMap<u16, SchemaRec>,
    pub(super) channels: BTreeMap<u16, ChannelRec>,
    pub(super) counts: BTreeMap<u16, (u64, u64, u64)>,
    pub(super) error: Option<(DamageKind, String, u64)>,
    /// Damaged regions skipped and their bytes.
    pub(super) skipped: (u64, u64),
    /// The message count of the summary section's statistics, if read.
    pub(super) expected_messages: Option<u64>,
}

/// Where one pass of the linear reader ended.
pub(super) struct PassEnd {
    /// The error that stopped it, if any: kind, reason, bytes read.
    pub(super) error: Option<(DamageKind, String, u64)>,
    /// File offset just after the last record that was read whole (where the damage starts).
    pub(super) last_good: u64,
    /// Whether the message limit was reached (the rest of the file is not wanted).
    pub(super) done: bool,
}

/// What a pass carries over to the next one.
#[derive(Default)]
pub(super) struct PassState {
    pub(super) data_end: bool,
    pub(super) footer: bool,
    pub(super) stats: Option<mcap::records::Statistics>,
}

/// Decodes one message of a known schema; the error says why not.
pub(super) fn validate(v: &MessageView<'_>) -> Result<(), String> {
    if v.message_encoding != "protobuf" || v.schema_encoding != "protobuf" {
        return Ok(());
    }
    let r = match v.schema_name {
        proto::SHAFT_STATE => proto::ShaftState::decode(v.data).map(drop),
        proto::SPLINE_STATE => proto::SplineState::decode(v.data).map(drop),
        proto::TOOTH_LOADS => proto::ToothLoads::decode(v.data).map(drop),
        proto::INTERFACE_STATE => proto::InterfaceState::decode(v.data).map(drop),
        proto::IMPACT => proto::Impact::decode(v.data).map(drop),
        proto::RUN_SUMMARY => proto::SummaryMessage::decode(v.data).map(drop),
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

pub(super) fn describe_mcap_error(e: &mcap::McapError, data_end: bool) -> (DamageKind, String) {
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
pub(super) fn scan(
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
pub(super) fn scan_pass(
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
pub(super) const CHUNK_PROBE: usize = 9 + 32 + 4 + 8;

/// Whether a chunk record starts at `at` whose stated length runs past the end of the file:
/// the chunk a killed run was writing (the recorder writes a chunk in place, its length a
/// placeholder until the chunk ends) or the last chunk of a partial copy.
pub(super) fn chunk_runs_past_end(input: &mut Input<'_>, at: u64) -> std::io::Result<bool> {
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
pub(super) fn next_chunk(input: &mut Input<'_>, from: u64) -> std::io::Result<Option<u64>> {
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
pub(super) fn plausible_metadata(
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
pub(super) fn plausible_chunk(head: &[u8], avail: u64) -> bool {
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
pub(super) fn preload_summary(input: &mut Input<'_>, s: &mut Scan) -> std::io::Result<()> {
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

pub(super) fn on_record(
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
                if let Ok(m) = proto::SummaryMessage::decode(view.data) {
                    s.info.summary = Some(RecordedSummary::from_proto(m));
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
