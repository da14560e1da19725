//! What a viewer that restores "the latest message of each topic" (Foxglove and Lichtblick
//! after a seek or on opening a file) finds in a recording, and the per-disc impact-peak
//! series that plots read instead of the sampled `load_n`.

use clutchpack_record::synthetic::{synthetic_run, SyntheticRun};
use clutchpack_record::{export_csv, log_time_ns, open, proto, topics, RecordOptions, Recorder};
use foxglove::schemas::SceneUpdate;
use prost::Message as _;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clutchpack_viewer");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A recording of 8 ms of the synthetic two-disc run (impacts every 1.5 ms per disc, so
/// several load-colour updates), per-tooth loads on.
fn recorded(name: &str) -> (SyntheticRun, PathBuf) {
    let run = synthetic_run(800, 1e-5);
    let path = tmp(name);
    let opts = RecordOptions {
        deterministic: true,
        per_tooth: true,
        flush_messages: 300,
        ..Default::default()
    };
    let mut rec = Recorder::create(&path, &run.info, &opts).unwrap();
    run.play(&mut rec);
    assert!(rec.error().is_none());
    (run, rec.finish(None).unwrap())
}

/// Per topic, `(log time ns, bytes)` in file order.
fn by_topic(path: &PathBuf) -> BTreeMap<String, Vec<(u64, Vec<u8>)>> {
    let r = open(path).unwrap();
    let mut out: BTreeMap<String, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
    r.for_each_message(|m| {
        out.entry(m.topic.to_string())
            .or_default()
            .push((m.log_time_ns, m.data.to_vec()));
    });
    out
}

/// The latest message of `msgs` logged at or before `t` (ns), as a viewer restores it.
fn latest_at(msgs: &[(u64, Vec<u8>)], t: u64) -> Option<&[u8]> {
    msgs.iter()
        .filter(|m| m.0 <= t)
        .max_by_key(|m| m.0)
        .map(|m| m.1.as_slice())
}

/// At any time from the start to the end, the latest `/scene` message is the whole static
/// pack (shaft and both discs with their teeth), and the latest `/scene/loads` message holds
/// every disc's load ring: a seek to anywhere shows the full pack with its colours. The
/// summary is logged at t = 0, so it is there on opening.
#[test]
fn every_seek_restores_the_whole_pack_and_its_colours() {
    let (run, path) = recorded("seek.mcap");
    let m = by_topic(&path);
    let end = log_time_ns(run.samples.last().unwrap().t_s);
    assert_eq!(m[topics::SCENE].len(), 1, "the static pack is one message");
    assert!(
        m[topics::SCENE_LOADS].len() >= 4,
        "several colour updates, so the test seeks between them"
    );
    for k in 0..=20 {
        let t = end / 20 * k;
        let scene = SceneUpdate::decode(latest_at(&m[topics::SCENE], t).unwrap()).unwrap();
        let ids: Vec<&str> = scene.entities.iter().map(|e| e.id.as_str()).collect();
        assert_eq!(ids, ["shaft", "disc/d1", "disc/disc_2"], "at {t} ns");
        for e in &scene.entities[1..] {
            // the annulus and the teeth (synthetic discs have 24 teeth of 8 corners)
            assert_eq!(e.triangles.len(), 2);
            assert_eq!(e.triangles[1].points.len(), 24 * 8);
        }
        let loads = SceneUpdate::decode(latest_at(&m[topics::SCENE_LOADS], t).unwrap()).unwrap();
        for id in ["disc/d1/load", "disc/disc_2/load"] {
            let e = loads.entities.iter().find(|e| e.id == id);
            assert!(e.is_some_and(|e| e.lines.len() == 1), "{id} at {t} ns");
        }
        let summary = latest_at(&m[topics::SUMMARY], t).expect("summary from t = 0 on");
        let summary = proto::SummaryMessage::decode(summary).unwrap();
        assert_eq!(summary.discs.len(), 2);
    }
    assert_eq!(m[topics::SUMMARY][0].0, 0, "/summary is logged at t = 0");
}

