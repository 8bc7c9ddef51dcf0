//! Atomic file output: write beside the target, then rename over it.
//!
//! A crash, a full disk or a bad path must never leave a partial CSV, SVG or mesh where a user
//! (or the next pipeline stage) would read it as complete. The temporary file lives in the
//! target's directory so the final rename cannot cross file systems, and is removed on failure.

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};

/// Writes what `fill` produces to `path` atomically. Errors name `path`.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let staged = stage(path, fill)?;
    staged.persist(path).map_err(|e| Error::output(path, e.error))?;
    Ok(())
}

/// Writes a set of files that belong together (the levels of a progressive mesh, one file
/// each): every file is written to its temporary first, and only when all are complete are they
/// renamed into place, so a failure leaves none of the set, new or half-written.
pub fn write_all(files: Vec<(&Path, Fill<'_>)>) -> Result<()> {
    let staged = files.into_iter().map(|(path, fill)| Ok((path, stage(path, fill)?))).collect::<Result<Vec<_>>>()?;
    for (path, tmp) in staged {
        tmp.persist(path).map_err(|e| Error::output(path, e.error))?;
    }
    Ok(())
}

/// What writes one file's bytes.
pub type Fill<'a> = Box<dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a>;

/// `fill`'s output in a temporary file beside `path`, removed if it is dropped unpersisted.
fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if path.is_dir() {
        return Err(Error::output(path, "is a directory"));
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".triorder-").suffix(".tmp");
    // tempfile creates 0600 files; an output should get the usual 0666 minus umask.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir).map_err(|e| Error::output(path, e))?;
    {
        let mut buffered = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buffered).and_then(|()| buffered.flush()).map_err(|e| Error::output(path, e))?;
    }
    Ok(tmp)
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes))
}
