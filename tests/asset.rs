//! `triorder order` keeps the asset (issue 23): every shared animated model comes back with the
//! same JSON, the same size, the same validator report and the same posed keyframes, its
//! primitives reordered each on its own; an OBJ keeps its groups, materials and smoothing groups;
//! a conversion says what it cannot hold, and `--strict` refuses it.

mod common;

use std::path::Path;
use std::process::Command;

use triorder::measure::{self, MeasureOptions};
use triorder::mesh::Source;
use triorder::order;

const SKIP: &str = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)";

/// Runs `triorder ARGS`; its status, stdout and stderr.
fn triorder(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_triorder")).args(args).output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

/// A GLB's JSON chunk, parsed.
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

/// The validator's count of each error and warning code for `path`, where it is installed.
fn validator_codes(path: &Path) -> Option<serde_json::Value> {
    common::gltf_validator(path).map(|report| report["codes"].clone())
}

/// Every triangle of `file` posed at the second of three keyframes of its animations, as the bits
/// of its corners, sorted: equal for two files that draw the same triangles in any order and
/// vertex numbering.
fn posed_triangles(file: &Path) -> Vec<[u32; 9]> {
    let source = Source::parse(&format!("{}#frames=3", file.display())).unwrap();
    let scene = source.open(None, 0).unwrap();
    let posed = scene.frames.posed(&scene.mesh, 1);
    let mut all: Vec<[u32; 9]> = posed
        .triangles
        .iter()
        .map(|t| {
            let p = t.map(|v| posed.positions[v as usize].to_array().map(f32::to_bits));
            [p[0][0], p[0][1], p[0][2], p[1][0], p[1][1], p[1][2], p[2][0], p[2][1], p[2][2]]
        })
        .collect();
    all.sort_unstable();
    all
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn every_shared_animated_model_keeps_everything() {
    let _ = SKIP;
    let dir = tempfile::tempdir().unwrap();
    let animated = common::data_dir().join("animated");
    let mut files: Vec<_> = std::fs::read_dir(&animated).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert!(files.len() >= 9, "the shared animated models");
    for input in &files {
        let name = input.file_name().unwrap().to_string_lossy().into_owned();
        let input_codes = validator_codes(input);
        for remap in [false, true] {
            let output = dir.path().join(format!("{remap}-{name}"));
            let mut args = vec!["order", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "-m", "tipsify"];
            if remap {
                args.push("--remap-vertices");
            }
            let (ok, stdout, stderr) = triorder(&args);
            assert!(ok, "{name}: {stderr}");
            println!("{name} remap={remap}: {}", stdout.lines().next().unwrap_or_default());
            // The JSON is the input's, object for object; the file is as compact as before.
            assert_eq!(glb_json(&output), glb_json(input), "{name}: the JSON changed");
            assert_eq!(std::fs::metadata(&output).unwrap().len(), std::fs::metadata(input).unwrap().len());
            // The validator finds exactly what it finds in the input (some inputs have errors of
            // their own: CesiumMan's weights do not sum to 1), nothing new.
            if let (Some(before), Some(after)) = (&input_codes, validator_codes(&output)) {
                assert_eq!(&after, before, "{name}: the validator's report changed");
            }
            // A keyframe posed from both draws the same triangles.
            assert_eq!(posed_triangles(&output), posed_triangles(input), "{name}: posed keyframe");
        }
    }
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn draw_calls_are_ordered_each_on_its_own() {
    let input = common::animated_file("BrainStem.glb");
    let scene = Source::File(input.display().to_string()).open(None, 0).unwrap();
    assert_eq!(scene.draw_calls.len(), 59, "one per primitive");
    let resolved = order::resolve("tipsify", 0).unwrap();
    let options = MeasureOptions { per_draw_call: true, ..MeasureOptions::default() };
    let raster = measure::backend("cpu").unwrap();
    let evaluation = measure::evaluate(&scene, &resolved, &options, raster.as_ref()).unwrap();
    let order = &evaluation.orders.single().unwrap().order;
    for call in &scene.draw_calls {
        let mut mine: Vec<u32> = order[call.clone()].to_vec();
        mine.sort_unstable();
        assert_eq!(
            mine,
            (call.start as u32..call.end as u32).collect::<Vec<_>>(),
            "a draw call's triangles stay in it"
        );
    }
    // The whole-mesh order (the papers') is free to interleave them.
    let whole = measure::evaluate(&scene, &resolved, &MeasureOptions::default(), raster.as_ref()).unwrap();
    assert_eq!(whole.orders.single().unwrap().order.len(), order.len());
}

/// An OBJ with a material library, two objects, two materials, smoothing groups, a quad and
/// negative (relative) indices.
const OBJ: &str = "# two parts\nmtllib parts.mtl\no first\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n\
usemtl red\ns 1\nf 1 2 3\nf 1 3 4\nf 2 5 6\nf 2 6 3\no second\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nusemtl blue\ns off\n\
f -4 -3 -2 -1\nf 7 9 10\nf 8 9 7\n";

#[test]
fn an_obj_keeps_its_groups_materials_and_lines() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("parts.obj");
    std::fs::write(&input, OBJ).unwrap();
    let output = dir.path().join("out.obj");
    let (ok, stdout, stderr) =
        triorder(&["order", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "-m", "random"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("2 draw call(s)"), "{stdout}");
    let written = std::fs::read_to_string(&output).unwrap();
    let (before, after): (Vec<&str>, Vec<&str>) = (OBJ.lines().collect(), written.lines().collect());
    assert_eq!(before.len(), after.len());
    // Every line that is not a face is where it was; faces stay within their object and material.
    for (b, a) in before.iter().zip(&after) {
        if !b.starts_with("f ") {
            assert_eq!(b, a);
        }
    }
    let faces = |lines: &[&str], range: std::ops::Range<usize>| {
        let mut f: Vec<String> = lines[range].iter().filter(|l| l.starts_with("f ")).map(|l| l.to_string()).collect();
        f.sort();
        f
    };
    assert_eq!(faces(&after, 0..15), faces(&before, 0..15), "the first material's faces");
    // The quad written with relative indices keeps them where it did not move, or is made
    // absolute where it did: either way the reloaded file draws the same triangles.
    let triangles = |path: &Path| {
        let mesh = triorder::mesh::load::load_file(path).unwrap();
        let mut t: Vec<[[u32; 3]; 3]> =
            mesh.triangles.iter().map(|t| t.map(|v| mesh.positions[v as usize].to_array().map(f32::to_bits))).collect();
        t.sort_unstable();
        t
    };
    assert_eq!(triangles(&output), triangles(&input));
    // As PLY the groups and materials cannot be kept: one warning says so, --strict refuses.
    let ply = dir.path().join("out.ply");
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", ply.to_str().unwrap()]);
    assert!(ok && stderr.contains("cannot hold everything") && stderr.contains("usemtl"), "{stderr}");
    std::fs::remove_file(&ply).unwrap();
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", ply.to_str().unwrap(), "--strict"]);
    assert!(!ok && stderr.contains("--strict") && stderr.contains("usemtl"), "{stderr}");
    assert!(!ply.exists(), "nothing written under --strict");
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn a_conversion_lists_what_it_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::animated_file("CesiumMan.glb");
    let obj = dir.path().join("man.obj");
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", obj.to_str().unwrap(), "--strict"]);
    assert!(!ok && !obj.exists(), "{stderr}");
    for held in ["skin", "animation", "material", "texture"] {
        assert!(stderr.contains(held), "the refusal lacks `{held}`: {stderr}");
    }
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", obj.to_str().unwrap()]);
    assert!(ok && obj.exists() && stderr.matches("warning: ").count() >= 1, "{stderr}");
    // Between the two glTF containers there is no in-place rewrite: refused, not converted.
    let gltf = dir.path().join("man.gltf");
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", gltf.to_str().unwrap()]);
    assert!(!ok && stderr.contains(".glb from a .glb"), "{stderr}");
}

/// `animated/NAME` split into a `.gltf` JSON file and its buffer `STEM.bin` in `dir`, with `edit`
/// applied to the JSON.
fn as_gltf(name: &str, dir: &Path, stem: &str, edit: impl Fn(&mut serde_json::Value)) -> std::path::PathBuf {
    let glb = std::fs::read(common::animated_file(name)).unwrap();
    let mut json = glb_json(&common::animated_file(name));
    let json_length = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let bin_at = 20 + json_length;
    let bin_length = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    std::fs::write(dir.join(format!("{stem}.bin")), &glb[bin_at + 8..bin_at + 8 + bin_length]).unwrap();
    json["buffers"][0]["uri"] = format!("{stem}.bin").into();
    edit(&mut json);
    let path = dir.join(format!("{stem}.gltf"));
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    path
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn a_gltf_with_an_external_buffer_is_rewritten_beside_its_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = as_gltf("RiggedFigure.glb", dir.path(), "figure", |_| {});
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let output = dir.path().join("out/optimized.gltf");
    let (ok, stdout, stderr) =
        triorder(&["order", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "--remap-vertices"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("1 primitive(s) reordered"), "{stdout}");
    // The JSON is the input's but for the buffer's new name, written beside the output.
    let read = |p: &Path| serde_json::from_slice::<serde_json::Value>(&std::fs::read(p).unwrap()).unwrap();
    let mut expected = read(&input);
    expected["buffers"][0]["uri"] = "optimized.bin".into();
    assert_eq!(read(&output), expected);
    let bin = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert_eq!(bin(&dir.path().join("out/optimized.bin")), bin(&dir.path().join("figure.bin")));
    if let (Some(before), Some(after)) = (validator_codes(&input), validator_codes(&output)) {
        assert_eq!(after, before);
    }
    assert_eq!(posed_triangles(&output), posed_triangles(&input));
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn compressed_geometry_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = as_gltf("RiggedSimple.glb", dir.path(), "simple", |json| {
        json["extensionsUsed"] = serde_json::json!(["EXT_meshopt_compression"]);
    });
    let output = dir.path().join("out.gltf");
    let (ok, _, stderr) = triorder(&["order", input.to_str().unwrap(), "-o", output.to_str().unwrap()]);
    assert!(!ok && stderr.contains("EXT_meshopt_compression") && stderr.contains("decompress"), "{stderr}");
    assert!(!output.exists() && !dir.path().join("out.bin").exists(), "nothing written");
}

#[test]
fn a_ply_keeps_its_face_properties_and_other_elements() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("strip.ply");
    let mut text = String::from(
        "ply\nformat ascii 1.0\ncomment kept\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n\
         element face 6\nproperty list uchar int vertex_indices\nproperty uchar red\nelement edge 1\nproperty int a\nproperty int b\nend_header\n",
    );
    for i in 0..4 {
        text += &format!("{i} 0 0\n{i} 1 0\n");
    }
    for (f, i) in (0..3).enumerate() {
        let v = 2 * i;
        text += &format!("3 {} {} {} {}\n3 {} {} {} {}\n", v, v + 2, v + 1, 10 * f, v + 1, v + 2, v + 3, 10 * f + 5);
    }
    text += "0 7\n";
    std::fs::write(&input, &text).unwrap();
    let output = dir.path().join("out.ply");
    let (ok, _, stderr) =
        triorder(&["order", input.to_str().unwrap(), "-o", output.to_str().unwrap(), "-m", "random", "--seed", "4"]);
    assert!(ok, "{stderr}");
    let written = std::fs::read_to_string(&output).unwrap();
    let lines = |t: &str| -> Vec<String> { t.lines().map(String::from).collect() };
    let (before, after) = (lines(&text), lines(&written));
    // Header, vertices and the edge element as they were; the faces, each with its red, permuted.
    let faces = 14 + 8..14 + 8 + 6;
    assert_eq!(before[..faces.start], after[..faces.start]);
    assert_eq!(before[faces.end..], after[faces.end..]);
    let (mut b, mut a) = (before[faces.clone()].to_vec(), after[faces.clone()].to_vec());
    assert_ne!(a, b, "a random order moves some face");
    b.sort();
    a.sort();
    assert_eq!(a, b);
}
