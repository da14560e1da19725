//! Output paths, checked before any work and written whole.
//!
//! Every command checks all its output paths before it starts ([`check_outputs`], the one
//! policy of every front end: `clutchpack_sdk::record::check_outputs`): the folder exists (the
//! recording's is created) and takes a new file, the path is not a folder, a FIFO or a
//! device, no two outputs name the same file and no output names an input (the scene being
//! run). A problem is bad input (exit 2) naming the flag and the path, found in
//! milliseconds rather than after a long simulation. Every output is then written to a
//! temporary sibling and renamed into place when complete ([`write_text`], [`write_with`],
//! `clutchpack_sdk::record::Recorder::create_output`), so a reader sees the old file or the
//! complete new one, never half of one.

use crate::common::BadInput;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// One output of a command: the flag that named it (for messages) and its path; the policy
/// is `clutchpack_sdk::record::check_outputs`, shared with the FMU and Python.
pub type Output<'a> = clutchpack_sdk::record::OutputPath<'a>;

/// Creates the folder of an output (`flag` names it in messages) and its parents; a file in
/// the way is said as such, not as the OS's "File exists". Bad input (exit 2) on failure.
pub fn create_folder(flag: &str, path: &Path) -> Result<()> {
    let dir = folder(path);
    if let Some(blocker) = dir
        .ancestors()
        .find(|a| std::fs::metadata(a).is_ok_and(|m| !m.is_dir()))
    {
        return Err(BadInput(format!(
            "{flag} {}: {} is a file, not a folder",
            path.display(),
            blocker.display()
        ))
        .into());
    }
    std::fs::create_dir_all(&dir).map_err(|e| {
        BadInput(format!(
            "{flag} {}: cannot create the folder {}: {e}",
            path.display(),
            dir.display()
        ))
        .into()
    })
}

/// The parent folder of `path` (`.` for a bare file name).
fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks every output before the command does any work: each path (see the module
/// documentation), no two outputs the same file, no output the same file as an input.
/// Errors are bad input (exit 2) naming the flag and the path.
pub fn check_outputs(outputs: &[Output<'_>], inputs: &[&Path]) -> Result<()> {
    clutchpack_sdk::record::check_outputs(outputs, inputs)
        .map_err(|e| BadInput(e.to_string()).into())
}

/// Writes `text` to `path` whole (temporary sibling, renamed into place).
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    clutchpack_sdk::record::write_whole(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Lets `write` produce the file at a temporary sibling path of `path` (same extension, for
/// writers that choose the format by extension, like the plots), then renames it into place;
/// removes the temporary file if `write` fails.
pub fn write_with(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let (pending, file) = clutchpack_sdk::record::PendingFile::create(
        path,
        clutchpack_sdk::record::Replace::Existing,
    )
    .with_context(|| format!("creating {}", path.display()))?;
    drop(file);
    let tmp = pending.tmp_path().to_path_buf();
    match write(&tmp) {
        Ok(()) => {
            pending
                .commit()
                .with_context(|| format!("writing {}", path.display()))?;
            Ok(())
        }
        Err(e) => {
            pending.discard();
            Err(e.context(format!("writing {}", path.display())))
        }
    }
}

/// Writes `value` as pretty JSON to `path`, whole or not at all.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    write_text(path, &(text + "\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("cp-outputs-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn is_bad_input(e: &anyhow::Error) -> bool {
        e.chain().any(|c| c.is::<BadInput>())
    }

    /// Two flags naming one file, an output naming the input, a folder, a missing folder:
    /// each refused as bad input naming the flag; distinct new files pass.
    #[test]
    fn outputs_that_would_clobber_each_other_or_an_input_are_refused() {
        let d = dir("clobber");
        let scene = d.join("my.toml");
        std::fs::write(&scene, "x").unwrap();
        let r = d.join("r.mcap");
        let same = d.join(".").join("r.mcap");
        let e = check_outputs(
            &[
                Output::file("--out", &r),
                Output::file("--impacts-csv", &same),
            ],
            &[],
        )
        .unwrap_err();
        assert!(
            is_bad_input(&e) && e.to_string().contains("--impacts-csv"),
            "{e}"
        );
        let e = check_outputs(&[Output::file("--out", &scene)], &[&scene]).unwrap_err();
        assert!(is_bad_input(&e) && e.to_string().contains("input"), "{e}");
        let e = check_outputs(&[Output::file("--plot", &d)], &[]).unwrap_err();
        assert!(is_bad_input(&e) && e.to_string().contains("folder"), "{e}");
        let missing = d.join("no/such/x.json");
        let e = check_outputs(&[Output::file("--summary-json", &missing)], &[]).unwrap_err();
        assert!(
            is_bad_input(&e) && e.to_string().contains("does not exist"),
            "{e}"
        );
        let c = d.join("c.csv");
        check_outputs(
            &[Output::file("--out", &r), Output::file("--impacts-csv", &c)],
            &[&scene],
        )
        .unwrap();
        let _ = std::fs::remove_dir_all(&d);
    }

    /// A character device (here /dev/null) is refused: renaming over it would be wrong.
    #[test]
    fn a_device_or_fifo_is_not_an_output() {
        let e = check_outputs(
            &[Output::file("--summary-json", Path::new("/dev/null"))],
            &[],
        )
        .unwrap_err();
        assert!(
            is_bad_input(&e) && e.to_string().contains("not a regular file"),
            "{e}"
        );
    }
}
