//! Inputs the fuzz targets (`fuzz/`, `scripts/fuzz.sh`) found to panic, hang or allocate far
//! beyond their size: each must now give an error that names the file. The files live in
//! `tests/data/fuzz/`, whose README.md says what each did.

mod common;

use std::path::{Path, PathBuf};

use triorder::mesh::load::load_file;

fn found(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz").join(name)
}

/// Loading `name` fails with a message naming the file and containing every phrase.
fn assert_rejected(name: &str, phrases: &[&str]) {
    common::rejected(&found(name), phrases);
}

#[test]
fn gltf_with_a_bom_before_a_glb_header_is_refused() {
    assert_rejected("gltf_bom_before_glb_header.gltf", &["GLB header", "declared length 0"]);
}

#[test]
fn gltf_sparse_accessor_without_a_view_cannot_declare_gigabytes() {
    assert_rejected(
        "gltf_sparse_without_view_huge_count.gltf",
        &["accessor 0", "count 60000000 without a buffer view", "bytes of the file's buffers"],
    );
}

/// The same accessor with the count the mesh has (4 vertices) is a valid file: all zeros but
/// the substituted vertex, and it still loads.
#[test]
fn gltf_sparse_accessor_without_a_view_of_a_sane_size_still_loads() {
    let text = std::fs::read_to_string(found("gltf_sparse_without_view_huge_count.gltf")).unwrap();
    assert_eq!(text.matches("60000000").count(), 1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sparse.gltf");
    std::fs::write(&path, text.replace("60000000", "4")).unwrap();
    let mesh = load_file(&path).unwrap();
    assert_eq!(mesh.triangle_count(), 4);
    // Vertex 1 is substituted with (2, 0, 0); node 0 mirrors x and moves it by (1, 2, 3).
    let moved = glam::Vec3::new(-1.0, 2.0, 3.0);
    assert!(mesh.positions.contains(&moved), "the sparse substitution is lost: {:?}", mesh.positions);
}

#[test]
fn every_found_input_is_tested() {
    let source = include_str!("fuzz_regressions.rs");
    for entry in std::fs::read_dir(found("")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name != "README.md" {
            assert!(source.contains(&format!("\"{name}\"")), "{name} has no test");
        }
    }
}
