//! The `triorder` binary end to end: outputs users and pipelines read, and failures that must be
//! clear (exit status 2, a message naming the file or value, no panic, no partial output).

mod common;

use std::path::Path;
use std::process::{Command, Output};

use triorder::mesh::{Mesh, load};

fn triorder(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("TRIORDER_DATA", "")
        .output()
        .expect("the triorder binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs a command that must fail cleanly, returning its stderr.
fn fails(args: &[&str]) -> String {
    let o = triorder(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?} should exit 2; stderr: {err}");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    err
}

#[test]
fn methods_lists_every_registered_method_with_parameters() {
    let out = stdout(&triorder(&["methods"]));
    for m in triorder::order::METHODS {
        assert!(out.contains(m.name), "{} missing", m.name);
        for p in m.params {
            assert!(out.contains(&format!("{}=", p.name)), "{}:{} missing", m.name, p.name);
        }
    }
    assert!(out.contains("[peer]"));
}

#[test]
fn eval_json_has_the_promised_fields() {
    let o = triorder(&[
        "eval",
        "grid:16x8",
        "-m",
        "input",
        "-m",
        "random:seed=3",
        "--cache",
        "fifo:4",
        "--cache",
        "lru:8",
        "--views",
        "ico:12",
        "--res",
        "64",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<serde_json::Value> = stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2);
    for line in &lines {
        for field in [
            "method",
            "triangles",
            "vertices",
            "acmr",
            "atvr",
            "cache",
            "seconds",
            "views",
            "res",
            "ovr_mean",
            "ovr_max",
        ] {
            assert!(line.get(field).is_some(), "no `{field}` in {line}");
        }
        assert_eq!(line["triangles"], 256);
        assert_eq!(line["vertices"], 153);
        assert_eq!(line["cache"], "fifo:4");
        assert_eq!(line["views"], "ico:12");
        assert_eq!(line["caches"].as_array().unwrap().len(), 2);
    }
    assert_eq!(lines[1]["method"], "random:seed=3");
    // A flat grid is seen from one side only: some ico:12 views see nothing, the others OVR 1.
    assert_eq!(lines[0]["ovr_max"], 1.0);
    assert!(lines[0]["ovr_empty"].as_f64().unwrap() > 0.0);
}

#[test]
fn eval_table_is_readable() {
    let o = triorder(&["eval", "assets/spot.obj", "-m", "input", "-m", "meshopt-vcache"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("ACMR/ATVR fifo:16") && out.contains("meshopt-vcache") && out.contains("5856 triangles"));
}

/// Each input triangle's corners (position, uv, normal) as comparable bit patterns.
fn corners(mesh: &Mesh, t: [u32; 3]) -> Vec<Vec<u32>> {
    t.iter()
        .map(|&v| {
            let v = v as usize;
            let mut c: Vec<u32> = mesh.positions[v].to_array().iter().map(|x| x.to_bits()).collect();
            if let Some(uv) = &mesh.attributes.uvs {
                c.extend(uv[v].iter().map(|x| x.to_bits()));
            }
            if let Some(n) = &mesh.attributes.normals {
                c.extend(n[v].iter().map(|x| x.to_bits()));
            }
            c
        })
        .collect()
}

#[test]
fn order_writes_every_format_with_attributes_and_winding_kept() {
    let dir = tempfile::tempdir().unwrap();
    let input = load::load_file(Path::new("assets/spot.obj")).unwrap();
    assert!(input.attributes.uvs.is_some());
    let mut expected: Vec<Vec<Vec<u32>>> = input.triangles.iter().map(|&t| corners(&input, t)).collect();
    expected.sort();
    for ext in ["obj", "ply", "glb"] {
        for remap in [false, true] {
            let out = dir.path().join(format!("spot-{remap}.{ext}"));
            let mut args = vec!["order", "assets/spot.obj", "-o", out.to_str().unwrap(), "-m", "meshopt-overdraw"];
            if remap {
                args.push("--remap-vertices");
            }
            let o = triorder(&args);
            assert!(o.status.success(), "{}", stderr(&o));
            assert!(stdout(&o).contains("ACMR/ATVR fifo:16: "), "{}", stdout(&o));
            if ext == "glb" {
                common::assert_valid_gltf(&out);
            }
            let written = load::load_file(&out).unwrap();
            assert_eq!(written.triangle_count(), input.triangle_count());
            assert!(written.attributes.uvs.is_some(), "{ext}");
            // Same corners with the same cyclic order: attributes travelled with their vertices.
            let mut got: Vec<Vec<Vec<u32>>> = written.triangles.iter().map(|&t| corners(&written, t)).collect();
            for tri in &mut got {
                let k = (0..3).min_by_key(|&k| tri[k].clone()).unwrap();
                tri.rotate_left(k);
            }
            got.sort();
            let mut want = expected.clone();
            for tri in &mut want {
                let k = (0..3).min_by_key(|&k| tri[k].clone()).unwrap();
                tri.rotate_left(k);
            }
            want.sort();
            assert_eq!(got, want, "{ext} remap={remap}");
            if remap {
                // First-use order: the first triangle uses vertices 0, 1, 2 (or fewer if repeated).
                assert_eq!(written.triangles[0], [0, 1, 2]);
            }
        }
    }
}

#[test]
fn order_reports_overdraw_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("layers.ply");
    let o = triorder(&[
        "order",
        "layers:4",
        "-o",
        out.to_str().unwrap(),
        "-m",
        "random",
        "--views",
        "axis6",
        "--res",
        "32",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("OVR mean/max/var axis6@32: 4.0000/4.0000/0.00000 -> "), "{}", stdout(&o));
}

#[test]
fn bad_values_are_named() {
    assert!(fails(&["eval", "grid:4x4", "-m", "no-such"]).contains("unknown method `no-such`"));
    assert!(fails(&["eval", "grid:4x4", "-m", "meshopt-fifo:cache=1"]).contains("`cache`=1"));
    assert!(fails(&["eval", "grid:4x4", "-m", "meshopt-overdraw:threshold=abc"]).contains("threshold"));
    assert!(fails(&["eval", "grid:4x4", "--cache", "fifo:0"]).contains("fifo:0"));
    assert!(fails(&["eval", "grid:4x4", "--cache", "mru:8"]).contains("mru:8"));
    assert!(fails(&["eval", "grid:4x4", "--views", "ico:100"]).contains("ico:100"));
    assert!(fails(&["eval", "grid:4x4", "--views", "axis6", "--res", "0"]).contains("resolution 0"));
    assert!(fails(&["eval", "grid:4x4", "--backend", "quantum"]).contains("quantum"));
    assert!(fails(&["eval", "grid:0x4"]).contains("grid:0x4"));
    assert!(fails(&["eval", "no/such/file.ply"]).contains("no/such/file.ply"));
}

#[test]
fn gpu_backend_without_a_driver_says_how_to_get_one() {
    // An ICD list that names no driver hides every Vulkan device, lavapipe included.
    let o = Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", "grid:4x4", "--views", "axis6", "--backend", "gpu"])
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for want in ["no GPU adapter", "mesa-vulkan-drivers", "VK_DRIVER_FILES"] {
        assert!(err.contains(want), "lacks `{want}`: {err}");
    }
    assert!(fails(&["run", "experiments/nbs06-variance-table.toml", "--backend", "metal"]).contains("metal"));
    // reproduce skips a spec that needs the GPU, says why, and goes on.
    let o = Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["reproduce", "--quick", "--only", "hw-vertex-reuse"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("skipping hw-vertex-reuse: it needs a GPU") && err.contains("mesa-vulkan-drivers"), "{err}");
    // The closing summary counts it and says why.
    let out = stdout(&o);
    assert!(!out.contains("wrote"), "wrote something: {out}");
    assert!(
        out.contains("reproduced 0 of 1 specs") && out.contains("skipped hw-vertex-reuse: it needs a GPU"),
        "{out}"
    );
}

/// `--cpu-only` skips the specs that need a GPU whether or not one is there (lavapipe is on CI),
/// and says so.
#[test]
fn cpu_only_skips_the_gpu_specs_wherever_a_gpu_is() {
    let o = Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["reproduce", "--quick", "--only", "hw-vertex-reuse", "--cpu-only"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let (out, err) = (stdout(&o), stderr(&o));
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(!out.contains("wrote") && !out.contains("GPU specs ran on"), "{out}");
    assert!(
        out.contains("reproduced 0 of 1 specs") && out.contains("skipped hw-vertex-reuse: it needs a GPU (--cpu-only"),
        "{out}"
    );
    assert!(fails(&["reproduce", "--quick", "--cpu-only", "--backend", "gpu"]).contains("--backend"));
}

#[test]
fn every_broken_file_fails_cleanly() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".md") || name.ends_with(".py") || name.ends_with(".bin") {
            continue;
        }
        let err = fails(&["eval", path.to_str().unwrap()]);
        assert!(err.contains(&name), "{name}: {err}");
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} broken files");
}

#[test]
fn failed_orders_leave_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let listing = || std::fs::read_dir(dir.path()).unwrap().count();
    let target = dir.path().join("out.obj");
    let t = target.to_str().unwrap();
    // Bad input, bad method, bad format, missing directory: nothing written, not even a temp file.
    fails(&["order", "tests/data/bad/obj_nan.obj", "-o", t]);
    fails(&["order", "grid:4x4", "-o", t, "-m", "no-such"]);
    assert!(fails(&["order", "grid:4x4", "-o", dir.path().join("out.xyz").to_str().unwrap()]).contains("out.xyz"));
    let missing = dir.path().join("no/such/dir/out.ply");
    assert!(fails(&["order", "grid:4x4", "-o", missing.to_str().unwrap()]).contains("out.ply"));
    assert!(fails(&["order", "grid:4x4", "-o", dir.path().to_str().unwrap()]).contains("directory"));
    assert_eq!(listing(), 0);
}

/// The shared animated model `name` as a path argument, or `None` (the test passes) without the
/// data directory.
fn animated_model(name: &str) -> String {
    common::animated_file(name).to_string_lossy().into_owned()
}

/// Animation options and `#` sources with a bad value fail before any file is read, naming the
/// source and the value; a static file asked for an animation says it is not glTF.
#[test]
fn bad_animation_options_are_named() {
    let max = triorder::mesh::source::MAX_SUBDIVISION;
    let err = fails(&["eval", "walker.glb", "--frames", "0", "-m", "hs17"]);
    assert!(err.contains("--frames 0") && err.contains("1..=65535"), "{err}");
    let err = fails(&["eval", "walker.glb", "--subdiv", "9", "-m", "hs17"]);
    assert!(err.contains("--subdiv 9") && err.contains(&format!("0..={max}")), "{err}");
    let err = fails(&["eval", "walker.glb#clip=Walk,speed=2", "-m", "hs17"]);
    assert!(err.contains("walker.glb#clip=Walk,speed=2") && err.contains("unknown key `speed`"), "{err}");
    let err = fails(&["eval", "walker.glb#clip=Walk", "--clip", "Run"]);
    assert!(err.contains("walker.glb#clip=Walk") && err.contains("--clip"), "{err}");
    let err = fails(&["eval", "assets/spot.obj", "--clip", "all", "-m", "hs17"]);
    assert!(err.contains("assets/spot.obj") && err.contains("not a .glb or .gltf file"), "{err}");
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn unknown_clip_lists_the_clips() {
    let fox = animated_model("Fox.glb");
    let clips = triorder::mesh::gltf::animation::read_animated(Path::new(&fox), &Default::default()).unwrap().clips;
    let err = fails(&["eval", &fox, "--clip", "Dance", "-m", "hs17:views=12,res=32", "--views", "random:4"]);
    assert!(err.contains(&fox) && err.contains("'Dance'"), "{err}");
    for clip in &clips {
        assert!(err.contains(&clip.name), "{err} does not list {}", clip.name);
    }
}

/// `order` writes one order: keyframe- and view-dependent methods are refused before the mesh is
/// even opened (so a missing file is not what is reported), and nothing is written.
#[test]
fn order_refuses_per_node_methods() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    for method in ["hs17", "hs17:clusters=2", "tipsify-per-frame"] {
        let err = fails(&["order", "no/such/file.ply", "-o", out.to_str().unwrap(), "-m", method]);
        let name = method.split(':').next().unwrap();
        assert!(err.contains(&format!("method `{name}`")) && err.contains("triorder eval"), "{err}");
        assert!(!err.contains("no/such/file.ply"), "{method}: the file was opened first: {err}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// `eval --clip` through hs17 and tipsify-per-frame: one JSON line per method with the buffer
/// count, the keyframes, the k-means report and the overdraw per clip.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn eval_animation_json_reports_buffers_and_keyframes() {
    let fox = animated_model("Fox.glb");
    let frames = 2;
    let selection = triorder::mesh::gltf::animation::ClipSelection { clip: None, frames: Some(frames) };
    let animated = triorder::mesh::gltf::animation::read_animated(Path::new(&fox), &selection).unwrap();
    let keyframes: usize = animated.clips.iter().map(|c| c.frames.len()).sum();
    let clusters = 2;
    let hs17 = format!("hs17:views=12,res=32,clusters={clusters}");
    let args = ["eval", &fox, "--clip", "all", "--frames", "2", "-m", &hs17, "-m", "tipsify-per-frame"];
    let o = triorder(&[&args[..], &["--views", "random:20", "--res", "32", "--json"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<serde_json::Value> = stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2, "{}", stdout(&o));
    for line in &lines {
        assert_eq!(line["frames"], keyframes, "{line}");
        assert_eq!(line["triangles"], animated.mesh.triangle_count(), "{line}");
        assert_eq!(line["views"], "random:20");
        assert!(line["ovr_mean"].as_f64().unwrap() >= 1.0, "{line}");
        let clips: Vec<&str> = line["clips"].as_array().unwrap().iter().map(|c| c["clip"].as_str().unwrap()).collect();
        assert_eq!(clips, animated.clips.iter().map(|c| c.name.as_str()).collect::<Vec<_>>());
    }
    let (hs17, per_frame) = (&lines[0], &lines[1]);
    let buffers = hs17["buffers"].as_u64().unwrap() as usize;
    // mode=single: at most k buffers for each clip.
    assert!((1..=clusters * animated.clips.len()).contains(&buffers), "{hs17}");
    assert!(hs17["iterations"].as_u64().unwrap() >= 1 && hs17["converged"].is_boolean(), "{hs17}");
    assert!(hs17["phases"].as_object().unwrap().contains_key("rasterization"), "{hs17}");
    assert_eq!(per_frame["buffers"], keyframes, "one buffer per keyframe");
}
