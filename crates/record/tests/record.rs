//! Recordings written from a synthetic stream and read back: exact round trips, determinism,
//! the Foxglove schemas, and robustness against truncated, corrupted, empty and foreign files.

use clutchpack_model::{Collector, DiscSample, Observer, Sample};
use clutchpack_record::synthetic::{synthetic_run, SyntheticRun};
use clutchpack_record::{
    export_csv, from_bytes, from_bytes_with, open, open_with, topics, DamageKind, ReadError,
    ReadOptions, RecordError, RecordOptions, RecordedSummary, Recorder, RecordingReader,
};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clutchpack_record");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn options() -> RecordOptions {
    RecordOptions {
        deterministic: true,
        per_tooth: true,
        // several chunks even for a small run
        flush_messages: 200,
        // a pose per sample, to check them one by one
        tf_interval_s: 0.0,
        ..Default::default()
    }
}

/// Records `run` to `name` with `opts` and returns the path.
fn record(run: &SyntheticRun, name: &str, opts: &RecordOptions) -> PathBuf {
    let path = tmp(name);
    let mut rec = Recorder::create(&path, &run.info, opts).unwrap();
    run.play(&mut rec);
    assert!(rec.error().is_none());
    rec.finish(None).unwrap()
}

fn small() -> SyntheticRun {
    synthetic_run(400, 1e-5)
}

/// Samples (with per-tooth loads), impacts, the summary and the run info come back exactly
/// as written: f64 values travel as protobuf doubles, bit for bit.
#[test]
fn round_trip_is_exact() {
    let run = small();
    assert!(
        run.impacts.len() >= 4,
        "the synthetic run has impacts on both discs"
    );
    let path = record(&run, "round_trip.mcap", &options());
    let r = open(&path).unwrap();
    assert!(r.is_complete(), "{:?}", r.damage());
    r.require_complete().unwrap();
    assert_eq!(r.samples(), run.samples);
    assert_eq!(r.impacts(), {
        // written in closing order; read back in file order (the same)
        run.impacts.clone()
    });
    let t_end = run.samples.last().unwrap().t_s;
    let want = RecordedSummary::from_impacts(&run.info.disc_names(), &run.impacts, t_end);
    assert_eq!(r.summary(), Some(&want));
    assert_eq!(r.summary_or_recomputed(), want);

    let mut info = r.run_info().unwrap();
    assert_eq!(info.shaft, Some(run.info.shaft_geometry()));
    info.shaft = None;
    assert_eq!(info, run.info);
    assert_eq!(r.disc_names(), vec!["d1".to_string(), "disc 2".to_string()]);

    // the friction interface: one topic named by its two bodies, every field exact
    let f = r.interface_series();
    assert_eq!(f.len(), 1);
    assert_eq!((f[0].lower.as_str(), f[0].upper.as_str()), ("d1", "disc 2"));
    assert_eq!(f[0].segment, "d1__disc_2");
    let got: Vec<(f64, Vec<clutchpack_model::InterfaceSample>)> = f[0]
        .states
        .iter()
        .map(|m| {
            assert_eq!(m.interface_index, 0);
            (
                m.t_s,
                vec![clutchpack_model::InterfaceSample {
                    slip_rad_s: m.slip_rad_s,
                    slip_m_s: m.slip_m_s,
                    mu: m.mu,
                    clamp_n: m.clamp_n,
                    torque_n_m: m.torque_n_m,
                    locked: m.locked,
                    dissipated_j: m.dissipated_j,
                }],
            )
        })
        .collect();
    assert_eq!(got, run.interfaces);
    assert!(got.iter().any(|(_, f)| f[0].locked) && got.iter().any(|(_, f)| !f[0].locked));

    let h = r.load_histories();
    assert_eq!(h.len(), 2);
    assert_eq!(h[1].name, "disc 2");
    assert_eq!(h[1].t_s.len(), 400);
    assert_eq!(h[1].load_n[123], run.samples[123].discs[1].load_n);

    let i = r.info();
    assert!(i.summary_section);
    assert_eq!(i.start_s, Some(0.0));
    assert!((i.end_s.unwrap() - 399e-5).abs() < 1e-12);
    let n = |t: &str| i.topic(t).map(|t| t.messages).unwrap_or(0);
    assert_eq!(n(topics::SHAFT), 400);
    assert_eq!(n(topics::TF), 400);
    assert_eq!(n("/discs/d1/spline"), 400);
    assert_eq!(n("/discs/disc_2/spline"), 400);
    assert_eq!(n("/discs/disc_2/teeth"), 400);
    assert_eq!(n("/interfaces/d1__disc_2"), 400);
    assert_eq!(n(topics::IMPACTS), run.impacts.len() as u64);
    assert_eq!(n(topics::SUMMARY), 1);
    // the static scene once, at t = 0; load colours at t = 0 plus updates (at most one per
    // simulated ms) on their own topic
    assert_eq!(n(topics::SCENE), 1);
    assert!(
        (2..=4).contains(&n(topics::SCENE_LOADS)),
        "{}",
        n(topics::SCENE_LOADS)
    );
    assert!(
        i.chunks.unwrap() > 1,
        "flush_messages cut the data into chunks"
    );
    let att = &i.attachments[0];
    assert_eq!(att.name, "synthetic.toml");
    assert_eq!(att.data, run.info.scene_text.as_bytes());
    let meta = i.metadata("clutchpack.run").unwrap();
    assert_eq!(
        meta["scene_sha256"],
        clutchpack_record::sha256_hex(run.info.scene_text.as_bytes())
    );
    assert_eq!(meta["engine"], "synthetic");
    assert!(
        !meta.contains_key("recorded_at_utc"),
        "deterministic: no wall clock"
    );
    // What `clutchpack replay` prints (its text is the CLI's, tested there).
    assert!(r.is_complete() && r.damage().is_none());
    assert!(i.topic("/discs/disc_2/spline").is_some());
    assert!(r.summary().is_some(), "the summary is stored");
    assert_eq!(i.start_s, Some(0.0));
    assert!((i.end_s.unwrap() - 0.00399).abs() < 1e-12, "{:?}", i.end_s);
}

