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

/// The shared data directory (`$TRIORDER_DATA`, else ../shared/data beside the crate), if present.
pub fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("TRIORDER_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("note: no data directory at {}; skipping tests on real meshes", dir.display());
        None
    }
}

/// Loads `models/NAME` from the data directory, or `None` (with a notice) when there is none.
pub fn real_mesh(name: &str) -> Option<Mesh> {
    let path = data_dir()?.join("models").join(name);
    Some(load::load_file(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// The GPU raster backend, opened once per test binary, or `None` with a notice when this machine
/// has no Vulkan adapter. With `TRIORDER_REQUIRE_GPU` set (CI sets it, after installing Mesa's
/// lavapipe) a missing adapter fails the test instead of skipping it.
pub fn gpu() -> Option<&'static triorder::raster::gpu::GpuRaster> {
    static GPU: std::sync::OnceLock<Option<triorder::raster::gpu::GpuRaster>> = std::sync::OnceLock::new();
    GPU.get_or_init(|| available(triorder::raster::gpu::GpuRaster::new())).as_ref()
}

/// A GPU part that opened, or `None` with a notice; a failure with `TRIORDER_REQUIRE_GPU` set.
pub fn available<T>(opened: triorder::Result<T>) -> Option<T> {
    match opened {
        Ok(part) => Some(part),
        Err(e) if std::env::var_os("TRIORDER_REQUIRE_GPU").is_some() => panic!("TRIORDER_REQUIRE_GPU is set: {e}"),
        Err(e) => {
            eprintln!("note: skipping a GPU test: {e}");
            None
        }
    }
}

/// Writes `text` as `ROOT/experiments/ID.toml` and returns its path.
pub fn write_spec(root: &std::path::Path, id: &str, text: &str) -> std::path::PathBuf {
    let dir = root.join("experiments");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{id}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Every raster backend this machine can run: the CPU reference, then the GPU when there is one.
pub fn backends() -> Vec<&'static dyn triorder::raster::RasterBackend> {
    static CPU: triorder::raster::cpu::CpuRaster = triorder::raster::cpu::CpuRaster;
    let mut all: Vec<&'static dyn triorder::raster::RasterBackend> = vec![&CPU];
    if let Some(gpu) = gpu() {
        all.push(gpu);
    }
    all
}

/// A results CSV as one column → value map per row.
pub fn csv_rows(path: &std::path::Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader.records().map(|r| header.iter().cloned().zip(r.unwrap().iter().map(String::from)).collect()).collect()
}
