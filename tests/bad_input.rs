//! Broken mesh files and unwritable outputs: every one must give an error (never a panic) that
//! names the file and says where the problem is.
//!
//! The files live in `tests/data/bad/` (made once by its `generate.py`; its README.md lists
//! what is wrong with each). Several of them make the parsing libraries themselves panic or
//! silently accept bad data when used directly; see the module docs of `src/mesh/{obj,ply,gltf}.rs`.

mod common;

use std::path::{Path, PathBuf};

use glam::Vec3;
use triorder::mesh::load::load_file;
use triorder::mesh::save::save;
use triorder::mesh::{Mesh, VertexAttributes};

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad").join(name)
}

/// Loading `name` fails with a message naming the file and containing every phrase.
fn assert_rejected(name: &str, phrases: &[&str]) {
    common::rejected(&bad(name), phrases);
}

macro_rules! rejected {
    ($($test:ident: $file:literal => [$($phrase:literal),+ $(,)?];)+) => {
        $(
            #[test]
            fn $test() {
                assert_rejected($file, &[$($phrase),+]);
            }
        )+
    };
}

rejected! {
    ply_truncated_little_endian: "ply_truncated_le.ply" => ["vertex 2", "ends inside"];
    ply_truncated_big_endian: "ply_truncated_be.ply" => ["face 1", "ends inside"];
    ply_header_only: "ply_header_only.ply" => ["vertex 0 (line 10)", "ends before"];
    ply_nan_vertex: "ply_nan_vertex.ply" => ["vertex 1", "y is NaN"];
    ply_nan_in_ascii: "ply_nan_ascii.ply" => ["vertex 1 (line 11)", "'nan' is not a number"];
    ply_face_index_past_the_end: "ply_index_past_end.ply" => ["face 1", "vertex index 7 is out of range", "4 vertices"];
    ply_face_with_two_indices: "ply_face_two_indices.ply" => ["face 0", "2 vertex indices"];
    ply_without_vertex_element: "ply_no_vertex_element.ply" => ["no 'vertex' element"];
    ply_float_index_list: "ply_float_index_list.ply" => ["header line 8", "vertex_indices", "floating-point"];
    ply_without_faces: "ply_no_faces.ply" => ["no faces", "4 vertices"];
    ply_property_declared_twice: "ply_duplicate_property.ply" => ["header line 6", "'x'", "declared twice"];
    ply_line_with_an_extra_value: "ply_extra_value.ply" => ["vertex 1 (line 11)", "4 values", "declares 3"];
    ply_header_line_that_does_not_parse: "ply_bad_header_line.ply" => ["header line 5", "property flot y"];
    ply_list_longer_than_the_file: "ply_huge_list.ply" => ["face 0", "ends inside"];
    ply_empty: "empty.ply" => ["empty"];
    ply_format_version_2: "ply_format_version_2.ply" => ["header line 2", "version 2.0 is not supported"];
    ply_that_is_text: "not_a_mesh.ply" => ["not a PLY file", "line 1"];
    obj_nan: "obj_nan.obj" => ["line 3", "'nan' is not a finite number"];
    obj_inf: "obj_inf.obj" => ["line 2", "'inf' is not a finite number"];
    obj_non_numeric_coordinate: "obj_non_numeric.obj" => ["line 4", "'one' is not a number"];
    obj_index_past_the_end: "obj_index_past_end.obj" => ["line 6", "face index 9 is out of range", "defines 4 vertices"];
    obj_negative_index_out_of_range: "obj_negative_index.obj" => ["line 7", "face index -9 is out of range", "4 vertices defined so far"];
    obj_face_with_two_vertices: "obj_face_two_vertices.obj" => ["line 6", "face has 2 vertices"];
    obj_zero_index: "obj_zero_index.obj" => ["line 5", "index 0 is invalid"];
    obj_negative_uv_index_that_panics_tobj: "obj_negative_uv_index.obj" => ["line 6", "texture-coordinate index -5 is out of range"];
    obj_without_faces: "obj_no_faces.obj" => ["no faces", "4 vertices"];
    obj_empty: "empty.obj" => ["empty"];
    glb_empty: "empty.glb" => ["empty"];
    glb_bad_magic: "glb_bad_magic.glb" => ["does not start with the GLB magic"];
    glb_length_shorter_than_the_file: "glb_length_shorter_than_file.glb" => ["declared length 380 bytes", "the file has 424"];
    glb_buffer_view_past_the_buffer: "glb_view_past_end.glb" => ["buffer view 0", "past the end of buffer 0"];
    glb_accessor_past_its_view: "glb_accessor_past_view.glb" => ["accessor 0", "past the end of buffer view 0"];
    glb_accessor_index_out_of_range: "glb_accessor_index_out_of_range.glb" => ["mesh 0 primitive 0", "accessor 5"];
    glb_header_length_zero: "glb_header_length_zero.glb" => ["declared length 0"];
    glb_node_cycle: "glb_node_cycle.glb" => ["node", "cycle"];
    glb_that_is_text: "not_a_mesh.glb" => ["does not start with the GLB magic"];
    gltf_missing_bin: "gltf_missing_bin.gltf" => ["buffer 0", "missing.bin"];
    gltf_uri_that_is_not_utf8: "gltf_bad_uri.gltf" => ["buffer 0", "%FF.bin"];
    unsupported_extension: "mesh.stl" => ["unsupported file extension '.stl'"];
}

