//! The translucency metric (issue 18): blending in draw order against the exact depth-sorted
//! blend, on scenes whose answer is known.

mod common;

use triorder::measure::{self, MeasureOptions, Value};
use triorder::mesh::Source;
use triorder::order::{self, METHODS};
use triorder::raster::ViewSet;

fn options(views: &str, res: u32) -> MeasureOptions {
    MeasureOptions {
        views: Some(views.parse::<ViewSet>().unwrap()),
        res,
        translucency: true,
        ..MeasureOptions::default()
    }
}

/// The value of summary metric `name` of `method` on `mesh`.
fn summary(mesh: &str, method: &str, options: &MeasureOptions, name: &str) -> f64 {
    let scene = Source::parse(mesh).unwrap().open(None, 0).unwrap();
    let raster = measure::backend("cpu").unwrap();
    let evaluation = measure::evaluate(&scene, &order::resolve(method, 0).unwrap(), options, raster.as_ref()).unwrap();
    let values: Vec<&Value> = evaluation.values().collect();
    values.iter().find(|v| v.metric == name && v.is_summary()).unwrap_or_else(|| panic!("no {name}")).value
}

#[test]
fn stacked_layers_blend_right_only_back_to_front() {
    // Four unit squares stacked along z, facing +z: only the +z view of axis6 sees them, every
    // pixel covered by all four.
    let o = options("axis6", 64);
    let near_first = "front-to-back:x=0,y=0,z=1";
    let far_first = "front-to-back:x=0,y=0,z=-1";
    assert_eq!(summary("layers:4", near_first, &o, "translucency_wrong_pixels"), 1.0);
    assert_eq!(summary("layers:4", near_first, &o, "translucency_pairs"), 6.0, "all 4·3/2 pairs inverted");
    assert!(summary("layers:4", near_first, &o, "translucency_rmse") > 0.05);
    for metric in ["translucency_wrong_pixels", "translucency_pairs", "translucency_rmse"] {
        assert_eq!(summary("layers:4", far_first, &o, metric), 0.0, "{metric}");
    }
}

#[test]
fn on_a_closed_convex_mesh_every_order_is_exact() {
    // With back faces culled, no two front faces of a convex mesh overlap: nothing to blend
    // wrongly, whatever the order.
    let o = options("ico:12", 64);
    for method in METHODS {
        let wrong = summary("sphere:500", method.name, &o, "translucency_wrong_pixels");
        assert_eq!(wrong, 0.0, "{}", method.name);
    }
}

#[test]
fn a_run_writes_the_translucency_rows() {
    let root = tempfile::tempdir().unwrap();
    let text = r#"
id = "blend"
title = "Blending"
question = "Are the rows there?"
models = ["layers:3", "sphere:80"]
methods = ["input", "translucent-dist-angle"]
caches = ["fifo:8"]
views = "axis6"
res = 32
translucency = true

[figure]
kind = "bar"
metric = "translucency_wrong_pixels"
x = "model"
"#;
    let spec = common::write_spec(root.path(), "blend", text);
    let opts = triorder::experiment::RunOptions { out_dir: root.path().into(), ..Default::default() };
    let rows = common::csv_rows(&triorder::experiment::run(&spec, &opts).unwrap().csv);
    for metric in ["translucency_wrong_pixels", "translucency_rmse", "translucency_pairs"] {
        assert_eq!(rows.iter().filter(|r| r["metric"] == metric).count(), 4, "{metric}: 2 models × 2 methods");
    }
    // Without views there is nothing to blend: the spec is refused by its key.
    std::fs::write(&spec, text.replace("views = \"axis6\"\nres = 32\n", "")).unwrap();
    let err = triorder::experiment::run(&spec, &opts).unwrap_err().to_string();
    assert!(err.contains("translucency") && err.contains("views"), "{err}");
}

#[test]
fn every_static_sort_puts_a_reversed_stack_back_to_front() {
    // The layers of `layers:5` listed top first (nearest the +z view first): every translucent
    // sort must draw them bottom first, exactly.
    let layers = Source::parse("layers:5").unwrap().mesh(None, 0).unwrap();
    let mut triangles = layers.triangles.clone();
    triangles.reverse();
    let mesh = triorder::mesh::Mesh { triangles, ..layers };
    let scene = triorder::mesh::Scene::still(mesh);
    let raster = measure::backend("cpu").unwrap();
    let o = options("axis6", 64);
    let input = measure::evaluate(&scene, &order::resolve("input", 0).unwrap(), &o, raster.as_ref()).unwrap();
    let wrong = |e: &measure::Evaluation| {
        e.values().find(|v| v.metric == "translucency_pairs" && v.is_summary()).unwrap().value
    };
    assert_eq!(wrong(&input), 10.0, "all 5·4/2 pairs inverted as listed");
    for method in ["translucent-topo", "translucent-coverage", "translucent-dist-angle", "translucent-peeling"] {
        let e = measure::evaluate(&scene, &order::resolve(method, 0).unwrap(), &o, raster.as_ref()).unwrap();
        assert_eq!(wrong(&e), 0.0, "{method}");
    }
}
