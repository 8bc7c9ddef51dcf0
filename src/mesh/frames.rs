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
//! - **Levels** of a progressive mesh: one frame a level, the positions unchanged but each level
//!   with its own triangles ([`Frames::triangles`]); a method's sequence follows the removals
//!   by an [`Update`], and every metric is reported level by level.

use std::ops::Range;

use glam::{DVec3, Vec3, Vec3A};
use rayon::prelude::*;

use super::Mesh;
use super::animated::Animated;
use super::progressive::{History, Update};

/// How a model is framed: bounding-box centre and the largest vertex distance from it.
///
/// Both are computed in f64 from the f32 positions, so neither overflows (a radius of 1e25 squares
/// to 1e50, past f32), underflows (1e-30 squares to 0 in f32) nor loses a far-off-centre mesh's
/// size to the rounding of its centre. [`Framing::to_unit`] maps a position into the *unit frame*
/// (centre at the origin, radius 1), where every camera, rasterizer and geometric ordering works:
/// what they compute then depends on the shape alone, never on where the mesh stands or its
/// units. The map is exact under scaling by a power of two and under translations that are exact
/// in f32; any other scale changes the f32 positions themselves by their rounding, and with them
/// the unit-frame positions by at most about an ulp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Framing {
    pub center: DVec3,
    pub radius: f64,
}

impl Framing {
    /// The centre of the frame of `positions`: the middle of their bounding box, in f64.
    pub fn center_of(positions: &[Vec3]) -> DVec3 {
        let (lo, hi) = Framing::bounds_of(positions);
        (lo + hi) * 0.5
    }

    /// The corners of the bounding box of `positions` (zero for none).
    pub fn bounds_of(positions: &[Vec3]) -> (DVec3, DVec3) {
        // In four SIMD lanes of running bounds, so that no vertex waits on the one before.
        let (mut lo, mut hi) = ([Vec3A::INFINITY; 4], [Vec3A::NEG_INFINITY; 4]);
        let mut quads = positions.chunks_exact(4);
        for quad in &mut quads {
            for ((lo, hi), &p) in lo.iter_mut().zip(&mut hi).zip(quad) {
                (*lo, *hi) = (lo.min(p.into()), hi.max(p.into()));
            }
        }
        for &p in quads.remainder() {
            (lo[0], hi[0]) = (lo[0].min(p.into()), hi[0].max(p.into()));
        }
        let (lo, hi) =
            (lo.into_iter().fold(Vec3A::INFINITY, Vec3A::min), hi.into_iter().fold(Vec3A::NEG_INFINITY, Vec3A::max));
        if positions.is_empty() { (DVec3::ZERO, DVec3::ZERO) } else { (lo.as_dvec3(), hi.as_dvec3()) }
    }

    /// The unit frame itself: positions already centred and of radius 1 map to themselves.
    pub const UNIT: Framing = Framing { center: DVec3::ZERO, radius: 1.0 };

    pub fn of(positions: &[Vec3]) -> Framing {
        let center = Framing::center_of(positions);
        let radius = positions.iter().map(|p| p.as_dvec3().distance(center)).fold(0.0f64, f64::max);
        // A single point or a degenerate mesh still needs a non-empty view volume.
        Framing { center, radius: if radius > 0.0 { radius } else { 1.0 } }
    }

    /// `p` in the unit frame, in f64.
    pub fn to_unit64(&self, p: Vec3) -> DVec3 {
        (p.as_dvec3() - self.center) / self.radius
    }

    /// `p` in the unit frame: centred, divided by the radius in f64, then rounded to f32.
    pub fn to_unit(&self, p: Vec3) -> Vec3 {
        self.to_unit64(p).as_vec3()
    }

    /// Every position in the unit frame ([`Framing::to_unit`]).
    pub fn unit_positions(&self, positions: &[Vec3]) -> Vec<Vec3> {
        positions.iter().map(|&p| self.to_unit(p)).collect()
    }