/// The transforms and the scene use Foxglove's well-known schemas by their exact names,
/// and decode with the SDK's own types: one transform per body, rotating about +z by the
/// body's angle, discs at their z.
#[test]
fn foxglove_schemas_and_transforms() {
    use prost::Message as _;
    let run = small();
    let r = open(record(&run, "foxglove.mcap", &options())).unwrap();
    let schema = |t: &str| r.info().topic(t).unwrap().schema_name.clone();
    assert_eq!(schema("/tf"), "foxglove.FrameTransforms");
    assert_eq!(schema("/scene"), "foxglove.SceneUpdate");
    assert_eq!(schema("/discs/d1/spline"), "clutchpack.SplineState");
    for t in &r.info().topics {
        // but /joints, a ROS 2 message for Rerun (checked in tests/viewer.rs)
        if t.topic != topics::JOINTS {
            assert_eq!(t.schema_encoding, "protobuf", "{}", t.topic);
            assert_eq!(t.message_encoding, "protobuf", "{}", t.topic);
        }
    }
    let mut tfs = Vec::new();
    let mut scenes = Vec::new();
    let mut loads = Vec::new();
    r.for_each_message(|m| match m.topic {
        "/tf" => tfs.push(foxglove::schemas::FrameTransforms::decode(m.data).unwrap()),
        "/scene" => scenes.push(foxglove::schemas::SceneUpdate::decode(m.data).unwrap()),
        "/scene/loads" => loads.push(foxglove::schemas::SceneUpdate::decode(m.data).unwrap()),
        _ => {}
    });
    let k = 250;
    let tf = &tfs[k];
    let s = &run.samples[k];
    assert_eq!(tf.transforms.len(), 3);
    assert_eq!(tf.transforms[0].child_frame_id, "shaft");
    assert_eq!(tf.transforms[2].child_frame_id, "disc/disc_2");
    assert_eq!(tf.transforms[2].parent_frame_id, "world");
    let q = tf.transforms[2].rotation.unwrap();
    let angle = 2.0 * q.z.atan2(q.w);
    let d = (angle - s.discs[1].angle_rad).rem_euclid(2.0 * std::f64::consts::PI);
    assert!(d.min(2.0 * std::f64::consts::PI - d) < 1e-12);
    assert_eq!(tf.transforms[2].translation.unwrap().z, 0.004);
    // the static pack is the one message of /scene; every /scene/loads message holds every
    // disc's load ring, so the latest one alone restores the colours after a seek
    assert_eq!(scenes.len(), 1);
    let first = &scenes[0];
    let ids: Vec<&str> = first.entities.iter().map(|e| e.id.as_str()).collect();
    assert!(
        ids.contains(&"shaft") && ids.contains(&"disc/d1") && ids.contains(&"disc/disc_2"),
        "{ids:?}"
    );
    for l in &loads {
        let ids: Vec<&str> = l.entities.iter().map(|e| e.id.as_str()).collect();
        assert!(
            ids.contains(&"disc/d1/load") && ids.contains(&"disc/disc_2/load"),
            "{ids:?}"
        );
    }
    assert!(first.entities.iter().all(|e| e.frame_locked));
    // the static disc carries its body and its teeth (synthetic discs have 24) as parry
    // meshes: 64 wedges of 8 corners, 24 cuboids of 8
    let d1 = first.entities.iter().find(|e| e.id == "disc/d1").unwrap();
    assert_eq!(d1.triangles.len(), 2, "body and teeth");
    assert_eq!(d1.triangles[0].points.len(), 64 * 8);
    assert_eq!(d1.triangles[1].points.len(), 24 * 8);
    // later updates colour the load rings, and (per-tooth run) each tooth by its own load:
    // the synthetic teeth carry loads rising with the tooth index (tooth 23 2.15 times tooth
    // 0), so in a loaded update tooth 23 is hotter than tooth 0
    let later: Vec<_> = loads[1..].iter().flat_map(|s| &s.entities).collect();
    let collar_red = later
        .iter()
        .filter(|e| e.id.ends_with("/load"))
        .flat_map(|e| &e.lines)
        .any(|c| c.color.unwrap().b < 0.5);
    assert!(collar_red, "a loaded collar is coloured");
    // r - g - b rises monotonically from grey (-0.6) through yellow (0.15) to red (1)
    let heat = |e: &foxglove::schemas::SceneEntity, k: usize| {
        let c = e.cubes[k].color.unwrap();
        c.r - c.g - c.b
    };
    let teeth: Vec<_> = later.iter().filter(|e| e.id == "disc/d1/teeth").collect();
    assert!(!teeth.is_empty(), "per-tooth updates");
    assert!(teeth.iter().all(|e| e.cubes.len() == 24));
    assert!(
        teeth.iter().any(|e| heat(e, 23) > heat(e, 0) + 0.1),
        "tooth 23 carries more than tooth 0"
    );
    assert!(teeth.iter().all(|e| heat(e, 23) >= heat(e, 0) - 1e-12));
}

/// The same stream recorded twice with `deterministic` gives byte-identical files.
#[test]
fn deterministic_recordings_are_byte_identical() {
    let run = small();
    let a = std::fs::read(record(&run, "det_a.mcap", &options())).unwrap();
    let b = std::fs::read(record(&run, "det_b.mcap", &options())).unwrap();
    assert_eq!(a.len(), b.len());
    assert!(a == b, "deterministic recordings differ");
    // and a non-deterministic one carries its wall-clock metadata
    let opts = RecordOptions {
        deterministic: false,
        ..options()
    };
    let r = open(record(&run, "wall.mcap", &opts)).unwrap();
    assert!(r
        .info()
        .metadata("clutchpack.run")
        .unwrap()
        .contains_key("recorded_at_utc"));
    assert!(r
        .info()
        .metadata("clutchpack.stats")
        .unwrap()
        .contains_key("wall_s"));
}

