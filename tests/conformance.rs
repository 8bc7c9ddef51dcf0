//! Every registered ordering, on every test mesh, the awkward ones included: well-formed orders
//! (each buffer a permutation of the input triangles whose clusters tile it, a lookup naming
//! buffers that exist), deterministic for a seed, and clear errors for bad parameters; and for
//! every static method, what `triorder order` writes is the input's triangles in the method's
//! order, each with its winding and attributes, in OBJ, PLY and GLB. A new ordering gets these
//! tests by being registered in `order::METHODS`; nothing here names a method.

mod common;

use std::path::Path;
use std::process::Command;

use glam::Vec3;
use triorder::mesh::{Mesh, Scene, Source, load, procedural};
use triorder::order::{self, METHODS, ParamKind};

fn procedural_meshes() -> Vec<Mesh> {
    let mut meshes: Vec<Mesh> = ["grid:16x8", "disk:950", "sphere:2000", "helix:3", "layers:4"]
        .iter()
        .map(|s| procedural::generate(s, 1).unwrap().unwrap())
        .collect();
    meshes.push(load::load_file(Path::new("assets/spot.obj")).unwrap());
    meshes
}

/// Meshes that break careless code: fins, duplicate and degenerate faces, nothing but degenerate
/// faces, a 3,000-triangle fan, a non-manifold "book" of 40 pages on one edge, several
/// components, a single triangle, and no triangle at all.
fn awkward_meshes() -> Vec<Mesh> {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mesh = |name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>| {
        Mesh::new(name, positions, triangles, Default::default()).unwrap()
    };
    let square = vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(0.5, 0.5, 1.), p(0.5, 0.5, -1.)];
    let mut book = procedural::generate("grid:6x6", 0).unwrap().unwrap();
    for page in 0..40 {
        book.positions.push(p(0.5, -1.0, page as f32 + 1.0));
        book.triangles.push([0, 1, book.positions.len() as u32 - 1]);
    }
    let fan_positions = std::iter::once(p(0., 0., 0.))
        .chain((0..=3000).map(|i| p((i as f32 * 0.002).cos(), (i as f32 * 0.002).sin(), 0.)));
    let mut components = procedural::generate("grid:3x3", 0).unwrap().unwrap();
    for shift in [5.0, 10.0] {
        let base = components.positions.len() as u32;
        components.positions.extend([p(shift, 0., 0.), p(shift + 1., 0., 0.), p(shift, 1., 0.)]);
        components.triangles.push([base, base + 1, base + 2]);
    }
    let one = mesh("one triangle", square[..3].to_vec(), vec![[0, 1, 2]]);
    vec![
        mesh("fins", square.clone(), vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5], [2, 1, 3]]),
        mesh("duplicates and degenerates", square.clone(), vec![[0, 1, 2], [0, 1, 2], [2, 1, 0], [1, 1, 3], [3, 3, 3]]),
        mesh("all degenerate", square.clone(), vec![[0, 0, 0], [1, 1, 2], [2, 2, 1], [3, 3, 3]]),
        mesh("fan", fan_positions.collect(), (1..=3000).map(|i| [0, i, i + 1]).collect()),
        mesh("book", book.positions, book.triangles),
        mesh("components", components.positions, components.triangles),
        Mesh { triangles: Vec::new(), ..one.clone() },
        one,
    ]
}

/// Every method on `mesh`: what it returns passes `order::run`'s checks, and the same spec gives
/// the same orders again.
fn check_every_method(mesh: &Mesh) {
    let scene = Scene::still(mesh.clone());
    for method in METHODS {
        let resolved = order::resolve(method.name, 42).unwrap();
        let orders = order::run(&resolved, &scene).unwrap_or_else(|e| panic!("{} on {}: {e}", method.name, mesh.name));
        assert!(!method.per_node || orders.lookup.frames() == 1, "{} on {}", method.name, mesh.name);
        assert!(method.per_node || orders.buffers.len() == 1, "{} on {}: a static method", method.name, mesh.name);
        let again = order::run(&order::resolve(&resolved.canonical(), 7).unwrap(), &scene).unwrap();
        assert_eq!(
            (&orders.buffers, &orders.lookup),
            (&again.buffers, &again.lookup),
            "{} on {} is not deterministic",
            method.name,
            mesh.name
        );
    }
}

#[test]
fn every_method_gives_well_formed_orders_on_procedural_meshes() {
    procedural_meshes().iter().for_each(check_every_method);
}

#[test]
fn every_method_copes_with_awkward_meshes() {
    awkward_meshes().iter().for_each(check_every_method);
}

/// Real, irregular meshes: one closed, one with non-manifold edges from decimation, one
/// quad-dominant with seams.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn every_method_gives_well_formed_orders_on_real_meshes() {
    for name in ["bunny_2k.ply", "dragon_vrip_res4.ply", "pirate.obj"] {
        check_every_method(&common::real_mesh(name));
    }
}

