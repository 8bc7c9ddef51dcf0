//! Render timing on the GPU (`--render pixel|vertex`): the plumbing and its failures. Times are
//! measured here, never asserted against each other (speed belongs in benchmarks); what must
//! hold is that every view is timed, percentiles are ordered, and rows name the device.
//!
//! Skipped without a Vulkan adapter, unless TRIORDER_REQUIRE_GPU is set (as in CI).

mod common;

use triorder::gpu::render_time::{self, RenderTimer, Shading};
use triorder::mesh::Framing;
use triorder::raster::ViewSet;

fn timer() -> &'static RenderTimer {
    common::available(render_time::shared())
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn every_shader_times_every_view_with_ordered_percentiles() {
    let timer = timer();
    let mesh = triorder::mesh::procedural::generate("layers:8", 0).unwrap().unwrap();
    let cameras = ViewSet::Axis6.cameras(Framing::of(&mesh.positions), 0);
    for shading in [Shading::Pixel, Shading::Vertex] {
        for camera in &cameras {
            let t = timer.time(&mesh.positions, &mesh.triangles, camera, 64, shading, 5).unwrap();
            assert!(t.median_ms.is_finite() && t.median_ms > 0.0, "{shading:?}: {t:?}");
            assert!(t.p10_ms <= t.median_ms && t.median_ms <= t.p90_ms, "{shading:?}: {t:?}");
        }
    }
    let err = timer.time(&mesh.positions, &mesh.triangles, &cameras[0], 64, Shading::Pixel, 0).unwrap_err();
    assert!(err.to_string().contains("frames = 0"), "{err}");
    let err = timer.time(&mesh.positions, &[[0, 1, 99_999]], &cameras[0], 64, Shading::Pixel, 5).unwrap_err();
    assert!(err.to_string().contains("99999"), "{err}");
}

#[test]
#[cfg_attr(not(triorder_gpu), ignore = "needs a Vulkan driver (sudo apt-get install mesa-vulkan-drivers libvulkan1)")]
fn eval_and_specs_write_render_rows() {
    let timer = timer();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", "assets/spot.obj", "-m", "tipsify", "--views", "axis6", "--res", "64", "--json"])
        .args(["--render", "pixel", "--render", "vertex", "--render-frames", "3"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for shading in ["pixel", "vertex"] {
        assert!(json[format!("render_ms_{shading}")].as_f64().unwrap() > 0.0, "{json}");
        assert!(json[format!("render_spread_{shading}")].as_f64().unwrap() >= 0.0, "{json}");
        assert_eq!(json["per_view"][format!("render_ms_{shading}_view")].as_array().unwrap().len(), 6, "{json}");
    }
    assert_eq!(json["device"], timer.device());

    let root = tempfile::tempdir().unwrap();
    let text = r#"id = "tiny-time"
title = "Render time smoke"
question = "Do render times land in the CSV?"
models = ["sphere:500", "layers:4"]
methods = ["input", "front-to-back"]
caches = ["fifo:16"]
views = "axis6"
res = 64
render = ["pixel"]
render_frames = 3
[figure]
kind = "bar"
metric = "render_ms_pixel_view"
x = "view"
series = "method_name"
facet = "model"
"#;
    let spec = common::write_spec(root.path(), "tiny-time", text);
    let options = triorder::experiment::RunOptions { out_dir: root.path().into(), ..Default::default() };
    let csv = triorder::experiment::run(&spec, &options).unwrap().csv;
    let rows = common::csv_rows(&csv);
    let timed: Vec<_> = rows.iter().filter(|r| r["metric"].starts_with("render_")).collect();
    // 2 models × 2 methods × (mean + spread + 6 views).
    assert_eq!(timed.len(), 32);
    assert!(timed.iter().all(|r| r["value"].parse::<f64>().unwrap() >= 0.0));
    assert!(timed.iter().all(|r| r["backend"] == format!("gpu: {}", timer.device())));
    assert_eq!(timed.iter().filter(|r| !r["view"].is_empty()).count(), 24);
    // A figure of vertex-bound times needs render = ["vertex"]; rendering needs views.
    let vertex = text.replace("render_ms_pixel_view", "render_ms_vertex");
    std::fs::write(&spec, &vertex).unwrap();
    let err = triorder::experiment::run(&spec, &options).unwrap_err().to_string();
    assert!(err.contains("needs render = [\"vertex\"]"), "{err}");
    std::fs::write(&spec, text.replace("render_ms_pixel_view", "render_spread_vertex")).unwrap();
    let err = triorder::experiment::run(&spec, &options).unwrap_err().to_string();
    assert!(err.contains("needs render = [\"vertex\"]"), "{err}");
}
