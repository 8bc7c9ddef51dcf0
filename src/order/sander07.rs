//! `sander07`: Sander, Nehab & Barczak 2007, "Fast triangle reordering for vertex locality and
//! reduced overdraw", §3–§5, our own implementation (ALGORITHMS.md §2): Tipsify, then fast linear
//! clustering of its output, then clusters sorted by the dot rule. No rendering at all: the whole
//! pipeline is linear in the triangles plus a sort of the clusters.
//!
//! **Fast linear clustering** (§4). The Tipsify order is first cut at its *cache-flush
//! boundaries*: dead ends where Tipsify jumped to a triangle none of whose vertices is still in
//! the FIFO, so nothing is lost by drawing the pieces apart. (meshoptimizer cuts at every dead end;
//! Tootle only where the restart vertex is over 2k misses old; a jump that lands on a cached vertex
//! is not a flush, so we keep it.) Each piece is then scanned with a FIFO reset at every cluster
//! start, and a cluster ends after the triangle at which its own ACMR (misses ÷ triangles since the
//! cluster began) falls to λ or below. A cold cluster always starts at 3 misses for one triangle,
//! so λ ≥ 3 cuts every triangle apart, while λ < 0.5 (below any reachable ACMR) keeps only the
//! flush boundaries; λ bounds from below the ACMR the clusters can cost in any order.
//!
//! **Dot-rule sort** (§5). Each cluster's area-weighted centroid C(P) and area-weighted normal
//! N(P) (normalised), and the mesh's area-weighted centroid C(M): clusters are drawn in decreasing
//! `(C(P) − C(M)) · N(P)`, outward-facing peripheral clusters first, since they are the ones likely
//! to occlude others. The sort is stable, so ties keep Tipsify's order.

use glam::{DVec3, Vec3};

use super::tipsify::{FIFO_CACHE, tipsify};
use super::{Clustered, Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::frames::unit_positions64;
use crate::mesh::topology::Csr;
use crate::mesh::{Mesh, Scene};

pub static METHOD: Method = Method {
    name: "sander07",
    summary: "Tipsify + fast linear clustering (λ) + dot-rule cluster sort, no rendering",
    source: "Sander, Nehab & Barczak 2007, §3-5",
    peer: false,
    per_node: false,
    cost: Cost::Linear,
    params: &[FIFO_CACHE, LAMBDA],
    build,
};

/// λ, the clustering threshold (shared with the animated orderings that cluster the same way).
pub(crate) const LAMBDA: ParamInfo = ParamInfo {
    name: "lambda",
    default: "0.85",
    kind: ParamKind::Float { min: 0.0, max: 3.0 },
    help: "end a cluster once its own ACMR falls to this (higher: smaller clusters, less overdraw, more misses)",
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Sander07 { cache: params.int(&FIFO_CACHE) as u32, lambda: params.float(&LAMBDA) })
}

struct Sander07 {
    cache: u32,
    lambda: f64,
}

impl Ordering for Sander07 {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        Ok(sander07(&scene.mesh, &scene.topology.vertex_triangles, self.cache, self.lambda).into())
    }
}

/// The whole pipeline on `mesh`, whose vertex→triangle adjacency is `vertex_triangles`.
pub(crate) fn sander07(mesh: &Mesh, vertex_triangles: &Csr, cache: u32, lambda: f64) -> Clustered {
    let patches = patches(mesh, vertex_triangles, cache, lambda);
    let clusters: Vec<&[u32]> = patches.starts.windows(2).map(|w| &patches.order[w[0]..w[1]]).collect();
    let sorted = dot_rule_sort(&mesh.positions, &mesh.triangles, &clusters, Facing::Unit);
    Clustered::concat(sorted.iter().map(|&c| clusters[c]))
}

/// The first two stages, which use connectivity only: the Tipsify order cut into clusters by
/// fast linear clustering with `lambda`, in Tipsify's order. The animated orderings (Han &
/// Sander 2017, §3.1) start from these "cache-efficient patches" and only reorder them.
pub(crate) fn patches(mesh: &Mesh, vertex_triangles: &Csr, cache: u32, lambda: f64) -> Clustered {
    let (order, dead_ends) = tipsify(&mesh.triangles, vertex_triangles, cache);
    let starts = linear_clusters(&mesh.triangles, &order, &dead_ends, mesh.vertex_count(), cache, lambda);
    Clustered { order, starts }
}

