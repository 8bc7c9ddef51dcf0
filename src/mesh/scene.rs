//! A mesh source opened for ordering and measuring: the rest mesh, its connectivity (derived
//! once, shared by every ordering) and the frames drawn.

use super::Mesh;
use super::frames::Frames;
use super::report::MeshReport;
use super::topology::Topology;

/// What every ordering reads and every measurement draws.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The rest mesh: the triangles orderings permute, the attributes written back, and for a
    /// still the positions drawn.
    pub mesh: Mesh,
    pub topology: Topology,
    /// The positions drawn: the mesh itself (one frame), or an animation's keyframes.
    pub frames: Frames,
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
        Scene { mesh, topology, frames }
    }

    /// What is unusual about the mesh (degenerate, duplicate, non-manifold faces, …).
    pub fn report(&self) -> MeshReport {
        MeshReport::new(&self.mesh, &self.topology)
    }
}
