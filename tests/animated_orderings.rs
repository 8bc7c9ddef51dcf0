//! Keyframe- and view-dependent orderings (Han & Sander 2017, issue 7): `hs17` and
//! `tipsify-per-frame` on the shared animated models and on static meshes as one frame.
//!
//! Covers: every buffer is a permutation and every lookup cell names one; `mode=single` keeps each
//! clip to its own buffers and `mode=joint` to k in all; same seed, same result; the k-means
//! iteration cap and the `converged` flag; view clustering on a static mesh lowers overdraw;
//! `tipsify-per-frame`'s buffer f is `sander07` on the mesh posed at frame f; evaluation views are
//! not optimization views; the lookup returns a node's own buffer from the node's direction;
//! linear blend skinning of RiggedSimple against a pose computed by hand from the file; and hs17
//! orderings of one scene sharing its rasterized nodes.
//!
//! Tests on the shared models return early (pass) when the data directory is absent.

mod common;

use std::collections::{BTreeSet, HashMap};
use std::path::PathBuf;

use glam::{DVec3, Mat4, Quat, Vec3};
use triorder::measure::{MeasureOptions, measure, measure_many};
use triorder::mesh::gltf::animation::{ClipSelection, read_animated, read_with_rest_pose};
use triorder::mesh::{Frames, Framing, Mesh, Scene};
use triorder::order::{self, Lookup, Orders, check_permutation};
use triorder::raster::ViewSet;
use triorder::raster::cpu::CpuRaster;
use triorder::raster::views::{icosphere_directions, perspective};

fn animated_path(file: &str) -> PathBuf {
    common::animated_file(file)
}

/// `file`'s clip (`None`: every clip), each resampled to `frames` frames.
fn animation(file: &str, clip: Option<&str>, frames: usize) -> Scene {
    let path = animated_path(file);
    let selection = ClipSelection { clip: clip.map(str::to_string), frames: Some(frames) };
    let animated = read_animated(&path, &selection).unwrap_or_else(|e| panic!("{e}"));
    let frames = Frames::of(&animated);
    Scene::animated(animated.mesh, frames)
}

/// A static mesh as an animation of one frame.
fn still(mesh: Mesh) -> Scene {
    Scene::still(mesh)
}

fn procedural(spec: &str) -> Mesh {
    triorder::mesh::procedural::generate(spec, 0).unwrap().unwrap()
}

/// The method's own output, not passed through `order::run`'s checks.
fn orders_of(spec: &str, scene: &Scene) -> Orders {
    let resolved = order::resolve(spec, 0).unwrap_or_else(|e| panic!("{spec}: {e}"));
    resolved.ordering.order(scene).unwrap_or_else(|e| panic!("{spec}: {e}"))
}

/// The buffer ids the lookup cells of `frames` name.
fn buffers_used(lookup: &Lookup, frames: std::ops::Range<usize>) -> BTreeSet<u16> {
    let cells = lookup.cells_per_frame();
    lookup.cells()[frames.start * cells..frames.end * cells].iter().copied().collect()
}

