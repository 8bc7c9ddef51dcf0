//! Reading skinned and animated glTF files into `Animated` meshes: the shared models (when the
//! data directory is there) and small hand-made files that pin down the interpolation formulas
//! and the errors.

mod common;

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::Vec3;
use serde_json::{Value, json};
use triorder::mesh::animated::{Animated, Pose};
use triorder::mesh::gltf::animation::{ClipSelection, read_animated, read_with_rest_pose};
use triorder::mesh::load::load_file;

fn animated_file(name: &str) -> PathBuf {
    common::animated_file(name)
}

fn all_clips() -> ClipSelection {
    ClipSelection::default()
}

fn max_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max)
}

fn extent(points: &[Vec3]) -> f32 {
    let lo = points.iter().copied().fold(Vec3::INFINITY, Vec3::min);
    let hi = points.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
    (hi - lo).max_element()
}

fn assert_weights_normalised(animated: &Animated, file: &str) {
    assert_eq!(animated.influences.len(), animated.mesh.vertex_count(), "{file}");
    for (v, influences) in animated.influences.iter().enumerate() {
        let sum: f32 = influences.iter().map(|(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{file}: vertex {v}'s weights sum to {sum}");
        assert!(influences.iter().all(|&(j, w)| w > 0.0 && (j as usize) < animated.joint_count), "{file}: vertex {v}");
    }
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn rigged_simple_has_one_clip_at_its_keyframes() {
    let path = animated_file("RiggedSimple.glb");
    let animated = read_animated(&path, &all_clips()).unwrap();
    assert_eq!(animated.clips.len(), 1);
    assert_eq!(animated.mesh.vertex_count(), 96);
    assert_eq!(animated.mesh.triangle_count(), 188);
    assert_eq!(animated.joint_count, 2);
    // MANIFEST.md: 3 keyframes over 2.08 s.
    let frames = &animated.clips[0].frames;
    assert_eq!(frames.len(), 3, "{:?}", frames.iter().map(|f| f.time).collect::<Vec<_>>());
    // Its keyframes are at 1/24, 25/24 and 50/24 s: the clip does not start at 0.
    let times: Vec<f32> = frames.iter().map(|f| f.time).collect();
    assert!(times.iter().zip([1.0, 25.0, 50.0]).all(|(t, k)| (t - k / 24.0).abs() < 1e-5), "{times:?}");
    assert_weights_normalised(&animated, "RiggedSimple.glb");
}

/// RiggedSimple is a cylinder along Z skinned to two bones: the lower bone stays put, the upper
/// one bends. Posed at its middle keyframe, the bottom ring is where it was at rest and the top
/// ring has moved.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn rigged_simple_bends_at_the_top_and_keeps_its_bottom() {
    let path = animated_file("RiggedSimple.glb");
    let (animated, rest) = read_with_rest_pose(&path, &all_clips()).unwrap();
    let at_rest = animated.positions(&rest);
    let axis = {
        let lo = at_rest.iter().copied().fold(Vec3::INFINITY, Vec3::min);
        let hi = at_rest.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
        (hi - lo).max_position()
    };
    let height: Vec<f32> = at_rest.iter().map(|p| p[axis]).collect();
    let (bottom, top) = height.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| (lo.min(h), hi.max(h)));
    let posed = animated.positions(&animated.clips[0].frames[1]);
    let moved = |v: usize| posed[v].distance(at_rest[v]);
    let length = top - bottom;
    let bottom_ring: Vec<usize> = (0..height.len()).filter(|&v| height[v] < bottom + 0.01 * length).collect();
    let top_ring: Vec<usize> = (0..height.len()).filter(|&v| height[v] > top - 0.01 * length).collect();
    assert!(!bottom_ring.is_empty() && !top_ring.is_empty());
    let bottom_moved = bottom_ring.iter().map(|&v| moved(v)).fold(0.0, f32::max);
    let top_moved = top_ring.iter().map(|&v| moved(v)).fold(f32::INFINITY, f32::min);
    eprintln!("RiggedSimple: axis {axis}, length {length}, bottom ring moved ≤ {bottom_moved}, top ring ≥ {top_moved}");
    assert!(bottom_moved < 1e-3 * length, "the bottom moved by {bottom_moved}");
    assert!(top_moved > 0.1 * length, "the top moved only {top_moved}");
}

/// The rest mesh is the static loader's mesh before posing: the same vertices and triangles in
/// the same order, and posed at rest the same positions.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn rest_pose_is_the_static_loaders_mesh() {
    let dir = common::data_dir();
    for file in
        ["RiggedSimple.glb", "RiggedFigure.glb", "CesiumMan.glb", "Fox.glb", "Soldier.glb", "RobotExpressive.glb"]
    {
        let path = dir.join("animated").join(file);
        let (animated, rest) = read_with_rest_pose(&path, &all_clips()).unwrap();
        let static_mesh = load_file(&path).unwrap();
        assert_eq!(animated.mesh.triangles, static_mesh.triangles, "{file}");
        assert_eq!(animated.mesh.attributes.uvs, static_mesh.attributes.uvs, "{file}");
        assert_eq!(animated.mesh.name, static_mesh.name, "{file}");
        // Morph targets the static loader leaves out would move the rest pose if any default
        // weight were not zero; none of these files has one.
        assert!(rest.morph_weights.iter().all(|&w| w == 0.0), "{file}: {:?}", rest.morph_weights);
        let posed = animated.positions(&rest);
        let error = max_distance(&posed, &static_mesh.positions);
        assert!(error <= 1e-5 * extent(&static_mesh.positions), "{file}: rest pose off by {error}");
    }
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn soldier_clips_pose_finite_positions() {
    let path = animated_file("Soldier.glb");
    let (animated, rest) = read_with_rest_pose(&path, &all_clips()).unwrap();
    let names: Vec<&str> = animated.clips.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Idle", "Run", "TPose", "Walk"]);
    let frame_counts: Vec<usize> = animated.clips.iter().map(|c| c.frames.len()).collect();
    // MANIFEST.md's largest sampler key counts: Idle 48, Run 17, TPose 1, Walk 25.
    assert_eq!(frame_counts, [48, 17, 1, 25]);
    for clip in &animated.clips {
        assert!(animated.positions(&clip.frames[0]).iter().all(|p| p.is_finite()), "{}", clip.name);
    }
    assert_weights_normalised(&animated, "Soldier.glb");

    // The TPose clip is the bind pose (every skinning matrix the identity, to float noise), not
    // the pose the file's nodes rest in: those hold another stance, a fair part of the figure's
    // size away (Hips alone is rotated differently).
    let tpose = animated.positions(&animated.clips[2].frames[0]);
    let size = extent(&animated.mesh.positions);
    let from_bind = max_distance(&tpose, &animated.mesh.positions);
    let from_rest = max_distance(&tpose, &animated.positions(&rest));
    eprintln!("Soldier: TPose vs bind pose {from_bind}, vs node rest pose {from_rest}, figure size {size}");
    assert!(from_bind < 1e-3 * size, "TPose is {from_bind} from the bind pose (figure size {size})");
    assert!(from_rest > 0.1 * size, "TPose is only {from_rest} from the node rest pose (figure size {size})");
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn resampling_gives_evenly_spaced_frames() {
    let path = animated_file("Soldier.glb");
    for n in [1, 2, 7, 30] {
        let animated = read_animated(&path, &ClipSelection { clip: Some("Walk".into()), frames: Some(n) }).unwrap();
        assert_eq!(animated.clips.len(), 1);
        let times: Vec<f32> = animated.clips[0].frames.iter().map(|f| f.time).collect();
        assert_eq!(times.len(), n);
        if n > 1 {
            let step = (times[n - 1] - times[0]) / (n - 1) as f32;
            assert!((times[n - 1] - times[0] - 1.0).abs() < 0.02, "Walk lasts about 1 s: {times:?}");
            for (i, t) in times.iter().enumerate() {
                assert!((t - (times[0] + step * i as f32)).abs() < 1e-5, "{times:?}");
            }
        }
    }
    // A clip whose keyframes are all at one instant has one frame however many are asked for.
    let tpose = read_animated(&path, &ClipSelection { clip: Some("TPose".into()), frames: Some(10) }).unwrap();
    assert_eq!(tpose.clips[0].frames.len(), 1);
}

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn clips_are_chosen_by_name() {
    let path = animated_file("Soldier.glb");
    let run = read_animated(&path, &ClipSelection { clip: Some("Run".into()), frames: None }).unwrap();
    assert_eq!(run.clips.len(), 1);
    assert_eq!(run.clips[0].name, "Run");
    assert_eq!(run.clips[0].frames.len(), 17);
    let error =
        read_animated(&path, &ClipSelection { clip: Some("Dance".into()), frames: None }).unwrap_err().to_string();
    assert!(error.contains("Soldier.glb") && error.contains("'Dance'"), "{error}");
    assert!(error.contains("Idle, Run, TPose, Walk"), "{error}");
    let zero = read_animated(&path, &ClipSelection { clip: None, frames: Some(0) });
    assert!(zero.is_err());
}

/// Clip names with their keyframe counts.
type Clips = &'static [(&'static str, usize)];

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn khronos_and_mixamo_samples_load() {
    let dir = common::data_dir();
    // (file, triangles, clips with their keyframe counts as MANIFEST.md lists them).
    let expected: [(&str, usize, Clips); 5] = [
        ("CesiumMan.glb", 4_672, &[("animation_0", 49)]),
        ("Fox.glb", 576, &[("Survey", 83), ("Walk", 18), ("Run", 25)]),
        ("Xbot.glb", 49_112, &[]),
        ("Michelle.glb", 28_106, &[]),
        ("BrainStem.glb", 61_666, &[]),
    ];
    for (file, triangles, clips) in expected {
        let path = dir.join("animated").join(file);
        let animated = read_animated(&path, &all_clips()).unwrap();
        assert_eq!(animated.mesh.triangle_count(), triangles, "{file}");
        assert_weights_normalised(&animated, file);
        for (name, frames) in clips {
            let clip = animated.clips.iter().find(|c| c.name == *name).unwrap_or_else(|| panic!("{file}: {name}"));
            assert_eq!(clip.frames.len(), *frames, "{file} {name}");
        }
        for clip in &animated.clips {
            let last = clip.frames.last().unwrap();
            assert!(animated.positions(last).iter().all(|p| p.is_finite()), "{file} {}", clip.name);
        }
    }
}