/// Cutting the file anywhere gives either an error or the messages of the whole chunks
/// before the cut, never a panic; the recovered count never decreases as the cut moves on,
/// and only the full file is complete.
#[test]
fn truncated_files_recover_whole_chunks() {
    let run = small();
    let bytes = std::fs::read(record(&run, "truncate.mcap", &options())).unwrap();
    let total = open(tmp("truncate.mcap")).unwrap().info().messages;
    let mut cuts: Vec<usize> = (0..bytes.len()).step_by(97).collect();
    cuts.extend([
        1,
        7,
        8,
        9,
        20,
        100,
        bytes.len() - 1,
        bytes.len() - 8,
        bytes.len() - 9,
    ]);
    cuts.sort();
    let mut last = 0;
    for cut in cuts {
        match from_bytes("cut.mcap", bytes[..cut].to_vec()) {
            Err(e) => {
                assert!(cut < 64, "cut at {cut}: {e}");
                let line = e.to_string();
                assert!(!line.contains('\n'), "{line}");
            }
            Ok(r) => {
                let d = r.damage().expect("a cut file is damaged");
                assert_eq!(d.kind, DamageKind::Truncated, "cut at {cut}: {d}");
                assert!(!d.to_string().contains('\n'));
                let n = r.info().messages;
                assert!(n >= last, "cut at {cut}: {n} < {last}");
                assert!(n <= total);
                last = n;
                // what was recovered decodes
                let _ = r.samples();
                let _ = r.impacts();
            }
        }
    }
    assert!(last > total / 2, "most messages precede the last cuts");
    let err = open(tmp("truncate.mcap")).unwrap();
    assert!(err.is_complete());
}

/// A killed run: the file as it is on disk while the recorder is still running (some
/// messages not yet flushed) holds exactly the messages written before the last flush.
#[test]
fn killed_run_keeps_everything_up_to_the_last_flush() {
    let run = small();
    let path = tmp("killed.mcap");
    let mut rec = Recorder::create(&path, &run.info, &options()).unwrap();
    for s in &run.samples[..150] {
        rec.sample(s);
    }
    rec.flush().unwrap();
    let flushed = rec.messages();
    for s in &run.samples[150..170] {
        rec.sample(s);
    }
    let on_disk = std::fs::read(&path).unwrap(); // what SIGKILL would leave
    let r = from_bytes(&path, on_disk).unwrap();
    let d = r.damage().unwrap();
    assert_eq!(d.kind, DamageKind::Truncated);
    assert!(d.reason.contains("no summary section"), "{d}");
    assert_eq!(r.info().messages, flushed);
    assert_eq!(r.samples(), run.samples[..150].to_vec());
    assert!(r.summary().is_none());
    assert!(
        !r.summary_or_recomputed().discs.is_empty(),
        "recomputed from the recovered impacts"
    );
    assert!(
        r.run_info().is_some(),
        "metadata and scene precede the data"
    );
    let err = r.require_complete().unwrap_err();
    assert!(matches!(err, ReadError::Damaged { .. }));
    assert!(err.to_string().contains("recovered"), "{err}");
    drop(rec);
}

/// A run killed while a chunk is being compressed into the file: chunks are written in
/// place (their header is a placeholder until the chunk ends), so the file then ends in a
/// chunk record that claims more bytes than the file has. Everything up to the last flush
/// is read back exactly, and the partial chunk is reported as a truncation.
#[test]
fn killed_mid_chunk_keeps_the_flushed_chunks() {
    let run = synthetic_run(20_000, 1e-5);
    let path = tmp("killed-mid-chunk.mcap");
    let opts = RecordOptions {
        // no chunk ends by itself in this test: only the explicit flush below
        chunk_size_bytes: Some(1 << 30),
        flush_messages: usize::MAX,
        ..options()
    };
    let mut rec = Recorder::create(&path, &run.info, &opts).unwrap();
    let flushed_at = 300;
    for s in &run.samples[..flushed_at] {
        rec.sample(s);
    }
    rec.flush().unwrap();
    let flushed = rec.messages();
    let flushed_len = std::fs::metadata(&path).unwrap().len();
    // write on until part of the next chunk has reached the file (the compressor and the
    // file buffer hold some before they write)
    let mut written = flushed_at;
    while std::fs::metadata(&path).unwrap().len() < flushed_len + (256 << 10) {
        assert!(
            written < run.samples.len(),
            "the open chunk never reached the file"
        );
        rec.sample(&run.samples[written]);
        written += 1;
    }
    let on_disk = std::fs::read(&path).unwrap(); // what SIGKILL would leave
    let r = from_bytes(&path, on_disk).unwrap();
    let d = r.damage().unwrap();
    assert_eq!(d.kind, DamageKind::Truncated, "{d}");
    assert_eq!(r.info().messages, flushed);
    assert_eq!(r.samples(), run.samples[..flushed_at].to_vec());
    drop(rec);
}

/// A byte flipped inside a chunk is caught by the chunk CRC: a clean "corrupted" error,
/// with the messages of every other chunk recovered (the scan resynchronises on the next
/// chunk, issue 10): exactly the flipped chunk's messages are lost.
#[test]
fn bit_flip_in_a_chunk_is_a_clean_error() {
    let run = small();
    let path = record(&run, "flip.mcap", &options());
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunks = &summary.chunk_indexes;
    assert!(chunks.len() >= 3);
    let c = &chunks[2];
    let before: u64 = {
        // messages of the first two chunks
        let mut n = 0;
        for ci in &chunks[..2] {
            n += summary.stream_chunk(&bytes, ci).unwrap().count() as u64;
        }
        n
    };
    let mut bad = bytes.clone();
    let at = (c.chunk_start_offset + c.chunk_length - c.compressed_size / 2) as usize;
    bad[at] ^= 0x10;
    let r = from_bytes("flip.mcap", bad).unwrap();
    let d = r.damage().expect("damage found");
    assert_eq!(d.kind, DamageKind::Corrupt);
    let total = summary.stats.as_ref().unwrap().message_count;
    let lost = summary.stream_chunk(&bytes, c).unwrap().count() as u64;
    assert!(before < total - lost);
    assert_eq!(r.info().messages, total - lost, "{d}");
    assert_eq!(d.lost_messages, Some(lost), "{d}");
    let line = r.require_complete().unwrap_err().to_string();
    assert!(line.contains("corrupted recording"), "{line}");
    assert!(!line.contains('\n'));
}

