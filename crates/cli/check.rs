//! `clutchpack check`.

use crate::common::BadInput;
use anyhow::Result;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `clutchpack check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Scene files to validate.
    #[arg(required_unless_present = "keys")]
    pub scenes: Vec<PathBuf>,
    /// Print the reference of every scene key and exit.
    #[arg(long)]
    pub keys: bool,
}

pub fn check(a: CheckArgs) -> Result<ExitCode> {
    if a.keys {
        out!("{}", clutchpack_scene::keys_doc());
        return Ok(ExitCode::SUCCESS);
    }
    let mut bad = 0;
    for p in &a.scenes {
        match clutchpack_scene::load(p, &[]) {
            Ok(s) => out!(
                "{}: ok ({} discs, {} s)",
                p.display(),
                s.pack.discs.len(),
                s.simulation.duration_s
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
