//! An interrupted `triorder order` leaves nothing behind: SIGTERM or SIGINT while the output is
//! being written removes its temporary file (`.triorder-*.tmp` beside the target), exits with the
//! shell's status for the signal (143, 130) and never leaves a partial target.
#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Enough triangles that writing the OBJ takes seconds (about 2 s in a release build on one
/// core, much longer in a debug build), so the signal lands while the temporary is open.
const MESH: &str = "sphere:4000000";

/// How long to wait for the temporary to appear: generating, measuring and ordering the mesh
/// come first.
const PATIENCE: Duration = Duration::from_secs(300);

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(".triorder-"))
        .collect()
}

fn listing(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()
}

/// Waits until `dir` holds a temporary output, or the child has exited (then fails).
fn wait_for_temporary(child: &mut Child, dir: &Path) {
    let start = Instant::now();
    while temporaries(dir).is_empty() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("triorder exited ({status}) before a temporary output appeared in {}", dir.display());
        }
        assert!(start.elapsed() < PATIENCE, "no temporary output in {} after {PATIENCE:?}", dir.display());
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn interrupt_while_writing(signal: &str, number: i32) {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("out.obj");
    let mut child = Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["order", MESH, "-m", "input", "-o"])
        .arg(&target)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_temporary(&mut child, dir.path());
    let kill = Command::new("kill").arg(format!("-{signal}")).arg(child.id().to_string()).status().unwrap();
    assert!(kill.success(), "kill -{signal} failed");
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.code() == Some(128 + number),
        "after SIG{signal}: expected exit status {}, got {:?} (signal {:?}); stderr: {stderr}",
        128 + number,
        output.status.code(),
        output.status.signal()
    );
    // The mesh's load report comes first; the interrupt adds one line.
    let expected = format!("triorder: interrupted by SIG{signal}; removed 1 unfinished output");
    assert_eq!(stderr.lines().last(), Some(expected.as_str()), "stderr: {stderr}");
    assert_eq!(stderr.matches("interrupted").count(), 1, "stderr: {stderr}");
    assert!(listing(dir.path()).is_empty(), "left behind in {}: {:?}", dir.path().display(), listing(dir.path()));
}

#[test]
fn sigterm_while_writing_removes_the_temporary() {
    interrupt_while_writing("TERM", 15);
}

#[test]
fn sigint_while_writing_removes_the_temporary() {
    interrupt_while_writing("INT", 2);
}