/// The offsets of the top-level records of an MCAP file (after the magic) and the end of
/// the last one (the closing magic follows).
fn record_boundaries(bytes: &[u8]) -> Vec<usize> {
    let mut at = vec![8];
    let mut p = 8;
    while p + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[p + 1..p + 9].try_into().unwrap()) as usize;
        p += 9 + len;
        if p > bytes.len() {
            break;
        }
        at.push(p);
    }
    at
}

/// Damaged recordings (issue 10): a file cut at every record boundary is refused by the
/// strict reader and salvages exactly the messages of the chunks wholly before the cut; a
/// byte flipped in each chunk in turn loses that chunk's messages and no other (the scan
/// resynchronises on the next chunk and says how much it skipped); a byte flipped in the
/// scene attachment near the start loses no message at all. The expected counts come from
/// the file's own chunk index, read by the mcap crate (an independent path).
#[test]
fn damaged_recordings_salvage_every_intact_chunk() {
    let run = small();
    let path = record(&run, "damaged.mcap", &options());
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let total = summary.stats.as_ref().unwrap().message_count;
    let chunks: Vec<(usize, usize, u64)> = summary
        .chunk_indexes
        .iter()
        .map(|c| {
            let n = summary.stream_chunk(&bytes, c).unwrap().count() as u64;
            (
                c.chunk_start_offset as usize,
                (c.chunk_start_offset + c.chunk_length) as usize,
                n,
            )
        })
        .collect();
    assert!(chunks.len() >= 4, "several chunks: {}", chunks.len());

    // truncation at every record boundary
    let boundaries = record_boundaries(&bytes);
    // the last record is the footer, followed by the closing magic
    assert_eq!(*boundaries.last().unwrap(), bytes.len() - 8);
    for &cut in &boundaries {
        let r = from_bytes("cut.mcap", bytes[..cut].to_vec()).unwrap();
        assert!(r.require_complete().is_err(), "cut at {cut} passes strict");
        let whole: u64 = chunks.iter().filter(|c| c.1 <= cut).map(|c| c.2).sum();
        assert_eq!(r.info().messages, whole, "cut at {cut}");
    }

    // a byte flipped in each chunk in turn
    for (i, &(start, end, n)) in chunks.iter().enumerate() {
        let mut bad = bytes.clone();
        bad[(start + end) / 2] ^= 0x04;
        let r = from_bytes("flip.mcap", bad).unwrap();
        let d = r.damage().expect("a flipped chunk is found").clone();
        assert_eq!(d.kind, DamageKind::Corrupt, "chunk {i}: {d}");
        assert_eq!(r.info().messages, total - n, "chunk {i}: {d}");
        assert_eq!(d.lost_messages, Some(n), "chunk {i}: {d}");
        assert_eq!(d.skipped_regions, 1, "chunk {i}: {d}");
        assert!(
            d.to_string().contains("reading on past 1 damaged region"),
            "{d}"
        );
        // what was salvaged decodes
        assert!(!r.samples().is_empty());
    }

    // a byte flipped in the scene attachment, before every chunk
    let a = &summary.attachment_indexes[0];
    assert!((a.offset as usize) < chunks[0].0);
    let mut bad = bytes.clone();
    bad[(a.offset + a.length - 8) as usize] ^= 0x01;
    let r = from_bytes("attachment.mcap", bad).unwrap();
    let d = r.damage().expect("the attachment's CRC catches it");
    assert_eq!(r.info().messages, total, "{d}");
    assert_eq!(d.lost_messages, Some(0), "{d}");
}

/// Every message a reader hands over, as (channel, log time, bytes).
fn messages_of(r: &RecordingReader) -> Vec<(u16, u64, Vec<u8>)> {
    let mut v = Vec::new();
    r.try_for_each_message(|m| v.push((m.channel_id, m.log_time_ns, m.data.to_vec())))
        .unwrap();
    v
}

/// The reader streams (issue 10): read from disk in blocks of 61 bytes, far smaller than a
/// chunk, a complete file, a truncated copy and a copy with a byte flipped in a chunk (the
/// resynchronising search, in 61-byte windows) give the same info, damage, messages and
/// samples as the reader of the bytes in memory with its default 1 MiB block.
#[test]
fn small_blocks_read_like_memory() {
    let run = small();
    let path = record(&run, "blocks.mcap", &options());
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(summary.chunk_indexes.len() >= 4);
    let c = &summary.chunk_indexes[2];
    let mut flipped = bytes.clone();
    flipped[(c.chunk_start_offset + c.chunk_length / 2) as usize] ^= 0x04;
    let cut = bytes[..bytes.len() * 2 / 3].to_vec();
    let small_blocks = ReadOptions { block_bytes: 61 };
    for (name, b) in [("whole", bytes.clone()), ("cut", cut), ("flip", flipped)] {
        assert!(
            b.len() > 100 * small_blocks.block_bytes,
            "{name}: {}",
            b.len()
        );
        let file = tmp(&format!("blocks-{name}.mcap"));
        std::fs::write(&file, &b).unwrap();
        let mem = from_bytes(&file, b.clone()).unwrap();
        let disk = open_with(&file, &small_blocks).unwrap();
        let mem_small = from_bytes_with(&file, b.clone(), &small_blocks).unwrap();
        for r in [&disk, &mem_small] {
            // Debug: topics without messages have NaN spans
            assert_eq!(
                format!("{:?}", r.info()),
                format!("{:?}", mem.info()),
                "{name}"
            );
            assert_eq!(r.damage(), mem.damage(), "{name}");
            assert_eq!(r.file_bytes(), b.len() as u64, "{name}");
        }
        let want = messages_of(&mem);
        assert_eq!(want.len() as u64, mem.info().messages, "{name}");
        assert_eq!(messages_of(&disk), want, "{name}");
        assert_eq!(messages_of(&mem_small), want, "{name}");
        assert_eq!(disk.samples(), mem.samples(), "{name}");
        assert!(disk.reread_error().is_none(), "{name}");
        match name {
            "whole" => assert!(disk.is_complete()),
            "cut" => {
                let d = disk.damage().unwrap();
                assert_eq!(d.kind, DamageKind::Truncated, "{d}");
                assert!(
                    d.messages > 0 && d.messages < summary.stats.as_ref().unwrap().message_count
                );
            }
            _ => {
                let d = disk.damage().unwrap();
                assert_eq!(d.kind, DamageKind::Corrupt, "{d}");
                assert_eq!(d.skipped_regions, 1, "{d}");
                assert!(d.lost_messages.is_some_and(|n| n > 0), "{d}");
            }
        }
    }
}