/// Cluster starts (ending with `order.len()`) of the fast linear clustering of `order`, a Tipsify
/// order of `triangles` whose dead-end positions are `dead_ends`, for a FIFO of `cache`.
pub(crate) fn linear_clusters(
    triangles: &[[u32; 3]],
    order: &[u32],
    dead_ends: &[usize],
    vertex_count: usize,
    cache: u32,
    lambda: f64,
) -> Vec<usize> {
    let (mut global, mut local) = (Fifo::new(vertex_count, cache), Fifo::new(vertex_count, cache));
    let mut dead_ends = dead_ends.iter().peekable();
    let mut starts = vec![0];
    let (mut misses, mut count) = (0u32, 0u32);
    for (i, &t) in order.iter().enumerate() {
        let corners = triangles[t as usize];
        let at_dead_end = dead_ends.next_if_eq(&&i).is_some();
        let flushed = corners.iter().all(|&v| !global.cached(v));
        if i > 0 && at_dead_end && flushed && *starts.last().unwrap() != i {
            starts.push(i);
            (misses, count) = (0, 0);
            local.reset();
        }
        corners.iter().for_each(|&v| _ = global.touch(v));
        misses += corners.iter().filter(|&&v| local.touch(v)).count() as u32;
        count += 1;
        if f64::from(misses) <= lambda * f64::from(count) && i + 1 < order.len() {
            starts.push(i + 1);
            (misses, count) = (0, 0);
            local.reset();
        }
    }
    starts.push(order.len());
    starts.dedup();
    starts
}

/// A FIFO vertex cache by timestamps: a vertex is cached when it missed among the last `size`
/// misses since the last reset.
struct Fifo {
    stamp: Vec<u32>,
    now: u32,
    floor: u32,
    size: u32,
}

impl Fifo {
    fn new(vertex_count: usize, size: u32) -> Fifo {
        Fifo { stamp: vec![0; vertex_count], now: 1, floor: 0, size }
    }

    fn cached(&self, v: u32) -> bool {
        let s = self.stamp[v as usize];
        s > self.floor && self.now - s <= self.size
    }

    /// Uses `v`; true on a miss.
    fn touch(&mut self, v: u32) -> bool {
        let miss = !self.cached(v);
        if miss {
            self.stamp[v as usize] = self.now;
            self.now += 1;
        }
        miss
    }

    fn reset(&mut self) {
        self.floor = self.now - 1;
    }
}

/// How a cluster's facing enters the dot rule's key.
#[derive(Clone, Copy)]
pub(crate) enum Facing {
    /// The paper's: N(P), the area-weighted normal normalised.
    Unit,
    /// The area-weighted normal divided by the area: N(P) times how much the cluster faces one
    /// way (1 for a flat one, 0 for a closed one). For clusters that may be closed parts, whose
    /// normals cancel and whose normalised sum is the direction of rounding noise.
    Mean,
}