/// Every buffer a permutation of the triangles; a lookup of exactly one table per keyframe whose
/// every cell names an existing buffer; and no buffer that no cell can pick.
fn assert_well_formed(spec: &str, scene: &Scene, nodes: &Orders) {
    assert!(!nodes.buffers.is_empty(), "{spec}: no buffer");
    for (i, buffer) in nodes.buffers.iter().enumerate() {
        check_permutation(&buffer.order, scene.mesh.triangle_count())
            .unwrap_or_else(|why| panic!("{spec}: buffer {i}: {why}"));
    }
    assert_eq!(nodes.lookup.frames(), scene.frames.len(), "{spec}");
    assert_eq!(nodes.lookup.cells().len(), scene.frames.len() * nodes.lookup.cells_per_frame(), "{spec}");
    let used = buffers_used(&nodes.lookup, 0..scene.frames.len());
    assert!(used.iter().all(|&b| usize::from(b) < nodes.buffers.len()), "{spec}: {used:?}");
    assert_eq!(used.len(), nodes.buffers.len(), "{spec}: buffers no lookup cell picks");
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn every_buffer_is_a_permutation_and_every_cell_names_one() {
    for (file, frames) in [("RiggedSimple.glb", 3), ("RiggedFigure.glb", 3), ("Fox.glb", 2)] {
        let scene = animation(file, None, frames);
        for spec in ["hs17:views=12,res=32", "hs17:views=12,res=32,mode=joint,clusters=3", "tipsify-per-frame"] {
            let nodes = orders_of(spec, &scene);
            assert_well_formed(&format!("{file} {spec}"), &scene, &nodes);
            // The checked entry point accepts what the method returned, unchanged.
            let resolved = order::resolve(spec, 0).unwrap();
            let checked = order::run(&resolved, &scene).unwrap();
            assert_eq!((checked.buffers, checked.lookup), (nodes.buffers, nodes.lookup), "{file} {spec}");
        }
        // One buffer per keyframe, drawn from every direction of that keyframe only.
        let per_frame = orders_of("tipsify-per-frame", &scene);
        assert_eq!(per_frame.buffers.len(), scene.frames.len(), "{file}");
        for f in 0..scene.frames.len() {
            assert_eq!(buffers_used(&per_frame.lookup, f..f + 1), BTreeSet::from([f as u16]), "{file} frame {f}");
        }
    }
}

/// `mode=single` runs k-means per clip: a frame of one clip never draws with a buffer made for
/// another, and each clip has at most k. `mode=joint` shares at most k buffers among all clips.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn single_mode_keeps_clips_apart_and_joint_mode_shares_k_buffers() {
    let scene = animation("Fox.glb", None, 2);
    let clips = &scene.frames.clips;
    assert!(clips.len() >= 2, "Fox has several clips: {clips:?}");
    let k = 3;
    let single = orders_of(&format!("hs17:views=12,res=32,clusters={k}"), &scene);
    let per_clip: Vec<BTreeSet<u16>> = clips.iter().map(|(_, r)| buffers_used(&single.lookup, r.clone())).collect();
    for (i, (name, _)) in clips.iter().enumerate() {
        assert!(!per_clip[i].is_empty() && per_clip[i].len() <= k, "{name}: {:?}", per_clip[i]);
        for (j, (other, _)) in clips.iter().enumerate().skip(i + 1) {
            assert!(per_clip[i].is_disjoint(&per_clip[j]), "{name} and {other} share {:?}", per_clip[i]);
        }
    }
    assert_eq!(per_clip.iter().map(BTreeSet::len).sum::<usize>(), single.buffers.len());

    let joint = orders_of(&format!("hs17:views=12,res=32,clusters={k},mode=joint"), &scene);
    assert!(joint.buffers.len() <= k, "joint mode made {} buffers for k = {k}", joint.buffers.len());
    assert_well_formed("joint", &scene, &joint);
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn same_seed_same_buffers_and_lookup() {
    let scene = animation("Fox.glb", Some("Walk"), 3);
    for spec in ["hs17:views=12,res=32,seed=7", "hs17:views=42,res=32,seed=7,mode=joint", "tipsify-per-frame"] {
        let (a, b) = (orders_of(spec, &scene), orders_of(spec, &scene));
        assert!(a.buffers == b.buffers, "{spec}: buffers differ between runs");
        assert_eq!(a.lookup, b.lookup, "{spec}");
        assert_eq!((a.iterations, a.converged), (b.iterations, b.converged), "{spec}");
    }
    // The run seed stands in for a missing `seed=`: resolving with the same run seed agrees with
    // writing it out.
    let resolved = order::resolve("hs17:views=12,res=32", 7).unwrap();
    let implicit = resolved.ordering.order(&scene).unwrap();
    let explicit = orders_of("hs17:views=12,res=32,seed=7", &scene);
    assert!(implicit.buffers == explicit.buffers && implicit.lookup == explicit.lookup);
}

/// hs17 orderings of one scene rasterize its nodes once: a second ordering with other settings
/// but the same viewpoints and resolution reuses them, gives what it gives on a fresh scene, and
/// charges the reused rasterization to its own time, at what it cost the first; one with other
/// viewpoints rasterizes its own.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn hs17_orderings_of_one_scene_share_its_rasterized_nodes() {
    let scene = animation("Fox.glb", None, 3);
    let first = orders_of("hs17:views=42,res=32", &scene);
    assert_eq!(first.reused, 0.0, "the first ordering rasterizes its nodes");
    let phase = |o: &Orders| o.phases.iter().find(|(p, _)| *p == "rasterization").expect("a rasterization phase").1;
    for spec in ["hs17:views=42,res=32,lambda=3", "hs17:views=42,res=32,mode=joint,seed=4"] {
        let reusing = orders_of(spec, &scene);
        let fresh = orders_of(spec, &animation("Fox.glb", None, 3));
        assert!(reusing.buffers == fresh.buffers && reusing.lookup == fresh.lookup, "{spec}: reuse changed the result");
        assert_eq!(fresh.reused, 0.0);
        // The nodes reused, at what rasterizing them took the first run (its phase also holds
        // sorting the initial buffers).
        assert!(
            reusing.reused > 0.0 && reusing.reused <= phase(&first),
            "{spec}: {} vs {}",
            reusing.reused,
            phase(&first)
        );
        assert!(phase(&reusing) >= reusing.reused, "{spec}: the reused time is charged to the phase");
    }
    assert_eq!(orders_of("hs17:views=12,res=32", &scene).reused, 0.0, "other viewpoints, other nodes");
    assert_eq!(orders_of("hs17:views=42,res=64", &scene).reused, 0.0, "another resolution, other nodes");
}

