//! The experiment pipeline: spec → results CSV → SVG, checked end to end on procedural meshes in
//! a temporary project root.

mod common;

use std::collections::HashMap;
use std::path::Path;

use triorder::experiment::{RunOptions, Spec, run};
use triorder::figure::PlotOptions;
use triorder::measure::{CacheModel, MeasureOptions, evaluate};
use triorder::mesh::Source;
use triorder::reproduce::{plot, reproduce};
use triorder::results::COLUMNS;
use triorder::{measure, order};

/// A spec small enough to run in milliseconds: two procedural models (the grid is flat, so some
/// of its views see nothing), three methods (a seed grid), three cache models and six views.
const TINY: &str = r#"
id = "tiny"
title = "Tiny experiment"
question = "Does the pipeline work?"
claim = "It does (this test)."
models = ["sphere:80", "grid:4x4"]
methods = ["input", "random:seed={1,2}"]
caches = ["fifo:4..8/4", "lru:16"]
views = "axis6"
res = 32
seed = 3

[figure]
kind = "line"
metric = "acmr"
x = "cache_size"
facet = "model"
filter = { cache_kind = "fifo" }

[quick]
models = ["sphere:80", "grid:4x4"]
"#;

fn quick(root: &Path) -> RunOptions {
    RunOptions { quick: true, out_dir: root.to_path_buf(), ..RunOptions::default() }
}

fn plot_quick(root: &Path) -> PlotOptions {
    PlotOptions { quick: true, out_dir: root.to_path_buf(), data: None }
}

/// The CSV as a list of column → value maps (and the header).
fn read_csv(path: &Path) -> (Vec<String>, Vec<HashMap<String, String>>) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let rows =
        reader.records().map(|r| header.iter().cloned().zip(r.unwrap().iter().map(String::from)).collect()).collect();
    (header, rows)
}

/// The error `Spec::load` gives for `text` saved as `experiments/ID.toml`.
fn spec_error(id: &str, text: &str) -> String {
    let root = tempfile::tempdir().unwrap();
    let path = common::write_spec(root.path(), id, text);
    let err = Spec::load(&path).unwrap_err().to_string();
    assert!(err.contains(&path.display().to_string()), "error does not name the file: {err}");
    err
}

#[test]
fn repository_specs_parse() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let spec = Spec::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(spec.quick.is_some(), "{} has no [quick] table", path.display());
    }
    let acmr = Spec::load(&dir.join("universal-acmr-vs-cache.toml")).unwrap();
    assert_eq!(acmr.methods.len(), order::METHODS.len());
    assert_eq!(acmr.full.caches.len(), 11);
    assert_eq!(acmr.full.caches[10], CacheModel::Fifo(64));
    assert_eq!(acmr.full.caches[0], CacheModel::Fifo(4));
    assert_eq!(acmr.quick.as_ref().unwrap().caches.len(), 16);
    let ovr = Spec::load(&dir.join("ovr-distribution-bunny.toml")).unwrap();
    assert_eq!(ovr.full.views, Some("ico:162".parse().unwrap()));
    assert_eq!((ovr.full.res, ovr.quick.as_ref().unwrap().res), (512, 128));
    assert_eq!(ovr.methods, ["input", "meshopt-overdraw:threshold=1.05"]);
}

#[test]
fn grids_expand_to_canonical_methods() {
    let root = tempfile::tempdir().unwrap();
    let spec = Spec::load(&common::write_spec(root.path(), "tiny", TINY)).unwrap();
    assert_eq!(spec.methods, ["input", "random:seed=1", "random:seed=2"]);
    let caches: Vec<String> = spec.full.caches.iter().map(ToString::to_string).collect();
    assert_eq!(caches, ["fifo:4", "fifo:8", "lru:16"]);
}