/// RobotExpressive's face is a rigid mesh (no skin) hanging off a bone, with three morph
/// targets: its vertices follow the bone through the joint that stands for its node, and the
/// clips carry its morph weights.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn robot_expressive_moves_its_rigid_head_and_animates_its_morphs() {
    let path = animated_file("RobotExpressive.glb");
    let (animated, rest) = read_with_rest_pose(&path, &all_clips()).unwrap();
    assert_eq!(animated.morph_targets.len(), 3);
    assert_eq!(animated.clips.len(), 14);
    let morphed: Vec<usize> = (0..animated.mesh.vertex_count())
        .filter(|&v| animated.morph_targets.iter().any(|t| t[v] != Vec3::ZERO))
        .collect();
    assert!(!morphed.is_empty());
    // The morphed vertices are rigid: one influence, weight 1, on their node's joint.
    assert!(morphed.iter().all(|&v| animated.influences[v].len() == 1));
    let at_rest = animated.positions(&rest);
    let wave = animated.clips.iter().find(|c| c.name == "Wave").unwrap();
    let frame = &wave.frames[wave.frames.len() / 2];
    let posed = animated.positions(frame);
    let head_moved = morphed.iter().map(|&v| posed[v].distance(at_rest[v])).fold(0.0, f32::max);
    assert!(head_moved > 0.0, "the head does not follow its bone");
    // Every clip has a weights channel for the face, but all its values are 0 (three.js's
    // example sets the expressions from its UI), so the sampled weights stay 0.
    assert!(animated.clips.iter().flat_map(|c| &c.frames).all(|f| f.morph_weights == [0.0; 3]));
}

