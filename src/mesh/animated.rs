//! Animated meshes for Han & Sander 2017: fixed connectivity, positions that change per keyframe.
//!
//! An [`Animated`] mesh keeps what makes it move rather than a list of posed copies: the rest
//! mesh, each vertex's joint influences (linear blend skinning) and morph-target deltas, and, per
//! clip, the keyframes' joint matrices and morph weights. Posing is then one function
//! ([`Animated::positions`]), and Loop subdivision can refine the rest mesh together with the
//! influences and deltas (by the same stencils) so that the subdivided mesh animates, as the
//! paper's Fig. 4 needs.
//!
//! Every vertex has at least one influence. Rigid parts (a mesh parented to a bone, or not
//! animated at all) are expressed the same way: one influence of weight 1 on a *joint* that is
//! that node's own world transform. So a frame is always "blend joint matrices, add morphs".

use glam::{Mat4, Vec3};

use super::Mesh;

/// A mesh whose positions are posed per keyframe.
#[derive(Debug, Clone, PartialEq)]
pub struct Animated {
    /// The rest mesh: connectivity (the triangles orderings permute), attributes, and the
    /// positions the influences and morph deltas apply to.
    pub mesh: Mesh,
    /// Per vertex: `(joint, weight)` pairs, weights positive and summing to 1.
    pub influences: Vec<Vec<(u32, f32)>>,
    /// Per morph target: a position delta for every vertex.
    pub morph_targets: Vec<Vec<Vec3>>,
    /// Number of joints (including the rigid-node pseudo-joints); every influence indexes below it.
    pub joint_count: usize,
    pub clips: Vec<Clip>,
}

/// One animation clip sampled at its keyframes.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    pub name: String,
    pub frames: Vec<Pose>,
}

/// The state of every joint and morph target at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Seconds from the clip's start.
    pub time: f32,
    /// Per joint: the matrix taking a rest position to its posed position (for a skin joint, the
    /// joint's world transform times its inverse bind matrix).
    pub joints: Vec<Mat4>,
    /// Per morph target: its weight.
    pub morph_weights: Vec<f32>,
}

impl Animated {
    /// The vertex positions at `pose`: morph deltas added to the rest positions, then linear
    /// blend skinning.
    pub fn positions(&self, pose: &Pose) -> Vec<Vec3> {
        (0..self.mesh.positions.len())
            .map(|v| {
                let mut rest = self.mesh.positions[v];
                for (target, &w) in self.morph_targets.iter().zip(&pose.morph_weights) {
                    rest += w * target[v];
                }
                self.influences[v].iter().map(|&(j, w)| w * pose.joints[j as usize].transform_point3(rest)).sum()
            })
            .collect()
    }
}
