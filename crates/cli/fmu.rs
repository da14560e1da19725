//! `clutchpack fmu`: packs a scene into an FMI 2.0 co-simulation FMU
//! (docs/cosimulation.md).

use crate::common::{self, BadInput};
use anyhow::{Context, Result};
use clutchpack_sdk::scene::{EngineChoice, Override};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `clutchpack fmu`.
#[derive(clap::Args, Debug)]
pub struct FmuArgs {
    /// The scene to pack.
    pub scene: PathBuf,
    /// The FMU to write (replaced if it exists).
    #[arg(long, short)]
    pub out: PathBuf,
    /// The engine the FMU runs by default (its `engine` parameter; else the scene's choice).
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Override a scene key, `KEY=VALUE` (TOML value), repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<Override>,
}

/// The FMU's binary: `libclutchpack_fmu.so`, built by cargo beside this executable (the
/// `clutchpack_fmu` crate is a dependency of the CLI, so one `cargo build` makes both). Of
/// the copy beside it and the one in `deps/`, the newer: `cargo test` rebuilds only the
/// `deps/` copy, and taking the other first packed a stale binary after a change.
fn library() -> Result<PathBuf> {
    let exe = std::env::current_exe().context("locating the clutchpack executable")?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let name = "libclutchpack_fmu.so";
    [dir.join(name), dir.join("deps").join(name)]
        .into_iter()
        .filter(|p| p.is_file())
        .max_by_key(|p| std::fs::metadata(p).and_then(|m| m.modified()).ok())
        .ok_or_else(|| {
            anyhow::anyhow!(
                "the FMU's binary {name} is not beside {} (nor in its deps/): build the \
                 workspace with cargo (`cargo build --release`), which builds it with the \
                 executable",
                exe.display()
            )
        })
}

pub fn fmu(a: FmuArgs) -> Result<ExitCode> {
    let scene = clutchpack_sdk::scene::load(&a.scene, &a.sets)?;
    // the one output policy (`clutchpack_sdk::record::check_outputs`): never the scene itself, a
    // folder, a device or a FIFO
    let inputs: Vec<&std::path::Path> = std::iter::once(a.scene.as_path())
        .chain(scene.inputs.iter().map(|p| p.as_path()))
        .collect();
    crate::outputs::check_outputs(&[crate::outputs::Output::file("--out", &a.out)], &inputs)?;
    let engine = clutchpack_fmu::check_representable(&scene, a.engine).map_err(|e| match e {
        clutchpack_fmu::PackageError::Unrepresentable(why) => {
            anyhow::Error::new(BadInput(format!("{}: {why}", a.scene.display())))
        }
        other => other.into(),
    })?;
    let lib = library()?;
    let n = clutchpack_fmu::write_fmu(&scene, engine, &lib, &a.out)?;
    out!(
        "{}: FMI 2.0 co-simulation FMU of {} ({} engine, {n} variables)",
        a.out.display(),
        scene.name,
        engine.name()
    );
    Ok(ExitCode::SUCCESS)
}
