//! `clutchpack check`: validates scene files (and, with `--engine`, that the engine can run
//! them) without running anything; `--keys` prints the reference of every scene key.

use crate::common::{self, BadInput};
use anyhow::Result;
use clutchpack_scene::EngineChoice;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `clutchpack check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Scene files to validate.
    #[arg(required_unless_present = "keys")]
    pub scenes: Vec<PathBuf>,
    /// Also check that this engine can run each scene (else the engine `run` would choose:
    /// the scene's `simulation.engine`, else the one that fits the pack).
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Print the reference of every scene key and exit.
    #[arg(long)]
    pub keys: bool,
    /// With `--keys`: print the reference as the README's Markdown table.
    #[arg(long, requires = "keys")]
    pub markdown: bool,
}

pub fn check(a: CheckArgs) -> Result<ExitCode> {
    if a.keys {
        if a.markdown {
            out!("{}", clutchpack_scene::keys_markdown());
        } else {
            out!("{}", clutchpack_scene::keys_doc());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let mut bad = 0;
    for p in &a.scenes {
        let origin = p.display().to_string();
        let checked = clutchpack_scene::load(p, &[]).and_then(|s| {
            let engine = s.engine(a.engine, &origin)?;
            Ok((s, engine))
        });
        match checked {
            Ok((s, engine)) => out!(
                "{}: ok ({} discs, {} s, {} engine)",
                p.display(),
                s.pack.discs.len(),
                s.simulation.duration_s,
                engine.name()
            ),
            Err(e) => {
                eprintln!("{e}");
                bad += 1;
            }
        }
    }
    if bad > 0 {
        return Err(BadInput(format!(
            "{bad} of {} scene files are invalid",
            a.scenes.len()
        ))
        .into());
    }
    Ok(ExitCode::SUCCESS)
}
