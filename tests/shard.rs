//! Sharded runs and corpora (issue 24): the shards of a spec merge into exactly the CSV an
//! unsharded run writes, stale and missing shards are refused by name, and a corpus entry
//! (directory, glob, list file) expands to its meshes with broken files recorded, not fatal.

mod common;

use std::collections::HashMap;
use std::path::Path;

use triorder::experiment::shard::{self, Shard};
use triorder::experiment::{RunOptions, merge, run};

/// Procedural models of very different sizes and methods of different cost classes, so the
/// shards are cut by cost, with overdraw so every kind of row is there.
const SWEEP: &str = r#"
id = "sweep"
title = "Sharded sweep"
question = "Do shards merge into the unsharded CSV?"
models = ["sphere:80", "grid:16x16", "disk:300", "helix:2", "sphere:2000"]
methods = ["input", "random:seed={1,2}", "tipsify", "hoppe"]
caches = ["fifo:4..16/4", "lru:16"]
views = "axis6"
res = 32

[figure]
kind = "line"
metric = "acmr"
x = "cache_size"
facet = "model"
"#;

fn options(root: &Path, shard: Option<Shard>) -> RunOptions {
    RunOptions { out_dir: root.to_path_buf(), shard, ..RunOptions::default() }
}

/// The CSV's rows with the provenance that may differ between runs blanked: machine, commit,
/// the ordering's time, and the value of `seconds` rows.
fn comparable(path: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let blank = |column: &str| header.iter().position(|h| h == column).unwrap();
    let (machine, commit, seconds, metric, value) =
        (blank("machine"), blank("commit"), blank("seconds"), blank("metric"), blank("value"));
    reader
        .records()
        .map(|r| {
            let mut row: Vec<String> = r.unwrap().iter().map(String::from).collect();
            for c in [machine, commit, seconds] {
                row[c].clear();
            }
            if row[metric] == "seconds" {
                row[value].clear();
            }
            row
        })
        .collect()
}

#[test]
fn shards_merge_into_the_unsharded_csv() {
    let root = tempfile::tempdir().unwrap();
    let spec = common::write_spec(root.path(), "sweep", SWEEP);
    let whole = run(&spec, &options(root.path(), None)).unwrap();
    let expected = comparable(&whole.csv);
    std::fs::remove_file(&whole.csv).unwrap();
    for count in [1, 3, 7, 40] {
        let mut units = 0;
        for index in 1..=count {
            let outcome = run(&spec, &options(root.path(), Some(Shard { index, count }))).unwrap();
            assert_eq!(outcome.csv, root.path().join(format!("results/sweep.shard-{index}-of-{count}.csv")));
            assert!(!outcome.skipped && outcome.failures.is_empty());
            assert_eq!(outcome.total_units, whole.total_units);
            units += outcome.units;
        }
        assert_eq!(units, whole.total_units, "{count} shards do every unit once");
        let merged = merge(&spec, &options(root.path(), None), Some(count)).unwrap();
        assert_eq!(merged.csv, whole.csv);
        assert_eq!(comparable(&merged.csv), expected, "{count} shards");
    }
    // 40 shards of 20 units: 20 shards did nothing, and their files say so.
    let empty = shard::Header::read(&root.path().join("results/sweep.shard-40-of-40.csv")).unwrap().unwrap();
    assert!(empty.mine.is_empty());
    // Several cuts are present now: merge must be told which.
    let err = merge(&spec, &options(root.path(), None), None).unwrap_err().to_string();
    assert!(err.contains("--shards N") && err.contains("1, 3, 7, 40"), "{err}");
}

