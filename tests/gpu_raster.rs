//! The GPU raster backend against the CPU reference on real meshes, and its failures.
//!
//! On the hand-made scenes of tests/overdraw.rs the two backends must agree exactly. On real
//! meshes they may differ where the rules leave room: how a device rounds a vertex to its 1/256
//! sub-pixel grid, and how it interpolates depth, so a fragment within a rounding error of an
//! earlier one at the same pixel can pass on one backend and fail on the other. Every difference
//! is counted here and must stay under 0.1% of fragments (issue 6): per view and in total on
//! meshes whose surfaces do not overlap, over the view set on a mesh whose surfaces do.
//!
//! Without a Vulkan adapter these tests skip with a notice, unless TRIORDER_REQUIRE_GPU is set
//! (CI installs Mesa's lavapipe and sets it).

mod common;

use triorder::mesh::Framing;
use triorder::mesh::{Mesh, load};
use triorder::order;
use triorder::raster::cpu::CpuRaster;
use triorder::raster::{RasterBackend, ViewSet};

/// Sums of |gpu − cpu| over views, per count, and the CPU's total fragments (those that pass the
/// depth test: the fragments a renderer shades).
#[derive(Debug, Default)]
struct Difference {
    covered: u64,
    passed: u64,
    fragments: u64,
}

/// Compares the backends on every view; with `per_view`, each view must be within 0.1% (or one
/// fragment in 1,000 when it has fewer than 1,000).
fn compare(name: &str, mesh: &Mesh, method: &str, views: &str, res: u32, per_view: bool) -> Difference {
    let gpu = common::gpu();
    let order = common::static_order(&order::resolve(method, 1).unwrap(), mesh).unwrap();
    let triangles = mesh.triangles_in_order(&order);
    let cameras = views.parse::<ViewSet>().unwrap().cameras(Framing::of(&mesh.positions), 5);
    let cpu = CpuRaster.count(&mesh.positions, &triangles, &cameras, res).unwrap();
    let gpu_counts = gpu.count(&mesh.positions, &triangles, &cameras, res).unwrap();
    assert_eq!(cpu.len(), gpu_counts.len());
    let mut d = Difference::default();
    for (i, (c, g)) in cpu.iter().zip(&gpu_counts).enumerate() {
        let view = Difference {
            covered: c.covered.abs_diff(g.covered),
            passed: c.passed.abs_diff(g.passed),
            fragments: c.passed,
        };
        for (what, delta) in [("covered", view.covered), ("passed", view.passed)] {
            assert!(
                !per_view || delta * 1000 <= c.passed.max(1000),
                "{name} {method} {views}@{res} view {i}: {what} {c:?} vs {g:?}"
            );
        }
        d.covered += view.covered;
        d.passed += view.passed;
        d.fragments += view.fragments;
    }
    eprintln!(
        "{name} {method} {views}@{res}: |Δ| covered {} passed {} of {} fragments",
        d.covered, d.passed, d.fragments
    );
    d
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn real_meshes_count_within_a_tenth_of_a_percent() {
    let mut meshes = vec![("spot".to_string(), load::load_file(std::path::Path::new("assets/spot.obj")).unwrap())];
    for name in ["bun_zipper.ply", "horse.ply"] {
        meshes.push((name.to_string(), common::real_mesh(name)));
    }
    for (name, mesh) in &meshes {
        for method in ["input", "random"] {
            for (views, res) in [("ico:42", 128), ("random:20", 256)] {
                let d = compare(name, mesh, method, views, res, true);
                for delta in [d.covered, d.passed] {
                    assert!(delta * 1000 <= d.fragments, "{name} {method}: {d:?}");
                }
            }
        }
    }
}

/// The crudely decimated vrip dragons fold over themselves (MANIFEST.md: non-manifold edges), so
/// many pixels hold two front-facing surfaces within a depth rounding error of each other, and
/// which one passes first is decided by how each backend interpolates depth: the CPU from the
/// snapped vertices, lavapipe its own way. At 512² a single view of the 11k dragon differs by up
/// to 0.2% of its fragments (other meshes: under 0.01%); over ico:162 the total stays under 0.1%.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn overlapping_surfaces_count_within_a_tenth_of_a_percent_over_the_view_set() {
    let mesh = common::real_mesh("dragon_vrip_res4.ply");
    for method in ["input", "random"] {
        let d = compare("dragon_vrip_res4", &mesh, method, "ico:162", 512, false);
        for delta in [d.covered, d.passed] {
            assert!(delta * 1000 <= d.fragments, "{method}: {d:?}");
        }
    }
}

