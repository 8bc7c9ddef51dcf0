//! An animation posed at its keyframes and framed, ready for keyframe-aware orderings and for
//! measuring (Han & Sander 2017, §3.2 "Framing").
//!
//! Each frame is translated so that its own centre is at the origin: "we compute the model's
//! bounding sphere in each frame and translate the model such that its center matches that of
//! the subdivided icosahedron of viewpoints", so a running character stays inside a tight sphere
//! of viewpoints. The centre is the bounding-box centre, as for static meshes
//! ([`Framing::of`]); the radius is the largest over all frames, so one sphere of viewpoints (and
//! one camera distance) serves the whole animation.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::Mesh;
use super::animated::Animated;
use crate::raster::Framing;

/// Framed positions per keyframe for one connectivity, grouped by clip.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframes {
    /// Per frame: every vertex position, that frame's centre at the origin.
    pub frames: Vec<Vec<Vec3>>,
    /// Each clip's name and its frames' range in `frames`; the ranges tile `frames` in order.
    pub clips: Vec<(String, Range<usize>)>,
    /// The largest distance of a vertex from its frame's centre, over all frames.
    pub radius: f32,
}

impl Keyframes {
    /// Every keyframe of every clip of `animated`, posed and framed.
    pub fn of(animated: &Animated) -> Keyframes {
        let mut clips = Vec::new();
        let mut poses = Vec::new();
        for clip in &animated.clips {
            clips.push((clip.name.clone(), poses.len()..poses.len() + clip.frames.len()));
            poses.extend(&clip.frames);
        }
        let frames: Vec<Vec<Vec3>> = poses.par_iter().map(|pose| animated.positions(pose)).collect();
        Keyframes::framed(frames, clips)
    }

    /// A static mesh as an animation of one frame in one unnamed clip.
    pub fn still(mesh: &Mesh) -> Keyframes {
        Keyframes::framed(vec![mesh.positions.clone()], vec![(String::new(), 0..1)])
    }

    fn framed(mut frames: Vec<Vec<Vec3>>, clips: Vec<(String, Range<usize>)>) -> Keyframes {
        let mut radius = 0.0f32;
        for frame in &mut frames {
            let framing = Framing::of(frame);
            frame.iter_mut().for_each(|p| *p -= framing.center);
            radius = radius.max(framing.radius);
        }
        Keyframes { frames, clips, radius }
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }

    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The framing every frame is seen with: the origin and the largest radius.
    pub fn framing(&self) -> Framing {
        Framing { center: Vec3::ZERO, radius: self.radius }
    }

    /// The mesh posed at frame `f` (connectivity and attributes of `rest`).
    pub fn posed(&self, rest: &Mesh, f: usize) -> Mesh {
        Mesh { positions: self.frames[f].clone(), ..rest.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_frame_is_centred_and_the_radius_is_the_largest() {
        let near = vec![Vec3::new(10.0, 0.0, 0.0), Vec3::new(12.0, 0.0, 0.0)];
        let far = vec![Vec3::new(-5.0, 1.0, 0.0), Vec3::new(-5.0, 7.0, 0.0)];
        let k = Keyframes::framed(vec![near, far], vec![("a".into(), 0..2)]);
        assert_eq!(k.frames[0], vec![Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)]);
        assert_eq!(k.frames[1], vec![Vec3::new(0.0, -3.0, 0.0), Vec3::new(0.0, 3.0, 0.0)]);
        assert_eq!(k.radius, 3.0);
        assert_eq!(k.framing().center, Vec3::ZERO);
    }
}
