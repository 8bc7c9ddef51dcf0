//! Assets downloaded from anywhere: a glTF file reads its buffers from its own folder only
//! (unless `--allow-outside-uris`), only regular files, never more than it declares, and no
//! error quotes the bytes it read; a UTF-8 byte-order mark never changes what a text file
//! means; unknown OBJ keywords are reported, not skipped in silence.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use triorder::mesh::load::{load_file, load_file_with_report};

/// A one-triangle glTF whose buffer (36 bytes of positions, 12 of indices) is at `uri`.
fn gltf(uri: &str, length: usize) -> String {
    serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5125, "count": 3, "type": "SCALAR"}
        ],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 12}],
        "buffers": [{"byteLength": length, "uri": uri}]
    })
    .to_string()
}

fn triangle_bin() -> Vec<u8> {
    let floats = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.];
    let mut bin: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    bin
}

/// A temporary root with `outside.bin` in it and a `model/` folder holding `sub/tri.bin`.
struct Root {
    dir: tempfile::TempDir,
}

impl Root {
    fn new() -> Root {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("model/sub")).unwrap();
        std::fs::write(dir.path().join("outside.bin"), triangle_bin()).unwrap();
        std::fs::write(dir.path().join("model/sub/tri.bin"), triangle_bin()).unwrap();
        Root { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Writes `model/NAME.gltf` with its buffer at `uri` and returns its path.
    fn model(&self, name: &str, uri: &str) -> PathBuf {
        let path = self.path(&format!("model/{name}.gltf"));
        std::fs::write(&path, gltf(uri, 48)).unwrap();
        path
    }
}

/// `triorder eval PATH --allow-outside-uris`: its status and stderr.
fn eval_allowing(path: &Path) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", path.to_str().unwrap(), "--allow-outside-uris"])
        .output()
        .unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn a_buffer_beside_the_model_loads() {
    let root = Root::new();
    assert_eq!(load_file(&root.model("ok", "sub/tri.bin")).unwrap().triangle_count(), 1);
    assert_eq!(load_file(&root.model("escaped", "sub/tri%2Ebin")).unwrap().triangle_count(), 1);
    assert_eq!(load_file(&root.model("inner dots", "sub/../sub/tri.bin")).unwrap().triangle_count(), 1);
}

#[test]
fn uris_that_leave_the_folder_are_refused_and_say_how_to_allow_them() {
    let root = Root::new();
    let outside = root.path("outside.bin");
    let allow = "--allow-outside-uris";
    let cases = [
        ("absolute", outside.display().to_string(), "absolute path"),
        ("file", format!("file://{}", outside.display()), "file: URI"),
        ("dotdot", "../outside.bin".to_string(), "leads outside the model's folder"),
        ("encoded", "%2E%2E/outside.bin".to_string(), "leads outside the model's folder"),
        ("deeper", "sub/../../outside.bin".to_string(), "leads outside the model's folder"),
    ];
    for (name, uri, why) in cases {
        let path = root.model(name, &uri);
        common::rejected(&path, &["buffer 0", why, allow]);
        let (ok, stderr) = eval_allowing(&path);
        assert!(ok, "{name} with {allow}: {stderr}");
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, root.path("model/link.bin")).unwrap();
        let path = root.model("link", "link.bin");
        common::rejected(&path, &["buffer 0", "leads outside the model's folder", allow]);
        assert!(eval_allowing(&path).0);
    }
}

#[test]
fn other_schemes_and_nul_bytes_are_refused() {
    let root = Root::new();
    common::rejected(&root.model("http", "http://example.com/tri.bin"), &["scheme 'http:'"]);
    common::rejected(&root.model("host", "file://server/tri.bin"), &["file: URI"]);
    common::rejected(&root.model("nul", "sub/tri%00.bin"), &["NUL byte"]);
}

/// A device never ends and a pipe blocks whoever opens it: only regular files are read, even
/// where outside files are allowed.
#[test]
#[cfg(unix)]
fn devices_and_pipes_are_not_read() {
    let root = Root::new();
    let zero = root.model("zero", "/dev/zero");
    common::rejected(&zero, &["absolute path"]);
    let (ok, stderr) = eval_allowing(&zero);
    assert!(!ok && stderr.contains("not a regular file"), "{stderr}");
    let fifo = root.path("model/pipe");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    common::rejected(&root.model("fifo", "pipe"), &["not a regular file"]);
    std::fs::create_dir(root.path("model/folder")).unwrap();
    common::rejected(&root.model("folder", "folder"), &["not a regular file"]);
}

/// A buffer file shorter than its `byteLength` is an error that does not quote it; a longer one
/// is read up to `byteLength` only.
#[test]
fn buffers_are_read_to_their_declared_length_and_never_quoted() {
    let root = Root::new();
    std::fs::write(root.path("model/short.bin"), b"SECRET-PASSWORD").unwrap();
    let message = common::rejected(&root.model("short", "short.bin"), &["holds 15 bytes", "declares 48"]);
    assert!(!message.contains("SECRET"), "the error quotes the file: {message}");
    let mut long = triangle_bin();
    long.extend(std::iter::repeat_n(7u8, 1 << 20));
    std::fs::write(root.path("model/long.bin"), long).unwrap();
    assert_eq!(load_file(&root.model("long", "long.bin")).unwrap().triangle_count(), 1);
    // A file that is not a GLB is not quoted either.
    let text = root.path("model/list.glb");
    std::fs::write(&text, "SECRET shopping list: eggs").unwrap();
    let message = common::rejected(&text, &["GLB magic"]);
    assert!(!message.contains("SECRET") && !message.contains("shop"), "{message}");
}

