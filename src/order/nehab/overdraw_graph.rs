//! The pairwise cluster overdraw graph of Nehab, Barczak & Sander 2006, §4, computed exactly in
//! one raster pass per view.
//!
//! The paper draws every pair of clusters in both orders under an occlusion query, per view, with
//! the depth buffer cleared each time, and adds an arc a → b when drawing a first generates fewer
//! pixels, weighted by the net difference summed over views: O(n²) renders per view.
//!
//! We get the same numbers from one rasterization per view. Drawing a then b costs
//! `pass(a) + pass(b | a)`, where `pass(a)` counts the fragments of a that pass the depth test
//! when a is drawn alone (in its own triangle order), and `pass(b | a)` those of b that still pass
//! behind a. A fragment of b passes behind a exactly when it passes alone *and* is nearer than the
//! nearest fragment of a at that pixel (depth test LESS). So per pixel it is enough to know, for
//! every cluster there, its nearest depth and the depths of its alone-passing fragments (the
//! running minima of its fragments in draw order). Then
//!
//! `cost(a, b) − cost(b, a) = saved(b → a) − saved(a → b)`, with `saved(a → b)` the number of
//! b's alone-passing fragments at or behind a's nearest depth,
//!
//! and the graph is the antisymmetric part of the matrix `saved`, summed over pixels and views.
//! Only pixels reached by two or more fragments can hold a pair, and those are what a view's
//! [`DepthLayers`] keep, each sorted by depth: walking one nearest first, a cluster's fragments at
//! one depth pass alone when the earliest drawn of them is drawn before every nearer one of the
//! cluster. So the graph of any draw order of the same triangles is counted from the same layers
//! ([`from_layers`]): `nehab`'s search over cluster counts rasterizes each view once for every
//! count it tries. Work per view is O(fragments) to rasterize and sort, then per contested pixel
//! O(fragments × clusters there). [`pair_by_pair`] is the paper's method, kept as the test oracle:
//! the two agree exactly.
//!
//! Memory: one n×n matrix of u64 per worker thread, plus the layers of the views being counted:
//! [`one_pass`] rasterizes as many views at a time as a budget of pixels allows (`views_at_once`).

use glam::Vec3;
use rayon::prelude::*;

use crate::error::Result;
use crate::raster::cpu::{CpuRaster, depth_layers};
use crate::raster::layers::{Contested, DepthLayers};
use crate::raster::{Camera, RasterBackend};

/// Clusters as contiguous runs of a draw list: cluster `c` is `triangles[starts[c]..starts[c + 1]]`,
/// in the order it will be drawn.
#[derive(Debug, Clone, Copy)]
pub struct ClusteredDraw<'a> {
    pub positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    pub starts: &'a [usize],
}

impl ClusteredDraw<'_> {
    pub fn cluster_count(&self) -> usize {
        self.starts.len() - 1
    }

    fn cluster(&self, c: usize) -> &[[u32; 3]] {
        &self.triangles[self.starts[c]..self.starts[c + 1]]
    }
}

/// `saved[a][b]` summed over views: fragments of b that drawing a first keeps from passing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OverdrawGraph {
    n: usize,
    saved: Vec<u64>,
}

/// An arc `from → to`: drawing `from` first saves `weight` more fragments, over all views, than
/// the opposite order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Arc {
    pub from: u32,
    pub to: u32,
    pub weight: u64,
}

impl OverdrawGraph {
    fn zero(n: usize) -> OverdrawGraph {
        OverdrawGraph { n, saved: vec![0; n * n] }
    }

    pub fn node_count(&self) -> usize {
        self.n
    }

    /// Fragments of `b` that drawing `a` before it keeps from passing, over all views.
    pub fn saved(&self, a: usize, b: usize) -> u64 {
        self.saved[a * self.n + b]
    }

    /// The paper's arcs: toward the cheaper order of each pair, weighted by the net saving; none
    /// on ties.
    pub fn arcs(&self) -> Vec<Arc> {
        arcs_of(self.n, |a, b| self.saved(a, b))
    }

    fn add(mut self, other: OverdrawGraph) -> OverdrawGraph {
        self.saved.iter_mut().zip(other.saved).for_each(|(s, o)| *s += o);
        self
    }
}

