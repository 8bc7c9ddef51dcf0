//! Fragment counting for overdraw: one trait, two backends (the CPU reference and a wgpu GPU
//! backend), returning the same per-view counts under the same rules so they can be cross-checked.

pub mod cpu;
pub mod kept;
pub mod layers;
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

    /// Counts several draw orders of the same triangles ([`OrderPicks`]) from each camera:
    /// per camera, one count per order it picks, what [`RasterBackend::count`] gives for that
    /// order. Several methods measured over one view set draw the same triangles from the same
    /// cameras, each in its own order; this draws each order with the views that pick it, and
    /// the CPU backend rasterizes each view once instead.
    fn count_orders(
        &self,
        positions: &[Vec3],
        cameras: &[Camera],
        draws: &OrderPicks,
        res: u32,
    ) -> Result<Vec<Vec<ViewCounts>>> {
        count_each_order(self, positions, cameras, draws, res)
    }
}

/// Several draw orders of one triangle list, and which of them each camera draws: what
/// [`RasterBackend::count_orders`] counts.
#[derive(Debug, Clone, Copy)]
pub struct OrderPicks<'a> {
    pub triangles: &'a [[u32; 3]],
    /// Permutations of the triangles' indices.
    pub orders: &'a [&'a [u32]],
    /// Per camera, the orders (indices into `orders`) drawn from it.
    pub picks: &'a [Vec<usize>],
}

/// [`RasterBackend::count_orders`] by drawing each order with the views that pick it.
pub fn count_each_order<B: RasterBackend + ?Sized>(
    backend: &B,
    positions: &[Vec3],
    cameras: &[Camera],
    draws: &OrderPicks,
    res: u32,
) -> Result<Vec<Vec<ViewCounts>>> {
    let picks = draws.picks;
    let mut counts: Vec<Vec<ViewCounts>> = picks.iter().map(|p| vec![ViewCounts::default(); p.len()]).collect();
    for (o, order) in draws.orders.iter().enumerate() {
        let slots: Vec<(usize, usize)> = picks
            .iter()
            .enumerate()
            .flat_map(|(v, p)| p.iter().enumerate().filter(move |&(_, &q)| q == o).map(move |(s, _)| (v, s)))
            .collect();
        if slots.is_empty() {
            continue;
        }
        let drawn: Vec<[u32; 3]> = order.iter().map(|&t| draws.triangles[t as usize]).collect();
        let views: Vec<Camera> = slots.iter().map(|&(v, _)| cameras[v]).collect();
        for (&(v, s), c) in slots.iter().zip(backend.count(positions, &drawn, &views, res)?) {
            counts[v][s] = c;
        }
    }
    Ok(counts)
}
