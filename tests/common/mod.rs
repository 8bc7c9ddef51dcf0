//! Helpers shared by integration tests: where the real meshes are.

#![allow(dead_code)] // each test binary uses a different subset

use std::path::PathBuf;

use triorder::mesh::{Mesh, load};

/// Every static model in the shared data directory (`models/`), as MANIFEST.md lists them.
pub const STATIC_MODELS: [&str; 13] = [
    "bun_zipper.ply",
    "bunny_2k.ply",
    "dragon_vrip_res2.ply",
    "dragon_vrip_res3.ply",
    "dragon_vrip_res4.ply",
    "happy_buddha_100k.obj",
    "horse.ply",
    "feline.obj",
    "armadillo.obj",
    "spot.obj",
    "nefertiti_lowres.obj",
    "pirate.obj",
    "rocker-arm.obj",
];

/// Why tests on real meshes are ignored (`#[cfg_attr(not(triorder_data), ignore = …)]`): the build
/// found no data directory (see build.rs).
pub const NEEDS_DATA: &str = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)";

/// The shared data directory (`$TRIORDER_DATA`, else ../shared/data beside the crate). Tests that
/// call it are ignored where the build found none; if it is gone since, or TRIORDER_REQUIRE_DATA
/// made them run without it, they fail here, saying so.
pub fn data_dir() -> PathBuf {
    let dir = std::env::var_os("TRIORDER_DATA")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    assert!(dir.is_dir(), "no data directory at {}: {NEEDS_DATA}", dir.display());
    dir
}

/// Loads `models/NAME` from the data directory.
pub fn real_mesh(name: &str) -> Mesh {
    let path = data_dir().join("models").join(name);
    load::load_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// `animated/NAME` in the data directory.
pub fn animated_file(name: &str) -> PathBuf {
    data_dir().join("animated").join(name)
}

/// The GPU raster backend, opened once per test binary. Tests that call it are ignored where the
/// build found no Vulkan driver (`triorder_gpu`, see build.rs); with one, a device that does not
/// open fails the test with the reason.
pub fn gpu() -> &'static triorder::gpu::raster::GpuRaster {
    static GPU: std::sync::OnceLock<triorder::Result<triorder::gpu::raster::GpuRaster>> = std::sync::OnceLock::new();
    GPU.get_or_init(triorder::gpu::raster::GpuRaster::new).as_ref().unwrap_or_else(|e| opened(e))
}

/// A GPU part that must open on a machine with a driver.
pub fn available<T>(opened_part: triorder::Result<T>) -> T {
    opened_part.unwrap_or_else(|e| opened(&e))
}

fn opened(e: &triorder::Error) -> ! {
    panic!("a Vulkan driver is installed but the GPU does not open: {e}")
}

/// Writes `text` as `ROOT/experiments/ID.toml` and returns its path.
pub fn write_spec(root: &std::path::Path, id: &str, text: &str) -> std::path::PathBuf {
    let dir = root.join("experiments");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{id}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Every raster backend this machine can run: the CPU reference, then the GPU where the build
/// found a Vulkan driver (`triorder_gpu`).
pub fn backends() -> Vec<&'static dyn triorder::raster::RasterBackend> {
    static CPU: triorder::raster::cpu::CpuRaster = triorder::raster::cpu::CpuRaster;
    let mut all: Vec<&'static dyn triorder::raster::RasterBackend> = vec![&CPU];
    if cfg!(triorder_gpu) {
        all.push(gpu());
    }
    all
}

/// A results CSV as one column → value map per row.
pub fn csv_rows(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader.records().map(|r| header.iter().cloned().zip(r.unwrap().iter().map(String::from)).collect()).collect()
}

/// Runs `resolved` (a static method) on `mesh` as every command does, checked, and returns its
/// one order.
pub fn static_order(resolved: &triorder::order::Resolved, mesh: &Mesh) -> triorder::Result<triorder::order::Order> {
    let scene = triorder::mesh::Scene::still(mesh.clone());
    let orders = triorder::order::run(resolved, &scene)?;
    Ok(orders.single().expect("a static method gives one order").order.clone())
}

/// Loading `path` fails, without a panic, with a message that names the file and contains every
/// phrase; returns the message.
pub fn rejected(path: &std::path::Path, phrases: &[&str]) -> String {
    assert!(path.exists(), "{} is missing", path.display());
    let message = match load::load_file(path) {
        Ok(mesh) => panic!("{} loaded ({} triangles) but is broken", path.display(), mesh.triangle_count()),
        Err(e) => e.to_string(),
    };
    assert!(message.contains(&path.display().to_string()), "the error does not name the file: {message}");
    for phrase in phrases {
        assert!(message.contains(phrase), "{}: expected {phrase:?} in: {message}", path.display());
    }
    message
}

/// The Khronos glTF validator's report on `path` (`scripts/validate-gltf.cjs`: errors, warnings,
/// and the count of each error and warning code), or `None` where the validator is not installed:
/// said on stdout, and a failure when `TRIORDER_REQUIRE_VALIDATOR` is set (CI sets it).
#[allow(dead_code)]
pub fn gltf_validator(path: &std::path::Path) -> Option<serde_json::Value> {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/validate-gltf.cjs");
    let why = match std::process::Command::new("node").arg(&script).arg(path).output() {
        Ok(out) if out.status.success() => return Some(serde_json::from_slice(&out.stdout).unwrap()),
        Ok(out) => String::from_utf8_lossy(&out.stderr).into_owned(),
        Err(e) => format!("node: {e}"),
    };
    assert!(
        std::env::var_os("TRIORDER_REQUIRE_VALIDATOR").is_none(),
        "the glTF validator is required (TRIORDER_REQUIRE_VALIDATOR) but did not run: {why}"
    );
    println!("skipped the glTF validator on {}: {why}", path.display());
    None
}

/// The validator finds no error and no warning in `path` (where it is installed).
#[allow(dead_code)]
pub fn assert_valid_gltf(path: &std::path::Path) {
    if let Some(report) = gltf_validator(path) {
        assert_eq!((report["errors"].as_u64(), report["warnings"].as_u64()), (Some(0), Some(0)), "{report}");
    }
}