/// The iteration cap: a run that needs n rounds converges, and reports it, when allowed n; capped
/// at n − 1 it stops there and says it did not converge. The first round can never confirm
/// convergence (there is no previous assignment to compare with), so `iterations=1` is always
/// unconverged; one cluster converges in the round after the first.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn kmeans_reports_its_rounds_and_whether_it_converged() {
    let scene = animation("RiggedFigure.glb", None, 3);
    let base = "hs17:views=42,res=32,clusters=5,seed=1";
    let free = orders_of(base, &scene);
    let Some(n) = free.iterations else { panic!("hs17 reports its rounds") };
    eprintln!("RiggedFigure {base}: {n} rounds, converged {}", free.converged);
    assert!(free.converged, "did not converge in the default cap of rounds ({n})");
    assert!(n >= 2, "convergence takes a confirming round: {n}");

    let once = orders_of(&format!("{base},iterations=1"), &scene);
    assert_eq!((once.iterations, once.converged), (Some(1), false));
    assert_well_formed("iterations=1", &scene, &once);

    let exact = orders_of(&format!("{base},iterations={n}"), &scene);
    assert_eq!((exact.iterations, exact.converged), (Some(n), true), "capped at the round it converges in");
    assert!(exact.buffers == free.buffers && exact.lookup == free.lookup);
    if n > 2 {
        let short = orders_of(&format!("{base},iterations={}", n - 1), &scene);
        assert_eq!((short.iterations, short.converged), (Some(n - 1), false));
        assert_well_formed("capped short", &scene, &short);
    }

    let one = orders_of("hs17:views=12,res=32,clusters=1", &scene);
    assert_eq!((one.iterations, one.converged), (Some(2), true));
    let capped = orders_of("hs17:views=12,res=32,clusters=1,iterations=2", &scene);
    assert_eq!((capped.iterations, capped.converged), (Some(2), true));
}

/// Mean OVR of `nodes` drawn from `views` random cameras, each with the buffer its lookup picks.
fn mean_ovr(scene: &Scene, nodes: &Orders, views: u32, seed: u64) -> f64 {
    let options =
        MeasureOptions { caches: vec![], views: Some(ViewSet::Random(views)), res: 64, seed, ..Default::default() };
    let measured = measure(scene, nodes, &options, &CpuRaster).unwrap();
    let values = measured.iter().flat_map(|m| &m.values);
    values.filter(|v| v.metric == "ovr_mean" && v.is_summary()).map(|v| v.value).next().expect("the views see the mesh")
}

