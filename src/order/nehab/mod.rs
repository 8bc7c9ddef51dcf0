//! `nehab`: Nehab, Barczak & Sander 2006, "Triangle order optimization for graphics hardware
//! computation culling" (I3D), §3–§5, our own implementation (ALGORITHMS.md §4):
//!
//! 1. planar k-means clustering of the faces by normal ([`planar_clusters`], §3);
//! 2. each cluster ordered for the vertex cache by the inner locality ordering (`hoppe`, as the
//!    paper, or `tipsify`), on its own;
//! 3. the pairwise cluster overdraw graph over `views` icosahedral orthographic views at
//!    `res`×`res`, computed exactly from one rasterization per view ([`overdraw_graph`], §4),
//!    with each cluster drawn in its inner order, so the graph measures what will be rendered;
//!    the views are rasterized once per scene and kept for every nehab ordering of it with the
//!    same views and resolution;
//! 4. clusters ordered by the greedy minimum feedback arc set ([`feedback_arc_set`], §5)
//!    and concatenated.
//!
//! The cluster count is the single knob, as the paper says. `select=fixed` (the default) takes
//! `clusters` as given. `select=doubling` is the paper's own rule (§6, with Fig. 9): "trying the
//! method on successive powers of two, until the average overdraw stops improving consistently".
//! We read "consistently" as two doublings in a row: the count k is taken when neither 2k nor 4k
//! lowers the mean overdraw ratio over the graph's own views by [`STALL`] or more, once some
//! doubling has (a mesh of several components gains nothing from its first doublings);
//! `clusters` is the largest count tried. The mean is counted exactly, on the CPU rasterizer, for each
//! count tried (the doubling costs a few times one run).

pub mod feedback_arc_set;
pub mod overdraw_graph;
pub mod patch_graph;
pub(crate) mod planar_clusters;

use feedback_arc_set::greedy_order;
use overdraw_graph::from_layers;
use planar_clusters::planar_clusters;
use rayon::prelude::*;
use std::sync::Arc;

use super::hoppe;
use super::{Clustered, Cost, Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::Framing;
use crate::mesh::{Mesh, Scene};
use crate::measure::OverdrawSummary;
use crate::raster::cpu::depth_layers;
use crate::raster::layers::{DepthLayers, ranks};
use crate::raster::{ViewCounts, ViewSet, naming_mesh};

const CLUSTERS: ParamInfo = ParamInfo {
    name: "clusters",
    default: "64",
    kind: ParamKind::Int { min: 1, max: 4096 },
    help: "target number of planar clusters (more: less overdraw, slightly more misses)",
};

const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "162",
    kind: ParamKind::Choice(&["12", "42", "162", "642", "2562"]),
    help: "icosahedral orthographic views the overdraw graph is measured over",
};

const RES: ParamInfo = ParamInfo {
    name: "res",
    default: "512",
    kind: ParamKind::Int { min: 16, max: 4096 },
    help: "side of the square images the graph is rasterized at",
};

const INNER: ParamInfo = ParamInfo {
    name: "inner",
    default: "hoppe",
    kind: ParamKind::Choice(&["hoppe", "tipsify"]),
    help: "locality ordering applied inside each cluster",
};

const CACHE: ParamInfo = ParamInfo { help: "FIFO size the inner ordering is tuned for", ..hoppe::CACHE };

const SELECT: ParamInfo = ParamInfo {
    name: "select",
    default: "fixed",
    kind: ParamKind::Choice(&["fixed", "doubling"]),
    help: "fixed: `clusters` as given; doubling: the paper's search over 1, 2, 4, … up to `clusters` (see the module doc)",
};

/// A doubling of the cluster count that lowers the mean overdraw ratio by less than this (half a
/// percent of the covered pixels) does not count as an improvement for `select=doubling`.
pub const STALL: f64 = 0.005;

pub static METHOD: Method = Method {
    name: "nehab",
    summary: "planar clusters ordered by a view-independent overdraw graph (greedy FAS), locality inside",
    source: "Nehab, Barczak & Sander 2006, §3-5",
    peer: false,
    per_node: false,
    cost: Cost::Heaviest,
    params: &[
        CLUSTERS,
        VIEWS,
        RES,
        INNER,
        CACHE,
        ParamInfo { name: "seed", default: "", kind: ParamKind::Seed, help: "picks the first cluster seed face" },
        SELECT,
    ],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Nehab {
        clusters: params.int(&CLUSTERS) as usize,
        views: params.word(&VIEWS).parse().expect("the schema lists only numbers"),
        res: params.int(&RES) as u32,
        inner: format!("{}:cache={}", params.word(&INNER), params.int(&CACHE)),
        seed: params.seed(),
        doubling: params.word(&SELECT) == "doubling",
    })
}

struct Nehab {
    clusters: usize,
    views: u32,
    res: u32,
    /// The inner ordering's spec.
    inner: String,
    seed: u64,
    /// Search the cluster count by doubling (`select=doubling`).
    doubling: bool,
}

