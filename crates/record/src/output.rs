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
//!
//! Which paths may be outputs at all is one policy for every front end ([`check_outputs`]:
//! the CLI, the FMU and Python call it before any work), so that no front end writes over a
//! folder, a device, a FIFO or its own input.

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

/// The longest file name, in bytes, that the file systems we write to accept (ext4, XFS,
/// Btrfs, tmpfs, NFS: `NAME_MAX` = 255).
pub const NAME_MAX_BYTES: usize = 255;

/// The temporary sibling of `target` for this process: `<stem>.partial-<pid>-<k>.<ext>`
/// (the extension kept, so that format-by-extension writers such as the plotter still work).
/// When that name would be longer than [`NAME_MAX_BYTES`] (a target name that the file system
/// accepts but leaves no room for the suffix), the stem is cut to fit and a hash of the whole
/// stem keeps names of different targets apart: `<cut stem>~<16 hex>.partial-<pid>-<k>.<ext>`.
pub fn partial_path(target: &Path, k: usize) -> PathBuf {
    let stem = target
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let ext = target
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let suffix = format!(".partial-{}-{k}{ext}", std::process::id());
    let stem = fit_stem(&stem, NAME_MAX_BYTES.saturating_sub(suffix.len()));
    target.with_file_name(format!("{stem}{suffix}"))
}

/// `stem` if it has at most `room` bytes, else its longest prefix (on a character boundary)
/// that leaves room for `~` and 16 hex digits of a hash of the whole stem.
fn fit_stem(stem: &str, room: usize) -> String {
    use std::hash::{Hash, Hasher};
    if stem.len() <= room {
        return stem.to_string();
    }
    let mut h = std::collections::hash_map::DefaultHasher::new();
    stem.hash(&mut h);
    let tag = format!("~{:016x}", h.finish());
    let mut cut = room.saturating_sub(tag.len());
    while !stem.is_char_boundary(cut) {
        cut -= 1;
    }
    format!("{}{tag}", &stem[..cut])
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

/// One output path of a command, as the front end names it: the flag, parameter or argument
/// (`--out`, `recording_path`, `record`) for messages, and the path.
#[derive(Debug, Clone, Copy)]
pub struct OutputPath<'a> {
    /// How the front end names this output in messages (`--out`, `recording_path`, `record`).
    pub label: &'a str,
    /// The path asked for.
    pub path: &'a Path,
    /// A figure: its format must follow from its extension (`.png`, `.svg`).
    pub figure: bool,
}

impl<'a> OutputPath<'a> {
    /// A file output (any format).
    pub fn file(label: &'a str, path: &'a Path) -> OutputPath<'a> {
        OutputPath {
            label,
            path,
            figure: false,
        }
    }

    /// A figure output: `.png` or `.svg`.
    pub fn figure(label: &'a str, path: &'a Path) -> OutputPath<'a> {
        OutputPath {
            label,
            path,
            figure: true,
        }
    }
}

/// Why an output path is refused: bad input, found before any work ([`check_outputs`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{label} {}: {why}", path.display())]
pub struct OutputRefused {
    /// The front end's name of the output (`--out`, `recording_path`, `record`).
    pub label: String,
    /// The path refused.
    pub path: PathBuf,
    /// The rule it breaks.
    pub why: String,
}