/// The measurements the report quotes: size, joints, clips and frames, load time.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn shared_characters_match_the_manifest() {
    let dir = common::data_dir();
    // (file, triangles, clips with their keyframe counts), as data/MANIFEST.md lists them.
    type Facts = (&'static str, usize, &'static [(&'static str, usize)]);
    let expected: [Facts; 3] = [
        ("Soldier.glb", 11_376, &[("Idle", 48), ("Run", 17), ("TPose", 1), ("Walk", 25)]),
        (
            "Xbot.glb",
            49_112,
            &[
                ("agree", 56),
                ("headShake", 78),
                ("idle", 76),
                ("run", 22),
                ("sad_pose", 2),
                ("sneak_pose", 2),
                ("walk", 30),
            ],
        ),
        ("Michelle.glb", 28_106, &[("SambaDance", 547), ("TPose", 2)]),
    ];
    for (file, triangles, clips) in expected {
        let animated = read_animated(&dir.join("animated").join(file), &all_clips()).unwrap();
        assert_eq!(animated.mesh.triangle_count(), triangles, "{file}");
        let found: Vec<(&str, usize)> = animated.clips.iter().map(|c| (c.name.as_str(), c.frames.len())).collect();
        assert_eq!(found, clips, "{file}");
    }
}

// ---- Hand-made files ----

/// One animation channel of a hand-made file.
struct Channel {
    node: usize,
    path: &'static str,
    interpolation: &'static str,
    times: Vec<f32>,
    /// Flat float values: VEC3 elements (SCALAR for weights).
    values: Vec<f32>,
}

/// A glTF (JSON with its buffer inline as base64) holding one triangle skinned to two joints:
/// node 0 holds the mesh, node 1 is the root joint and node 2 its child joint. Vertex v has
/// `joints[v]` and `weights[v]`. The inverse bind matrices are identity, so a vertex bound to
/// node 2 moves by node 2's translation.
fn skinned_triangle(joints: [[u8; 4]; 3], weights: [[f32; 4]; 3], channels: &[Channel]) -> String {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut add = |bytes: Vec<u8>, component: u32, count: usize, kind: &str| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        accessors
            .push(json!({"bufferView": views.len() - 1, "componentType": component, "count": count, "type": kind}));
        accessors.len() - 1
    };
    let floats = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let position = add(floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]), 5126, 3, "VEC3");
    let joint = add(joints.concat(), 5121, 3, "VEC4");
    let weight = add(floats(&weights.concat()), 5126, 3, "VEC4");
    let mut samplers = Vec::new();
    let mut targets = Vec::new();
    for (c, channel) in channels.iter().enumerate() {
        let input = add(floats(&channel.times), 5126, channel.times.len(), "SCALAR");
        let (kind, width) = if channel.path == "weights" { ("SCALAR", 1) } else { ("VEC3", 3) };
        let output = add(floats(&channel.values), 5126, channel.values.len() / width, kind);
        samplers.push(json!({"input": input, "output": output, "interpolation": channel.interpolation}));
        targets.push(json!({"sampler": c, "target": {"node": channel.node, "path": channel.path}}));
    }
    // glTF requires POSITION's bounds.
    accessors[position]["min"] = json!([0.0, 0.0, 0.0]);
    accessors[position]["max"] = json!([1.0, 1.0, 0.0]);
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let mut gltf = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"children": [2]}, {"translation": [0.0, 0.0, 0.0]}],
        "skins": [{"joints": [1, 2]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": position, "JOINTS_0": joint, "WEIGHTS_0": weight}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
    });
    if !channels.is_empty() {
        gltf["animations"] = json!([{"name": "move", "samplers": samplers, "channels": targets}]);
    }
    gltf.to_string()
}