/// The paper's arcs between `n` clusters from `saved(a, b)` (what drawing a first saves of b):
/// toward the cheaper order of each pair, weighted by the net saving; none on ties. Shared by the
/// drawn graph and the estimated one ([`super::patch_graph`]).
pub(crate) fn arcs_of(n: usize, saved: impl Fn(usize, usize) -> u64) -> Vec<Arc> {
    let mut arcs = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            let (ab, ba) = (saved(a, b), saved(b, a));
            if ab != ba {
                let (from, to) = if ab > ba { (a, b) } else { (b, a) };
                arcs.push(Arc { from: from as u32, to: to as u32, weight: ab.abs_diff(ba) });
            }
        }
    }
    arcs
}

/// The graph from one rasterization per camera: each view's fragments as [`DepthLayers`] (a few
/// views at a time, in parallel), then [`from_layers`].
pub fn one_pass(draw: ClusteredDraw, cameras: &[Camera], res: u32) -> Result<OverdrawGraph> {
    in_batches(draw, cameras, res, views_at_once(res))
}

/// [`one_pass`] with the layers of `batch` views held at once.
fn in_batches(draw: ClusteredDraw, cameras: &[Camera], res: u32, batch: usize) -> Result<OverdrawGraph> {
    let n = draw.cluster_count();
    let mut cluster_of = vec![0u32; draw.triangles.len()];
    for c in 0..n {
        cluster_of[draw.starts[c]..draw.starts[c + 1]].fill(c as u32);
    }
    // The triangles are listed in draw order.
    let rank: Vec<u32> = (0..draw.triangles.len() as u32).collect();
    let mut graph = OverdrawGraph::zero(n);
    for views in cameras.chunks(batch) {
        let layers = depth_layers(draw.positions, draw.triangles, views, res)?;
        graph = graph.add(from_layers(&layers, &rank, &cluster_of, n));
    }
    Ok(graph)
}

/// How many views' layers [`one_pass`] holds at once: as many as [`PIXELS_AT_ONCE`] pixels
/// allow, so that memory does not grow with the view set, and at least one per thread. Sized by
/// pixels rather than views: small views in one batch share one renumbering of the mesh and one
/// start of the threads (cheap-cuts' 42 views at 64² are one batch, not three).
fn views_at_once(res: u32) -> usize {
    let pixels = (res as usize * res as usize).max(1);
    (PIXELS_AT_ONCE / pixels).max(rayon::current_num_threads())
}

/// The pixels of sixteen views at 512²: the batch [`one_pass`] held at every resolution before it
/// was sized by pixels.
const PIXELS_AT_ONCE: usize = 16 * 512 * 512;

/// The graph of `n` clusters (`cluster_of[t]`: triangle t's) drawn in the order `rank` (`rank[t]`:
/// triangle t's place), from views of those triangles already rasterized ([`DepthLayers`], views
/// in parallel). Every order of the same triangles from the same views is counted from the same
/// layers: `nehab`'s search over cluster counts rasterizes each view once for all of them.
pub fn from_layers(layers: &[DepthLayers], rank: &[u32], cluster_of: &[u32], n: usize) -> OverdrawGraph {
    // One run of views per worker thread, so only that many n×n matrices ever exist.
    let per_thread = layers.len().div_ceil(rayon::current_num_threads()).max(1);
    layers
        .par_iter()
        .with_min_len(per_thread)
        .fold(
            || (OverdrawGraph::zero(n), PixelScratch::default()),
            |(mut graph, mut scratch), view| {
                for pixel in view.contested() {
                    scratch.accumulate(pixel, rank, cluster_of, &mut graph);
                }
                (graph, scratch)
            },
        )
        .map(|(graph, _)| graph)
        .reduce(|| OverdrawGraph::zero(n), OverdrawGraph::add)
}

/// One contested pixel's clusters, reused from pixel to pixel.
#[derive(Default)]
struct PixelScratch {
    clusters: Vec<Present>,
    /// The alone-passing fragments: their cluster and depth index.
    passing: Vec<(u32, u32)>,
}