fn eval_json(backend: &str) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", "assets/spot.obj", "-m", "tipsify", "--views", "ico:12", "--res", "128", "--json"])
        .args(["--backend", backend])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    serde_json::from_str(text.lines().next().unwrap()).unwrap()
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn eval_names_the_device_and_matches_the_cpu() {
    let gpu = common::gpu();
    let (cpu, on_gpu) = (eval_json("cpu"), eval_json("gpu"));
    assert_eq!(cpu["backend"], "cpu");
    assert_eq!(on_gpu["backend"], format!("gpu: {}", gpu.device()));
    // spot counts identically on both backends (real_meshes_count_within_a_tenth_of_a_percent).
    for key in ["ovr_mean", "ovr_max", "ovr_var", "acmr"] {
        assert_eq!(cpu[key], on_gpu[key], "{key}");
    }
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn a_spec_runs_on_the_gpu_and_its_rows_name_the_device() {
    let gpu = common::gpu();
    let root = tempfile::tempdir().unwrap();
    let spec = common::write_spec(
        root.path(),
        "tiny-gpu",
        r#"id = "tiny-gpu"
title = "GPU smoke"
question = "Does a spec run on the GPU backend?"
claim = "Same counts as the CPU."
models = ["sphere:500", "layers:3"]
methods = ["input", "random"]
views = "axis6"
res = 64
[figure]
kind = "bar"
metric = "ovr_mean"
x = "method"
facet = "model"
"#,
    );
    let read = |backend: &str| {
        let options = triorder::experiment::RunOptions {
            out_dir: root.path().into(),
            backend: Some(backend.into()),
            ..Default::default()
        };
        let csv = triorder::experiment::run(&spec, &options).unwrap().csv;
        common::csv_rows(&csv)
            .into_iter()
            .map(|r| (r["backend"].clone(), r["metric"].clone(), r["value"].clone()))
            .collect::<Vec<_>>()
    };
    let (cpu, on_gpu) = (read("cpu"), read("gpu"));
    assert!(on_gpu.iter().all(|(b, _, _)| *b == format!("gpu: {}", gpu.device())));
    let ovr = |rows: &[(String, String, String)]| {
        rows.iter().filter(|(_, m, _)| m.starts_with("ovr")).map(|(_, m, v)| (m.clone(), v.clone())).collect::<Vec<_>>()
    };
    assert!(!ovr(&cpu).is_empty());
    assert_eq!(ovr(&cpu), ovr(&on_gpu));
}

/// The backend benchmark times only work that succeeds: a resolution both backends refuse is an
/// error, not a row of timed failures.
#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn the_backend_benchmark_refuses_what_it_cannot_count() {
    let gpu = common::gpu();
    let spot = load::load_file(std::path::Path::new("assets/spot.obj")).unwrap();
    let row = triorder::experiment::bench::compare_backends(&spot, gpu, ViewSet::Ico(12), 64, 1).unwrap();
    assert!(row.cpu_seconds > 0.0 && row.gpu_seconds > 0.0, "{row:?}");
    let refused = triorder::experiment::bench::compare_backends(&spot, gpu, ViewSet::Ico(12), 20_000, 1);
    assert!(refused.unwrap_err().to_string().contains("resolution"));
}