/// Every vertex on joint 1 (node 2), except vertex 0 on joint 0.
const ON_CHILD: ([[u8; 4]; 3], [[f32; 4]; 3]) = ([[0, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]], [[1.0, 0.0, 0.0, 0.0]; 3]);

fn translate_child(interpolation: &'static str, times: Vec<f32>, values: Vec<f32>) -> Channel {
    Channel { node: 2, path: "translation", interpolation, times, values }
}

fn write(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("made.gltf");
    std::fs::write(&path, text).unwrap();
    path
}

/// Where vertex 1 (on the animated joint) is at each frame of the only clip, with that frame's time.
fn track_vertex_1(path: &Path, frames: Option<usize>) -> Vec<(f32, Vec3)> {
    let animated = read_animated(path, &ClipSelection { clip: None, frames }).unwrap();
    assert_eq!(animated.joint_count, 2);
    let pose = |f: &Pose| (f.time, animated.positions(f)[1] - Vec3::X);
    animated.clips[0].frames.iter().map(pose).collect()
}

#[test]
fn linear_step_and_cubic_spline_follow_the_spec() {
    let dir = tempfile::tempdir().unwrap();
    let (joints, weights) = ON_CHILD;
    let linear = translate_child("LINEAR", vec![0.0, 1.0], vec![0.0, 0.0, 0.0, 2.0, 0.0, 0.0]);
    let path = write(dir.path(), &skinned_triangle(joints, weights, &[linear]));
    let offsets = track_vertex_1(&path, Some(5));
    let xs: Vec<f32> = offsets.iter().map(|(_, p)| p.x).collect();
    assert!(xs.iter().zip([0.0, 0.5, 1.0, 1.5, 2.0]).all(|(a, b)| (a - b).abs() < 1e-6), "{xs:?}");
    // Vertex 0 is on the root joint, which does not move.
    let animated = read_animated(&path, &ClipSelection::default()).unwrap();
    assert_eq!(animated.clips[0].frames.len(), 2);
    assert!(animated.clips[0].frames.iter().all(|f| animated.positions(f)[0] == Vec3::ZERO));

    let step = translate_child("STEP", vec![0.0, 1.0], vec![0.0, 0.0, 0.0, 2.0, 0.0, 0.0]);
    let path = write(dir.path(), &skinned_triangle(joints, weights, &[step]));
    let xs: Vec<f32> = track_vertex_1(&path, Some(5)).iter().map(|(_, p)| p.x).collect();
    assert_eq!(xs, [0.0, 0.0, 0.0, 0.0, 2.0]);

    // Hermite with the out-tangent 1 at key 0, keys 0 and 2 at t = 0 and 2: at t = 1 (s = 1/2)
    // p = 0 + 2·(1/8 − 2/4 + 1/2)·1 + (−2/8 + 3/4)·2 + 0 = 1/4 + 1 = 1.25.
    let cubic = translate_child(
        "CUBICSPLINE",
        vec![0.0, 2.0],
        vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    let path = write(dir.path(), &skinned_triangle(joints, weights, &[cubic]));
    let offsets = track_vertex_1(&path, Some(3));
    assert!((offsets[1].1.x - 1.25).abs() < 1e-6, "{offsets:?}");
    assert!((offsets[2].1.x - 2.0).abs() < 1e-6, "{offsets:?}");
}

#[test]
fn keyframes_are_the_union_of_sampler_times_and_values_clamp_outside_them() {
    let dir = tempfile::tempdir().unwrap();
    let (joints, weights) = ON_CHILD;
    let late = translate_child("LINEAR", vec![0.5, 1.0], vec![1.0, 0.0, 0.0, 3.0, 0.0, 0.0]);
    // A scale channel on the root over a longer range, constant, and with an instant that
    // differs from one of the translation's by less than a microsecond.
    let long = Channel {
        node: 1,
        path: "scale",
        interpolation: "LINEAR",
        times: vec![0.0, 0.5000001, 2.0],
        values: vec![1.0; 9],
    };
    let path = write(dir.path(), &skinned_triangle(joints, weights, &[late, long]));
    let offsets = track_vertex_1(&path, None);
    let times: Vec<f32> = offsets.iter().map(|(t, _)| *t).collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 2.0]);
    let xs: Vec<f32> = offsets.iter().map(|(_, p)| p.x).collect();
    assert_eq!(xs, [1.0, 1.0, 3.0, 3.0]);
}

