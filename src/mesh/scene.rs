//! A mesh source opened for ordering and measuring: the rest mesh, its connectivity (derived
//! once, shared by every ordering) and the frames drawn.

use super::Mesh;
use super::frames::{Frames, Kind};
use super::progressive::{History, Update};
use super::report::MeshReport;
use super::topology::Topology;
use crate::error::{Error, Result};

/// What every ordering reads and every measurement draws.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The rest mesh: the triangles orderings permute, the attributes written back, and for a
    /// still the positions drawn.
    pub mesh: Mesh,
    pub topology: Topology,
    /// The positions drawn: the mesh itself (one frame), or an animation's keyframes.
    pub frames: Frames,
    /// The file's draw calls, as ranges of the mesh's triangles ([`LoadReport::draw_calls`]):
    /// what an engine draws separately. Empty: the mesh is one draw call.
    ///
    /// [`LoadReport::draw_calls`]: crate::mesh::load::LoadReport::draw_calls
    pub draw_calls: Vec<std::ops::Range<usize>>,
}

impl Scene {
    /// A static mesh, drawn as it stands.
    pub fn still(mesh: Mesh) -> Scene {
        let frames = Frames::still(&mesh);
        Scene::animated(mesh, frames)
    }

    /// `mesh` (the rest pose) drawn in `frames`.
    pub fn animated(mesh: Mesh, frames: Frames) -> Scene {
        let topology = Topology::new(&mesh);
        Scene { mesh, topology, frames, draw_calls: Vec::new() }
    }

    /// The mesh as a progressive mesh at each of `fractions` of its triangles (each in (0, 1];
    /// drawn from the most to the fewest triangles), its sequence kept by `update`: one frame a
    /// level, the simplification history built once down to the smallest fraction.
    pub fn with_levels(self, fractions: &[f64], update: Update) -> Result<Scene> {
        if self.frames.kind != Kind::Still {
            return Err(Error::usage(format!("{}: progressive levels are for a static mesh", self.mesh.name)));
        }
        if let Some(bad) = fractions.iter().find(|f| !(**f > 0.0 && **f <= 1.0)) {
            return Err(Error::usage(format!("level {bad} is not a fraction of the triangles in (0, 1]")));
        }
        let mut fractions = fractions.to_vec();
        fractions.sort_by(|a, b| b.total_cmp(a));
        fractions.dedup();
        let smallest = fractions.last().ok_or_else(|| Error::usage("no level given"))?;
        let target = (smallest * self.mesh.triangle_count() as f64).round() as usize;
        let history = History::build(&self.mesh, &self.topology, target);
        let frames = Frames::progressive(&self.mesh, history, &fractions, update);
        // A level's triangles are not the file's: its draw calls no longer apply.
        Ok(Scene { frames, draw_calls: Vec::new(), ..self })
    }

    /// The same levels with their sequence kept by `update` instead (no effect on other scenes).
    pub fn set_update(&mut self, update: Update) {
        if let Kind::Levels(levels) = &mut self.frames.kind {
            levels.update = update;
        }
    }

    /// What is unusual about the mesh (degenerate, duplicate, non-manifold faces, …).
    pub fn report(&self) -> MeshReport {
        MeshReport::new(&self.mesh, &self.topology)
    }
}
