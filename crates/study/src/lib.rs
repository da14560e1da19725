//! # clutchpack_study
//!
//! Studies: many runs of one base scene, for design studies and Monte Carlo analyses of a
//! chaotic rattle, sharded over threads and machines (Slurm job arrays, Kubernetes Indexed
//! Jobs) and merged into one table.
//!
//! - [`spec`]: study files (TOML), validated with every problem at once; case `k` is a pure
//!   function of the file and `k` ([`spec::Study::case`], [`spec::Study::scene`]).
//! - [`rng`]: counter-based random streams keyed by (seed, case, stream).
//! - [`tolerance`]: per-tooth spacing errors from ISO 1328-1:2013 tolerance classes.
//! - [`part`]: shards, running one on J threads with a clean stop, part files written
//!   atomically and resumed on rerun.
//! - [`merge`]: completeness of the parts, the results table (CSV, [`parquet`]) and the
//!   per-design-point summary; [`stats`]: t intervals and Welch's test; [`plot`]: main effects.
//! - [`scheduler`]: Slurm batch scripts and Kubernetes manifests.
//!
//! It does not run engines: the caller passes a function from a scene to a case's statistics
//! (the CLI uses its engines), so that this crate depends only on the model, the scene and
//! the analysis crates.

#![warn(missing_docs)]

pub mod merge;
pub mod parquet;
pub mod part;
pub mod plot;
pub mod rng;
pub mod scheduler;
pub mod spec;
pub mod stats;
pub mod tolerance;

pub use merge::{collect, MergeError, Merged};
pub use part::{run_shard, CaseOutput, CaseRecord, Shard, ShardOutcome};
pub use spec::{load, parse, SpecError, Study};