/// The reader does not hold the file: each pass reads it again. A file that grew since it
/// was opened (a run still recording) gives the same messages; one shortened or removed
/// gives an error naming it (kept for `reread_error` by `for_each_message`), never a panic.
#[test]
fn passes_read_the_file_again() {
    let run = small();
    let src = record(&run, "reread-src.mcap", &options());
    let path = tmp("reread.mcap");
    std::fs::copy(&src, &path).unwrap();
    let r = open(&path).unwrap();
    let want = messages_of(&r);
    // grown: appended bytes are not read
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(&path)
        .unwrap();
    std::io::Write::write_all(&mut f, &[0x42; 1000]).unwrap();
    drop(f);
    assert_eq!(messages_of(&r), want);
    // shortened
    let bytes = std::fs::read(&src).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let e = r.try_for_each_message(|_| {}).unwrap_err();
    assert!(matches!(e, ReadError::Reread { .. }), "{e}");
    assert!(
        e.to_string().contains("reread.mcap") && e.to_string().contains("changed"),
        "{e}"
    );
    assert!(r.reread_error().is_none(), "try_ does not keep the error");
    let n = r.samples().len();
    assert!(n < run.samples.len(), "{n}");
    let e = r.reread_error().expect("for_each_message keeps the error");
    assert!(e.to_string().contains("reread.mcap"), "{e}");
    // same length, other bytes: fewer messages recovered than at open
    let mut other = bytes.clone();
    for b in &mut other[bytes.len() / 4..bytes.len() / 2] {
        *b ^= 0x5a;
    }
    std::fs::write(&path, &other).unwrap();
    let e = r.try_for_each_message(|_| {}).unwrap_err();
    assert!(e.to_string().contains("messages read again"), "{e}");
    // removed
    std::fs::remove_file(&path).unwrap();
    let e = r.try_for_each_message(|_| {}).unwrap_err();
    assert!(e.to_string().contains("cannot read the file again"), "{e}");
    assert!(r.impacts().is_empty());
}

/// A FIFO is refused at once (reading it would block, and a pass could not read it again),
/// with an error naming it.
#[cfg(unix)]
#[test]
fn a_fifo_is_not_a_recording() {
    let fifo = tmp("fifo.mcap");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let e = open(&fifo).unwrap_err();
    assert!(matches!(e, ReadError::NotAFile { .. }), "{e}");
    assert!(e.to_string().contains("fifo.mcap"), "{e}");
    std::fs::remove_file(&fifo).unwrap();
}

/// Flipping any one byte of a small recording never panics, and never goes unnoticed
/// outside the few bytes no check covers (record padding, the summary-offset section).
#[test]
fn any_single_byte_flip_is_handled() {
    let run = synthetic_run(60, 1e-5);
    let opts = RecordOptions {
        flush_messages: 50,
        ..options()
    };
    let bytes = std::fs::read(record(&run, "fuzz.mcap", &opts)).unwrap();
    let mut unnoticed = 0;
    // every byte of the header, attachment, metadata and schemas; every 13th after that
    let offsets: Vec<usize> = (0..2048.min(bytes.len()))
        .chain((2048..bytes.len()).step_by(13))
        .collect();
    for &at in &offsets {
        let mut bad = bytes.clone();
        bad[at] ^= 0x41;
        match from_bytes("fuzz.mcap", bad) {
            Err(e) => assert!(!e.to_string().contains('\n')),
            Ok(r) => {
                if r.is_complete() {
                    unnoticed += 1;
                }
                let _ = r.samples();
                let _ = r.disc_series();
            }
        }
    }
    assert!(
        unnoticed * 50 < offsets.len(),
        "{unnoticed} of {} flips went unnoticed",
        offsets.len()
    );
}

/// Empty, text and other foreign files give a one-line error that says what they are.
#[test]
fn empty_and_foreign_files() {
    let e = from_bytes("empty.mcap", Vec::new()).unwrap_err();
    assert!(matches!(e, ReadError::Empty { .. }));
    assert!(e.to_string().contains("empty"), "{e}");
    let e = from_bytes("notes.txt", b"hello, this is text\nline 2\n".to_vec()).unwrap_err();
    assert!(matches!(e, ReadError::NotMcap { .. }));
    assert!(e.to_string().contains("\"hello, this is text"), "{e}");
    assert!(!e.to_string().contains('\n'));
    let e = from_bytes("x.png", vec![0x89, b'P', b'N', b'G', 0, 1, 2, 3, 4, 5]).unwrap_err();
    assert!(e.to_string().contains("89 50 4e 47"), "{e}");
    let e = from_bytes("short.mcap", mcap::MAGIC[..5].to_vec()).unwrap_err();
    assert!(matches!(e, ReadError::Damaged { .. }), "{e}");
    let e = open(tmp("does-not-exist.mcap")).unwrap_err();
    assert!(matches!(e, ReadError::Io { .. }));
    // the magic followed by noise: a clean "corrupted" or "truncated", whatever the noise
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    for len in [1usize, 9, 17, 100, 1000, 10_000] {
        for _ in 0..20 {
            let mut b = mcap::MAGIC.to_vec();
            b.extend((0..len).map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            }));
            let r = from_bytes("noise.mcap", b).unwrap();
            assert!(r.damage().is_some());
            let _ = (
                r.summary_or_recomputed(),
                r.interface_stats(),
                r.samples(),
                r.impacts(),
            );
        }
    }
}

