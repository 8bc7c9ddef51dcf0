//! A mesh source opened for ordering and measuring: the rest mesh, its connectivity (derived
//! once, shared by every ordering) and the frames drawn.

use std::any::Any;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;

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
    /// Work derived from the scene that several of its orderings need, done once (see
    /// [`SharedWork`]).
    pub shared: SharedWork,
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
        Scene { mesh, topology, frames, draw_calls: Vec::new(), shared: SharedWork::default() }
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
        // A level's triangles are not the file's: its draw calls no longer apply, nor anything
        // derived from the frames.
        Ok(Scene { frames, draw_calls: Vec::new(), shared: SharedWork::default(), ..self })
    }

    /// The same levels with their sequence kept by `update` instead (no effect on other scenes).
    /// The shared work stays: the levels' meshes do not change, only how an order is kept through
    /// them, and the full mesh's order that both updates keep is made once.
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

/// Work derived from a scene that several orderings of it need, computed by the first that asks
/// and kept for the others while the scene lives (and by `reproduce` for the later specs that open
/// the same scene, [`crate::experiment::run::RunMemo`]): `hs17` rasterizes the same (keyframe,
/// viewpoint) nodes for every λ, mode, seed and cluster count, and a run orders all of a model's
/// methods on one scene. Each entry keeps the wall time computing it took, which a later ordering
/// that reuses it charges to its own time ([`crate::order::Orders::reused`]), so that an
/// ordering's `seconds` stay what it costs on its own, whichever ran first. Entries are named
/// by what they were computed from besides the scene; a scene whose frames change starts afresh,
/// but not one whose levels only change their update ([`Scene::set_update`]): an entry must not
/// depend on it.
#[derive(Default)]
pub struct SharedWork {
    entries: Mutex<HashMap<String, Computed>>,
}

/// A shared value and the seconds computing it took.
type Computed = (Arc<dyn Any + Send + Sync>, f64);

impl SharedWork {
    /// The entry named `key`, computed by `compute` if there is none yet; with the seconds its
    /// computation took when it was reused (`None`: computed now).
    pub fn get_or_compute<T: Any + Send + Sync, E>(
        &self,
        key: &str,
        compute: impl FnOnce() -> std::result::Result<T, E>,
    ) -> std::result::Result<(Arc<T>, Option<f64>), E> {
        let found = self.entries.lock().expect("no panic while held").get(key).cloned();
        if let Some((value, seconds)) = found {
            let value = value.downcast::<T>().expect("one type per key");
            return Ok((value, Some(seconds)));
        }
        // Computed without the lock held: `compute` may itself run in parallel.
        let start = Instant::now();
        let value = Arc::new(compute()?);
        let seconds = start.elapsed().as_secs_f64();
        let stored: Arc<dyn Any + Send + Sync> = value.clone();
        self.entries.lock().expect("no panic while held").insert(key.to_string(), (stored, seconds));
        Ok((value, None))
    }
}

/// A copy of a scene computes its own shared work.
impl Clone for SharedWork {
    fn clone(&self) -> SharedWork {
        SharedWork::default()
    }
}

impl std::fmt::Debug for SharedWork {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let entries = self.entries.lock().map(|e| e.len()).unwrap_or(0);
        write!(f, "SharedWork {{ {entries} entries }}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_work_is_computed_once_and_a_failure_is_not_kept() {
        let shared = SharedWork::default();
        let failed: std::result::Result<(Arc<u32>, _), &str> = shared.get_or_compute("a", || Err("no"));
        assert_eq!(failed.err(), Some("no"));
        let (first, reused) = shared.get_or_compute::<u32, ()>("a", || Ok(7)).unwrap();
        assert_eq!((*first, reused), (7, None));
        let (again, reused) = shared.get_or_compute::<u32, ()>("a", || panic!("computed twice")).unwrap();
        assert!(*again == 7 && reused.is_some_and(|s| s >= 0.0));
        assert!(shared.clone().get_or_compute::<u32, ()>("a", || Ok(8)).unwrap().1.is_none(), "a copy starts afresh");
    }
}
