//! Fragment counting for overdraw: one trait, two backends (the CPU reference and a wgpu GPU
//! backend), returning the same per-view counts under the same rules so they can be cross-checked.

pub mod cpu;
pub mod views;

use glam::Vec3;

use crate::error::{Error, Result};
pub use views::{Camera, ViewSet};

/// `error`, raised while drawing the mesh named `mesh`, as a problem of that mesh: a view its
/// geometry cannot be drawn from (a vertex that would need clipping or projects far off screen,
/// which the view sets are framed never to need) names the file, as every input error does.
/// The backends report those as usage errors, since they do not know the mesh; others pass
/// unchanged.
pub fn naming_mesh(mesh: &str, error: Error) -> Error {
    match error {
        Error::Usage(problem) => Error::input(mesh, problem),
        other => other,
    }
}

/// What one view of one draw order produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ViewCounts {
    /// Pixels with at least one front-facing fragment (the projected area of the mesh).
    pub covered: u64,
    /// Fragments that passed the depth test, i.e. were shaded with early-Z: depends on order.
    pub passed: u64,
}

impl ViewCounts {
    /// Overdraw ratio passed ÷ covered; `None` when nothing is visible from this view.
    pub fn ovr(&self) -> Option<f64> {
        (self.covered > 0).then(|| self.passed as f64 / self.covered as f64)
    }
}

/// Counts fragments of `triangles` (in draw order, indexing `positions`) for each camera at R×R.
pub trait RasterBackend: Sync {
    fn name(&self) -> &'static str;
    /// The backend as written into results: its name, and for a GPU the device and driver.
    fn describe(&self) -> String {
        self.name().to_string()
    }
    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>>;
}