/// Indices of `clusters` (lists of triangle ids) in dot-rule order: decreasing
/// `(C(P) − C(M)) · N(P)` (with `facing` deciding N(P)), stable. Computed in f64 on the positions
/// in their unit frame ([`unit_positions64`]), where the keys are the world keys divided by the
/// radius (the order is the same) and the same bits wherever the mesh stands and whatever its
/// units.
pub(crate) fn dot_rule_sort(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    clusters: &[&[u32]],
    facing: Facing,
) -> Vec<usize> {
    let positions = unit_positions64(positions);
    // Per cluster: Σ area·centroid, Σ area, Σ area-weighted normal (twice the area, the cross product).
    let sums: Vec<(DVec3, f64, DVec3)> = clusters
        .iter()
        .map(|tris| {
            tris.iter().fold((DVec3::ZERO, 0.0, DVec3::ZERO), |(c, a, n), &t| {
                let [p, q, r] = triangles[t as usize].map(|v| positions[v as usize]);
                let cross = (q - p).cross(r - p);
                let area = cross.length();
                (c + area * (p + q + r) / 3.0, a + area, n + cross)
            })
        })
        .collect();
    let (total, area) = sums.iter().fold((DVec3::ZERO, 0.0), |(c, a), s| (c + s.0, a + s.1));
    let mesh_centre = if area > 0.0 { total / area } else { DVec3::ZERO };
    let key: Vec<f64> = sums
        .iter()
        .map(|&(c, a, n)| {
            let facing = match facing {
                Facing::Unit => n.normalize_or_zero(),
                Facing::Mean => n / a,
            };
            if a > 0.0 { (c / a - mesh_centre).dot(facing) } else { 0.0 }
        })
        .collect();
    let mut sorted: Vec<usize> = (0..clusters.len()).collect();
    sorted.sort_by(|&x, &y| key[y].total_cmp(&key[x]));
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of quads along x: triangles (2i, 2i+1) share vertices with their neighbours.
    fn strip(quads: u32) -> Vec<[u32; 3]> {
        (0..quads).flat_map(|i| [[2 * i, 2 * i + 1, 2 * i + 2], [2 * i + 1, 2 * i + 3, 2 * i + 2]]).collect()
    }

    #[test]
    fn lambda_extremes_give_single_triangles_or_hard_boundaries_only() {
        let tris = strip(20);
        let order: Vec<u32> = (0..tris.len() as u32).collect();
        let singles = linear_clusters(&tris, &order, &[0], 42, 16, 3.0);
        assert_eq!(singles, (0..=tris.len()).collect::<Vec<_>>());
        let whole = linear_clusters(&tris, &order, &[0], 42, 16, 0.4);
        assert_eq!(whole, [0, tris.len()]);
    }

    /// On a strip, a cold cluster of n triangles costs n + 2 misses: the ratio reaches 1.25 at
    /// n + 2 ≤ 1.25 n, i.e. n ≥ 8, so λ = 1.25 cuts every 8 triangles, while λ = 0.85 (below a
    /// strip's limit of 1) never cuts.
    #[test]
    fn lambda_cuts_where_the_local_acmr_reaches_it() {
        let tris = strip(20);
        let order: Vec<u32> = (0..tris.len() as u32).collect();
        assert_eq!(linear_clusters(&tris, &order, &[0], 42, 16, 1.25), [0, 8, 16, 24, 32, 40]);
        assert_eq!(linear_clusters(&tris, &order, &[0], 42, 16, 0.85), [0, 40]);
    }

    #[test]
    fn a_jump_to_uncached_vertices_is_a_hard_boundary_and_one_to_cached_ones_is_not() {
        // Two separate strips: the jump to the second is a flush.
        let mut tris = strip(3);
        tris.extend(strip(3).iter().map(|t| t.map(|v| v + 100)));
        let order: Vec<u32> = (0..tris.len() as u32).collect();
        assert_eq!(linear_clusters(&tris, &order, &[0, 6], 200, 16, 0.0), [0, 6, 12]);
        // A "dead end" inside one strip lands on cached vertices: no cut.
        let tris = strip(6);
        let order: Vec<u32> = (0..tris.len() as u32).collect();
        assert_eq!(linear_clusters(&tris, &order, &[0, 6], 200, 16, 0.0), [0, 12]);
    }

    #[test]
    fn dot_rule_draws_outward_facing_peripheral_clusters_first() {
        // Two unit squares facing +z at z = 0 (near the centre) and z = 1 (on the rim), plus one
        // facing −z at z = 0.5.
        let quad = |z: f32, up: bool| {
            let p = [Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 0.0, z), Vec3::new(1.0, 1.0, z), Vec3::new(0.0, 1.0, z)];
            (p, if up { [[0, 1, 2], [0, 2, 3]] } else { [[0, 2, 1], [0, 3, 2]] })
        };
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for (z, up) in [(0.0, true), (1.0, true), (0.5, false)] {
            let (p, t) = quad(z, up);
            let base = positions.len() as u32;
            positions.extend(p);
            triangles.extend(t.map(|t| t.map(|v| v + base)));
        }
        let clusters: [&[u32]; 3] = [&[0, 1], &[2, 3], &[4, 5]];
        // Centre z = 0.5: keys 0·... = −0.5, +0.5, and 0 (the −z square sits at the centre).
        assert_eq!(dot_rule_sort(&positions, &triangles, &clusters, Facing::Unit), [1, 2, 0]);
    }
}
