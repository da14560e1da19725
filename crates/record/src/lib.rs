//! # clutchpack_record
//!
//! Recordings of clutchpack runs: MCAP files that Foxglove, PlotJuggler and Rerun open as
//! they are, written from an engine's stream of [`Sample`](clutchpack_model::Sample)s and
//! [`ImpactEvent`](clutchpack_model::ImpactEvent)s, and read back (robustly) into the same
//! typed values for `replay`, `compare`, `export` and `plot`.
//!
//! ## What this crate does
//! - [`Recorder`]: the one recorder, an [`Observer`](clutchpack_model::Observer) that streams
//!   a run (a pack's or a network's) into an MCAP file: protobuf messages with embedded schemas, zstd chunks, message and chunk
//!   indexes, a summary section; chunks flushed every [`RecordOptions::flush_messages`]
//!   messages and at least every [`RecordOptions::flush_interval`] of wall time, so a killed
//!   run leaves a file readable up to the last flush. [`RunInfo`] goes in as metadata
//!   records and the scene file as an attachment, so a recording describes itself and can
//!   be run again.
//! - [`open`] / [`RecordingReader`]: topics, counts, time span, metadata, the stored summary
//!   ([`RecordingInfo`]), and typed data: [`RecordingReader::samples`],
//!   [`RecordingReader::load_histories`], [`RecordingReader::impacts`],
//!   [`RecordingReader::disc_series`]. Truncated, corrupted, empty and foreign files give a
//!   one-line reason ([`ReadError`], [`Damage`]) and never a panic; a killed run's file is
//!   read up to its last complete chunk.
//! - [`Recorder::create_network_output`] / [`read_network`]: the same recorder records a
//!   driveline network's run (MODEL.md section 8) with the same header, metadata and scene
//!   attachment: each body's and coupling's state, the clutches' mode changes, a 3D view;
//!   read back into its samples.
//! - [`export_csv`]: one CSV per topic of ours.
//! - `serve` (feature `serve`): plays a recording to Foxglove over its WebSocket protocol.
//!
//! ## What it does not do
//! - Run engines, parse scenes or compute statistics beyond the stored summary: the CLI
//!   fills [`RunInfo`] from the scene, and `clutchpack_analysis` does the statistics (the summary's
//!   per-disc entry is its [`DiscStats`]).
//! - Depend on rapier or on the engines: it knows only `clutchpack_model`'s stream types.
//!
//! ## Topics
//! All messages are protobuf but `/joints` (ROS 2 CDR, for Rerun); log time = publish time =
//! simulated time in ns (deterministic).
//!
//! | topic | schema | when | fields (units in names) |
//! | --- | --- | --- | --- |
//! | `/tf` | `foxglove.FrameTransforms` | every [`RecordOptions::tf_interval_s`] (0.2 ms) | `world` -> `shaft`, `world` -> `disc/<segment>`: rotation about +z, discs at `z_m` |
//! | `/scene` | `foxglove.SceneUpdate` | once, at t = 0 | the static pack: shaft cylinder, disc annuli (triangle meshes) with their teeth |
//! | `/scene/loads` | `foxglove.SceneUpdate` | t = 0, then every [`RecordOptions::scene_interval_s`] when a colour changed | every disc's load ring over its teeth coloured by load (per-tooth runs: each tooth by its own load) |
//! | `/pack/<frame>` | `foxglove.PointCloud` | once, at t = 0 | the same pack as points in each body's frame, for Rerun (which does not draw scene updates) |
//! | `/joints` | `sensor_msgs/msg/JointState` (`ros2msg`, `cdr`) | each sample | one joint per disc: `position` = `rel_angle_rad`, `velocity` = shaft minus disc speed (rad/s), `effort` = `load_n`; Rerun plots it with no setup |
//! | `/shaft` | `clutchpack.ShaftState` | each sample | `t_s, angle_rad, speed_rad_s` |
//! | `/discs/<segment>/spline` | `clutchpack.SplineState` | each sample | `t_s, rel_angle_rad, closing_speed_m_s, penetration_m, load_n, torque_n_m, engaged, stiffness_n_m1_5, speed_rad_s, angle_rad, disc_index` |
//! | `/discs/<segment>/teeth` | `clutchpack.ToothLoads` | each sample, if [`RecordOptions::per_tooth`] | `t_s, loads_n[], disc_index` |
//! | `/interfaces/<lower>__<upper>` | `clutchpack.InterfaceState` | each sample, packs with a stack | `t_s, slip_rad_s, slip_m_s, mu, clamp_n, torque_n_m, locked, interface_index, dissipated_j` |
//! | `/impacts` | `clutchpack.Impact` | each impact, at `t_peak_s` | `disc, disc_index, t_on_s, t_peak_s, t_off_s, flank, v_on_m_s, peak_n` |
//! | `/discs/<segment>/impacts` | `clutchpack.Impact` | each impact of that disc, at `t_peak_s` | the same messages as `/impacts`: a per-disc series of the exact located peaks |
//! | `/discs/<segment>/temperature` | `clutchpack.Temperature` | thermal runs: t = 0, then each thermal window's end | `t_s, temperature_k, body_index` |
//! | `/oil/temperature` | `clutchpack.Temperature` | thermal runs, as above | the oil's `temperature_k`; `body_index` = the number of bodies |
//! | `/scene/temperatures` | `foxglove.SceneUpdate` | thermal runs: when a body's colour changed (steps of 1/32 of the range) | every body's faces and rims coloured by temperature (blue .. yellow .. red over [`RecordOptions::temperature_color_range_k`]) and a legend naming the range and the oil's temperature |
//! | `/summary` | `clutchpack.RunSummary` | once, written at the end, logged at t = 0 (so viewers show it on open) | `t_end_s, discs[]{name, index, max_positive_n, max_negative_n, p99_abs_n, impacts, positive_impacts, negative_impacts, mean_top10_abs_n}` |
//!
//! `<segment>` is the disc's scene name made topic-safe by [`topic_segment`]. The
//! `clutchpack.*` schemas are in `crates/record/proto/clutchpack.proto` (generated from
//! [`proto`]). Metadata records: `clutchpack.run` (program, program_version, engine,
//! scene_name, scene_file, scene_sha256, overrides, disc_names, recorder options, and
//! `recorded_at_utc` unless deterministic), `clutchpack.solver`, `clutchpack.geometry`,
//! `clutchpack.params`, and at the end `clutchpack.stats`. Attachment: the scene file,
//! `application/toml`.
//!
//! ## Use
//! ```no_run
//! use clutchpack_record::{open, Recorder, RecordOptions, RunInfo};
//! # fn engine_run(_: &mut dyn clutchpack_model::Observer) {}
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let info = RunInfo { engine: "reference".into(), ..Default::default() };
//! let mut rec = Recorder::create("recordings/run.mcap", &info, &RecordOptions::default())?;
//! engine_run(&mut rec); // the engine calls sample() and impact()
//! let path = rec.finish(None)?; // None: store the recorder's own per-disc summary
//!
//! let reader = open(&path)?;
//! if let Some(damage) = reader.damage() {
//!     eprintln!("warning: {damage}");
//! }
//! for h in reader.load_histories() {
//!     println!("{}: {} samples", h.name, h.t_s.len());
//! }
//! # Ok(()) }
//! ```
//!
//! ## Cost
//! Measured with `cargo bench -p clutchpack_record` on the 2-core dev machine: writing one
//! sample of an 8-disc pack (`/shaft`, eight spline messages, `/tf` every 0.2 ms, the load
//! collars every 1 ms) costs about 9 us, roughly 1 us per message, most of it the MCAP
//! writer's seven small writes per message record into the zstd stream; about 40 bytes per
//! message on disk. The CLI runs the recorder on its own thread (`clutchpack bench` reports
//! its CPU time against the engine's and the wall-time overhead of recording). Memory stays
//! flat with run length: chunks (4 MiB uncompressed) are compressed straight into the file,
//! and what is held is the open chunk's message indexes, the impact peaks and heaps of
//! bounded size, and the chunk index (about 0.7 kB per chunk, which the `mcap` writer holds
//! until the summary section). Reading streams too: opening scans the file in blocks,
//! holding one chunk at a time, and every later pass
//! ([`RecordingReader::for_each_message`]) reads the file again, so a reader's memory does
//! not grow with the file (the series that return every sample, such as
//! [`RecordingReader::samples`], do).
//!
//! # Conventions
//! - SI units, named in fields and keys (`load_n`, `t_s`); loads are per tooth, negative
//!   when the shaft leads (Hu et al. eq (6)), as in `clutchpack_model`.
//! - z is the shaft axis; positive rotation is the shaft's running direction (about +z).
//! - Deterministic recordings ([`RecordOptions::deterministic`]) of the same stream are
//!   byte-identical: no wall-clock data, single-threaded zstd,
//!   chunks cut by message count and size only.
//! - Errors: [`RecordError`] for writing, [`ReadError`] for reading; each displays as one line.

