//! Opening a recording for reading, with the one policy for damaged files: refused unless
//! the caller asks to salvage what could be read.

use crate::{Error, Result};
use clutchpack_record::RecordingReader;
use std::path::Path;

/// Opens the recording at `path`. A damaged file (cut by a kill, a flipped byte) is bad
/// input naming the damage unless `salvage`, in which case the recovered messages are used
/// and the damage is returned as a warning to show; a salvage that recovered no message is
/// bad input too. A file that is not a recording is bad input.
pub fn open_recording(path: &Path, salvage: bool) -> Result<(RecordingReader, Option<String>)> {
    let reader = clutchpack_record::open(path).map_err(|e| Error::BadInput(e.to_string()))?;
    let Some(d) = reader.damage() else {
        return Ok((reader, None));
    };
    let warning = format!("{}: {d}", path.display());
    if !salvage {
        return Err(Error::BadInput(format!(
            "{warning} (salvage to use the recovered messages: `--salvage`, `salvage=True` in Python)"
        )));
    }
    if reader.info().messages == 0 {
        return Err(Error::BadInput(format!(
            "{warning}; salvage recovered no message"
        )));
    }
    Ok((
        reader,
        Some(format!("{warning}; using the recovered messages")),
    ))
}