#[test]
fn bad_specs_name_the_key() {
    let cases: &[(&str, &str, &[&str])] = &[
        (
            r#"methods = ["input", "random:seed={1,2}"]"#,
            r#"methods = ["input", "tipsy:cache=16"]"#,
            &["methods[1]", "unknown method `tipsy`"],
        ),
        (
            r#"methods = ["input", "random:seed={1,2}"]"#,
            r#"methods = ["random:seed={1,2"]"#,
            &["methods[0]", "without `}`"],
        ),
        (r#"methods = ["input", "random:seed={1,2}"]"#, r#"methods = "most""#, &["methods", "\"all\""]),
        (
            r#"methods = ["input", "random:seed={1,2}"]"#,
            r#"methods = 3"#,
            &["methods = 3", "expected \"all\" or a list"],
        ),
        (r#"caches = ["fifo:4..8/4", "lru:16"]"#, r#"caches = ["fifo:64..4"]"#, &["caches[0]", "empty range"]),
        (r#"caches = ["fifo:4..8/4", "lru:16"]"#, r#"caches = ["fifo:4..8/0"]"#, &["caches[0]", "step"]),
        (r#"caches = ["fifo:4..8/4", "lru:16"]"#, r#"caches = ["mru:4"]"#, &["caches[0]", "mru:4"]),
        (r#"views = "axis6""#, r#"views = "ico:100""#, &["views", "ico:100"]),
        (
            r#"seed = 3"#,
            r#"seed = 3
modles = ["a"]"#,
            &["modles"],
        ),
        (r#"id = "tiny""#, "", &["missing field `id`"]),
        (r#"id = "tiny""#, r#"id = "other""#, &["id `other`", "file name"]),
        (r#"x = "cache_size""#, r#"x = "cache_sise""#, &["figure.x", "cache_sise"]),
        (r#"kind = "line""#, r#"kind = "pie""#, &["pie"]),
        (
            r#"kind = "line""#,
            "kind = \"line\"\nhighlight = [\"tipsify\"]",
            &["figure.highlight", "`tipsify`", "not a method of this spec"],
        ),
        (r#"kind = "line""#, "kind = \"bar\"\nhighlight = [\"input\"]", &["figure.highlight", "line and scatter"]),
        (r#"kind = "line""#, "kind = \"line\"\naxes = \"each\"", &["figure.axes = \"each\"", "\"own\""]),
        (r#"kind = "line""#, "kind = \"bar\"\naxes = \"own\"", &["figure.axes", "line and scatter"]),
        (r#"facet = "model""#, "facet = \"model\"\naxes = \"own\"", &[]),
        (r#"facet = "model""#, "series = \"model+method\"\naxes = \"own\"", &["figure.axes", "needs figure.facet"]),
        (r#"metric = "acmr""#, r#"metric = "acmrr""#, &["figure.metric", "acmrr"]),
        (r#"metric = "acmr""#, r#"metric = ["acmr", "atvr"]"#, &["several metrics", "\"metric\""]),
        (r#"x = "cache_size""#, r#"x = "param:nope""#, &["figure.x", "no method of this spec has a parameter `nope`"]),
        (r#"x = "cache_size""#, r#"x = "metric:atvr""#, &["figure.x", "metric:atvr"]),
        (
            "kind = \"line\"\nmetric = \"acmr\"\nx = \"cache_size\"",
            "kind = \"scatter\"\nmetric = \"acmr\"\nx = \"metric:acmr@cahce=lru:16\"",
            &["figure.x", "`cahce` is not a CSV column"],
        ),
        (r#"kind = "line""#, "kind = \"bar\"\nx_log = true", &["figure.x_log", "bar"]),
        (r#"kind = "line""#, "kind = \"ratio\"", &["figure.ratio = [A, B]"]),
        (r#"kind = "line""#, "kind = \"ratio\"\nratio = [\"input\", \"nope\"]", &["figure.ratio names `nope`"]),
        (r#"kind = "line""#, "kind = \"ratio\"\nratio = [\"input\", \"random\"]", &["x = \"metric:NAME\""]),
        (
            r#"kind = "line""#,
            "kind = \"bar\"\nratio = [\"input\", \"random\"]",
            &["figure.ratio is for kind = \"ratio\""],
        ),
        (
            r#"models = ["sphere:80", "grid:4x4"]
"#,
            r#"models = ["models/bunny_2k.ply"]
"#,
            &["quick.models[0]", "models/bunny_2k.ply"],
        ),
        // Rows that would collide are found before the run, not by `plot` after it.
        (r#"facet = "model""#, "", &["measures 2 models", "do not tell them apart", "model_triangles"]),
        (r#"facet = "model""#, r#"facet = "model_triangles""#, &[]),
        (
            "facet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
            r#"filter = { cache_kind = "fifo", model = "grid:4x4" }"#,
            &[],
        ),
        (
            "x = \"cache_size\"\nfacet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
            "x = \"model_triangles\"\nfacet = \"model\"",
            &["measures 3 cache models", "cache_size"],
        ),
        (r#"filter = { cache_kind = "fifo" }"#, r#"series = "cache""#, &["measures 3 methods", "method_name"]),
    ];
    for (from, to, expected) in cases {
        assert!(TINY.contains(from), "{from}");
        let text = TINY.replacen(from, to, if from.starts_with("models") { 2 } else { 1 });
        if expected.is_empty() {
            Spec::load(&common::write_spec(tempfile::tempdir().unwrap().path(), "tiny", &text)).unwrap();
            continue;
        }
        let err = spec_error("tiny", &text);
        for want in *expected {
            assert!(err.contains(want), "`{to}`: error lacks `{want}`:\n{err}");
        }
    }
    // `res` without `views`, and overdraw metrics without views.
    let no_views = TINY.replace("views = \"axis6\"\n", "");
    assert!(spec_error("tiny", &no_views).contains("res is set but views is not"));
    let err =
        spec_error("tiny", &no_views.replace("res = 32\n", "").replace("metric = \"acmr\"", "metric = \"ovr_mean\""));
    assert!(err.contains("figure.metric = \"ovr_mean\" needs `views`"), "{err}");
    // The hardware fit needs counted and simulated caches, reads ACMR, and takes no x.
    let fit = TINY.replace("kind = \"line\"", "kind = \"hardware-fit\"").replace("x = \"cache_size\"\n", "");
    assert!(spec_error("tiny", &fit).contains("caches must list simulated models and `gpu`"));
    let counted = fit.replace(r#"caches = ["fifo:4..8/4", "lru:16"]"#, r#"caches = ["gpu", "fifo:4..8/4"]"#);
    let spec = Spec::load(&common::write_spec(tempfile::tempdir().unwrap().path(), "tiny", &counted)).unwrap();
    assert!(spec.full.gpu_vertices && spec.full.caches.len() == 2);
    let with_x = counted.replace("metric = \"acmr\"", "metric = \"acmr\"\nx = \"cache_size\"");
    assert!(spec_error("tiny", &with_x).contains("figure.x is not used by kind = \"hardware-fit\""));
    let ovr = counted.replace("metric = \"acmr\"", "metric = \"ovr_mean\"");
    assert!(spec_error("tiny", &ovr).contains("metric must be \"acmr\""));
}

#[test]
fn quick_run_writes_one_row_per_measurement_matching_evaluate() {
    let root = tempfile::tempdir().unwrap();
    let spec_path = common::write_spec(root.path(), "tiny", TINY);
    let csv = run(&spec_path, &quick(root.path())).unwrap().csv;
    assert_eq!(csv, root.path().join("results/quick/tiny.csv"));
    let (header, rows) = read_csv(&csv);
    assert_eq!(header, COLUMNS);

    let spec = Spec::load(&spec_path).unwrap();
    let work = spec.workload(true).unwrap();
    let options = MeasureOptions {
        caches: work.caches.clone(),
        views: work.views,
        res: work.res,
        seed: spec.seed,
        ..Default::default()
    };
    let cpu = measure::backend("cpu").unwrap();
    let mut expected_rows = 0;
    for model in &work.models {
        let (name, scene) = (&model.name, model.source.open(None, spec.seed).unwrap());
        for method in &spec.methods {
            let direct = evaluate(&scene, &order::resolve(method, spec.seed).unwrap(), &options, cpu.as_ref()).unwrap();
            let mine: Vec<_> = rows.iter().filter(|r| r["model"] == *name && r["method"] == *method).collect();
            let value = |metric: &str, cache: &str, view: &str| -> f64 {
                let hits: Vec<_> =
                    mine.iter().filter(|r| r["metric"] == metric && r["cache"] == cache && r["view"] == view).collect();
                assert_eq!(hits.len(), 1, "{name} {method} {metric} {cache} {view}");
                hits[0]["value"].parse().unwrap()
            };
            for cache in &work.caches {
                let stats = triorder::measure::cache::simulate(
                    *cache,
                    &scene.mesh.triangles_in_order(&direct.orders.buffers[0].order),
                    scene.mesh.vertex_count(),
                );
                assert_eq!(value("acmr", &cache.to_string(), ""), stats.acmr());
                assert_eq!(value("atvr", &cache.to_string(), ""), stats.atvr());
            }
            let visible = direct.values().filter(|v| v.metric == "ovr").count();
            assert!(visible > 0);
            // The figure draws ACMR, so the per-view ratios are summarised, not written.
            assert!(mine.iter().all(|r| r["metric"] != "ovr"));
            assert_eq!(value("ovr_empty", "", "") as usize, 6 - visible);
            for metric in ["ovr_mean", "ovr_max", "ovr_var"] {
                assert_eq!(value(metric, "", ""), direct.summary(metric).unwrap());
            }
            let r = mine[0];
            assert_eq!(r["model_triangles"], scene.mesh.triangle_count().to_string());
            assert_eq!((r["method_name"].as_str(), r["seed"].as_str()), (method.split(':').next().unwrap(), "3"));
            assert_eq!((r["backend"].as_str(), r["triorder"].as_str()), ("cpu", env!("CARGO_PKG_VERSION")));
            assert!(!r["machine"].is_empty() && !r["commit"].is_empty());
            // 3 caches × (acmr, atvr) + seconds + ovr_empty + 5 summaries.
            assert_eq!(mine.len(), 3 * 2 + 1 + 1 + 5);
            expected_rows += mine.len();
        }
    }
    assert_eq!(rows.len(), expected_rows);
    let grid_empty: f64 =
        rows.iter().find(|r| r["model"] == "grid:4x4" && r["metric"] == "ovr_empty").unwrap()["value"].parse().unwrap();
    assert!(grid_empty > 0.0, "a flat grid is invisible from behind and edge-on");

    // Plotting reads the CSV and names the title, the claim and every series.
    let svg = plot(&spec_path, &plot_quick(root.path())).unwrap();
    assert_eq!(svg, root.path().join("paper-figures/quick/tiny.svg"));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    for want in [
        "Tiny experiment",
        "It does (this test).",
        "input",
        // Method specs are shown by what tells them apart.
        "random seed=1",
        "random seed=2",
        "sphere:80 (80 triangles)",
    ] {
        assert!(text.contains(want), "SVG lacks `{want}`");
    }
}

/// A figure that draws the per-view ratios gets one `ovr` row per visible view, equal to what
/// `evaluate` measures.
#[test]
fn per_view_rows_are_written_when_the_figure_draws_them() {
    let root = tempfile::tempdir().unwrap();
    let text = TINY.replace("id = \"tiny\"", "id = \"spread\"").replace(
        "kind = \"line\"\nmetric = \"acmr\"\nx = \"cache_size\"\nfacet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
        "kind = \"distribution\"\nmetric = \"ovr\"\nfacet = \"model\"",
    );
    let path = common::write_spec(root.path(), "spread", &text);
    let (_, rows) = read_csv(&run(&path, &quick(root.path())).unwrap().csv);
    let spec = Spec::load(&path).unwrap();
    let work = spec.workload(true).unwrap();
    let options =
        MeasureOptions { caches: vec![], views: work.views, res: work.res, seed: spec.seed, ..Default::default() };
    for model in &work.models {
        let (name, scene) = (&model.name, model.source.open(None, spec.seed).unwrap());
        for method in &spec.methods {
            let resolved = order::resolve(method, spec.seed).unwrap();
            let direct = evaluate(&scene, &resolved, &options, measure::backend("cpu").unwrap().as_ref()).unwrap();
            let expected: Vec<(String, f64)> =
                direct.values().filter(|v| v.metric == "ovr").map(|v| (v.view.unwrap().to_string(), v.value)).collect();
            let written: Vec<(String, f64)> = rows
                .iter()
                .filter(|r| r["model"] == *name && r["method"] == *method && r["metric"] == "ovr")
                .map(|r| (r["view"].clone(), r["value"].parse().unwrap()))
                .collect();
            assert!(!written.is_empty());
            assert_eq!(written, expected, "{name} {method}");
        }
    }
}

#[test]
fn every_figure_kind_draws_from_one_csv() {
    let root = tempfile::tempdir().unwrap();
    let kinds = [
        ("bars", "kind = \"bar\"\nmetric = \"acmr\"\nx = \"model\"\nfilter = { cache = \"fifo:8\" }", "grid:4x4"),
        (
            "points",
            "kind = \"scatter\"\nmetric = \"acmr\"\nx = \"seconds\"\nseries = \"model\"\nx_log = true",
            "sphere:80",
        ),
        ("views", "kind = \"distribution\"\nmetric = \"ovr\"\nfacet = \"model\"\ny_log = true", "mean "),
        ("numbers", "kind = \"table\"\nmetric = \"acmr\"\nx = \"model\"\nfilter = { cache = \"fifo:8\" }", "grid:4x4"),
        ("paths", "kind = \"sequence\"\nmetric = \"acmr\"", "<polygon"),
        ("pictures", "kind = \"corners\"\nmetric = \"acmr\"\nview = [1, 1, 1]", "data:image/png;base64,"),
        ("patches", "kind = \"clusters\"\nmetric = \"acmr\"", "colour: cluster"),
        ("ranks", "kind = \"cluster-order\"\nmetric = \"acmr\"", "last cluster drawn"),
        ("heat", "kind = \"overdraw\"\nmetric = \"acmr\"\nview = [0, 1, 0]", "5 or more"),
        (
            "metrics",
            "kind = \"line\"\nmetric = [\"acmr\", \"atvr\"]\nx = \"param:seed\"\nseries = \"metric\"\nfacet = \"model\"\nfilter = { cache = \"fifo:8\" }",
            "ATVR (misses per referenced vertex)",
        ),
        ("versus", "kind = \"scatter\"\nmetric = \"ovr_mean\"\nx = \"metric:ovr_max\"", "random seed=2"),
        // One metric under two cache models, against each other.
        (
            "caches",
            "kind = \"scatter\"\nmetric = \"acmr\"\nx = \"metric:acmr@cache=lru:16\"\nfacet = \"model\"\nfilter = { cache = \"fifo:8\" }",
            "random seed=2",
        ),
    ];
    for (id, figure, want) in kinds {
        let text = TINY.replace("id = \"tiny\"", &format!("id = \"{id}\"")).replace(
            "kind = \"line\"\nmetric = \"acmr\"\nx = \"cache_size\"\nfacet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
            figure,
        );
        let path = common::write_spec(root.path(), id, &text);
        run(&path, &quick(root.path())).unwrap();
        let svg = std::fs::read_to_string(plot(&path, &plot_quick(root.path())).unwrap()).unwrap();
        assert!(svg.contains(want), "{id}: SVG lacks `{want}`");
    }
}

#[test]
fn plotting_without_results_or_with_unusable_results_says_why() {
    let root = tempfile::tempdir().unwrap();
    let path = common::write_spec(root.path(), "tiny", TINY);
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("results/quick/tiny.csv") && err.contains("run the experiment first"), "{err}");
    assert!(!root.path().join("paper-figures").exists());

    // A line chart needs a numeric x.
    run(&path, &quick(root.path())).unwrap();
    let by_model =
        TINY.replace("x = \"cache_size\"", "x = \"model\"").replace("cache_kind = \"fifo\"", "cache = \"fifo:8\"");
    std::fs::write(&path, by_model).unwrap();
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("column `model`") && err.contains("not a number"), "{err}");
    // Two rows at one point of a line (fifo and lru both at size 16) are ambiguous.
    let mixed = TINY
        .replace("caches = [\"fifo:4..8/4\", \"lru:16\"]", "caches = [\"fifo:16\", \"lru:16\"]")
        .replace("filter = { cache_kind = \"fifo\" }", "");
    std::fs::write(&path, mixed).unwrap();
    run(&path, &quick(root.path())).unwrap();
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("a second `acmr` row") && err.contains("figure.filter"), "{err}");
    // A metric on x that has a row per cache model must name the one it means.
    let versus = TINY.replace(
        "kind = \"line\"\nmetric = \"acmr\"\nx = \"cache_size\"\nfacet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
        "kind = \"scatter\"\nmetric = \"acmr\"\nx = \"metric:acmr\"\nfacet = \"model\"\nfilter = { cache = \"fifo:8\" }",
    );
    std::fs::write(&path, versus).unwrap();
    run(&path, &quick(root.path())).unwrap();
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("several `acmr` values") && err.contains("metric:acmr@COLUMN=VALUE"), "{err}");
    // Rows named that are not there are said to be missing, not drawn as an empty chart.
    let absent =
        std::fs::read_to_string(&path).unwrap().replace("x = \"metric:acmr\"", "x = \"metric:acmr@cache=lru:99\"");
    std::fs::write(&path, absent).unwrap();
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("has no `acmr` rows at cache = lru:99"), "{err}");
}

#[test]
fn missing_models_are_refused_before_any_work() {
    let root = tempfile::tempdir().unwrap();
    let text =
        TINY.replacen("models = [\"sphere:80\", \"grid:4x4\"]", "models = [\"sphere:80\", \"models/nowhere.ply\"]", 1);
    let path = common::write_spec(root.path(), "tiny", &text);
    let opts = RunOptions {
        data: Some(root.path().join("data")),
        ..RunOptions { out_dir: root.path().into(), ..RunOptions::default() }
    };
    let err = run(&path, &opts).unwrap_err().to_string();
    for want in ["models[1]", "models/nowhere.ply", "--data", "TRIORDER_DATA", "scripts/fetch-data.sh"] {
        assert!(err.contains(want), "error lacks `{want}`: {err}");
    }
    assert!(!root.path().join("results").exists());
    // --quick on a spec without a [quick] table.
    let no_quick = TINY[..TINY.find("[quick]").unwrap()].to_string();
    std::fs::write(&path, no_quick).unwrap();
    assert!(run(&path, &quick(root.path())).unwrap_err().to_string().contains("[quick]"));
}

#[test]
fn a_broken_model_is_recorded_and_the_run_goes_on() {
    let root = tempfile::tempdir().unwrap();
    // The first model exists but is not a valid mesh: it becomes an error row, and the second
    // model is measured as in a run without it.
    let broken = root.path().join("broken.obj");
    std::fs::write(&broken, "v 0 0 0\nf 1 2 3\n").unwrap();
    let models = format!("models = [\"{}\", \"sphere:80\"]", broken.display());
    let path =
        common::write_spec(root.path(), "tiny", &TINY.replacen("models = [\"sphere:80\", \"grid:4x4\"]", &models, 1));
    let opts = RunOptions { out_dir: root.path().into(), ..RunOptions::default() };
    let outcome = run(&path, &opts).unwrap();
    assert_eq!(outcome.failures.len(), 1, "{:?}", outcome.failures);
    let failure = &outcome.failures[0];
    assert!(failure.model.ends_with("broken.obj") && failure.method.is_none());
    assert!(failure.reason.contains("broken.obj") && failure.reason.contains("out of range"), "{}", failure.reason);
    let (_, rows) = read_csv(&outcome.csv);
    let errors: Vec<_> = rows.iter().filter(|r| r["metric"] == "error").collect();
    assert_eq!(errors.len(), 1, "one row for the model, not one per method");
    assert_eq!(errors[0]["error"], failure.reason);
    assert!(errors[0]["method"].is_empty());
    // The sphere's rows are those of a run that never named the broken model.
    let alone = common::write_spec(
        root.path(),
        "tiny",
        TINY.replacen("models = [\"sphere:80\", \"grid:4x4\"]", "models = [\"sphere:80\"]", 1).as_str(),
    );
    let measured = |rows: &[HashMap<String, String>]| -> Vec<(String, String, String, String)> {
        rows.iter()
            .filter(|r| r["metric"] != "error" && r["metric"] != "seconds")
            .map(|r| (r["method"].clone(), r["metric"].clone(), r["cache"].clone(), r["value"].clone()))
            .collect()
    };
    let (_, sphere_rows) = read_csv(&run(&alone, &opts).unwrap().csv);
    assert_eq!(measured(&rows), measured(&sphere_rows));
    let files: Vec<_> =
        std::fs::read_dir(outcome.csv.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(files, ["tiny.csv"], "no temporary file is left behind");
}

#[test]
fn reproduce_runs_and_plots_every_matching_spec_in_order() {
    let root = tempfile::tempdir().unwrap();
    common::write_spec(root.path(), "tiny", TINY);
    common::write_spec(root.path(), "another", &TINY.replace("id = \"tiny\"", "id = \"another\""));
    let outputs = reproduce(&quick(root.path()), None, false).unwrap().ran;
    let ids: Vec<_> = outputs.iter().map(|ran| ran.csv.file_stem().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(ids, ["another", "tiny"]);
    assert!(outputs.iter().all(|ran| ran.csv.is_file() && ran.svg.is_file() && ran.seconds > 0.0));
    assert_eq!(reproduce(&quick(root.path()), Some("tin"), false).unwrap().ran.len(), 1);
    let err = reproduce(&quick(root.path()), Some("nothing"), false).unwrap_err().to_string();
    assert!(err.contains("matching `nothing`"), "{err}");
    // A broken spec stops everything before any run.
    common::write_spec(
        root.path(),
        "broken",
        &TINY.replace("id = \"tiny\"", "id = \"broken\"").replace("\"input\"", "\"nope\""),
    );
    std::fs::remove_dir_all(root.path().join("results")).unwrap();
    assert!(reproduce(&quick(root.path()), None, false).unwrap_err().to_string().contains("broken.toml"));
    assert!(!root.path().join("results").exists());
}

#[test]
fn drawings_show_the_saved_orders_and_refuse_stale_ones() {
    let root = tempfile::tempdir().unwrap();
    let text = TINY.replace("id = \"tiny\"", "id = \"corners\"").replace(
        "kind = \"line\"\nmetric = \"acmr\"\nx = \"cache_size\"\nfacet = \"model\"\nfilter = { cache_kind = \"fifo\" }",
        "kind = \"corners\"\nmetric = \"acmr\"",
    );
    let path = common::write_spec(root.path(), "corners", &text);
    run(&path, &quick(root.path())).unwrap();
    let orders = root.path().join("results/quick/corners.orders.csv");
    let (header, rows) = read_csv(&orders);
    assert_eq!(header, triorder::results::ORDER_COLUMNS);
    assert!(rows.iter().all(|r| r["level"].is_empty() && r["update"].is_empty()), "a still has no levels");
    // One whole order per (model, method): 80 and 32 triangles, three methods, none clustered.
    assert_eq!(rows.len(), 2 * 3);
    let lengths: Vec<usize> = rows.iter().map(|r| r["order"].split(' ').count()).collect();
    assert_eq!(lengths, [80, 80, 80, 32, 32, 32]);
    let clusters: Vec<&str> = rows.iter().map(|r| r["clusters"].as_str()).collect();
    assert_eq!(clusters, ["0 80", "0 80", "0 80", "0 32", "0 32", "0 32"]);
    let svg = std::fs::read_to_string(plot(&path, &plot_quick(root.path())).unwrap()).unwrap();
    // Two models × three methods × three caches, one picture each.
    assert_eq!(svg.matches("<image").count(), 18);

    // Swap two triangles of one saved order: the saved corners no longer fit it.
    let text = std::fs::read_to_string(&orders).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let input = lines.iter().position(|l| l.starts_with("sphere:80,input,")).unwrap();
    let mut fields: Vec<String> = lines[input].split(',').map(String::from).collect();
    let mut ids: Vec<&str> = fields[2].split(' ').collect();
    ids.swap(0, 40);
    fields[2] = ids.join(" ");
    lines[input] = fields.join(",");
    std::fs::write(&orders, lines.join("\n") + "\n").unwrap();
    let err = plot(&path, &plot_quick(root.path())).unwrap_err().to_string();
    assert!(err.contains("corners.orders.csv") && err.contains("rerun the experiment"), "{err}");
}

#[test]
fn simplified_models_are_named_with_their_triangle_count() {
    let open = |source: &str| Source::parse(source)?.mesh(None, 0);
    let mesh = open("assets/spot.obj@1000").unwrap();
    assert!((980..=1020).contains(&mesh.triangle_count()), "{}", mesh.triangle_count());
    assert!(mesh.triangles.iter().flatten().all(|&v| (v as usize) < mesh.vertex_count()));
    // No unused vertices are kept.
    let mut used = vec![false; mesh.vertex_count()];
    mesh.triangles.iter().flatten().for_each(|&v| used[v as usize] = true);
    assert!(used.iter().all(|&u| u));
    let simplified_grid = open("grid:20x20@200").unwrap();
    assert!((196..=204).contains(&simplified_grid.triangle_count()), "{}", simplified_grid.triangle_count());
    for (bad, want) in [("assets/spot.obj@0", "positive"), ("assets/spot.obj@9999999", "only 5856")] {
        let err = open(bad).unwrap_err().to_string();
        assert!(err.contains(bad) && err.contains(want), "{err}");
        assert!(Source::parse(bad).and_then(|s| s.check(None)).is_err() || want == "only 5856");
    }
}

/// An animated spec small enough for a debug build: the bundled Fox (three clips) resampled to two
/// frames per clip, and a static sphere, which a per-node method in the spec measures as one frame.
const ANIMATED: &str = r#"
id = "animated"
title = "Animated experiment"
question = "Does the pipeline measure index buffers per clip?"
models = ["assets/Fox.glb#frames=2"]
methods = ["tipsify", "hs17:clusters=2,views=12,res=32,iterations=3"]
caches = ["fifo:16"]
views = "axis6"
res = 32

[figure]
kind = "bar"
metric = "seconds"
x = "method_name"
facet = "model"
label = "metric:buffers"

[quick]
models = ["assets/Fox.glb#frames=2", "sphere:80"]
"#;

#[test]
fn animated_runs_write_buffers_and_a_row_per_clip() {
    let root = tempfile::tempdir().unwrap();
    let path = common::write_spec(root.path(), "animated", ANIMATED);
    let (header, rows) = read_csv(&run(&path, &quick(root.path())).unwrap().csv);
    assert_eq!(header, COLUMNS);
    let find = |model: &str, method: &str, metric: &str, clip: &str| {
        let found: Vec<f64> = rows
            .iter()
            .filter(|r| r["model"] == model && r["method_name"] == method && r["metric"] == metric && r["clip"] == clip)
            .map(|r| r["value"].parse().unwrap())
            .collect();
        assert!(found.len() <= 1, "several {metric} rows for {model} {method} {clip}");
        found.first().copied()
    };
    let fox = "assets/Fox.glb#frames=2";
    // Static methods need one buffer; hs17 at most two per clip, and says how it iterated.
    assert_eq!(find(fox, "tipsify", "buffers", "all"), Some(1.0));
    let buffers = find(fox, "hs17", "buffers", "all").unwrap();
    assert!((2.0..=6.0).contains(&buffers), "{buffers}");
    assert!(find(fox, "hs17", "iterations", "all").is_some_and(|i| (1.0..=3.0).contains(&i)));
    assert!(find(fox, "hs17", "converged", "all").is_some_and(|c| c == 0.0 || c == 1.0));
    assert_eq!(find(fox, "tipsify", "iterations", "all"), None);
    // Overdraw over all frames and per clip; caches and times once, under `all`.
    for method in ["tipsify", "hs17"] {
        for clip in ["all", "Survey", "Walk", "Run"] {
            let ovr = find(fox, method, "ovr_mean", clip).unwrap_or_else(|| panic!("{method} {clip}"));
            assert!(ovr >= 1.0, "{ovr}");
        }
        // Fox is not indexed: every triangle misses three times, whatever the order.
        assert_eq!(find(fox, method, "acmr", "all"), Some(3.0));
        assert_eq!(find(fox, method, "acmr", "Walk"), None);
    }
    // A static model in a spec with a per-node method: one frame, no clip.
    assert!(rows.iter().filter(|r| r["model"] == "sphere:80").all(|r| r["clip"].is_empty()));
    assert_eq!(find("sphere:80", "tipsify", "buffers", ""), Some(1.0));
    assert!(find("sphere:80", "hs17", "ovr_mean", "").is_some());
    // The bars carry the buffer counts above them.
    let svg = std::fs::read_to_string(plot(&path, &plot_quick(root.path())).unwrap()).unwrap();
    let texts: Vec<&str> = svg.split("</text>").filter_map(|t| Some(t.rsplit_once('>')?.1.trim())).collect();
    assert!(texts.contains(&buffers.to_string().as_str()), "no buffer count label in the SVG: {texts:?}");
}

#[test]
fn animated_specs_are_checked_before_any_work() {
    let cases: &[(&str, &str, &[&str])] = &[
        ("#frames=2\", \"sphere", "#frames=x\", \"sphere", &["quick.models[0]", "frames `x`"]),
        ("kind = \"bar\"", "kind = \"line\"", &["figure.label", "bar"]),
        ("label = \"metric:buffers\"", "label = \"metric:nope\"", &["figure.label", "nope"]),
        ("x = \"method_name\"", "x = \"source:speed\"", &["figure.x", "source:speed", "clip, frames, subdiv"]),
        (
            "kind = \"bar\"\nmetric = \"seconds\"\nx = \"method_name\"\nfacet = \"model\"\nlabel = \"metric:buffers\"",
            "kind = \"clusters\"\nmetric = \"acmr\"",
            &["kind = \"clusters\"", "hs17", "index buffer per (keyframe, view)"],
        ),
    ];
    for (from, to, expected) in cases {
        assert!(ANIMATED.contains(from), "{from}");
        let err = spec_error("animated", &ANIMATED.replacen(from, to, 1));
        for want in *expected {
            assert!(err.contains(want), "`{to}`: error lacks `{want}`:\n{err}");
        }
    }
    // A clip the file does not have fails the run before anything is ordered or written.
    let root = tempfile::tempdir().unwrap();
    let path = common::write_spec(
        root.path(),
        "animated",
        &ANIMATED.replace("#frames=2\", \"sphere", "#clip=Fly\", \"sphere"),
    );
    let err = run(&path, &quick(root.path())).unwrap_err().to_string();
    for want in [path.display().to_string().as_str(), "quick.models[0]", "Fly", "Survey"] {
        assert!(err.contains(want), "error lacks `{want}`: {err}");
    }
    assert!(!root.path().join("results").exists());
}
