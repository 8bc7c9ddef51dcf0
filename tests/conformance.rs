//! Every registered ordering, on every test mesh: a permutation of the input triangles with
//! winding kept, deterministic for a seed, and clear errors for bad parameters. A new ordering
//! gets these tests by being registered in `order::METHODS`; nothing here names a method.

mod common;

use triorder::mesh::keyframes::Keyframes;
use triorder::mesh::{Mesh, procedural};
use triorder::order::{self, METHODS, OrderInput, ParamKind};
use triorder::topology::Topology;

fn test_meshes() -> Vec<Mesh> {
    let mut meshes: Vec<Mesh> = ["grid:16x8", "disk:950", "sphere:2000", "helix:3", "layers:4"]
        .iter()
        .map(|s| procedural::generate(s, 1).unwrap().unwrap())
        .collect();
    meshes.push(triorder::mesh::load::load_file(std::path::Path::new("assets/spot.obj")).unwrap());
    // Real, irregular meshes: one closed, one with non-manifold edges from decimation, one quad-dominant with seams.
    meshes.extend(["bunny_2k.ply", "dragon_vrip_res4.ply", "pirate.obj"].iter().filter_map(|m| common::real_mesh(m)));
    meshes
}

#[test]
fn every_method_returns_a_permutation_with_winding_kept() {
    let meshes = test_meshes();
    for method in METHODS {
        let resolved = order::resolve(method.name, 42).unwrap();
        for mesh in &meshes {
            let topology = Topology::new(mesh);
            let input = OrderInput { mesh, topology: &topology };
            if method.per_node {
                check_node_orders(&resolved, &input);
                continue;
            }
            let order =
                resolved.ordering.order(&input).unwrap_or_else(|e| panic!("{} on {}: {e}", method.name, mesh.name));
            order::check_permutation(&order, mesh.triangle_count())
                .unwrap_or_else(|e| panic!("{} on {}: {e}", method.name, mesh.name));
            // Winding: each drawn triangle is the input triangle it names, vertex for vertex.
            let drawn = mesh.reordered(&order);
            for (i, &t) in order.iter().enumerate() {
                assert_eq!(drawn.triangles[i], mesh.triangles[t as usize]);
            }
            // Determinism: the same spec and seed give the same order.
            let again = order::resolve(&resolved.canonical(), 7).unwrap().ordering.order(&input).unwrap();
            assert_eq!(order, again, "{} on {} is not deterministic", method.name, mesh.name);
        }
    }
}

/// A keyframe- and view-dependent method on a static mesh (one frame): every buffer a
/// permutation with winding kept, every lookup cell a buffer that exists, deterministic; and its
/// single-order interface refuses by name rather than returning one buffer as if it were all.
fn check_node_orders(resolved: &order::Resolved, input: &OrderInput) {
    let (name, mesh) = (resolved.method.name, input.mesh);
    let keyframes = Keyframes::still(mesh);
    let nodes =
        resolved.ordering.order_nodes(input, &keyframes).unwrap_or_else(|e| panic!("{name} on {}: {e}", mesh.name));
    assert!(!nodes.buffers.is_empty());
    for buffer in &nodes.buffers {
        order::check_permutation(buffer, mesh.triangle_count())
            .unwrap_or_else(|e| panic!("{name} on {}: {e}", mesh.name));
    }
    assert_eq!(nodes.lookup.frames(), 1);
    assert!(nodes.lookup.cells().iter().all(|&b| usize::from(b) < nodes.buffers.len()), "{name} on {}", mesh.name);
    order::run_nodes(resolved, input, &keyframes).unwrap();
    let again = order::resolve(&resolved.canonical(), 7).unwrap().ordering.order_nodes(input, &keyframes).unwrap();
    assert_eq!(
        (&nodes.buffers, &nodes.lookup),
        (&again.buffers, &again.lookup),
        "{name} on {} is not deterministic",
        mesh.name
    );
    let refused = resolved.ordering.order(input).err().unwrap_or_else(|| panic!("{name} gave one order"));
    assert!(refused.to_string().contains(name), "{refused}");
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
    let topology = Topology::new(&mesh);
    let input = OrderInput { mesh: &mesh, topology: &topology };
    let a = order::resolve("random:seed=1", 0).unwrap().ordering.order(&input).unwrap();
    let b = order::resolve("random:seed=2", 0).unwrap().ordering.order(&input).unwrap();
    let c = order::resolve("random", 1).unwrap().ordering.order(&input).unwrap();
    assert_ne!(a, b);
    assert_eq!(a, c, "the run seed is the default seed");
}