/// `text` with one morph target on the triangle (every vertex raised by 1 along Z), default
/// weight 0.5 from the mesh.
fn with_morph_target(text: &str) -> String {
    let mut gltf: Value = serde_json::from_str(text).unwrap();
    let deltas: Vec<u8> = [0.0f32, 0.0, 1.0].repeat(3).iter().flat_map(|f| f.to_le_bytes()).collect();
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&deltas));
    let buffers = gltf["buffers"].as_array_mut().unwrap();
    buffers.push(json!({"byteLength": deltas.len(), "uri": uri}));
    let buffer = buffers.len() - 1;
    let views = gltf["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": buffer, "byteLength": deltas.len()}));
    let view = views.len() - 1;
    let accessors = gltf["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": view, "componentType": 5126, "count": 3, "type": "VEC3"}));
    let accessor = accessors.len() - 1;
    gltf["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": accessor}]);
    gltf["meshes"][0]["weights"] = json!([0.5]);
    gltf.to_string()
}

/// Morph deltas are added before skinning, with the mesh's default weight at rest and the
/// animated weight in the clip.
#[test]
fn morph_weights_add_deltas_before_skinning() {
    let dir = tempfile::tempdir().unwrap();
    let (joints, weights) = ON_CHILD;
    let weight =
        Channel { node: 0, path: "weights", interpolation: "LINEAR", times: vec![0.0, 1.0], values: vec![0.0, 1.0] };
    let shift = translate_child("STEP", vec![0.0], vec![0.0, 2.0, 0.0]);
    let path = write(dir.path(), &with_morph_target(&skinned_triangle(joints, weights, &[weight, shift])));
    let (animated, rest) =
        read_with_rest_pose(&path, &ClipSelection { clip: Some("move".into()), frames: Some(3) }).unwrap();
    assert_eq!(animated.morph_targets, [vec![Vec3::Z; 3]]);
    assert_eq!(rest.morph_weights, [0.5]);
    assert_eq!(animated.positions(&rest)[1], Vec3::new(1.0, 0.0, 0.5));
    let frames = &animated.clips[0].frames;
    assert_eq!(frames.iter().map(|f| f.morph_weights[0]).collect::<Vec<_>>(), [0.0, 0.5, 1.0]);
    // Vertex 1 is on the joint moved by (0, 2, 0); vertex 0 on the still one.
    assert_eq!(animated.positions(&frames[2])[1], Vec3::new(1.0, 2.0, 1.0));
    assert_eq!(animated.positions(&frames[1])[0], Vec3::new(0.0, 0.0, 0.5));
}