    /// A point of the unit frame back in world coordinates, rounded to f32.
    pub fn to_world(&self, p: DVec3) -> Vec3 {
        (self.center + p * self.radius).as_vec3()
    }
}

/// `positions` in their own unit frame (centre at the origin, radius 1; see [`Framing`]): what
/// every ordering that reads geometry works on, so that it orders a mesh the same wherever it
/// stands and whatever its units.
pub fn unit_positions(positions: &[Vec3]) -> Vec<Vec3> {
    Framing::of(positions).unit_positions(positions)
}

/// [`unit_positions`] in f64, for orderings that compute in f64.
pub fn unit_positions64(positions: &[Vec3]) -> Vec<DVec3> {
    let framing = Framing::of(positions);
    positions.iter().map(|&p| framing.to_unit64(p)).collect()
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
    /// What the frames are, which decides how they are drawn and how results name them.
    pub kind: Kind,
}

/// What a scene's frames are.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// One frame, the mesh as it stands.
    Still,
    /// The keyframes of an animation, one connectivity: results name them by clip.
    Animation,
    /// Levels of a progressive mesh, one frame each, each with its own triangles: every metric is
    /// reported per level.
    Levels(Levels),
}

/// The levels of a progressive mesh and how a rendering sequence follows them.
#[derive(Debug, Clone, PartialEq)]
pub struct Levels {
    pub history: History,
    /// Per level: the fraction of the mesh's triangles asked for, the removals that reach it, and
    /// its triangles (ids into `history.triangles`, ascending).
    pub fractions: Vec<f64>,
    pub records: Vec<usize>,
    pub alive: Vec<Vec<u32>>,
    pub update: Update,
    /// What the user should know when a level asked for is not reached (the history stopped
    /// above it: no vertex left could be removed without a fold or a non-manifold result), or
    /// repeats the level before it: which levels are drawn coarser than asked and which are left
    /// out.
    pub note: Option<String>,
}

