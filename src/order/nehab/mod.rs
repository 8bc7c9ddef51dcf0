//! `nehab`: Nehab, Barczak & Sander 2006, "Triangle order optimization for graphics hardware
//! computation culling" (I3D), §3–§5, our own implementation (ALGORITHMS.md §4):
//!
//! 1. planar k-means clustering of the faces by normal ([`planar_clusters`], §3);
//! 2. each cluster ordered for the vertex cache by the inner locality ordering (`hoppe`, as the
//!    paper, or `tipsify`), on its own;
//! 3. the pairwise cluster overdraw graph over `views` icosahedral orthographic views at
//!    `res`×`res`, computed exactly in one raster pass per view ([`overdraw_graph`], §4),
//!    with each cluster drawn in its inner order, so the graph measures what will be rendered;
//! 4. clusters ordered by the greedy minimum feedback arc set ([`feedback_arc_set`], §5)
//!    and concatenated.
//!
//! The cluster count is the single knob, as the paper says. The paper chooses it per model as the
//! smallest power of two after which overdraw stops improving; we leave that search to the
//! cluster-count sweep (paper Fig. 9).

pub mod feedback_arc_set;
pub mod overdraw_graph;
pub(crate) mod planar_clusters;

use feedback_arc_set::greedy_order;
use overdraw_graph::{ClusteredDraw, one_pass};
use planar_clusters::planar_clusters;
use rayon::prelude::*;

use super::hoppe;
use super::{Clustered, Cost, Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::Framing;
use crate::mesh::{Mesh, Scene};
use crate::raster::{ViewSet, naming_mesh};

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
    })
}

struct Nehab {
    clusters: usize,
    views: u32,
    res: u32,
    /// The inner ordering's spec.
    inner: String,
    seed: u64,
}

impl Ordering for Nehab {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let clusters = planar_clusters(mesh, &scene.topology, self.clusters, self.seed);
        let members = members(&clusters.cluster, clusters.count);
        let inner = super::resolve(&self.inner, self.seed)?;
        let inner_orders: Vec<Order> =
            members.par_iter().map(|tris| order_inside(mesh, tris, inner.ordering.as_ref())).collect::<Result<_>>()?;
        let local = Clustered::concat(inner_orders.iter().map(Vec::as_slice));
        let triangles = mesh.triangles_in_order(&local.order);
        let draw = ClusteredDraw { positions: &mesh.positions, triangles: &triangles, starts: &local.starts };
        let cameras = ViewSet::Ico(self.views).cameras(Framing::of(&mesh.positions), 0);
        let graph = one_pass(draw, &cameras, self.res).map_err(|e| naming_mesh(&mesh.name, e))?;
        let sequence = greedy_order(clusters.count, &graph.arcs());
        Ok(Clustered::concat(sequence.iter().map(|&c| inner_orders[c as usize].as_slice())).into())
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