impl Ordering for Nehab {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let (layers, reused) = self.views(scene)?;
        if !self.doubling {
            let mut orders = Orders::from(self.order_with(scene, self.clusters, &layers)?);
            orders.reused = reused;
            return Ok(orders);
        }
        let mean_ovr = |order: &Clustered| -> Result<f64> {
            let rank = ranks(&order.order);
            let counts: Vec<ViewCounts> = layers.par_iter().map(|view| view.counts(&rank)).collect();
            Ok(OverdrawSummary::of(&counts).map_or(1.0, |s| s.mean))
        };
        // Counts 1, 2, 4, … up to `clusters`, each ordered and measured once.
        let measured = |k: usize| -> Result<(Clustered, f64)> {
            let order = self.order_with(scene, k, &layers)?;
            let ovr = mean_ovr(&order)?;
            Ok((order, ovr))
        };
        let mut tried: Vec<(Clustered, f64)> = Vec::new();
        let mut k = 1;
        loop {
            // Planar clustering runs on one thread: two counts are ordered side by side, and the
            // second is dropped when the first settles the search (the same counts are tried
            // and the same one picked as one at a time).
            let next = (2 * k).min(self.clusters);
            let (first, second) = rayon::join(|| measured(k), || (next > k).then(|| measured(next)));
            for (count, result) in [(k, Some(first)), (next, second)] {
                let Some(result) = result else { continue };
                tried.push(result?);
                let n = tried.len();
                let stalled = |a: usize| tried[a].1 - tried[a + 1].1 < STALL;
                // The first count whose next two doublings both stall, once the overdraw has
                // started improving: the first doublings of a mesh of several components change
                // nothing (a cluster per component), and stopping there would never try the knee.
                let knee = || {
                    let improved = (0..n.saturating_sub(1)).find(|&i| !stalled(i))?;
                    (improved + 1..n.saturating_sub(2)).find(|&i| stalled(i) && stalled(i + 1))
                };
                if knee().is_some() || count >= self.clusters {
                    // Else (the cap reached first) the last count tried.
                    let pick = knee().unwrap_or(n - 1);
                    let mut orders = Orders::from(tried.swap_remove(pick).0);
                    orders.iterations = Some(n);
                    orders.reused = reused;
                    return Ok(orders);
                }
            }
            k = (2 * next).min(self.clusters);
        }
    }
}

impl Nehab {
    /// The rest mesh from the graph's views, rasterized once per scene and kept as
    /// [`DepthLayers`]: every order of its triangles, whatever the cluster count, has its graph
    /// and its depth test counted from them, so the nehab orderings of a scene that share views
    /// and resolution (a sweep over cluster counts, the doubling search) rasterize them once.
    /// Also the seconds reusing them saved, as they cost then.
    fn views(&self, scene: &Scene) -> Result<(Arc<Vec<DepthLayers>>, f64)> {
        let mesh = &scene.mesh;
        let key = format!("the rest mesh's depth layers: ico:{} orthographic at {}²", self.views, self.res);
        let (layers, reused) = scene.shared.get_or_compute(&key, || {
            let cameras = ViewSet::Ico(self.views).cameras(Framing::of(&mesh.positions), 0);
            depth_layers(&mesh.positions, &mesh.triangles, &cameras, self.res).map_err(|e| naming_mesh(&mesh.name, e))
        })?;
        Ok((layers, reused.unwrap_or(0.0)))
    }

    /// The order with `target` planar clusters, its graph counted from `layers` ([`Nehab::views`]).
    fn order_with(&self, scene: &Scene, target: usize, layers: &[DepthLayers]) -> Result<Clustered> {
        let mesh = &scene.mesh;
        let clusters = planar_clusters(mesh, &scene.topology, target, self.seed);
        let members = members(&clusters.cluster, clusters.count);
        let inner = super::resolve(&self.inner, self.seed)?;
        let inner_orders: Vec<Order> =
            members.par_iter().map(|tris| order_inside(mesh, tris, inner.ordering.as_ref())).collect::<Result<_>>()?;
        let local = Clustered::concat(inner_orders.iter().map(Vec::as_slice));
        let graph = from_layers(layers, &ranks(&local.order), &clusters.cluster, clusters.count);
        let sequence = greedy_order(clusters.count, &graph.arcs());
        Ok(Clustered::concat(sequence.iter().map(|&c| inner_orders[c as usize].as_slice())))
    }
}

/// The triangles of each cluster, in increasing id.
fn members(cluster: &[u32], count: usize) -> Vec<Vec<u32>> {
    let mut members = vec![Vec::new(); count];
    for (t, &c) in cluster.iter().enumerate() {
        members[c as usize].push(t as u32);
    }
    members
}

/// `triangles` (ids into `mesh`) ordered by `inner` as a mesh of their own, so the inner ordering
/// sees the cluster's boundary as a boundary. Its vertices keep their relative numbering (orderings
/// such as Tipsify depend on it). Returns ids into `mesh`.
fn order_inside(mesh: &Mesh, triangles: &[u32], inner: &dyn Ordering) -> Result<Order> {
    let mut vertices: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t as usize]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local = |v: u32| vertices.binary_search(&v).expect("every corner is listed") as u32;
    let part = Mesh {
        name: mesh.name.clone(),
        positions: vertices.iter().map(|&v| mesh.positions[v as usize]).collect(),
        triangles: triangles.iter().map(|&t| mesh.triangles[t as usize].map(local)).collect(),
        attributes: Default::default(),
    };
    let orders = inner.order(&Scene::still(part))?;
    let order = &orders.single().expect("the inner orderings are static").order;
    Ok(order.iter().map(|&i| triangles[i as usize]).collect())
}