/// The parent folder of `path` (`.` for a bare file name).
fn folder(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A comparable identity of `path`: its canonical folder joined with its file name (the file
/// itself need not exist).
fn identity(path: &Path) -> Option<PathBuf> {
    let dir = folder(path).canonicalize().ok()?;
    let name = path.file_name()?;
    let full = dir.join(name);
    // an existing file may be a symbolic link to another
    Some(full.canonicalize().unwrap_or(full))
}

/// Checks one output path (see [`check_outputs`]).
fn check_one(o: &OutputPath<'_>) -> Result<(), OutputRefused> {
    let path = o.path;
    let bad = |why: String| OutputRefused {
        label: o.label.to_string(),
        path: path.to_path_buf(),
        why,
    };
    if path.as_os_str().is_empty() || path.file_name().is_none() {
        return Err(bad("names no file".into()));
    }
    let name_len = path.file_name().map_or(0, |n| n.len());
    if name_len > NAME_MAX_BYTES {
        return Err(bad(format!(
            "the file name has {name_len} bytes; a file name may have at most {NAME_MAX_BYTES}"
        )));
    }
    if o.figure {
        if let Err(clutchpack_analysis::PlotError::UnsupportedFormat { extension, .. }) =
            clutchpack_analysis::figure_format(path)
        {
            return Err(bad(format!(
                "a figure is written as .png or .svg, chosen by the extension (got {extension:?})"
            )));
        }
    }
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.is_dir() {
            return Err(bad("is a folder; give a file path".into()));
        }
        if !meta.is_file() {
            return Err(bad(
                "exists and is not a regular file (a FIFO, device or socket); outputs are \
                 written to a temporary file and renamed into place, which would replace it: \
                 give a regular file path"
                    .into(),
            ));
        }
    }
    let dir = folder(path);
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(bad(format!("{} is not a folder", dir.display()))),
        Err(_) => return Err(bad(format!("the folder {} does not exist", dir.display()))),
    }
    // the real test of writability: create (and remove) a new file in the folder, under the
    // longest temporary name the output will be written to
    let probe = partial_path(path, usize::MAX);
    match OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
        Err(e) => {
            return Err(bad(format!(
                "cannot create a file in the folder {}: {e}",
                dir.display()
            )))
        }
    }
    Ok(())
}

/// The one output policy of every front end (the CLI, the FMU, Python), checked before any
/// work: each path names a file (not a folder, not a FIFO, device or socket, whose node the
/// rename into place would replace), in an existing folder that takes a new file, a figure
/// with a `.png` or `.svg` extension; no two outputs name the same file; no output names an
/// input (`inputs`: the scene run, a recording read), which it would overwrite.
pub fn check_outputs(outputs: &[OutputPath<'_>], inputs: &[&Path]) -> Result<(), OutputRefused> {
    for o in outputs {
        check_one(o)?;
    }
    let ids: Vec<Option<PathBuf>> = outputs.iter().map(|o| identity(o.path)).collect();
    for (i, a) in outputs.iter().enumerate() {
        let Some(ia) = &ids[i] else { continue };
        for (j, b) in outputs.iter().enumerate().skip(i + 1) {
            if ids[j].as_ref() == Some(ia) {
                return Err(OutputRefused {
                    label: a.label.to_string(),
                    path: a.path.to_path_buf(),
                    why: format!(
                        "{} {} names the same file: each output needs its own path",
                        b.label,
                        b.path.display()
                    ),
                });
            }
        }
        for input in inputs {
            if input.canonicalize().ok().as_ref() == Some(ia) {
                return Err(OutputRefused {
                    label: a.label.to_string(),
                    path: a.path.to_path_buf(),
                    why: format!(
                        "is an input of this run ({}): refusing to overwrite it",
                        input.display()
                    ),
                });
            }
        }
    }
    Ok(())
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

    /// A target name of 250 bytes (the file system takes up to 255) still gets a temporary
    /// sibling that the file system accepts, and commits under its own name; two long names
    /// that differ only at the end get different temporary names (issue 25, reproducer 3).
    #[test]
    fn long_target_names_get_temporary_names_that_fit() {
        let d = dir("long");
        let a = d.join(format!("{}a.mcap", "x".repeat(245)));
        let b = d.join(format!("{}b.mcap", "x".repeat(245)));
        assert_eq!(a.file_name().unwrap().len(), 251);
        let (ta, tb) = (partial_path(&a, 0), partial_path(&b, 0));
        for t in [&ta, &tb] {
            let n = t.file_name().unwrap().len();
            assert!(n <= NAME_MAX_BYTES, "{n}");
            assert!(t.to_string_lossy().ends_with(".mcap"));
        }
        assert_ne!(ta, tb);
        write_whole(&a, b"long").unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"long");
        // a multi-byte character across the cut is not split
        let c = d.join(format!("{}.csv", "é".repeat(120)));
        let tc = partial_path(&c, 0);
        assert!(tc.file_name().unwrap().len() <= NAME_MAX_BYTES);
        let _ = std::fs::remove_dir_all(&d);
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
