//! Order a mesh with a method and measure the result: the one code path `eval`, `order` and
//! experiments share, so every number triorder prints is computed the same way.

use std::time::Instant;

use crate::error::Result;
use crate::mesh::Mesh;
use crate::metrics::{CacheModel, CacheStats, OverdrawSummary, cache};
use crate::order::{self, Order, OrderInput, Resolved};
use crate::raster::{Framing, RasterBackend, ViewCounts, ViewSet};
use crate::topology::Topology;

/// What to measure.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasureOptions {
    pub caches: Vec<CacheModel>,
    /// Overdraw is measured only when a view set is given (it costs far more than the caches).
    pub views: Option<ViewSet>,
    pub res: u32,
    /// Seeds `random:N` view sets.
    pub seed: u64,
}

/// Overdraw of one order over a view set.
#[derive(Debug, Clone, PartialEq)]
pub struct Overdraw {
    pub views: ViewSet,
    pub res: u32,
    pub per_view: Vec<ViewCounts>,
    /// `None` when no view sees any front face.
    pub summary: Option<OverdrawSummary>,
}

/// The metrics of one draw order.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub caches: Vec<(CacheModel, CacheStats)>,
    pub overdraw: Option<Overdraw>,
}

/// Measures the draw order `order` of `mesh`.
pub fn measure(
    mesh: &Mesh,
    order: &[u32],
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Measurement> {
    let triangles = mesh.triangles_in_order(order);
    let caches =
        options.caches.iter().map(|&model| (model, cache::simulate(model, &triangles, mesh.vertex_count()))).collect();
    let overdraw = match options.views {
        None => None,
        Some(views) => {
            let cameras = views.cameras(Framing::of(&mesh.positions), options.seed);
            let per_view = raster.count(&mesh.positions, &triangles, &cameras, options.res)?;
            let summary = OverdrawSummary::of(&per_view);
            Some(Overdraw { views, res: options.res, per_view, summary })
        }
    };
    Ok(Measurement { caches, overdraw })
}

/// One method's result on one mesh.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The method spec with every parameter (canonical form).
    pub method: String,
    pub peer: bool,
    /// Wall time of the ordering alone.
    pub seconds: f64,
    pub order: Order,
    /// Where the order's clusters start, ending with its length (`[0, n]` for methods without
    /// clusters).
    pub cluster_starts: Vec<usize>,
    pub measurement: Measurement,
}

/// Orders `mesh` with `method` (timed) and measures the order.
pub fn evaluate(
    mesh: &Mesh,
    topology: &Topology,
    method: &Resolved,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Evaluation> {
    let start = Instant::now();
    let clustered = order::run_clustered(method, &OrderInput { mesh, topology })?;
    let seconds = start.elapsed().as_secs_f64();
    let measurement = measure(mesh, &clustered.order, options, raster)?;
    Ok(Evaluation {
        method: method.canonical(),
        peer: method.method.peer,
        seconds,
        order: clustered.order,
        cluster_starts: clustered.starts,
        measurement,
    })
}
