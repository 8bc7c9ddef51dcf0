//! What is drawn: one connectivity seen in one or more frames, each frame a full set of vertex
//! positions. Every ordering and every measurement reads its positions from here, so a static
//! mesh, an animation and (next) a sequence of progressive levels go through one path.
//!
//! - A **still** is a static mesh: one frame, its positions as loaded, framed at its own
//!   bounding-box centre ([`Framing::of`]).
//! - An **animation** is posed at its keyframes (Han & Sander 2017, §3.2 "Framing"): each frame is
//!   translated so that its own centre is at the origin, "we compute the model's bounding sphere
//!   in each frame and translate the model such that its center matches that of the subdivided
//!   icosahedron of viewpoints", so a running character stays inside a tight sphere of
//!   viewpoints. The radius is the largest over all frames, so one sphere of viewpoints (and one
//!   camera distance) serves the whole animation.
//!
//! Progressive levels will be a third kind: frames whose triangles differ too, each level with
//! its own order; measurement already works frame by frame through [`Frames::framing`] and the
//! lookup of each method's orders.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::Mesh;
use super::animated::Animated;

/// How a model is framed: bounding-box centre and the largest vertex distance from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Framing {
    pub center: Vec3,
    pub radius: f32,
}

impl Framing {
    pub fn of(positions: &[Vec3]) -> Framing {
        let (lo, hi) = positions
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let center = (lo + hi) * 0.5;
        let radius = positions.iter().map(|p| p.distance(center)).fold(0.0f32, f32::max);
        // A single point or a degenerate mesh still needs a non-empty view volume.
        Framing { center, radius: if radius > 0.0 { radius } else { 1.0 } }
    }
}

/// Positions per frame for one connectivity, grouped by clip.
#[derive(Debug, Clone, PartialEq)]
pub struct Frames {
    /// Per frame: every vertex position.
    pub frames: Vec<Vec<Vec3>>,
    /// Each clip's name and its frames' range in `frames`; the ranges tile `frames` in order.
    /// A still is one unnamed clip.
    pub clips: Vec<(String, Range<usize>)>,
    /// How every frame is seen: one centre and radius for all of them.
    pub framing: Framing,
    /// True for the keyframes of an animation, false for a still: results name the frames of an
    /// animation by clip.
    pub animated: bool,
}

impl Frames {
    /// Every keyframe of every clip of `animated`, posed and each centred at the origin.
    pub fn of(animated: &Animated) -> Frames {
        let mut clips = Vec::new();
        let mut poses = Vec::new();
        for clip in &animated.clips {
            clips.push((clip.name.clone(), poses.len()..poses.len() + clip.frames.len()));
            poses.extend(&clip.frames);
        }
        let mut frames: Vec<Vec<Vec3>> = poses.par_iter().map(|pose| animated.positions(pose)).collect();
        let mut radius = 0.0f32;
        for frame in &mut frames {
            let framing = Framing::of(frame);
            frame.iter_mut().for_each(|p| *p -= framing.center);
            radius = radius.max(framing.radius);
        }
        Frames { frames, clips, framing: Framing { center: Vec3::ZERO, radius }, animated: true }
    }

    /// A static mesh: one frame, its positions untouched, framed where it stands.
    pub fn still(mesh: &Mesh) -> Frames {
        Frames {
            frames: vec![mesh.positions.clone()],
            clips: vec![(String::new(), 0..1)],
            framing: Framing::of(&mesh.positions),
            animated: false,
        }
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The mesh posed at frame `f` (connectivity and attributes of `rest`).
    pub fn posed(&self, rest: &Mesh, f: usize) -> Mesh {
        Mesh { positions: self.frames[f].clone(), ..rest.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    use crate::mesh::animated::{Clip, Pose};

    #[test]
    fn each_keyframe_is_centred_and_the_radius_is_the_largest() {
        let rest = Mesh::new("t", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]], Default::default()).unwrap();
        let pose = |m: Mat4| Pose { time: 0.0, joints: vec![m], morph_weights: vec![] };
        let frames =
            vec![pose(Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0))), pose(Mat4::from_scale(Vec3::splat(3.0)))];
        let animated = Animated {
            mesh: rest,
            influences: vec![vec![(0, 1.0)]; 3],
            morph_targets: vec![],
            joint_count: 1,
            clips: vec![Clip { name: "a".into(), frames }],
        };
        let k = Frames::of(&animated);
        for frame in &k.frames {
            assert_eq!(Framing::of(frame).center, Vec3::ZERO);
        }
        let scaled: Vec<Vec3> = animated.mesh.positions.iter().map(|&p| 3.0 * p).collect();
        assert_eq!(k.framing, Framing { center: Vec3::ZERO, radius: Framing::of(&scaled).radius });
        assert!(k.animated);
    }

    #[test]
    fn a_still_keeps_its_positions_and_its_own_framing() {
        let mesh = Mesh::new(
            "t",
            vec![Vec3::new(10.0, 0.0, 0.0), Vec3::new(12.0, 0.0, 0.0), Vec3::new(10.0, 1.0, 0.0)],
            vec![[0, 1, 2]],
            Default::default(),
        )
        .unwrap();
        let still = Frames::still(&mesh);
        assert_eq!(still.frames, vec![mesh.positions.clone()]);
        assert_eq!(still.framing, Framing::of(&mesh.positions));
        assert!(!still.animated);
    }
}