impl Levels {
    /// The triangles of level `f` (corners), in id order.
    pub fn triangles(&self, f: usize) -> Vec<[u32; 3]> {
        self.alive[f].iter().map(|&t| self.history.triangles[t as usize]).collect()
    }
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
        let mut radius = 0.0f64;
        for frame in &mut frames {
            let framing = Framing::of(frame);
            frame.iter_mut().for_each(|p| *p = (p.as_dvec3() - framing.center).as_vec3());
            radius = radius.max(framing.radius);
        }
        Frames { frames, clips, framing: Framing { center: DVec3::ZERO, radius }, kind: Kind::Animation }
    }

    /// A static mesh: one frame, its positions untouched, framed where it stands.
    pub fn still(mesh: &Mesh) -> Frames {
        Frames {
            frames: vec![mesh.positions.clone()],
            clips: vec![(String::new(), 0..1)],
            framing: Framing::of(&mesh.positions),
            kind: Kind::Still,
        }
    }

    /// `mesh` at each fraction of its triangle count (descending), by `history`'s removals: one
    /// frame a level, framed where the mesh stands. A fraction the history cannot reach gives the
    /// coarsest level it has, once ([`Levels::note`] says so).
    pub fn progressive(mesh: &Mesh, history: History, fractions: &[f64], update: Update) -> Frames {
        // A level that would repeat the one before it (the history stopped above both, or two
        // fractions round to the same removals) is left out; the first level the history stops
        // above is drawn at the coarsest it reaches. The note says which.
        let mut kept: Vec<(f64, usize)> = Vec::with_capacity(fractions.len());
        let (mut coarser, mut left_out) = (Vec::new(), Vec::new());
        for &f in fractions {
            let target = (f * mesh.triangle_count() as f64).round() as usize;
            let records = history.records_for(target);
            if kept.last().is_some_and(|&(_, r)| records <= r) {
                left_out.push(f.to_string());
            } else {
                kept.push((f, records));
                if history.triangles_after(records) > target {
                    coarser.push(f.to_string());
                }
            }
        }
        let note = (!coarser.is_empty() || !left_out.is_empty()).then(|| {
            let mut note = format!(
                "the simplification stops at {} triangles (no vertex left can be removed without a fold or a \
                 non-manifold result)",
                history.triangles_after(history.records.len())
            );
            if !coarser.is_empty() {
                note += &format!("; level {} is drawn with that many", coarser.join(", "));
            }
            if !left_out.is_empty() {
                note += &format!("; level(s) {} left out, as they would repeat the level before", left_out.join(", "));
            }
            note
        });
        let (fractions, records): (Vec<f64>, Vec<usize>) = kept.into_iter().unzip();
        let alive = records.iter().map(|&r| history.level(r)).collect();
        let count = fractions.len();
        let levels = Levels { history, fractions, records, alive, update, note };
        Frames {
            frames: vec![mesh.positions.clone(); count],
            clips: vec![(String::new(), 0..count)],
            framing: Framing::of(&mesh.positions),
            kind: Kind::Levels(levels),
        }
    }

    /// The levels of a progressive mesh, if these frames are its levels.
    pub fn levels(&self) -> Option<&Levels> {
        match &self.kind {
            Kind::Levels(levels) => Some(levels),
            _ => None,
        }
    }

    /// True for the keyframes of an animation.
    pub fn is_animation(&self) -> bool {
        self.kind == Kind::Animation
    }

    /// The triangles frame `f` draws: the mesh's, or for a level its own.
    pub fn triangles<'a>(&'a self, f: usize, mesh: &'a Mesh) -> std::borrow::Cow<'a, [[u32; 3]]> {
        match &self.kind {
            Kind::Levels(levels) => std::borrow::Cow::Owned(levels.triangles(f)),
            _ => std::borrow::Cow::Borrowed(&mesh.triangles),
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
            assert_eq!(Framing::of(frame).center, DVec3::ZERO);
        }
        let scaled: Vec<Vec3> = animated.mesh.positions.iter().map(|&p| 3.0 * p).collect();
        assert_eq!(k.framing, Framing { center: DVec3::ZERO, radius: Framing::of(&scaled).radius });
        assert!(k.is_animation());
    }

    #[test]
    fn framing_holds_at_any_scale_and_the_unit_frame_is_exact() {
        let shape = [[-1.0, 0.5, 2.0], [3.0, -2.0, 0.25], [0.5, 1.5, -1.0], [0.0, 0.0, 0.0]];
        let placed = |scale: f64, offset: f64| shape.map(|p| (DVec3::from(p) * scale + offset).as_vec3()).to_vec();
        let one = Framing::of(&placed(1.0, 0.0));
        let unit = one.unit_positions(&placed(1.0, 0.0));
        assert!(unit.iter().all(|p| p.length() <= 1.0 + 1e-6) && unit.iter().any(|p| (p.length() - 1.0).abs() < 1e-6));
        // Scaled by powers of two, or moved by a translation f32 holds exactly: the same bits.
        for (scale, offset) in [((-120f64).exp2(), 0.0), (120f64.exp2(), 0.0), (1.0, 4096.0), (0.5, -1e6)] {
            let positions = placed(scale, offset);
            let framing = Framing::of(&positions);
            assert_eq!(framing.radius, one.radius * scale, "×{scale} +{offset}");
            assert_eq!(framing.unit_positions(&positions), unit, "×{scale} +{offset}");
        }
        // Whose radius squared leaves f32 (1e-60 underflows, 1e50 overflows): still framed.
        for scale in [1e-30, 1e25] {
            let framing = Framing::of(&placed(scale, 0.0));
            assert!((framing.radius / (one.radius * scale) - 1.0).abs() < 1e-6, "×{scale}: {framing:?}");
        }
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
        assert!(!still.is_animation());
    }
}