#[test]
fn shards_are_balanced_by_estimated_cost() {
    let root = tempfile::tempdir().unwrap();
    // One model a hundred times the others: its costly units each go to a shard of their own.
    let text = SWEEP.replace("\"sphere:2000\"", "\"sphere:20000\"");
    let spec = common::write_spec(root.path(), "sweep", &text);
    let mut loads = Vec::new();
    for index in 1..=4 {
        let outcome = run(&spec, &options(root.path(), Some(Shard { index, count: 4 }))).unwrap();
        let header = shard::Header::read(&outcome.csv).unwrap().unwrap();
        // Units are (model, method): the big sphere is the last model, units 16..20.
        let big = header.mine.iter().filter(|&&u| u >= 16).count();
        loads.push((header.mine.len(), big));
    }
    assert!(loads.iter().all(|&(_, big)| big >= 1), "the big model's units are spread: {loads:?}");
    // Not round robin: the shard with the two cheapest big units (input, random) takes more small ones.
    assert!(loads.iter().any(|&(n, _)| n > 5), "{loads:?}");
}

#[test]
fn complete_shards_are_skipped_and_stale_or_missing_ones_refused() {
    let root = tempfile::tempdir().unwrap();
    let spec = common::write_spec(root.path(), "sweep", SWEEP);
    let first = Shard { index: 1, count: 2 };
    let outcome = run(&spec, &options(root.path(), Some(first))).unwrap();
    let written = std::fs::read(&outcome.csv).unwrap();
    // The same shard again: nothing runs, the file is untouched.
    let again = run(&spec, &options(root.path(), Some(first))).unwrap();
    assert!(again.skipped);
    assert_eq!(std::fs::read(&again.csv).unwrap(), written);
    // Shard 2 was never run.
    let err = merge(&spec, &options(root.path(), None), None).unwrap_err().to_string();
    for want in ["missing shards", "sweep.shard-2-of-2.csv", "--shard 2/2"] {
        assert!(err.contains(want), "error lacks `{want}`: {err}");
    }
    assert!(!root.path().join("results/sweep.csv").exists(), "nothing merged");
    run(&spec, &options(root.path(), Some(Shard { index: 2, count: 2 }))).unwrap();
    merge(&spec, &options(root.path(), None), None).unwrap();
    // The spec changes: both shards are stale, the merge names the first, and a rerun is not
    // skipped.
    std::fs::write(&spec, SWEEP.replace("fifo:4..16/4", "fifo:4..20/4")).unwrap();
    let err = merge(&spec, &options(root.path(), None), None).unwrap_err().to_string();
    for want in ["sweep.shard-1-of-2.csv", "stale", "--shard 1/2"] {
        assert!(err.contains(want), "error lacks `{want}`: {err}");
    }
    assert!(!run(&spec, &options(root.path(), Some(first))).unwrap().skipped);
    // A file that is not a shard is refused by name.
    std::fs::write(root.path().join("results/sweep.shard-2-of-2.csv"), "model,value\n").unwrap();
    let err = merge(&spec, &options(root.path(), None), None).unwrap_err().to_string();
    assert!(err.contains("sweep.shard-2-of-2.csv") && err.contains("not a shard file"), "{err}");
}

#[test]
fn drawing_specs_merge_their_orders_too() {
    let root = tempfile::tempdir().unwrap();
    let text = r#"
id = "drawn"
title = "Sequences"
question = "Do drawings survive sharding?"
models = ["grid:8x8", "disk:200"]
methods = ["input", "hilbert", "tipsify"]
caches = ["fifo:8"]

[figure]
kind = "sequence"
metric = "acmr"
"#;
    let spec = common::write_spec(root.path(), "drawn", text);
    let whole = run(&spec, &options(root.path(), None)).unwrap();
    let orders = root.path().join("results/drawn.orders.csv");
    let expected = std::fs::read(&orders).unwrap();
    std::fs::remove_file(&orders).unwrap();
    for index in 1..=4 {
        run(&spec, &options(root.path(), Some(Shard { index, count: 4 }))).unwrap();
    }
    assert!(root.path().join("results/drawn.orders.shard-3-of-4.csv").exists());
    merge(&spec, &options(root.path(), None), None).unwrap();
    assert_eq!(std::fs::read(&orders).unwrap(), expected, "orders hold no provenance: byte-identical");
    assert_eq!(comparable(&whole.csv).len(), 6 * 2 + 6, "acmr and atvr per pair, and its time");
}