#[test]
fn broken_skins_and_animations_are_errors_that_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let (joints, weights) = ON_CHILD;
    let channel = || translate_child("LINEAR", vec![0.0, 1.0], vec![0.0; 6]);
    let error = |text: String| {
        let path = write(dir.path(), &text);
        let error = read_animated(&path, &ClipSelection::default()).unwrap_err().to_string();
        assert!(error.contains("made.gltf"), "{error}");
        error
    };

    let mut nan = weights;
    nan[1][0] = f32::NAN;
    let e = error(skinned_triangle(joints, nan, &[channel()]));
    assert!(e.contains("mesh 0 primitive 0") && e.contains("WEIGHTS_0") && e.contains("element 1"), "{e}");
    assert!(e.contains("non-finite"), "{e}");

    let mut zero = weights;
    zero[2] = [0.0; 4];
    let e = error(skinned_triangle(joints, zero, &[channel()]));
    assert!(e.contains("mesh 0 primitive 0") && e.contains("vertex 2") && e.contains("weights are all 0"), "{e}");

    let mut far = joints;
    far[0][0] = 7;
    let e = error(skinned_triangle(far, weights, &[channel()]));
    assert!(e.contains("JOINTS_0 of vertex 0 names joint 7, but the skin has 2 joints"), "{e}");

    let e = error(skinned_triangle(joints, weights, &[]));
    assert!(e.contains("no animation clips"), "{e}");

    let mut gltf: Value = serde_json::from_str(&skinned_triangle(joints, weights, &[channel()])).unwrap();
    gltf["animations"][0]["channels"][0]["target"]["node"] = json!(99);
    let e = error(gltf.to_string());
    assert!(e.contains("animation 0 channel 0: targets node 99"), "{e}");

    gltf["animations"][0]["channels"][0]["target"] = json!({"node": 2, "path": "pointer"});
    let e = error(gltf.to_string());
    assert!(e.contains("unsupported target path"), "{e}");

    let short = translate_child("CUBICSPLINE", vec![0.0, 1.0], vec![0.0; 6]);
    let e = error(skinned_triangle(joints, weights, &[short]));
    assert!(e.contains("2 keyframes of CubicSpline Translation need 18"), "{e}");

    let backwards = translate_child("LINEAR", vec![1.0, 0.0], vec![0.0; 6]);
    let e = error(skinned_triangle(joints, weights, &[backwards]));
    assert!(e.contains("time 1 comes before time 0"), "{e}");

    let no_morphs = Channel { node: 0, path: "weights", interpolation: "LINEAR", times: vec![0.0], values: vec![1.0] };
    let e = error(skinned_triangle(joints, weights, &[no_morphs]));
    assert!(e.contains("no morph targets"), "{e}");
}