/// A valid MCAP file from another program opens: its topics are listed, it has no run info
/// and none of our data.
#[test]
fn foreign_mcap_opens_without_our_data() {
    let path = tmp("foreign.mcap");
    {
        let mut w = mcap::Writer::new(std::io::BufWriter::new(
            std::fs::File::create(&path).unwrap(),
        ))
        .unwrap();
        let ch = w
            .add_channel(0, "/chatter", "json", &Default::default())
            .unwrap();
        for i in 0..5u32 {
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i,
                log_time: u64::from(i) * 1000,
                publish_time: 0,
            };
            w.write_to_known_channel(&header, b"{\"a\": 1}").unwrap();
        }
        w.finish().unwrap();
    }
    let r = open(&path).unwrap();
    assert!(r.is_complete(), "{:?}", r.damage());
    assert_eq!(r.info().topics[0].topic, "/chatter");
    assert_eq!(r.info().messages, 5);
    assert!(r.run_info().is_none());
    assert!(r.samples().is_empty() && r.impacts().is_empty() && r.summary().is_none());
}

/// An error inside the observer methods is not lost: recording stops, `progress` asks the
/// engine to stop, and `finish` returns the first error.
#[test]
fn observer_errors_reach_finish() {
    let run = small();
    let mut rec = Recorder::create(tmp("observer_error.mcap"), &run.info, &options()).unwrap();
    rec.sample(&run.samples[0]);
    rec.sample(&Sample {
        t_s: 1e-5,
        discs: vec![DiscSample::default()],
        ..Default::default()
    });
    assert!(rec.progress(1e-5), "a failed recorder stops the run");
    rec.sample(&run.samples[2]);
    let e = rec.finish(None).unwrap_err();
    assert!(
        matches!(
            e,
            RecordError::DiscCount {
                got: 1,
                expected: 2,
                ..
            }
        ),
        "{e}"
    );
}

/// Dropping a recorder without `finish` still leaves a complete file (summary section),
/// just without `/summary`.
#[test]
fn dropped_recorder_closes_the_file() {
    let run = small();
    let path = tmp("dropped.mcap");
    {
        let mut rec = Recorder::create(&path, &run.info, &options()).unwrap();
        run.play(&mut rec);
    }
    let r = open(&path).unwrap();
    assert!(r.is_complete(), "{:?}", r.damage());
    assert!(r.summary().is_none());
    assert_eq!(r.samples().len(), run.samples.len());
    assert_eq!(
        r.summary_or_recomputed().discs,
        RecordedSummary::from_impacts(&run.info.disc_names(), &run.impacts, 0.0).discs
    );
}

