//! Vertex-shader invocations counted on the GPU (`--cache gpu`): what any device's counts must
//! satisfy, and the plumbing into `eval` and experiment rows. Lavapipe's reuse is not a GPU's
//! (../shared/GPU.md), so nothing here asserts a particular hardware figure.
//!
//! Skipped without a Vulkan adapter, unless TRIORDER_REQUIRE_GPU is set (as in CI).

mod common;

use glam::Vec3;
use triorder::gpu::vertex_reuse::{self, VertexCounter};
use triorder::measure::{CacheModel, cache};
use triorder::mesh::load;
use triorder::order;

fn counter() -> &'static VertexCounter {
    common::available(vertex_reuse::shared())
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn invocations_are_bounded_repeatable_and_reward_locality() {
    let counter = counter();
    let mesh = load::load_file(std::path::Path::new("assets/spot.obj")).unwrap();
    let mut acmr = Vec::new();
    for method in ["random", "input", "tipsify", "meshopt-vcache"] {
        let order = common::static_order(&order::resolve(method, 3).unwrap(), &mesh).unwrap();
        let triangles = mesh.triangles_in_order(&order);
        let invocations = counter.count(&mesh.positions, &triangles).unwrap();
        assert_eq!(counter.count(&mesh.positions, &triangles).unwrap(), invocations, "{method}: not repeatable");
        // Every referenced vertex is shaded at least once; no corner more than once.
        let simulated = cache::simulate(CacheModel::Fifo(16), &triangles, mesh.vertex_count());
        assert!(
            invocations >= simulated.vertices as u64 && invocations <= 3 * simulated.triangles as u64,
            "{method}: {invocations} invocations"
        );
        let gpu_acmr = invocations as f64 / triangles.len() as f64;
        eprintln!("{method}: GPU ACMR {gpu_acmr:.4}, FIFO-16 {:.4} on {}", simulated.acmr(), counter.device());
        acmr.push(gpu_acmr);
    }
    // A cache-optimised order never costs the GPU more vertex work than a random one.
    assert!(acmr[2] < acmr[0] && acmr[3] < acmr[0], "{acmr:?}");
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn unshared_corners_cost_three_invocations_per_triangle() {
    let counter = counter();
    let n = 1000u32;
    let positions: Vec<Vec3> = (0..3 * n).map(|i| Vec3::new(i as f32, (i % 3) as f32, 0.0)).collect();
    let triangles: Vec<[u32; 3]> = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    assert_eq!(counter.count(&positions, &triangles).unwrap(), 3 * u64::from(n));
    let err = counter.count(&positions, &[[0, 1, 3 * n]]).unwrap_err().to_string();
    assert!(err.contains("out of range"), "{err}");
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn eval_and_specs_write_counted_rows() {
    let counter = counter();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", "assets/spot.obj", "-m", "tipsify", "--cache", "fifo:16", "--cache", "gpu", "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["cache"], "fifo:16");
    let counted = json["caches"].as_array().unwrap().iter().find(|c| c["cache"] == "gpu").unwrap();
    assert_eq!(counted["device"], counter.device());
    // At least one invocation per referenced vertex.
    assert!(counted["atvr"].as_f64().unwrap() >= 1.0, "{counted}");

    let root = tempfile::tempdir().unwrap();
    let text = r#"id = "tiny-hw"
title = "Hardware reuse smoke"
question = "Do counted rows land beside simulated ones?"
models = ["sphere:500", "grid:8x8"]
methods = ["input", "random"]
caches = ["fifo:16", "gpu"]
[figure]
kind = "bar"
metric = "acmr"
x = "method"
series = "cache"
facet = "model"
"#;
    let spec = common::write_spec(root.path(), "tiny-hw", text);
    let options = triorder::experiment::RunOptions { out_dir: root.path().into(), ..Default::default() };
    let csv = triorder::experiment::run(&spec, &options).unwrap().csv;
    let rows = common::csv_rows(&csv);
    let counted: Vec<_> = rows.iter().filter(|r| r["cache"] == "gpu").collect();
    // Two models × two methods × (acmr, atvr), each naming the device that counted it.
    assert_eq!(counted.len(), 8);
    assert!(counted.iter().all(|r| r["backend"] == format!("gpu: {}", counter.device())));
    assert_eq!(counted.iter().filter(|r| r["metric"] == "acmr").count(), 4);
    // A method with several buffers is counted over its draws like any other.
    std::fs::write(&spec, text.replace(r#"["input", "random"]"#, r#"["hs17:views=12,res=32"]"#)).unwrap();
    let rows = common::csv_rows(&triorder::experiment::run(&spec, &options).unwrap().csv);
    assert_eq!(rows.iter().filter(|r| r["cache"] == "gpu").count(), 4);
}