/// Each corner of `t` (position, uv, normal) as comparable bit patterns.
fn corners(mesh: &Mesh, t: [u32; 3]) -> Vec<Vec<u32>> {
    t.iter()
        .map(|&v| {
            let v = v as usize;
            let mut c: Vec<u32> = mesh.positions[v].to_array().iter().map(|x| x.to_bits()).collect();
            let a = &mesh.attributes;
            c.extend(a.uvs.iter().flat_map(|uv| uv[v].map(f32::to_bits)));
            c.extend(a.normals.iter().flat_map(|n| n[v].map(f32::to_bits)));
            c
        })
        .collect()
}

/// What `triorder order` writes, for every static method and each output format: triangle i of
/// the file is input triangle `order[i]` of the method's order, starting at the same corner or
/// rotated (never mirrored), each corner with its position and attributes bit for bit.
#[test]
fn order_writes_the_methods_order_with_winding_and_attributes() {
    let source = "assets/spot.obj@1000";
    let input = Source::parse(source).unwrap().mesh(None, 0).unwrap();
    assert!(input.attributes.uvs.is_some(), "the attributes must travel too");
    let dir = tempfile::tempdir().unwrap();
    for method in METHODS.iter().filter(|m| !m.per_node) {
        let resolved = order::resolve(method.name, 0).unwrap();
        let expected = common::static_order(&resolved, &input).unwrap();
        for ext in ["obj", "ply", "glb"] {
            let out = dir.path().join(format!("{}.{ext}", method.name));
            let o = Command::new(env!("CARGO_BIN_EXE_triorder"))
                .args(["order", source, "-o", out.to_str().unwrap(), "-m", method.name])
                .output()
                .unwrap();
            assert!(o.status.success(), "{} {ext}: {}", method.name, String::from_utf8_lossy(&o.stderr));
            let written = load::load_file(&out).unwrap();
            assert_eq!(written.triangle_count(), input.triangle_count(), "{} {ext}", method.name);
            for (i, (&w, &t)) in written.triangles.iter().zip(&expected).enumerate() {
                let (got, want) = (corners(&written, w), corners(&input, input.triangles[t as usize]));
                let rotated = (0..3).any(|k| (0..3).all(|c| got[(c + k) % 3] == want[c]));
                assert!(rotated, "{} {ext}: triangle {i} is not input triangle {t} with its winding", method.name);
            }
        }
    }
}

#[test]
fn every_parameter_rejects_bad_values_by_name() {
    for method in METHODS {
        assert!(
            order::resolve(&format!("{}:no_such_parameter=1", method.name), 0)
                .err()
                .is_some_and(|e| e.to_string().contains("no_such_parameter"))
        );
        for p in method.params {
            let bad: Vec<String> = match p.kind {
                ParamKind::Int { min, max } => {
                    vec![(min - 1).to_string(), (max + 1).to_string(), "x".into(), "1.5".into()]
                }
                ParamKind::Float { min, max } => {
                    vec![(min - 1.0).to_string(), (max + 1.0).to_string(), "nan".into(), "inf".into()]
                }
                ParamKind::Choice(_) => vec!["no-such-choice".into()],
                ParamKind::Seed => vec!["-1".into(), "x".into()],
            };
            for value in bad {
                let spec = format!("{}:{}={value}", method.name, p.name);
                let err = order::resolve(&spec, 0).err().unwrap_or_else(|| panic!("`{spec}` was accepted"));
                assert!(err.to_string().contains(p.name), "`{spec}`: {err}");
            }
            // And the default is accepted as written.
            if !matches!(p.kind, ParamKind::Seed) {
                order::resolve(&format!("{}:{}={}", method.name, p.name, p.default), 0).unwrap();
            }
        }
        // Building a method reads each of its parameters: a name its schema lacks panics here.
        let names: Vec<&str> = method.params.iter().map(|p| p.name).collect();
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(names.len(), unique.len(), "{}: a parameter declared twice", method.name);
    }
}

#[test]
fn unknown_methods_are_named() {
    let err = order::resolve("no-such-method:cache=3", 0).err().unwrap().to_string();
    assert!(err.contains("unknown method `no-such-method`") && err.contains("input"));
}

#[test]
fn random_orders_depend_on_the_seed() {
    let mesh = procedural::generate("grid:8x8", 0).unwrap().unwrap();
    let order = |spec: &str, seed: u64| common::static_order(&order::resolve(spec, seed).unwrap(), &mesh).unwrap();
    let (a, b, c) = (order("random:seed=1", 0), order("random:seed=2", 0), order("random", 1));
    assert_ne!(a, b);
    assert_eq!(a, c, "the run seed is the default seed");
}