/// Measuring several methods' orders of one animation together (each view of each frame
/// rasterized once, every order's depth test replayed) gives every value that measuring each on
/// its own gives: per clip, per view, with one buffer, one per frame and a lookup per view.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn measuring_orders_together_gives_each_ones_values() {
    let scene = animation("Fox.glb", None, 2);
    assert!(scene.frames.clips.len() >= 2, "per-clip values are compared too");
    let orders: Vec<Orders> = ["tipsify", "tipsify-per-frame", "hs17:views=12,res=32", "random"]
        .iter()
        .map(|spec| order::run(&order::resolve(spec, 3).unwrap(), &scene).unwrap())
        .collect();
    let options = MeasureOptions {
        caches: vec!["fifo:16".parse().unwrap()],
        views: Some(ViewSet::Random(24)),
        res: 64,
        ..Default::default()
    };
    let each: Vec<_> = orders.iter().map(|o| measure(&scene, o, &options, &CpuRaster).unwrap()).collect();
    let refs: Vec<&Orders> = orders.iter().collect();
    let together = measure_many(&scene, &refs, &options, &CpuRaster).unwrap();
    assert_eq!(together.len(), each.len());
    for (all, one) in together.iter().zip(&each) {
        let values = |m: &[triorder::measure::Measured]| m.iter().flat_map(|m| m.values.clone()).collect::<Vec<_>>();
        let (all, one) = (values(all), values(one));
        assert!(one.iter().filter(|v| v.metric == "ovr").count() > 24, "per-view ratios of several frames");
        assert_eq!(all, one);
    }
}

/// A static mesh is an animation of one frame; hs17 then clusters viewpoints only. On meshes
/// that occlude themselves, k view-dependent buffers draw with no more overdraw than one, and a
/// single cluster gives one buffer used everywhere.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn static_mesh_gets_view_clustered_buffers() {
    let mut meshes = vec![("helix:3".to_string(), procedural("helix:3"))];
    meshes.push(("bunny_2k".to_string(), common::real_mesh("bunny_2k.ply")));
    for (name, mesh) in meshes {
        let scene = still(mesh);
        assert_eq!(scene.frames.len(), 1);
        let one = orders_of("hs17:views=42,res=64,clusters=1", &scene);
        assert_eq!(one.buffers.len(), 1, "{name}");
        assert!(one.lookup.cells().iter().all(|&b| b == 0), "{name}");
        let five = orders_of("hs17:views=42,res=64,clusters=5", &scene);
        assert_well_formed(&name, &scene, &five);
        assert!(five.buffers.len() > 1, "{name}: one frame, yet the views did not split");
        for seed in [0, 1] {
            let (k1, k5) = (mean_ovr(&scene, &one, 100, seed), mean_ovr(&scene, &five, 100, seed));
            eprintln!("{name}: mean OVR over random:100 (seed {seed}): k=1 {k1:.4}, k=5 {k5:.4}");
            assert!(k5 <= k1, "{name}: k=5 draws with mean OVR {k5}, more than k=1's {k1}");
        }
    }
}

/// `tipsify-per-frame` reorders the same patches per frame by the dot rule: buffer f is exactly
/// `sander07` with the same parameters on the mesh posed (and framed) at keyframe f.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn tipsify_per_frame_is_sander07_on_each_posed_frame() {
    for (file, frames) in [("RiggedFigure.glb", 3), ("Fox.glb", 2)] {
        let scene = animation(file, None, frames);
        for params in ["", ":cache=12,lambda=0.6"] {
            let nodes = orders_of(&format!("tipsify-per-frame{params}"), &scene);
            let sander07 = order::resolve(&format!("sander07{params}"), 0).unwrap();
            assert_eq!(nodes.buffers.len(), scene.frames.len());
            let mut distinct = BTreeSet::new();
            for f in 0..scene.frames.len() {
                let posed = scene.frames.posed(&scene.mesh, f);
                let expected = common::static_order(&sander07, &posed).unwrap();
                assert!(nodes.buffers[f].order == expected, "{file}{params}: frame {f} differs from sander07");
                distinct.insert(expected);
            }
            eprintln!("{file}{params}: {} distinct buffers over {} frames", distinct.len(), scene.frames.len());
        }
    }
}

/// Han & Sander evaluate on random viewpoints, not the ones they optimize for: no `random:300`
/// camera (any of a few seeds) looks from an icosahedron viewpoint of `views=162`, though both
/// are the same perspective camera at 3r.
#[test]
fn evaluation_views_are_not_optimization_views() {
    let framing = Framing { center: DVec3::new(0.5, -1.0, 2.0), radius: 1.5 };
    let center = framing.center.as_vec3();
    let optimized: Vec<Vec3> = icosphere_directions(162).into_iter().map(|d| perspective(framing, d).eye).collect();
    assert_eq!(optimized.len(), 162);
    for seed in [0, 1, 42] {
        let random = ViewSet::Random(300).cameras(framing, seed);
        assert_eq!(random.len(), 300);
        let mut closest = f32::INFINITY;
        for camera in &random {
            assert!(camera.perspective);
            let offset = camera.eye - center;
            let radius = framing.radius as f32;
            assert!((offset.length() - 3.0 * radius).abs() < 1e-4 * radius);
            for eye in &optimized {
                closest = closest.min(offset.angle_between(*eye - center));
            }
        }
        eprintln!("seed {seed}: nearest random:300 eye is {:.3}° from an ico:162 eye", closest.to_degrees());
        assert!(closest > 1e-3, "seed {seed}: a random:300 eye is an ico:162 eye ({closest} rad away)");
    }
}