/// `/discs/<segment>/impacts` holds, per disc, exactly the rows of `impacts.csv` (`record
/// export`) for that disc, in the same order: each message logged at its peak time with the
/// same `t_peak_s` and `peak_n`, bit for bit (the CSV writes shortest round-trip numbers, so
/// an exact comparison is the right one).
#[test]
fn impact_peak_series_equals_the_impacts_csv_peak_for_peak() {
    let (run, path) = recorded("peaks.mcap");
    let dir = tmp("peaks-csv");
    export_csv(&open(&path).unwrap(), &dir).unwrap();
    let csv = std::fs::read_to_string(dir.join("impacts.csv")).unwrap();
    // columns: disc,disc_index,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n; the name may
    // be quoted, so split from the right
    let mut want: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.rsplitn(8, ',').collect();
        let (peak, t_peak, index) = (f[0], f[4], f[6]);
        want.entry(index.parse().unwrap())
            .or_default()
            .push((t_peak.parse().unwrap(), peak.parse().unwrap()));
    }
    assert_eq!(
        want.values().map(Vec::len).sum::<usize>(),
        run.impacts.len()
    );
    assert!(
        want.len() == 2 && want.values().all(|v| v.len() >= 4),
        "{want:?}"
    );

    let m = by_topic(&path);
    for (i, seg) in ["d1", "disc_2"].iter().enumerate() {
        let got: Vec<(f64, f64)> = m[&topics::disc_impacts(seg)]
            .iter()
            .map(|(t, data)| {
                let e = proto::Impact::decode(data.as_slice()).unwrap();
                assert_eq!(e.disc_index as usize, i);
                assert_eq!(*t, log_time_ns(e.t_peak_s), "logged at its peak time");
                (e.t_peak_s, e.peak_n)
            })
            .collect();
        assert_eq!(got, want[&i], "disc {seg}");
    }
    // the repeats are not counted as impacts of their own
    assert_eq!(open(&path).unwrap().impacts(), run.impacts);
}

/// For Rerun, which maps well-known messages to its own archetypes: `/joints`
/// (`sensor_msgs/msg/JointState`, ROS 2 CDR) carries one message per sample whose `effort`
/// (its last field: the final `8 n` bytes) is each disc's `load_n`, and `/pack/<frame>` one
/// `foxglove.PointCloud` per body at t = 0 in that body's frame.
#[test]
fn rerun_topics_carry_the_loads_and_the_pack() {
    let (run, path) = recorded("rerun.mcap");
    let r = open(&path).unwrap();
    let t = r.info().topic(topics::JOINTS).unwrap();
    assert_eq!(
        (t.schema_name.as_str(), t.schema_encoding.as_str()),
        ("sensor_msgs/msg/JointState", "ros2msg")
    );
    assert_eq!(t.message_encoding, "cdr");
    let m = by_topic(&path);
    let joints = &m[topics::JOINTS];
    assert_eq!(joints.len(), run.samples.len());
    for ((t, data), s) in joints.iter().zip(&run.samples) {
        assert_eq!(*t, log_time_ns(s.t_s));
        let n = s.discs.len();
        let effort: Vec<f64> = data[data.len() - 8 * n..]
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        let want: Vec<f64> = s.discs.iter().map(|d| d.load_n).collect();
        assert_eq!(effort, want);
        // and the count before them
        let count = &data[data.len() - 8 * n - 4..data.len() - 8 * n];
        assert!(
            count == (n as u32).to_le_bytes() || {
                // padding to 8 may sit between the count and the values
                let c = &data[data.len() - 8 * n - 8..data.len() - 8 * n - 4];
                c == (n as u32).to_le_bytes()
            }
        );
    }
    for (topic, frame) in [
        ("/pack/shaft", "shaft"),
        ("/pack/disc/d1", "disc/d1"),
        ("/pack/disc/disc_2", "disc/disc_2"),
    ] {
        let msgs = &m[topic];
        assert_eq!(msgs.len(), 1, "{topic}");
        assert_eq!(msgs[0].0, 0);
        let cloud = foxglove::schemas::PointCloud::decode(msgs[0].1.as_slice()).unwrap();
        assert_eq!(cloud.frame_id, frame);
        assert_eq!(cloud.point_stride, 16);
        assert!(cloud.data.len() > 16 * 100 && cloud.data.len() % 16 == 0);
        points_coloured_for_both_viewers(topic, &cloud);
    }
}

/// Each point's colour is readable two ways, and they agree: the packed `rgba` field (a
/// little-endian `u32` `0xAARRGGBB`, which Foxglove colours points by; without it Foxglove
/// painted them with a colour map of `x`) and the named bytes `red`, `green`, `blue`, `alpha`
/// (Rerun). Opaque points, and not all of one grey, so that a swap of red and blue shows.
fn points_coloured_for_both_viewers(topic: &str, cloud: &foxglove::schemas::PointCloud) {
    let offset = |name: &str| {
        cloud
            .fields
            .iter()
            .find(|f| f.name == name)
            .unwrap_or_else(|| panic!("{topic}: no field {name}"))
            .offset as usize
    };
    let (packed, r, g, b, a) = (
        offset("rgba"),
        offset("red"),
        offset("green"),
        offset("blue"),
        offset("alpha"),
    );
    let mut coloured = false;
    for p in cloud.data.chunks(16) {
        let argb = u32::from_le_bytes(p[packed..packed + 4].try_into().unwrap());
        let named = (u32::from(p[a]) << 24)
            | (u32::from(p[r]) << 16)
            | (u32::from(p[g]) << 8)
            | u32::from(p[b]);
        assert_eq!(argb, named, "{topic}");
        assert_eq!(p[a], 255, "{topic}");
        coloured |= p[r] != p[b];
    }
    assert!(coloured, "{topic}: every point grey");
}
