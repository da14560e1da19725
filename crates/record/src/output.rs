//! Output files written whole: each output goes to a temporary file beside its target (same
//! folder, so the final rename never crosses a file system) and is renamed into place only
//! when complete ([`PendingFile`]). A reader of the target therefore sees either the old file
//! or the complete new one, never a half-written one, and two runs writing the same target at
//! once each leave a complete file (the last rename wins).
//!
//! Whether an existing target may be replaced is the caller's choice ([`Replace`]): the CLI
//! replaces only the explicit paths whose `--help` says so, and never a default name, which
//! is made unique instead ([`Replace::Never`] commits under the first free name
//! `<stem>-2.<ext>`, `<stem>-3.<ext>`, ..., checked and taken atomically by a hard link).

use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// What committing does when the target exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Replace {
    /// Replace it (atomically, by a rename): the documented behaviour of an explicit path.
    Existing,
    /// Never replace it: take the first free name `<stem>-<k>.<ext>` (k = 2, 3, ...).
    Never,
}

/// An output being written to a temporary sibling of its target; [`PendingFile::commit`]
/// moves it into place. Dropped without a commit, the temporary file is left as it is (a
/// killed or failed run's partial output stays readable under its temporary name, which
/// says `partial`).
#[derive(Debug)]
pub struct PendingFile {
    tmp: PathBuf,
    target: PathBuf,
    replace: Replace,
    committed: bool,
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// The temporary sibling of `target` for this process: `<stem>.partial-<pid>-<k>.<ext>`
/// (the extension kept, so that format-by-extension writers such as the plotter still work).
pub fn partial_path(target: &Path, k: usize) -> PathBuf {
    let stem = target
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let name = match target.extension() {
        Some(ext) => format!(
            "{stem}.partial-{}-{k}.{}",
            std::process::id(),
            ext.to_string_lossy()
        ),
        None => format!("{stem}.partial-{}-{k}", std::process::id()),
    };
    target.with_file_name(name)
}

/// `<stem>-<k>.<ext>` beside `target`.
fn numbered(target: &Path, k: usize) -> PathBuf {
    let stem = target
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match target.extension() {
        Some(ext) => format!("{stem}-{k}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{k}"),
    };
    target.with_file_name(name)
}

impl PendingFile {
    /// Creates a new, empty temporary file beside `target` (never an existing one:
    /// `create_new`), creating the folder if needed. Errors say which file.
    pub fn create(target: impl AsRef<Path>, replace: Replace) -> io::Result<(PendingFile, File)> {
        let target = target.as_ref().to_path_buf();
        if target.file_name().is_none() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{} names no file", target.display()),
            ));
        }
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| {
                io::Error::new(
                    e.kind(),
                    format!("creating the folder {}: {e}", dir.display()),
                )
            })?;
        }
        loop {
            let k = COUNTER.fetch_add(1, Ordering::Relaxed);
            let tmp = partial_path(&target, k);
            match OpenOptions::new().write(true).create_new(true).open(&tmp) {
                Ok(f) => {
                    return Ok((
                        PendingFile {
                            tmp,
                            target,
                            replace,
                            committed: false,
                        },
                        f,
                    ))
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => {
                    return Err(io::Error::new(
                        e.kind(),
                        format!("creating {}: {e}", tmp.display()),
                    ))
                }
            }
        }
    }

    /// The temporary file being written.
    pub fn tmp_path(&self) -> &Path {
        &self.tmp
    }

    /// The path asked for.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Moves the (complete, closed or flushed) temporary file into place and returns the
    /// final path: the target, or with [`Replace::Never`] and an existing target the first
    /// free `<stem>-<k>.<ext>`.
    pub fn commit(mut self) -> io::Result<PathBuf> {
        let path = match self.replace {
            Replace::Existing => {
                std::fs::rename(&self.tmp, &self.target).map_err(|e| {
                    io::Error::new(
                        e.kind(),
                        format!(
                            "renaming {} to {}: {e}",
                            self.tmp.display(),
                            self.target.display()
                        ),
                    )
                })?;
                self.target.clone()
            }
            Replace::Never => {
                let mut k = 1;
                loop {
                    let cand = if k == 1 {
                        self.target.clone()
                    } else {
                        numbered(&self.target, k)
                    };
                    // a hard link fails if the name exists: the check and the taking are one
                    // step, so two runs never end up with the same name
                    match std::fs::hard_link(&self.tmp, &cand) {
                        Ok(()) => {
                            let _ = std::fs::remove_file(&self.tmp);
                            break cand;
                        }
                        Err(e) if e.kind() == io::ErrorKind::AlreadyExists && k < 100_000 => k += 1,
                        Err(e) => {
                            return Err(io::Error::new(
                                e.kind(),
                                format!("moving {} to {}: {e}", self.tmp.display(), cand.display()),
                            ))
                        }
                    }
                }
            }
        };
        self.committed = true;
        Ok(path)
    }

    /// Removes the temporary file (an output that is not wanted after all).
    pub fn discard(mut self) {
        let _ = std::fs::remove_file(&self.tmp);
        self.committed = true;
    }

    /// Whether the output was committed or discarded.
    pub fn is_done(&self) -> bool {
        self.committed
    }
}

/// Writes `bytes` to `target` whole: into a temporary sibling, then renamed over `target`
/// ([`Replace::Existing`]: the caller asked for this path). Nothing is left behind on error.
pub fn write_whole(target: &Path, bytes: &[u8]) -> io::Result<PathBuf> {
    use std::io::Write as _;
    let (p, mut f) = PendingFile::create(target, Replace::Existing)?;
    let written = f.write_all(bytes).and_then(|()| f.flush());
    drop(f);
    match written {
        Ok(()) => p.commit(),
        Err(e) => {
            let tmp = p.tmp_path().to_path_buf();
            p.discard();
            Err(io::Error::new(
                e.kind(),
                format!("writing {}: {e}", tmp.display()),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("cp-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// The target appears only at the commit; `Never` keeps an existing file and takes the
    /// next free name; `Existing` replaces it.
    #[test]
    fn commit_moves_into_place_without_clobbering_unless_asked() {
        use std::io::Write as _;
        let d = dir("commit");
        let t = d.join("r.csv");
        std::fs::write(&t, "old").unwrap();
        let (p, mut f) = PendingFile::create(&t, Replace::Never).unwrap();
        assert!(p.tmp_path().to_string_lossy().contains(".partial-"));
        assert_eq!(p.tmp_path().extension().unwrap(), "csv");
        f.write_all(b"new").unwrap();
        drop(f);
        assert_eq!(std::fs::read_to_string(&t).unwrap(), "old");
        let got = p.commit().unwrap();
        assert_eq!(got, d.join("r-2.csv"));
        assert_eq!(std::fs::read_to_string(&t).unwrap(), "old");
        assert_eq!(std::fs::read_to_string(&got).unwrap(), "new");
        let (p, mut f) = PendingFile::create(&t, Replace::Existing).unwrap();
        f.write_all(b"newer").unwrap();
        drop(f);
        assert_eq!(p.commit().unwrap(), t);
        assert_eq!(std::fs::read_to_string(&t).unwrap(), "newer");
        // only the two outputs are left, no temporary file
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2);
        let _ = std::fs::remove_dir_all(&d);
    }
}