/// The lookup, asked from the exact direction (or eye) of an optimization viewpoint, returns the
/// buffer that viewpoint's node was assigned, for every keyframe: true for the icosahedron sets
/// whose spacing is coarser than the table's 10° cells.
#[test]
fn lookup_returns_each_nodes_buffer_from_its_own_direction() {
    let framing = Framing { center: DVec3::ZERO, radius: 2.0 };
    for views in [12u32, 42, 162, 642] {
        let directions = icosphere_directions(views);
        let n = directions.len();
        let frames = 3;
        // Every node of a frame gets its own buffer id, shuffled differently per frame.
        let assignment: Vec<u16> =
            (0..frames).flat_map(|f| (0..n).map(move |v| ((v * 7 + f * 5) % n) as u16)).collect();
        let lookup = Lookup::nearest(&directions, &assignment);
        assert_eq!(lookup.frames(), frames);
        for f in 0..frames {
            for (v, &d) in directions.iter().enumerate() {
                let want = usize::from(assignment[f * n + v]);
                assert_eq!(lookup.buffer(f, d), want, "ico:{views}, frame {f}, viewpoint {v} ({d})");
                assert_eq!(lookup.buffer(f, perspective(framing, d).eye), want, "ico:{views} eye, frame {f}, {v}");
            }
        }
    }
}

/// `triorder` reads glTF through the `gltf` crate's own accessors here, independently of the
/// loader: node TRS with the animation's values at a keyframe, world transforms down the parent
/// chain, inverse bind matrices, one vertex's joints and weights.
struct HandPose {
    /// Per node: parent.
    parents: Vec<Option<usize>>,
    /// Per node: rest translation, rotation, scale.
    rest: Vec<(Vec3, Quat, Vec3)>,
}

impl HandPose {
    fn world(&self, local: &[(Vec3, Quat, Vec3)], node: usize) -> Mat4 {
        let (t, r, s) = local[node];
        let m = Mat4::from_scale_rotation_translation(s, r, t);
        match self.parents[node] {
            Some(p) => self.world(local, p) * m,
            None => m,
        }
    }
}