/// A byte-order mark is skipped by every text reader: the mesh is the one without it.
#[test]
fn a_byte_order_mark_changes_nothing() {
    let root = Root::new();
    let bom = |text: &[u8]| [triorder::mesh::BOM, text].concat();
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";
    let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let json = gltf("sub/tri.bin", 48);
    for (name, text) in [("plain.obj", &obj[..]), ("plain.ply", ply), ("plain.gltf", json.as_bytes())] {
        let plain = root.path(&format!("model/{name}"));
        let marked = root.path(&format!("model/bom-{name}"));
        std::fs::write(&plain, text).unwrap();
        std::fs::write(&marked, bom(text)).unwrap();
        let (a, b) = (load_file(&plain).unwrap(), load_file(&marked).unwrap());
        assert_eq!((a.positions, a.triangles), (b.positions, b.triangles), "{name}");
    }
    let spec = std::fs::read("experiments/bg02-fig7-progressive-updates.toml").unwrap();
    let dir = root.path("experiments");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("bg02-fig7-progressive-updates.toml"), bom(&spec)).unwrap();
    let spec = triorder::experiment::Spec::load(&dir.join("bg02-fig7-progressive-updates.toml")).unwrap();
    assert_eq!(spec.id, "bg02-fig7-progressive-updates");
}

#[test]
fn unknown_obj_keywords_are_reported() {
    let root = Root::new();
    let path = root.path("model/odd.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\no part\nusemtl red\nvx 1 2 3\nf 1 2 3\nzz\n").unwrap();
    let (mesh, report) = load_file_with_report(&path).unwrap();
    assert_eq!(mesh.triangle_count(), 1);
    assert!(
        report.dropped.iter().any(|d| d.contains("2 line(s)") && d.contains("`vx` on line 6")),
        "{:?}",
        report.dropped
    );
}

/// A NUL or an escape sequence from a file never reaches the terminal raw.
#[test]
fn errors_print_no_control_characters() {
    let root = Root::new();
    let path = root.path("model/nul.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 \x1b[31m0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_triorder")).args(["eval", path.to_str().unwrap()]).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("line 2"), "{stderr}");
    assert!(!stderr.contains('\x1b') && stderr.contains("\\u{1b}"), "{stderr}");
}

/// Errors speak the file's language, not a parsing library's debug output.
#[test]
fn messages_name_the_problem_in_our_words() {
    let root = Root::new();
    let ply = |name: &str, header: &str, body: &str| {
        let path = root.path(&format!("model/{name}.ply"));
        std::fs::write(&path, format!("ply\nformat ascii 1.0\n{header}end_header\n{body}")).unwrap();
        load_file(&path).unwrap_err().to_string()
    };
    let triangle = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
        element face 1\nproperty list uchar int vertex_indices\n";
    let cases = [
        (ply("count", "element vertex abc\n", ""), "header line 3 ('element vertex abc'): an element line is"),
        (ply("type", "element vertex 1\nproperty flot x\n", ""), "unknown property type 'flot'"),
        (ply("list", "element face 1\nproperty list uchar it v\n", ""), "unknown property type 'it'"),
        (ply("word", "elephant\n", ""), "not a PLY header line"),
        (ply("big", triangle, "0 0 0\n1 0 0\n0 1 0\n3 0 1 99999999999\n"), "'99999999999' does not fit the property"),
        (ply("long", triangle, "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n"), "list length '300' of 'vertex_indices'"),
    ];
    for (message, want) in cases {
        assert!(message.contains(want), "expected {want:?} in: {message}");
        assert!(!message.contains("Couldn't") && !message.contains("Error {"), "library text: {message}");
    }
    let message = triorder::mesh::Source::parse("grid:4x4@abc").unwrap_err().to_string();
    assert!(message.contains("`@abc`") && !message.contains("width"), "{message}");
    let glb = root.path("model/twelve.glb");
    std::fs::write(&glb, [&b"glTF"[..], &2u32.to_le_bytes(), &12u32.to_le_bytes()].concat()).unwrap();
    let message = common::rejected(&glb, &["declared length 12 bytes, less than a header and one chunk"]);
    assert!(!message.contains("the file has 12"), "{message}");
}

/// 20,000 copies of one face (160 KB of OBJ) once asked the dual graph for every pair of
/// triangles on an edge: 400 million links, 15 GB. Past a few triangles an edge links them in a
/// chain, so the graph stays linear and still connected.
#[test]
fn thousands_of_faces_on_one_edge_stay_linear() {
    let root = Root::new();
    let path = root.path("model/copies.obj");
    let faces = "f 1 2 3\n".repeat(20_000);
    std::fs::write(&path, format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{faces}")).unwrap();
    let scene = triorder::mesh::Scene::still(load_file(&path).unwrap());
    let links = scene.topology.neighbors.items().len();
    assert!(links <= 6 * 20_000, "{links} links for 20,000 triangles");
    assert_eq!(scene.topology.component_count, 1);
    for method in ["recursive-cut", "tipsify", "mla"] {
        let orders = triorder::order::run(&triorder::order::resolve(method, 0).unwrap(), &scene).unwrap();
        assert_eq!(orders.buffers[0].order.len(), 20_000, "{method}");
    }
}