/// A small closed mesh (a tetrahedron) as OBJ text.
const TETRAHEDRON: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

#[test]
fn corpora_expand_and_broken_files_are_recorded() {
    let root = tempfile::tempdir().unwrap();
    let corpus = root.path().join("corpus");
    std::fs::create_dir_all(corpus.join("sub")).unwrap();
    std::fs::create_dir_all(root.path().join("extra")).unwrap();
    std::fs::write(corpus.join("a.obj"), TETRAHEDRON).unwrap();
    std::fs::write(corpus.join("sub/b.OBJ"), TETRAHEDRON).unwrap();
    std::fs::write(corpus.join("sub/broken.obj"), "v 0 0 0\nf 1 2 9\n").unwrap();
    std::fs::write(corpus.join("notes.md"), "not a mesh").unwrap();
    std::fs::write(root.path().join("extra/c.obj"), TETRAHEDRON).unwrap();
    std::fs::write(root.path().join("list.txt"), "# a list\nextra/c.obj\n\nsphere:80\nmissing.ply\n").unwrap();
    let dir = corpus.display().to_string();
    let folder = root.path().display().to_string();
    let text = format!(
        r#"
id = "corpus"
title = "A corpus"
question = "Do corpora expand?"
models = ["{dir}/*.obj", "{dir}/", "{folder}/list.txt"]
methods = ["input", "tipsify"]
caches = ["fifo:8"]

[figure]
kind = "bar"
metric = "acmr"
x = "model"
"#
    );
    let spec = common::write_spec(root.path(), "corpus", &text);
    let outcome = run(&spec, &options(root.path(), None)).unwrap();
    let rows = common::csv_rows(&outcome.csv);
    let mut models: Vec<String> = Vec::new();
    for r in &rows {
        if !models.contains(&r["model"]) {
            models.push(r["model"].clone());
        }
    }
    // The glob's a.obj, then the folder's meshes at any depth, any case of extension, sorted
    // (a.obj again is measured once; notes.md is not a mesh), then the list's lines, relative to
    // the list's folder where the file is there (else as written: the data directory may have it).
    let expected = [
        format!("{dir}/a.obj"),
        format!("{dir}/sub/b.OBJ"),
        format!("{dir}/sub/broken.obj"),
        format!("{folder}/extra/c.obj"),
        "sphere:80".to_string(),
        "missing.ply".to_string(),
    ];
    assert_eq!(models, expected);
    // Two files fail (a face past the vertices, a file that is not there); each is one error
    // row naming the file and why, and every other model is measured with both methods.
    let errors: Vec<_> = rows.iter().filter(|r| r["metric"] == "error").collect();
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(errors[0]["model"].ends_with("broken.obj") && errors[0]["error"].contains("broken.obj"), "{errors:?}");
    assert!(errors[1]["model"].ends_with("missing.ply") && errors[1]["error"].contains("no such file"), "{errors:?}");
    assert_eq!(outcome.failures.len(), 2);
    let mut measured: HashMap<&str, usize> = HashMap::new();
    for r in rows.iter().filter(|r| r["metric"] == "acmr") {
        *measured.entry(r["model"].as_str()).or_default() += 1;
    }
    assert_eq!(measured.len(), 4, "{measured:?}");
    assert!(measured.values().all(|&n| n == 2), "{measured:?}");
    // An entry that names no mesh stops the run before any work, naming the entry.
    std::fs::write(&spec, text.replace("*.obj", "*.stl")).unwrap();
    let err = run(&spec, &options(root.path(), None)).unwrap_err().to_string();
    assert!(err.contains("models[0]") && err.contains("*.stl") && err.contains("no mesh file"), "{err}");
}
