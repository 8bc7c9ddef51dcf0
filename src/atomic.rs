//! Atomic file output: write beside the target, then rename over it.
//!
//! A crash, a full disk or a bad path must never leave a partial CSV, SVG or mesh where a user
//! (or the next pipeline stage) would read it as complete. The temporary file lives in the
//! target's directory so the final rename cannot cross file systems, and is removed on failure.
//!
//! An interrupt (SIGINT, SIGTERM) would end the process without running the destructors that
//! remove those temporaries, so every live one is also listed in a process-wide registry, and
//! [`remove_temporaries_on_signals`] (called once by the command line at start-up) deletes them
//! all before exiting. The registry's lock is held while a temporary is created, renamed or
//! removed, so the signal's clean-up sees each output either unfinished (and deletes its
//! temporary) or complete (and leaves it), never half-renamed; a set from [`write_all`] is
//! renamed under one lock, so an interrupt leaves all of it or none.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::error::{Error, Result};

/// Writes what `fill` produces to `path` atomically. Errors name `path`.
pub fn write_with(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let staged = stage(path, fill)?;
    persist(vec![(path, staged)])
}

/// Writes a set of files that belong together (the levels of a progressive mesh, one file
/// each): every file is written to its temporary first, and only when all are complete are they
/// renamed into place, so a failure leaves none of the set, new or half-written.
pub fn write_all(files: Vec<(&Path, Fill<'_>)>) -> Result<()> {
    let staged = files.into_iter().map(|(path, fill)| Ok((path, stage(path, fill)?))).collect::<Result<Vec<_>>>()?;
    persist(staged)
}

/// Installs the handler for SIGINT and SIGTERM: it deletes every temporary file of an output
/// still being written, says so in one line on stderr, and exits with status 130 (SIGINT) or
/// 143 (SIGTERM), as a shell reports a process killed by either. Call it once, at start-up.
///
/// The signal is received by a thread of its own (signal-hook's self-pipe iterator), so the
/// clean-up is ordinary code: it may lock, allocate and print.
#[cfg(unix)]
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Held until exit: no output is created or renamed after this.
            let live = registry();
            let removed = live.iter().filter(|tmp| std::fs::remove_file(tmp).is_ok()).count();
            let name = if signal == SIGINT { "SIGINT" } else { "SIGTERM" };
            let outputs = match removed {
                0 => String::new(),
                1 => "; removed 1 unfinished output".to_string(),
                n => format!("; removed {n} unfinished outputs"),
            };
            eprintln!("triorder: interrupted by {name}{outputs}");
            std::process::exit(128 + signal);
        }
    })?;
    Ok(())
}

/// Elsewhere there is nothing to install: temporaries are removed only on errors and drops.
#[cfg(not(unix))]
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    Ok(())
}

/// The temporaries of outputs being written, for the signal handler to delete.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The registry, locked. A panic elsewhere while it was held leaves the list itself intact.
fn registry() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Takes `tmp` off the registry.
fn forget(live: &mut Vec<PathBuf>, tmp: &Path) {
    if let Some(i) = live.iter().position(|p| p == tmp) {
        live.swap_remove(i);
    }
}

/// A temporary file on the registry: removed from disk and from the registry when dropped
/// unpersisted.
struct Staged {
    file: Option<tempfile::NamedTempFile>,
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(file) = self.file.take() {
            let mut live = registry();
            forget(&mut live, file.path());
            drop(file);
        }
    }
}

/// Renames each temporary onto its path, all under one lock of the registry. After a failed
/// rename the remaining temporaries are removed instead.
fn persist(staged: Vec<(&Path, Staged)>) -> Result<()> {
    let mut live = registry();
    let mut result = Ok(());
    for (path, mut staged) in staged {
        // Taken, so that dropping `staged` does not lock the registry again.
        let Some(file) = staged.file.take() else { continue };
        let tmp = file.path().to_path_buf();
        if result.is_ok()
            && let Err(e) = file.persist(path)
        {
            result = Err(Error::output(path, e.error));
        }
        forget(&mut live, &tmp);
    }
    result
}

/// What writes one file's bytes.
pub type Fill<'a> = Box<dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a>;

/// `fill`'s output in a temporary file beside `path`, removed if it is dropped unpersisted (or
/// the process is interrupted).
fn stage(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<Staged> {
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
    let mut staged = {
        // Created and listed under one lock, so that no interrupt falls between the two.
        let mut live = registry();
        let file = builder.tempfile_in(dir).map_err(|e| Error::output(path, e))?;
        live.push(file.path().to_path_buf());
        Staged { file: Some(file) }
    };
    let tmp = staged.file.as_mut().expect("staged just now");
    {
        let mut buffered = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buffered).and_then(|()| buffered.flush()).map_err(|e| Error::output(path, e))?;
    }
    Ok(staged)
}

/// Writes `bytes` to `path` atomically.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes))
}
