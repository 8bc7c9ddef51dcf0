//! Skinned and animated glTF 2.0 files read into [`Animated`] meshes, for Han & Sander 2017.
//!
//! Han & Sander 2017 (§3) optimise triangle orders over a finite set of (keyframe, viewpoint)
//! configurations: an animation enters their method as a list of poses, not as a continuous
//! motion, and every pose costs a rendering per viewpoint per cluster. So each clip is sampled
//! here at its keyframes, the instants at which the file itself gives values (the union of its
//! samplers' input times), or, where a caller wants a fixed budget per clip (the paper's clips
//! have 20 to 135 keyframes), at N evenly spaced instants.
//!
//! The glTF 2.0 specification's rules, by section:
//! - §3.5.3 *Transformations*: a node's local matrix is T·R·S, and its world transform the
//!   product of its ancestors' local matrices and its own.
//! - §3.7.2.2 *Morph Targets*: a target's `POSITION` deltas, times its weight, are added to the
//!   base positions (before skinning); the weights are the node's `weights`, else the mesh's,
//!   else zero.
//! - §3.7.3 *Skins*: a skinned vertex is moved by the weighted sum of its joints' matrices, each
//!   the joint node's world transform times the skin's inverse bind matrix; the transform of the
//!   node that holds the skinned mesh is ignored.
//! - §3.11 *Animations*: channels animate a node's translation, rotation, scale or morph
//!   weights through samplers of keyframe times and values; outside a sampler's time range its
//!   first or last value holds.
//! - Appendix C, *Animation Sampler Interpolation Modes*: STEP, LINEAR (spherical linear
//!   interpolation for rotations) and CUBICSPLINE (Hermite, with tangents scaled by the keyframe
//!   interval).
//!
//! Parsing, accessor decoding, the node hierarchy checks and primitive reading are
//! [`super`]'s, shared with the static loader, so the rest mesh here is the static
//! loader's mesh before posing: same vertices, same triangles in the same order.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::animation::{Interpolation, Property};
use ::gltf::json::validation::Checked;
use ::gltf::scene::Transform;
use ::gltf::{Document, Node};
use glam::{Mat4, Quat, Vec3, Vec4};

use super::Mesh;
use super::accessors::read_vectors;
use super::document::open;
use super::primitive::Part;
use super::scene::{Hierarchy, ScenePart, inverse_bind_matrices};
use crate::error::{Error, Result};
use crate::mesh::animated::{Animated, Clip, Pose};
use crate::mesh::load::LoadReport;

/// Keyframe times closer than this (seconds) are one keyframe: exporters write the same
/// instant with float noise in different samplers.
const SAME_INSTANT: f32 = 1e-6;

/// Which clips to keep and how to sample them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ClipSelection {
    /// The clip to keep, by name (every clip of that name); `None` keeps every clip. A clip
    /// without a name is called `animation_I`, I its index in the file.
    pub clip: Option<String>,
    /// Sample each kept clip at this many evenly spaced instants from its first keyframe to its
    /// last, instead of at its keyframes; a clip whose keyframes are all at one instant still
    /// gives one frame.
    pub frames: Option<usize>,
}

/// Reads the skinned, morphed and rigid meshes of a glTF or GLB file's scene with its animation
/// clips, sampled as `selection` says. See [`read_with_rest_pose`].
pub fn read_animated(path: &Path, selection: &ClipSelection) -> Result<Animated> {
    read_with_rest_pose(path, selection).map(|(animated, _)| animated)
}

/// Checks that `path` is a glTF/GLB file with the clip `selection` asks for, reading the document
/// but posing nothing: so a run refuses a misspelt clip before any work.
pub fn check_selection(path: &Path, selection: &ClipSelection) -> Result<()> {
    let origin = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::input(&origin, format!("cannot read: {e}")))?;
    let binary = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let (document, _) = open(&bytes, &origin, path.parent(), binary)?;
    choose_clips(&clip_names(&document), selection).map(drop).map_err(|problem| Error::input(&origin, problem))
}

/// Every animation's name, an unnamed one called `animation_I` (I its index in the file).
fn clip_names(document: &::gltf::Document) -> Vec<String> {
    document.animations().map(|a| a.name().map_or_else(|| format!("animation_{}", a.index()), str::to_string)).collect()
}