#[test]
fn missing_file_is_named() {
    let path = bad("no_such_file.ply");
    let message = load_file(&path).unwrap_err().to_string();
    assert!(message.contains("no_such_file.ply") && message.contains("cannot read"), "{message}");
}

#[test]
fn every_corpus_file_is_tested() {
    let source = include_str!("bad_input.rs");
    for entry in std::fs::read_dir(bad("")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name != "generate.py" && name != "README.md" {
            assert!(source.contains(&format!("\"{name}\"")), "{name} has no test");
        }
    }
}

fn triangle() -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    Mesh::new("triangle", positions, vec![[0, 1, 2]], VertexAttributes::default()).unwrap()
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

#[test]
fn save_into_a_missing_directory_fails_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent").join("out.ply");
    let message = save(&triangle(), &path).unwrap_err().to_string();
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn save_onto_a_directory_fails_and_leaves_it_alone() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.glb");
    std::fs::create_dir(&path).unwrap();
    let message = save(&triangle(), &path).unwrap_err().to_string();
    assert!(message.contains(&path.display().to_string()) && message.contains("directory"), "{message}");
    assert_eq!(listing(dir.path()), ["out.glb"]);
    assert!(path.is_dir() && listing(&path).is_empty());
}

#[cfg(unix)]
#[test]
fn save_into_a_read_only_directory_fails_and_leaves_nothing() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root ignores directory permissions; /proc refuses new files even to root.
    let root = std::fs::write(locked.join("probe"), b"").is_ok();
    let _ = std::fs::remove_file(locked.join("probe"));
    let target = if root { std::path::Path::new("/proc").to_path_buf() } else { locked.clone() };
    let path = target.join("triorder-out.obj");
    let result = save(&triangle(), &path);
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
    let message = result.unwrap_err().to_string();
    assert!(message.contains(&path.display().to_string()), "{message}");
    assert!(!path.exists());
    assert!(listing(&locked).is_empty());
}

#[test]
fn save_replaces_an_existing_file_whole() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.ply");
    std::fs::write(&path, vec![b'x'; 100_000]).unwrap();
    save(&triangle(), &path).unwrap();
    assert_eq!(listing(dir.path()), ["out.ply"]);
    assert_eq!(load_file(&path).unwrap().triangles, vec![[0, 1, 2]]);
}