/// RiggedSimple (two joints): one vertex blended between both joints, posed at a keyframe by the
/// glTF formula Σ wᵢ · world(jointᵢ) · inverseBind(jointᵢ) · p, from the file's own matrices; and
/// at rest every skinning matrix is the mesh node's placement, so the rest pose is the bind-pose
/// mesh, rigidly placed.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn rigged_simple_skins_one_vertex_as_computed_by_hand() {
    let path = animated_path("RiggedSimple.glb");
    let (document, buffers, _) = gltf::import(&path).unwrap();
    let data = |b: gltf::Buffer| Some(&buffers[b.index()][..]);

    let mut parents = vec![None; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            parents[child.index()] = Some(node.index());
        }
    }
    let rest: Vec<(Vec3, Quat, Vec3)> = document
        .nodes()
        .map(|n| {
            let (t, r, s) = n.transform().decomposed();
            (Vec3::from(t), Quat::from_array(r), Vec3::from(s))
        })
        .collect();
    let hand = HandPose { parents, rest };

    let skinned = document.nodes().find(|n| n.skin().is_some() && n.mesh().is_some()).unwrap();
    let skin = skinned.skin().unwrap();
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    assert_eq!(joints.len(), 2);
    let inverse_bind: Vec<Mat4> =
        skin.reader(data).read_inverse_bind_matrices().unwrap().map(|m| Mat4::from_cols_array_2d(&m)).collect();

    // The vertex whose weights are the most even split between the two joints.
    let primitive = skinned.mesh().unwrap().primitives().next().unwrap();
    let reader = primitive.reader(data);
    let positions: Vec<Vec3> = reader.read_positions().unwrap().map(Vec3::from).collect();
    let vertex_joints: Vec<[u16; 4]> = reader.read_joints(0).unwrap().into_u16().collect();
    let vertex_weights: Vec<[f32; 4]> = reader.read_weights(0).unwrap().into_f32().collect();
    let blend = |i: usize| {
        let mut w = vertex_weights[i];
        w.sort_by(|a, b| b.total_cmp(a));
        w[1]
    };
    let i = (0..positions.len()).max_by(|&a, &b| blend(a).total_cmp(&blend(b))).unwrap();
    assert!(blend(i) > 0.1, "no vertex blends two joints: best {}", blend(i));
    let skin_at = |local: &[(Vec3, Quat, Vec3)]| -> Vec3 {
        (0..4)
            .filter(|&k| vertex_weights[i][k] > 0.0)
            .map(|k| {
                let j = usize::from(vertex_joints[i][k]);
                vertex_weights[i][k] * (hand.world(local, joints[j]) * inverse_bind[j]).transform_point3(positions[i])
            })
            .sum()
    };

    // Rest: every joint's world(joint) · inverseBind(joint) is one and the same matrix, the world
    // transform of the node holding the skinned mesh (the file's Z-up to Y-up root), so the rest
    // pose is the bind-pose mesh placed by that node, undeformed.
    let placement = hand.world(&hand.rest, skinned.index());
    for (j, &node) in joints.iter().enumerate() {
        let product = hand.world(&hand.rest, node) * inverse_bind[j];
        assert!(product.abs_diff_eq(placement, 1e-4), "joint {j}: {product}, mesh node {placement}");
    }
    let (animated, rest_pose) = read_with_rest_pose(&path, &ClipSelection::default()).unwrap();
    let at_rest = animated.positions(&rest_pose);
    let size = animated.mesh.positions.iter().map(|p| p.length()).fold(0.0f32, f32::max);
    let tolerance = 1e-5 * size;
    for (v, (posed, bind)) in at_rest.iter().zip(&animated.mesh.positions).enumerate() {
        let placed = placement.transform_point3(*bind);
        assert!(posed.distance(placed) <= tolerance, "vertex {v}: rest {posed}, bind pose placed {placed}");
    }

    // The middle keyframe: every channel's value at its key of that time.
    let frame = &animated.clips[0].frames[1];
    let mut local = hand.rest.clone();
    let animation = document.animations().next().unwrap();
    for channel in animation.channels() {
        assert_ne!(channel.sampler().interpolation(), gltf::animation::Interpolation::CubicSpline);
        let reader = channel.reader(data);
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        let key = times.iter().position(|t| (t - frame.time).abs() < 1e-5).expect("a key at the keyframe's time");
        let node = channel.target().node().index();
        match reader.read_outputs().unwrap() {
            gltf::animation::util::ReadOutputs::Translations(mut t) => local[node].0 = Vec3::from(t.nth(key).unwrap()),
            gltf::animation::util::ReadOutputs::Rotations(r) => {
                local[node].1 = Quat::from_array(r.into_f32().nth(key).unwrap())
            }
            gltf::animation::util::ReadOutputs::Scales(mut s) => local[node].2 = Vec3::from(s.nth(key).unwrap()),
            gltf::animation::util::ReadOutputs::MorphTargetWeights(_) => {}
        }
    }
    let expected_rest = skin_at(&hand.rest);
    let expected = skin_at(&local);
    assert!(expected.distance(expected_rest) > 1e-3 * size, "the keyframe does not move vertex {i}");

    // The loader's vertex with that bind position and the same influences.
    let influences: HashMap<usize, f32> = (0..4)
        .filter(|&k| vertex_weights[i][k] > 0.0)
        .map(|k| (usize::from(vertex_joints[i][k]), vertex_weights[i][k]))
        .collect();
    let v = (0..animated.mesh.vertex_count())
        .find(|&v| animated.mesh.positions[v] == positions[i])
        .expect("the loader keeps the vertex's bind position");
    assert_eq!(animated.influences[v].len(), influences.len());
    let posed = animated.positions(frame)[v];
    eprintln!("RiggedSimple vertex {i} (weights {influences:?}): at rest {expected_rest}, keyframe 1 {expected}");
    assert!(posed.distance(expected) <= tolerance, "vertex {v}: skinned to {posed}, by hand {expected}");
    assert!(at_rest[v].distance(expected_rest) <= tolerance);
}