/// The indices of the clips `selection` keeps, or why there are none.
fn choose_clips(names: &[String], selection: &ClipSelection) -> std::result::Result<Vec<usize>, String> {
    if names.is_empty() {
        return Err("no animation clips: the file has no animations".into());
    }
    match &selection.clip {
        None => Ok((0..names.len()).collect()),
        Some(wanted) => {
            let chosen: Vec<usize> = (0..names.len()).filter(|&a| &names[a] == wanted).collect();
            if chosen.is_empty() {
                return Err(format!("no animation clip named '{wanted}'; the clips are: {}", names.join(", ")));
            }
            Ok(chosen)
        }
    }
}

/// Reads `path` as [`read_animated`] does, with the pose the file shows when no animation plays
/// (every node at its own transform, morph weights at their defaults): posed by it, a file
/// without morph targets gives the positions [`super::read`] gives.
///
/// Every triangle primitive of every mesh node of the default scene is merged into the rest
/// mesh, in the static loader's order. A skinned primitive keeps its bind-space positions and
/// normals, with its `JOINTS_n`/`WEIGHTS_n` as influences (weights normalised to sum to 1) on
/// global joints. A primitive of an unskinned node keeps its node-space positions and normals,
/// each vertex bound with weight 1 to a joint that is the node's world transform (so it follows
/// any animated ancestor); where that transform mirrors at rest, its triangles' winding is
/// reversed as the static loader does, so the triangles are the same. Joints are shared: one
/// per distinct (node, inverse bind matrix), so skins over the same skeleton, or rigid meshes on
/// one node, do not multiply them.
///
/// Frame times are the file's: seconds on the clip's timeline, which starts at 0 even where the
/// first keyframe does not (RiggedSimple's is at 1/24 s). Unlike the static loader, which leaves
/// a vertex with no joint weight where it is, this refuses it: it has no place in a pose. The
/// attributes the static loader reports as left out are left out here too, without the report
/// ([`super::read`] gives it).
pub fn read_with_rest_pose(path: &Path, selection: &ClipSelection) -> Result<(Animated, Pose)> {
    let origin = path.display().to_string();
    let fail = |problem: String| Error::input(&origin, problem);
    if selection.frames == Some(0) {
        return Err(Error::usage("a clip resampled to 0 frames has nothing to pose; ask for at least 1"));
    }
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(extension.as_deref(), Some("glb" | "gltf")) {
        return Err(fail(
            "is not a .glb or .gltf file: only glTF holds animations (--clip, --frames, --subdiv or `#...`); \
             name it without them to load it as a static mesh"
                .to_string(),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let binary = extension.as_deref() == Some("glb");
    let (document, buffers) = open(&bytes, &origin, path.parent(), binary)?;

    let hierarchy = Hierarchy::of(&document).map_err(fail)?;
    let rest_local = super::scene::local_transforms(&document).map_err(fail)?;
    let rest_world = hierarchy.world(&rest_local);
    let (rig, parts) = Rig::read(&document, &buffers, &rest_world).map_err(fail)?;
    let (positions, triangles, attributes) = super::primitive::merge(parts, &mut LoadReport::default());
    let mesh = Mesh::new(origin.as_str(), positions, triangles, attributes)?;
    let rest = rig.pose(0.0, &rest_world);

    let chosen = choose_clips(&clip_names(&document), selection).map_err(fail)?;
    let names = clip_names(&document);
    let animations: Vec<::gltf::Animation<'_>> = document.animations().collect();
    let mut clips = Vec::with_capacity(chosen.len());
    for a in chosen {
        let tracks = read_tracks(&document, &animations[a], &buffers, &rig.morph_slots).map_err(fail)?;
        let name = names[a].clone();
        let frames = sample_clip(&rig, &hierarchy, &rest_local, &document, &tracks, selection.frames)
            .map_err(|problem| fail(format!("clip '{name}': {problem}")))?;
        clips.push(Clip { name, frames });
    }
    let animated = Animated {
        mesh,
        influences: rig.influences,
        morph_targets: rig.morph_targets,
        joint_count: rig.joints.len(),
        clips,
    };
    Ok((animated, rest))
}

/// What moves the rest mesh: joints, influences and morph targets.
struct Rig {
    /// Per joint: the node whose world transform moves it, and the matrix applied first (the
    /// skin's inverse bind matrix, or identity for a rigid node's joint).
    joints: Vec<(usize, Mat4)>,
    influences: Vec<Vec<(u32, f32)>>,
    morph_targets: Vec<Vec<Vec3>>,
    /// Per node whose mesh has morph targets: the index of its first target and how many.
    morph_slots: HashMap<usize, (usize, usize)>,
    /// Per morph target: its weight when no animation sets it.
    default_weights: Vec<f32>,
}

impl Rig {
    /// Reads the scene's triangle primitives (placed nowhere: rest positions stay in bind or
    /// node space) and what moves them; `rest_world` are the nodes' world transforms at rest.
    fn read(
        document: &Document,
        buffers: &[Vec<u8>],
        rest_world: &[Mat4],
    ) -> std::result::Result<(Rig, Vec<Part>), String> {
        let scene = super::scene::scene_parts(document, buffers, &mut LoadReport::default())?;
        let total: usize = scene.iter().map(|s| s.part.positions.len()).sum();
        let mut rig = Rig {
            joints: Vec::new(),
            influences: Vec::with_capacity(total),
            morph_targets: Vec::new(),
            morph_slots: HashMap::new(),
            default_weights: Vec::new(),
        };
        let mut joint_ids: HashMap<(usize, [u32; 16]), u32> = HashMap::new();
        let mut joint = |node: usize, offset: Mat4| -> u32 {
            let next = rig.joints.len() as u32;
            *joint_ids.entry((node, offset.to_cols_array().map(f32::to_bits))).or_insert_with(|| {
                rig.joints.push((node, offset));
                next
            })
        };
        let mut skin_joints: HashMap<usize, Vec<u32>> = HashMap::new();
        let mut parts = Vec::with_capacity(scene.len());
        let mut base = 0;
        for ScenePart { node, primitive, at, mut part } in scene {
            let n = part.positions.len();
            match node.skin() {
                Some(skin) => {
                    let ids = match skin_joints.entry(skin.index()) {
                        Entry::Occupied(known) => known.into_mut(),
                        Entry::Vacant(slot) => {
                            let inverse_bind = inverse_bind_matrices(&skin, buffers)?;
                            slot.insert(skin.joints().zip(inverse_bind).map(|(j, m)| joint(j.index(), m)).collect())
                        }
                    };
                    for v in 0..n {
                        rig.influences.push(vertex_influences(&part, v, ids, &at)?);
                    }
                }
                None => {
                    part.keep_front_faces(rest_world[node.index()]);
                    let id = joint(node.index(), Mat4::IDENTITY);
                    rig.influences.extend(std::iter::repeat_n(vec![(id, 1.0)], n));
                }
            }
            let targets: Vec<::gltf::mesh::MorphTarget<'_>> = primitive.morph_targets().collect();
            if !targets.is_empty() {
                let (first, count) = match rig.morph_slots.entry(node.index()) {
                    Entry::Occupied(known) => *known.get(),
                    Entry::Vacant(slot) => {
                        let first = rig.morph_targets.len();
                        rig.default_weights.extend(default_morph_weights(&node, targets.len())?);
                        rig.morph_targets.resize(first + targets.len(), vec![Vec3::ZERO; total]);
                        *slot.insert((first, targets.len()))
                    }
                };
                if count != targets.len() {
                    return Err(format!(
                        "{at}: has {} morph targets, but an earlier primitive of the same mesh has {count}",
                        targets.len()
                    ));
                }
                for (k, target) in targets.iter().enumerate() {
                    let Some(accessor) = target.positions() else { continue };
                    if accessor.count() != n {
                        return Err(format!(
                            "{at}: morph target {k}'s POSITION accessor {} has {} elements, but POSITION has {n}",
                            accessor.index(),
                            accessor.count()
                        ));
                    }
                    let deltas = read_vectors::<3>(&accessor, buffers, "morph target POSITION")
                        .map_err(|e| format!("{at}: morph target {k}: {e}"))?;
                    for (slot, delta) in rig.morph_targets[first + k][base..base + n].iter_mut().zip(deltas) {
                        *slot = Vec3::from_array(delta);
                    }
                }
            }
            base += n;
            parts.push(part);
        }
        Ok((rig, parts))
    }

    /// The pose at `time` with the nodes at world transforms `world` and default morph weights.
    fn pose(&self, time: f32, world: &[Mat4]) -> Pose {
        Pose {
            time,
            joints: self.joints.iter().map(|&(node, offset)| world[node] * offset).collect(),
            morph_weights: self.default_weights.clone(),
        }
    }
}

/// Vertex `v`'s influences over every `JOINTS_n`/`WEIGHTS_n` set of a skinned part, as global
/// joint ids (`ids`, per skin joint), a joint named twice counted once with the weights summed,
/// and the weights normalised to sum to 1 (exporters often leave them slightly off).
fn vertex_influences(part: &Part, v: usize, ids: &[u32], at: &str) -> std::result::Result<Vec<(u32, f32)>, String> {
    let mut influences: Vec<(u32, f32)> = Vec::with_capacity(4);
    for set in &part.influences {
        let (Some(joints), Some(weights)) = (set.joints.get(v), set.weights.get(v)) else { continue };
        for (&j, &w) in joints.iter().zip(weights).filter(|(_, w)| **w != 0.0) {
            if w < 0.0 {
                return Err(format!("{at}: WEIGHTS_{} of vertex {v} has the negative weight {w}", set.set));
            }
            let id = Some(j).filter(|j| *j >= 0.0 && j.fract() == 0.0).and_then(|j| ids.get(j as usize));
            let Some(&id) = id else {
                return Err(format!(
                    "{at}: JOINTS_{} of vertex {v} names joint {j}, but the skin has {} joints",
                    set.set,
                    ids.len()
                ));
            };
            match influences.iter_mut().find(|(known, _)| *known == id) {
                Some((_, sum)) => *sum += w,
                None => influences.push((id, w)),
            }
        }
    }
    if influences.is_empty() {
        return Err(format!("{at}: vertex {v}'s joint weights are all 0, so no joint moves it"));
    }
    let total: f32 = influences.iter().map(|(_, w)| w).sum();
    if !total.is_finite() {
        return Err(format!("{at}: vertex {v}'s joint weights sum to {total}"));
    }
    influences.iter_mut().for_each(|(_, w)| *w /= total);
    Ok(influences)
}

/// A mesh node's morph weights when no animation sets them: the node's, else its mesh's, else 0.
fn default_morph_weights(node: &Node<'_>, count: usize) -> std::result::Result<Vec<f32>, String> {
    let Some(weights) = node.weights().or_else(|| node.mesh().and_then(|m| m.weights())) else {
        return Ok(vec![0.0; count]);
    };
    if weights.len() != count || !weights.iter().all(|w| w.is_finite()) {
        return Err(format!(
            "node {}: morph weights {weights:?} do not give one finite weight to each of its {count} morph targets",
            node.index()
        ));
    }
    Ok(weights.to_vec())
}

/// One animation channel: the keyframes of one property of one node.
struct Track {
    node: usize,
    property: Property,
    interpolation: Interpolation,
    times: Vec<f32>,
    /// Per keyframe, `width` numbers; for CUBICSPLINE three groups of `width` (in-tangent,
    /// value, out-tangent), as the file stores them.
    values: Vec<f32>,
    /// 3 for translation and scale, 4 for rotation, the morph target count for weights.
    width: usize,
}

/// Every channel of `animation`, checked: the `gltf` crate does not validate channel targets
/// (and would panic on a bad one), so their node index and path are checked in the JSON first.
fn read_tracks(
    document: &Document,
    animation: &::gltf::Animation<'_>,
    buffers: &[Vec<u8>],
    morph_slots: &HashMap<usize, (usize, usize)>,
) -> std::result::Result<Vec<Track>, String> {
    let a = animation.index();
    let json = &document.as_json().animations[a];
    if json.channels.is_empty() {
        return Err(format!("animation {a}: has no channels"));
    }
    let mut tracks: Vec<Track> = Vec::with_capacity(json.channels.len());
    for (c, channel) in json.channels.iter().enumerate() {
        let at = format!("animation {a} channel {c}");
        let node = channel.target.node.value();
        let Some(target) = document.nodes().nth(node) else {
            return Err(format!("{at}: targets node {node}, but the file has {} nodes", document.nodes().len()));
        };
        let Checked::Valid(property) = channel.target.path else {
            return Err(format!("{at}: unsupported target path (expected translation, rotation, scale or weights)"));
        };
        if let Some(other) = tracks.iter().position(|t| t.node == node && t.property == property) {
            return Err(format!("{at}: animates the same {property:?} of node {node} as channel {other}"));
        }
        let width = match property {
            Property::Translation | Property::Scale => 3,
            Property::Rotation => 4,
            // The count the loaded primitives have, so that the weights fit the rig's targets.
            Property::MorphTargetWeights => {
                let count = match morph_slots.get(&node) {
                    Some(&(_, count)) => count,
                    None => target.mesh().and_then(|m| m.primitives().next()).map_or(0, |p| p.morph_targets().len()),
                };
                if count == 0 {
                    return Err(format!("{at}: animates morph weights of node {node}, which has no morph targets"));
                }
                count
            }
        };
        if property != Property::MorphTargetWeights && matches!(target.transform(), Transform::Matrix { .. }) {
            return Err(format!(
                "{at}: animates node {node}, which has a matrix; glTF allows animating only nodes given by translation, rotation and scale"
            ));
        }
        let Some(sampler) = animation.samplers().nth(channel.sampler.value()) else {
            return Err(format!("{at}: no sampler {}", channel.sampler.value()));
        };
        let track = read_track(node, property, width, &sampler, buffers).map_err(|e| format!("{at}: {e}"))?;
        tracks.push(track);
    }
    Ok(tracks)
}

/// The keyframes of one sampler, checked against what its target needs.
fn read_track(
    node: usize,
    property: Property,
    width: usize,
    sampler: &::gltf::animation::Sampler<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<Track, String> {
    let input = sampler.input();
    if input.dimensions() != Dimensions::Scalar || input.data_type() != DataType::F32 {
        return Err(format!("keyframe times accessor {} is not SCALAR of floats", input.index()));
    }
    let times: Vec<f32> = read_vectors::<1>(&input, buffers, "keyframe times")?.into_iter().map(|[t]| t).collect();
    if times.is_empty() {
        return Err(format!("keyframe times accessor {} is empty", input.index()));
    }
    // The spec asks for strictly increasing times; repeated times (a jump) are sampled as the
    // later key, so only decreasing ones are refused.
    if let Some(k) = times.windows(2).position(|w| w[1] < w[0]) {
        return Err(format!("keyframe times accessor {}: time {} comes before time {}", input.index(), k + 1, k));
    }
    let interpolation = sampler.interpolation();
    let output = sampler.output();
    let values: Vec<f32> = match property {
        Property::Translation | Property::Scale => {
            read_vectors::<3>(&output, buffers, "keyframe values")?.into_iter().flatten().collect()
        }
        Property::Rotation => read_vectors::<4>(&output, buffers, "keyframe values")?.into_iter().flatten().collect(),
        Property::MorphTargetWeights => {
            read_vectors::<1>(&output, buffers, "morph weights")?.into_iter().flatten().collect()
        }
    };
    let groups = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
    if values.len() != times.len() * groups * width {
        return Err(format!(
            "keyframe values accessor {} holds {} numbers; {} keyframes of {interpolation:?} {property:?} need {}",
            output.index(),
            values.len(),
            times.len(),
            times.len() * groups * width
        ));
    }
    let track = Track { node, property, interpolation, times, values, width };
    if property == Property::Rotation
        && let Some(k) = (0..track.times.len()).find(|&k| Vec4::from_slice(track.value(k)).length() < 1e-6)
    {
        return Err(format!("keyframe values accessor {}: rotation {k} is zero, not a rotation", output.index()));
    }
    Ok(track)
}

impl Track {
    /// Keyframe `k`'s value (not its tangents).
    fn value(&self, k: usize) -> &[f32] {
        self.group(k, 1)
    }

    /// Keyframe `k`'s group `g`: for CUBICSPLINE 0 in-tangent, 1 value, 2 out-tangent; otherwise
    /// the only group, its value.
    fn group(&self, k: usize, g: usize) -> &[f32] {
        let w = self.width;
        let at = match self.interpolation {
            Interpolation::CubicSpline => (3 * k + g) * w,
            _ => k * w,
        };
        &self.values[at..at + w]
    }

    /// The property at time `t` (Appendix C's formulas), clamped to the first and last values
    /// outside the keyframes' range.
    fn sample(&self, t: f32) -> Vec<f32> {
        let after = self.times.partition_point(|&key| key <= t);
        if after == 0 {
            return self.value(0).to_vec();
        }
        let k = after - 1;
        if after == self.times.len() {
            return self.value(k).to_vec();
        }
        // times[k] <= t < times[k + 1], so the interval is not empty.
        let span = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / span;
        match self.interpolation {
            Interpolation::Step => self.value(k).to_vec(),
            Interpolation::Linear if self.property == Property::Rotation => {
                let q = |k| Quat::from_vec4(Vec4::from_slice(self.value(k)).normalize());
                q(k).slerp(q(k + 1), s).to_array().to_vec()
            }
            Interpolation::Linear => {
                self.value(k).iter().zip(self.value(k + 1)).map(|(a, b)| (1.0 - s) * a + s * b).collect()
            }
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let (v0, b0) = (self.value(k), self.group(k, 2));
                let (a1, v1) = (self.group(k + 1, 0), self.value(k + 1));
                (0..self.width)
                    .map(|i| {
                        (2.0 * s3 - 3.0 * s2 + 1.0) * v0[i]
                            + span * (s3 - 2.0 * s2 + s) * b0[i]
                            + (-2.0 * s3 + 3.0 * s2) * v1[i]
                            + span * (s3 - s2) * a1[i]
                    })
                    .collect()
            }
        }
    }
}

/// The instants a clip is posed at: its keyframes (the union of its samplers' times, instants
/// within [`SAME_INSTANT`] merged), or `frames` evenly spaced ones over the same range.
fn frame_times(tracks: &[Track], frames: Option<usize>) -> Vec<f32> {
    let start = tracks.iter().filter_map(|t| t.times.first()).copied().fold(f32::INFINITY, f32::min);
    let end = tracks.iter().filter_map(|t| t.times.last()).copied().fold(f32::NEG_INFINITY, f32::max);
    match frames {
        Some(n) if n > 1 && end > start => {
            (0..n).map(|i| start + (end - start) * (i as f32 / (n - 1) as f32)).collect()
        }
        Some(_) => vec![start],
        None => {
            let mut times: Vec<f32> = tracks.iter().flat_map(|t| t.times.iter().copied()).collect();
            times.sort_by(f32::total_cmp);
            times.dedup_by(|later, kept| *later - *kept <= SAME_INSTANT);
            times
        }
    }
}

/// The clip of `tracks` posed at each of its frame times.
fn sample_clip(
    rig: &Rig,
    hierarchy: &Hierarchy,
    rest_local: &[Mat4],
    document: &Document,
    tracks: &[Track],
    frames: Option<usize>,
) -> std::result::Result<Vec<Pose>, String> {
    // The nodes whose translation, rotation or scale the clip animates, from their rest values.
    let mut animated: Vec<usize> =
        tracks.iter().filter(|t| t.property != Property::MorphTargetWeights).map(|t| t.node).collect();
    animated.sort_unstable();
    animated.dedup();
    let rest_trs: Vec<(Vec3, Quat, Vec3)> = animated
        .iter()
        .filter_map(|&n| document.nodes().nth(n))
        .map(|node| {
            let (t, r, s) = node.transform().decomposed();
            (Vec3::from_array(t), Quat::from_array(r), Vec3::from_array(s))
        })
        .collect();

    let mut poses = Vec::new();
    for time in frame_times(tracks, frames) {
        let mut trs = rest_trs.clone();
        let mut morph_weights = rig.default_weights.clone();
        for track in tracks {
            let value = track.sample(time);
            match track.property {
                // Weights of a node outside the scene move no vertex.
                Property::MorphTargetWeights => {
                    if let Some(&(first, count)) = rig.morph_slots.get(&track.node) {
                        morph_weights[first..first + count].copy_from_slice(&value);
                    }
                }
                property => {
                    let Ok(slot) = animated.binary_search(&track.node) else { continue };
                    let (t, r, s) = &mut trs[slot];
                    match property {
                        Property::Translation => *t = Vec3::from_slice(&value),
                        Property::Scale => *s = Vec3::from_slice(&value),
                        // A cubic spline between unit quaternions leaves the unit sphere (the
                        // spec says to normalise); it passes through zero only in a broken file.
                        _ => *r = Quat::from_vec4(Vec4::from_slice(&value).normalize_or(Vec4::W)),
                    }
                }
            }
        }
        let mut local = rest_local.to_vec();
        for (&node, &(t, r, s)) in animated.iter().zip(&trs) {
            local[node] = Mat4::from_scale_rotation_translation(s, r, t);
        }
        let pose = Pose { morph_weights, ..rig.pose(time, &hierarchy.world(&local)) };
        if let Some(j) = pose.joints.iter().position(|m| !m.is_finite()) {
            return Err(format!("at {time} s, joint {j}'s matrix has a non-finite value"));
        }
        if pose.morph_weights.iter().any(|w| !w.is_finite()) {
            return Err(format!("at {time} s, a morph weight is not finite"));
        }
        poses.push(pose);
    }
    Ok(poses)
}
