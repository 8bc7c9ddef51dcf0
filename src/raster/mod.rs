//! Fragment counting for overdraw: one trait, several backends (the CPU reference here; a wgpu
//! backend later), all returning the same per-view counts under the same rules so they can be
//! cross-checked.

pub mod cpu;
pub mod views;

use glam::Vec3;

use crate::error::Result;
pub use views::{Camera, Framing, ViewSet};

/// What one view of one draw order produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ViewCounts {
    /// Pixels with at least one front-facing fragment (the projected area of the mesh).
    pub covered: u64,
    /// Front-facing fragments rasterized (depth complexity, independent of order).
    pub fragments: u64,
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
    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>>;
}

/// The backend named `name` (`cpu`; `gpu` arrives with the wgpu backend).
pub fn backend(name: &str) -> Result<Box<dyn RasterBackend>> {
    match name {
        "cpu" => Ok(Box::new(cpu::CpuRaster)),
        other => Err(crate::Error::usage(format!("unknown raster backend `{other}` (available: cpu)"))),
    }
}