/// Han & Sander's Table 1 rows at subdivision 1 and 2 need the subdivided character to animate:
/// Soldier's Walk, subdivided twice, has 16× the triangles and every posed frame stays within the
/// posed original's bounding box (Loop's stencils and the blended influences are convex
/// combinations, up to the blend of different joints' matrices: 2% of the box allowed).
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn soldier_subdivided_twice_still_walks() {
    use triorder::mesh::subdivide::loop_subdivide;
    let path = animated_file("Soldier.glb");
    let walk = ClipSelection { clip: Some("Walk".into()), frames: None };
    let animated = read_animated(&path, &walk).unwrap();
    let fine = loop_subdivide(&animated, 2).unwrap();
    assert_eq!(fine.mesh.triangle_count(), 16 * animated.mesh.triangle_count());
    let bounds = |points: &[Vec3]| {
        points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    };
    let mut moved = false;
    for (i, pose) in fine.clips[0].frames.iter().enumerate() {
        let (lo, hi) = bounds(&animated.positions(&animated.clips[0].frames[i]));
        let slack = 0.02 * (hi - lo).length();
        let posed = fine.positions(pose);
        assert!(posed.iter().all(|p| p.is_finite() && p.cmpge(lo - slack).all() && p.cmple(hi + slack).all()));
        moved |= i > 0 && posed != fine.positions(&fine.clips[0].frames[0]);
    }
    assert!(moved, "the subdivided soldier does not move");
}