/// A cluster at the pixel, its fragments walked nearest first.
struct Present {
    cluster: u32,
    /// The depth index of its nearest fragment.
    nearest: u32,
    /// Its earliest draw among fragments strictly nearer than `depth`.
    before: u32,
    /// Its earliest draw at `depth`, the depth of its fragments being walked.
    at: u32,
    depth: u32,
}

impl Present {
    /// Of the cluster's fragments at `depth`, the earliest drawn passes alone exactly when it is
    /// drawn before every nearer one of its cluster; the others at that depth fail the LESS test.
    fn close(&mut self, passing: &mut Vec<(u32, u32)>) {
        if self.at < self.before {
            passing.push((self.cluster, self.depth));
        }
        self.before = self.before.min(self.at);
    }
}

impl PixelScratch {
    /// Adds the pixel's `saved(a → b)`: b's alone-passing fragments at or behind a's nearest.
    fn accumulate(&mut self, pixel: Contested, rank: &[u32], cluster_of: &[u32], graph: &mut OverdrawGraph) {
        self.clusters.clear();
        self.passing.clear();
        for (t, depth) in pixel.by_depth() {
            let (cluster, r) = (cluster_of[t as usize], rank[t as usize]);
            match self.clusters.iter_mut().find(|p| p.cluster == cluster) {
                Some(present) if present.depth == depth => present.at = present.at.min(r),
                Some(present) => {
                    present.close(&mut self.passing);
                    (present.at, present.depth) = (r, depth);
                }
                None => self.clusters.push(Present { cluster, nearest: depth, before: u32::MAX, at: r, depth }),
            }
        }
        if self.clusters.len() < 2 {
            return;
        }
        for present in &mut self.clusters {
            present.close(&mut self.passing);
        }
        for a in &self.clusters {
            let row = &mut graph.saved[a.cluster as usize * graph.n..][..graph.n];
            for &(b, depth) in &self.passing {
                if b != a.cluster && depth >= a.nearest {
                    row[b as usize] += 1;
                }
            }
        }
    }
}

/// The paper's construction, kept as the oracle for [`one_pass`]: every cluster drawn alone and
/// every pair drawn in one order, per view, with the depth buffer cleared each time. O(n²) renders
/// per view, for tests on small inputs only.
pub fn pair_by_pair(draw: ClusteredDraw, cameras: &[Camera], res: u32) -> Result<OverdrawGraph> {
    let n = draw.cluster_count();
    let passed = |tris: &[[u32; 3]]| -> Result<Vec<u64>> {
        Ok(CpuRaster.count(draw.positions, tris, cameras, res)?.iter().map(|v| v.passed).collect())
    };
    let alone: Vec<Vec<u64>> = (0..n).map(|c| passed(draw.cluster(c))).collect::<Result<_>>()?;
    let mut graph = OverdrawGraph::zero(n);
    for a in 0..n {
        for b in 0..n {
            if a != b {
                let both = passed(&[draw.cluster(a), draw.cluster(b)].concat())?;
                graph.saved[a * n + b] = (0..cameras.len()).map(|v| alone[a][v] + alone[b][v] - both[v]).sum();
            }
        }
    }
    Ok(graph)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Framing, procedural};
    use crate::raster::ViewSet;

    /// The graph is a sum over views, so how many views are drawn at once changes nothing: one
    /// batch (what 42 views at 64² now are) and batches of five give the same counts.
    #[test]
    fn batching_the_views_changes_no_count() {
        let mesh = procedural::generate("helix:3", 1).unwrap().unwrap();
        let starts: Vec<usize> = (0..=6).map(|i| i * mesh.triangle_count() / 6).collect();
        let draw = ClusteredDraw { positions: &mesh.positions, triangles: &mesh.triangles, starts: &starts };
        let cameras = ViewSet::Ico(42).cameras(Framing::of(&mesh.positions), 0);
        assert!(views_at_once(64) >= cameras.len(), "42 views at 64² are one batch");
        let whole = one_pass(draw, &cameras, 64).unwrap();
        let fives = in_batches(draw, &cameras, 64, 5).unwrap();
        assert!(!whole.arcs().is_empty());
        assert_eq!(whole.saved, fives.saved);
    }
}