/// `export_csv` writes one file per topic of ours; the spline CSV gives the loads back
/// exactly.
#[test]
fn csv_export() {
    let run = small();
    let r: RecordingReader = open(record(&run, "export.mcap", &options())).unwrap();
    let dir = tmp("export_csv");
    let _ = std::fs::remove_dir_all(&dir);
    let files = export_csv(&r, &dir).unwrap();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for want in [
        "shaft.csv",
        "spline_d1.csv",
        "spline_disc_2.csv",
        "teeth_d1.csv",
        "teeth_disc_2.csv",
        "load_d1.csv",
        "load_disc_2.csv",
        "interface_d1__disc_2.csv",
        "impacts.csv",
        "summary.csv",
    ] {
        assert!(
            names.iter().any(|n| n == want),
            "{want} missing from {names:?}"
        );
    }
    let text = std::fs::read_to_string(dir.join("spline_disc_2.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "load_n").unwrap();
    let loads: Vec<f64> = lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    let want: Vec<f64> = run.samples.iter().map(|s| s.discs[1].load_n).collect();
    assert_eq!(loads, want);
    // the dense load series: here the samples' nonzero loads only (the synthetic run has no
    // contact samples), and the first
    let text = std::fs::read_to_string(dir.join("load_disc_2.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t_s,load_n,rel_angle_rad,contact_step"));
    let loads: Vec<f64> = lines
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let want: Vec<f64> = run
        .samples
        .iter()
        .enumerate()
        .filter(|(k, s)| *k == 0 || s.discs[1].engaged || s.discs[1].load_n != 0.0)
        .map(|(_, s)| s.discs[1].load_n)
        .collect();
    assert_eq!(loads, want);
    let summary = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 3);
    let teeth = std::fs::read_to_string(dir.join("teeth_d1.csv")).unwrap();
    assert!(teeth.starts_with("t_s,tooth_0_n,tooth_1_n"));
    let f = std::fs::read_to_string(dir.join("interface_d1__disc_2.csv")).unwrap();
    let mut lines = f.lines();
    assert_eq!(
        lines.next(),
        Some("t_s,slip_rad_s,slip_m_s,mu,clamp_n,torque_n_m,locked,dissipated_j")
    );
    let clamp: Vec<f64> = lines
        .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
        .collect();
    let want: Vec<f64> = run.interfaces.iter().map(|(_, f)| f[0].clamp_n).collect();
    assert_eq!(clamp, want);
}

/// The Collector and the recorder see the same stream (sanity check of `play`).
#[test]
fn synthetic_play_delivers_everything() {
    let run = small();
    let mut c = Collector::default();
    run.play(&mut c);
    assert_eq!(c.samples, run.samples);
    assert_eq!(c.impacts, run.impacts);
    assert_eq!(c.interfaces, run.interfaces);
}

/// The independent reader (the official Python `mcap` and `mcap-protobuf-support`
/// packages, tests/python/read_mcap.py) decodes every message of every channel with the
/// embedded schemas, agrees with our counts, and recovers the same messages from a truncated
/// copy. Installs the pinned packages into target/pyenv on first use (PyPI), hence opt-in:
/// `cargo test -p clutchpack_record -- --ignored`.
#[test]
#[ignore = "installs the Python mcap packages from PyPI into target/pyenv"]
fn python_reader_decodes_every_message() {
    use std::process::Command;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let setup = Command::new("bash")
        .arg(root.join("tests/python/setup.sh"))
        .output()
        .unwrap();
    assert!(
        setup.status.success(),
        "{}",
        String::from_utf8_lossy(&setup.stderr)
    );
    let python = String::from_utf8(setup.stdout).unwrap().trim().to_string();
    let script = root.join("tests/python/read_mcap.py");
    let read = |path: &std::path::Path, extra: &[&str]| {
        let out = Command::new(&python)
            .arg(&script)
            .arg(path)
            .arg("--json")
            .args(extra)
            .output()
            .unwrap();
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            out.status.code(),
            json,
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };

    let run = small();
    let path = record(&run, "python.mcap", &options());
    let ours = open(&path).unwrap();
    let (code, json, err) = read(&path, &[]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(json["complete"], true);
    assert_eq!(json["summary_section"], true);
    assert_eq!(json["messages"], ours.info().messages);
    for t in &ours.info().topics {
        assert_eq!(json["topics"][&t.topic]["schema"], t.schema_name.as_str());
        assert_eq!(json["topics"][&t.topic]["count"], t.messages, "{}", t.topic);
    }
    assert_eq!(json["topics"]["/tf"]["schema"], "foxglove.FrameTransforms");
    assert_eq!(json["topics"]["/scene"]["schema"], "foxglove.SceneUpdate");
    let last = &json["topics"]["/discs/disc_2/spline"]["last"];
    assert_eq!(
        last["load_n"].as_f64().unwrap(),
        run.samples[399].discs[1].load_n
    );
    assert_eq!(last["t_s"].as_f64().unwrap(), run.samples[399].t_s);
    let s = &json["summary"]["discs"][1];
    assert_eq!(s["name"], "disc 2");
    assert_eq!(
        s["max_positive_n"].as_f64().unwrap(),
        ours.summary().unwrap().discs[1].max_positive_n
    );

    let bytes = std::fs::read(&path).unwrap();
    let cut = tmp("python_cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let recovered = open(&cut).unwrap().info().messages;
    let (code, json, err) = read(&cut, &[]);
    assert_eq!(
        code,
        Some(1),
        "a truncated file fails without --allow-truncated: {err}"
    );
    let (code, json2, err) = read(&cut, &["--allow-truncated"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(json2["truncated"], true);
    assert_eq!(json2["messages"], recovered);
    assert_eq!(json["messages"], recovered);
}

/// Without `deterministic`, a chunk is flushed once `flush_interval` of wall time has passed,
/// at the next sample or `progress` call: what is on disk then holds every sample so far.
#[test]
fn wall_clock_flush_bounds_the_loss() {
    let run = small();
    let path = tmp("wall_flush.mcap");
    let opts = RecordOptions {
        deterministic: false,
        flush_interval: std::time::Duration::from_millis(30),
        ..options()
    };
    let mut rec = Recorder::create(&path, &run.info, &opts).unwrap();
    for s in &run.samples[..10] {
        rec.sample(s);
    }
    let before = from_bytes(&path, std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(
        before.samples().len(),
        0,
        "not flushed yet (10 samples < flush_messages)"
    );
    std::thread::sleep(std::time::Duration::from_millis(40));
    assert!(!rec.progress(1e-4));
    let after = from_bytes(&path, std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(after.samples(), run.samples[..10].to_vec());
    rec.finish(None).unwrap();
}

/// By default `/tf` is decimated to one message per 0.2 ms of simulated time, while every
/// other topic keeps every sample.
#[test]
fn default_tf_rate() {
    let run = small(); // 400 samples, 10 us apart
    let r = open(record(&run, "tf_rate.mcap", &RecordOptions::default())).unwrap();
    let n = |t: &str| r.info().topic(t).unwrap().messages;
    assert_eq!(n("/tf"), 20, "one per 0.2 ms: t = 0, 0.2 ms, ..., 3.8 ms");
    assert_eq!(n("/discs/d1/spline"), 400);
    assert_eq!(
        r.samples(),
        run.samples
            .iter()
            .map(|s| {
                let mut s = s.clone();
                s.discs.iter_mut().for_each(|d| d.tooth_loads_n.clear());
                s
            })
            .collect::<Vec<_>>(),
        "per_tooth is off by default"
    );
}

/// `/impacts` is written in peak-time order although engines hand impacts over when their
/// contact closes: a long contact of disc 0 (on 1 ms, peak 1.5 ms, off 4 ms) closes after two
/// short impacts of disc 1 that peak later (2.0 and 3.0 ms). Written as they came, the topic
/// went back in time, across chunks when a chunk ended between them (Rerun's `mcap check`
/// flags that); now every impact comes back, in peak order, on `/impacts` and per disc.
#[test]
fn impacts_are_written_in_peak_time_order() {
    let run = small();
    let path = tmp("impact_order.mcap");
    let opts = RecordOptions {
        // a chunk per few messages: the disorder would cross chunks
        flush_messages: 8,
        ..options()
    };
    let mut rec = Recorder::create(&path, &run.info, &opts).unwrap();
    let impact = |disc: usize, on: f64, peak: f64, off: f64| clutchpack_model::ImpactEvent {
        disc,
        t_on_s: on,
        t_peak_s: peak,
        t_off_s: off,
        flank: clutchpack_model::Flank::ShaftLeads,
        v_on_m_s: 0.1,
        peak_n: -100.0 * (1.0 + peak * 1e3),
    };
    // (closing order) disc 1 at 2.0 and 3.0 ms, disc 0's long contact at 4 ms
    let events = [
        impact(1, 1.9e-3, 2.0e-3, 2.1e-3),
        impact(1, 2.9e-3, 3.0e-3, 3.1e-3),
        impact(0, 1.0e-3, 1.5e-3, 4.0e-3),
    ];
    let mut next = 0;
    for k in 0..=60 {
        let t = k as f64 * 1e-4;
        let discs = (0..2)
            .map(|i| DiscSample {
                engaged: if i == 0 {
                    (1.0e-3..4.0e-3).contains(&t)
                } else {
                    events[..2]
                        .iter()
                        .any(|e| (e.t_on_s..e.t_off_s).contains(&t))
                },
                ..Default::default()
            })
            .collect();
        rec.sample(&Sample {
            t_s: t,
            discs,
            ..Default::default()
        });
        // each impact after the samples before its separation, as engines emit them
        while next < events.len() && events[next].t_off_s <= t + 1e-4 {
            rec.impact(&events[next]);
            next += 1;
        }
    }
    assert!(rec.error().is_none());
    let path = rec.finish(None).unwrap();
    let r = open(&path).unwrap();
    assert!(r.is_complete(), "{:?}", r.damage());
    let peaks: Vec<f64> = r.impacts().iter().map(|e| e.t_peak_s).collect();
    assert_eq!(peaks, vec![1.5e-3, 2.0e-3, 3.0e-3]);
    // log times per topic never go back
    let mut last: std::collections::BTreeMap<String, u64> = Default::default();
    r.for_each_message(|m| {
        let prev = last.insert(m.topic.to_string(), m.log_time_ns).unwrap_or(0);
        if m.topic.ends_with("impacts") {
            assert!(m.log_time_ns >= prev, "{} went back in time", m.topic);
        }
    });
    assert!(last.contains_key(topics::IMPACTS));
}

/// Issue 13 item 3: `/discs/<name>/load` carries each disc's load at the contact samples and
/// at the samples with a load (or engaged, or the first), in time order, exactly as sent; the
/// samples read back as before (the contact samples are not samples); without
/// `contact_samples` the topic is absent.
#[test]
fn contact_samples_round_trip_on_the_load_topic() {
    let run = small();
    // three contact samples per disc between consecutive samples, with known values
    let contact = |k: usize, j: usize, disc: usize| -> (f64, DiscSample) {
        let (t0, t1) = (run.samples[k - 1].t_s, run.samples[k].t_s);
        let t = t0 + (t1 - t0) * (j + 1) as f64 / 4.0;
        let d = DiscSample {
            load_n: -(k as f64) * 10.0 - j as f64 - 0.25 * disc as f64,
            rel_angle_rad: 1e-3 * k as f64 + 1e-5 * j as f64,
            engaged: true,
            ..Default::default()
        };
        (t, d)
    };
    let play = |rec: &mut Recorder| {
        for (k, s) in run.samples.iter().enumerate() {
            if k > 0 {
                for disc in 0..2 {
                    for j in 0..3 {
                        let (t, d) = contact(k, j, disc);
                        rec.contact_sample(disc, t, &d);
                    }
                }
            }
            rec.sample(s);
            rec.interfaces(run.interfaces[k].0, &run.interfaces[k].1);
        }
        for e in &run.impacts {
            rec.impact(e);
        }
    };
    let path = tmp("contact_samples.mcap");
    let mut rec = Recorder::create(&path, &run.info, &options()).unwrap();
    play(&mut rec);
    assert!(rec.error().is_none());
    let path = rec.finish(None).unwrap();
    let r = open(&path).unwrap();
    assert_eq!(r.samples(), run.samples, "the samples are unchanged");
    let loads = r.dense_loads();
    assert_eq!(loads.len(), 2);
    let n = run.samples.len();
    let written = |s: &Sample, disc: usize| {
        let d = &s.discs[disc];
        s.t_s == 0.0 || d.engaged || d.load_n != 0.0
    };
    let mut counts = Vec::new();
    for (disc, series) in loads.iter().enumerate() {
        let regular = run.samples.iter().filter(|s| written(s, disc)).count();
        assert!(
            regular > 1 && regular < n,
            "disc {disc}: {regular} of {n}: some loads are 0"
        );
        assert_eq!(series.len(), regular + 3 * (n - 1), "disc {disc}");
        counts.push(series.len());
        assert!(
            series.windows(2).all(|w| w[0].t_s <= w[1].t_s),
            "time order"
        );
        let mut it = series.iter();
        for (k, s) in run.samples.iter().enumerate() {
            if k > 0 {
                for j in 0..3 {
                    let (t, d) = contact(k, j, disc);
                    let m = it.next().unwrap();
                    assert!(m.contact_step && m.disc_index as usize == disc);
                    assert_eq!(
                        (m.t_s, m.load_n, m.rel_angle_rad),
                        (t, d.load_n, d.rel_angle_rad)
                    );
                }
            }
            if !written(s, disc) {
                continue;
            }
            let m = it.next().unwrap();
            assert!(!m.contact_step);
            let d = &s.discs[disc];
            assert_eq!(
                (m.t_s, m.load_n, m.rel_angle_rad),
                (s.t_s, d.load_n, d.rel_angle_rad)
            );
        }
    }
    let topic = topics::load("disc_2");
    let info = r.info().topic(&topic).expect("the load topic of `disc 2`");
    assert_eq!(info.messages as usize, counts[1]);

    // off: no load topic, the rest as before
    let off = RecordOptions {
        contact_samples: false,
        ..options()
    };
    let path = tmp("contact_samples_off.mcap");
    let mut rec = Recorder::create(&path, &run.info, &off).unwrap();
    play(&mut rec);
    let r = open(rec.finish(None).unwrap()).unwrap();
    assert!(r.dense_loads().is_empty());
    assert!(r.info().topic(&topic).is_none());
    assert_eq!(r.samples(), run.samples);
}