#![warn(missing_docs)]

mod export;
pub mod info;
mod network;
mod network_packs;
mod network_view;
pub mod output;
mod pack;
pub mod proto;
mod read;
mod recorder;
mod ros2;
#[cfg(feature = "serve")]
mod serve;
mod sink;
mod summary;
mod view3d;
// Test fixture for this crate's tests, benches and examples (integration tests are other
// crates, so it stays `pub`); not part of the API.
#[doc(hidden)]
/// Synthetic runs for tests and examples (feature `test-support`; not part of the product's
/// interface).
#[cfg(any(test, feature = "test-support"))]
pub mod synthetic;
mod threaded;
pub mod topics;
mod write;

pub use export::{export_csv, export_csv_until};
pub use info::{sha256_hex, DiscGeometry, FrictionInterface, RunInfo, ShaftGeometry};
pub use network::{
    body_frame, coupling_kind_name, impact_name, META_NETWORK, OPEN_CONTACTS_EVERY_S,
    SUMMARY_ATTACHMENT,
};
pub use output::{
    check_outputs, partial_path, write_whole, OutputPath, OutputRefused, PendingFile, Replace,
    NAME_MAX_BYTES,
};
pub use read::{
    from_bytes, from_bytes_with, open, open_complete, open_with, read_network, AttachmentInfo,
    Damage, DamageKind, DiscSeries, InterfaceSeries, LoadHistory, MessageView, ReadError,
    ReadOptions, RecordedNetwork, RecordingInfo, RecordingReader, TopicInfo,
};
pub use recorder::Recorder;
#[cfg(feature = "serve")]
pub use serve::{serve, ServeError, ServeOptions};
pub use summary::{DiscStats, FatigueSummary, RecordedSummary, MAX_EXTRA_DISCS, TOP_N};
pub use threaded::ThreadedRecorder;
pub use write::{auto_chunk_size_bytes, default_path, log_time_ns, RecordError, RecordOptions};

/// A disc name made safe for a topic and frame name: every character other than
/// `A-Z a-z 0-9 _ -` becomes `_` (an empty name becomes `_`). Repeated segments in one
/// recording get `_<index>` appended.
pub fn topic_segment(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "_".into()
    } else {
        s
    }
}
