//! The pairwise cluster overdraw graph of Nehab, Barczak & Sander 2006 (§4), estimated from the
//! surface instead of drawn: ours (issue 19), for `cheap-cuts`.
//!
//! The paper's graph counts, over a set of views, the pixels where drawing cluster a before b
//! saves b's fragments, each pair drawn alone. [`super::overdraw_graph`] counts that exactly, one
//! raster pass per view; at the views' small size (42 at 64² for cheap-cuts) the cost is the
//! setup of every triangle in every view, about 40 times what meshoptimizer spends ordering the
//! whole mesh. Here the views are integrated analytically instead.
//!
//! Cut each cluster into patches of consecutive triangles (a cache order keeps them together on
//! the surface; where the caller says it does not, along a Z-order curve instead). Two small
//! patches p and q, with area-weighted normals Np and Nq and centres r apart along the unit
//! vector u from q to p, overlap on screen only when seen nearly along u, with p the nearer;
//! summed over all view directions, the overlapping area is
//!
//! (Np·u)⁺ (Nq·u)⁺ / r²,
//!
//! the form factor of radiosity without its 1/π, and it counts only while both face the viewer,
//! when drawing p first saves q's fragments. So `saved(a → b)` is estimated by the sum of that
//! over the patches p of a and q of b (and `saved(b → a)` by the same with u reversed), and the
//! arcs are the paper's: toward the larger of the two, weighted by the difference. As in the
//! paper, no third cluster hides either of a pair.
//!
//! The far-field formula grows without bound as two patches close in. Stacked layers (clothing
//! over a body, a robot's shell over its parts) are where overdraw between clusters is largest,
//! and there the true overlap, summed over directions, is at most about π times a patch's area:
//! so in (Np·d)(Nq·d)/r⁴ (d = r·u) one factor r² becomes r² + (Ap + Aq)/2π, which keeps the far
//! field and saturates at π times the mean area when the centres meet. (The first version
//! softened with 0.5(Ap + Aq) added to r² in both factors of r⁴, which sends the term to zero
//! for stacked patches; the held-out characters showed it, see paper-figures/README.md.)
//!
//! Cost: O(triangles) for the patches, then O(P²) for P patches ([`PATCHES`] at most, plus one
//! per cluster), in loops the compiler vectorizes.

use std::ops::Range;

use glam::DVec3;

use super::overdraw_graph::{Arc, arcs_of};
use crate::mesh::Framing;
use crate::mesh::z_order::ZOrder;

/// About this many patches at most (plus one per cluster, where a run ends short): the pairs,
/// P²/2, then cost about a quarter of a millisecond (RobotExpressive, 513 patches, AMD EPYC).
pub const PATCHES: usize = 512;

/// Fewest triangles a patch holds: on a small mesh the pairs would otherwise cost more than
/// meshoptimizer's whole ordering (Fox's 576 triangles in 288 patches: 0.1 ms against its 0.04).
const LEAST: usize = 4;

/// The estimated graph's arcs for clusters given as runs of a draw list: cluster `c` is
/// `triangles[starts[c]..starts[c + 1]]`. Weights are the estimates scaled so that the largest
/// `saved` is 2⁴⁰, rounded.
///
/// Patches are runs of consecutive triangles, which is right where the draw list walks the
/// surface (a cache order). In the `scattered` ranges it need not: consecutive triangles there
/// may lie anywhere (cheap-cuts' loose units, sorted by the dot rule), and a patch of them would
/// have a centre in empty space and a normal that their own normals cancel. There, within each
/// cluster, the patches are taken along a Z-order curve through the triangles' centroids instead.
/// A cluster is the same set of triangles either way; only its patches change.
pub fn patch_arcs(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
    starts: &[usize],
    scattered: &[Range<usize>],
) -> Vec<Arc> {
    let bounds = Framing::bounds_of(positions);
    let regrouped;
    let triangles = if scattered.is_empty() {
        triangles
    } else {
        regrouped = along_curve(positions, bounds, triangles, starts, scattered);
        &regrouped
    };
    arcs(&saved(positions, bounds, triangles, starts), starts.len() - 1)
}

/// `triangles` with each piece of a `scattered` range that lies in one cluster sorted along a
/// Z-order curve through the triangles' centroids ([`ZOrder`], over `bounds`, the box of
/// `positions`; ties keep their order): any curve that keeps cells together makes the patches
/// compact. One stable radix sort of every scattered triangle, keyed by its cluster and then its
/// cell; `scattered` is in increasing order, without overlaps.
fn along_curve(
    positions: &[glam::Vec3],
    (lo, hi): (DVec3, DVec3),
    triangles: &[[u32; 3]],
    starts: &[usize],
    scattered: &[Range<usize>],
) -> Vec<[u32; 3]> {
    let grid = ZOrder::over(lo.as_vec3(), hi.as_vec3());
    let cell = |t: &[u32; 3]| {
        let centre = (positions[t[0] as usize] + positions[t[1] as usize] + positions[t[2] as usize]) / 3.0;
        u64::from(grid.key(centre))
    };
    let mut keyed: Vec<(u64, [u32; 3])> = Vec::with_capacity(scattered.iter().map(|r| r.len()).sum());
    let mut cluster = 0;
    for i in scattered.iter().flat_map(|r| r.clone()) {
        while starts[cluster + 1] <= i {
            cluster += 1;
        }
        keyed.push(((cluster as u64) << 32 | cell(&triangles[i]), triangles[i]));
    }
    radsort::sort_by_key(&mut keyed, |k| k.0);
    // The sort kept each cluster's places in the ranges, which come in increasing order: they
    // are refilled in turn.
    let mut regrouped = triangles.to_vec();
    for (place, (_, t)) in scattered.iter().flat_map(|r| r.clone()).zip(keyed) {
        regrouped[place] = t;
    }
    regrouped
}

/// The estimated `saved` matrix, row a, column b: the area of b that drawing a first hides,
/// summed over view directions (areas of the mesh scaled to unit size, per steradian); `bounds`
/// is the box of `positions`.
fn saved(positions: &[glam::Vec3], bounds: (DVec3, DVec3), triangles: &[[u32; 3]], starts: &[usize]) -> Vec<f64> {
    let clusters = starts.len() - 1;
    let patches = Patches::of(positions, bounds, triangles, starts);
    let mut saved = vec![0.0f64; clusters * clusters];
    let (mut over, mut under) = (vec![0.0f32; patches.len()], vec![0.0f32; patches.len()]);
    for p in 0..patches.len() {
        let a = patches.cluster[p] as usize;
        // Against every patch of the later clusters at once (one long loop the compiler
        // vectorizes), then summed cluster by cluster.
        let later = patches.first[a + 1];
        patches.hiding(p, later, &mut over[later..], &mut under[later..]);
        for (b, run) in patches.first.windows(2).enumerate().skip(a + 1) {
            let (over, under) = (&over[run[0]..run[1]], &under[run[0]..run[1]]);
            let (mut o, mut u) = (0.0f32, 0.0f32);
            for i in 0..over.len() {
                o += over[i];
                u += under[i];
            }
            saved[a * clusters + b] += f64::from(o);
            saved[b * clusters + a] += f64::from(u);
        }
    }
    saved
}

/// Patches as columns (structure of arrays), so that one patch against a run of others is a loop
/// the compiler vectorizes. In f32, four pairs to a register (in f64 it took 1.4× as long on
/// RobotExpressive, then half of cheap-cuts' time), and in a frame centred on the mesh and
/// scaled to its size, so that f32 keeps the same relative precision in any model's units.
struct Patches {
    centre: [Vec<f32>; 3],
    normal: [Vec<f32>; 3],
    /// The softening term (Ap / 2π) of each patch.
    soft: Vec<f32>,
    cluster: Vec<u32>,
    /// Cluster c's patches are `first[c]..first[c + 1]`.
    first: Vec<usize>,
}

impl Patches {
    fn of(positions: &[glam::Vec3], (lo, hi): (DVec3, DVec3), triangles: &[[u32; 3]], starts: &[usize]) -> Patches {
        let per_patch = triangles.len().div_ceil(PATCHES).max(LEAST);
        // The frame: centred on the bounding box, its largest side scaled to 1.
        let middle = (lo + hi) * 0.5;
        let unit = 1.0 / (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mut patches = Patches {
            centre: Default::default(),
            normal: Default::default(),
            soft: Vec::new(),
            cluster: Vec::new(),
            first: vec![0],
        };
        for (c, range) in starts.windows(2).enumerate() {
            for run in triangles[range[0]..range[1]].chunks(per_patch) {
                let (mut centre, mut normal, mut area) = (DVec3::ZERO, DVec3::ZERO, 0.0);
                let mut corners = DVec3::ZERO;
                for t in run {
                    let [a, b, c] = t.map(|v| positions[v as usize].as_dvec3());
                    let cross = (b - a).cross(c - a);
                    let twice = cross.length();
                    centre += (a + b + c) * twice;
                    corners += a + b + c;
                    normal += cross * 0.5;
                    area += twice * 0.5;
                }
                // Area-weighted centroid; the corners' mean for a run of degenerate triangles.
                let centre = if area > 0.0 { centre / (6.0 * area) } else { corners / (3 * run.len()) as f64 };
                let (centre, normal) = ((centre - middle) * unit, normal * unit * unit);
                for k in 0..3 {
                    patches.centre[k].push(centre[k] as f32);
                    patches.normal[k].push(normal[k] as f32);
                }
                patches.soft.push((area * unit * unit / std::f64::consts::TAU) as f32);
                patches.cluster.push(c as u32);
            }
            patches.first.push(patches.soft.len());
        }
        patches
    }

    fn len(&self) -> usize {
        self.soft.len()
    }

    /// For each patch q from `from` on, into `over[q − from]` and `under[q − from]`: the area p
    /// hides of q (p nearer, both facing the viewer) and the area q hides of p, each integrated
    /// over view directions.
    fn hiding(&self, p: usize, from: usize, over: &mut [f32], under: &mut [f32]) {
        let [cx, cy, cz] = [self.centre[0][p], self.centre[1][p], self.centre[2][p]];
        let [nx, ny, nz] = [self.normal[0][p], self.normal[1][p], self.normal[2][p]];
        let soft = self.soft[p];
        let n = over.len();
        let [qx, qy, qz] = self.centre.each_ref().map(|v| &v[from..from + n]);
        let [mx, my, mz] = self.normal.each_ref().map(|v| &v[from..from + n]);
        let q_soft = &self.soft[from..from + n];
        let under = &mut under[..n];
        for i in 0..n {
            let (dx, dy, dz) = (cx - qx[i], cy - qy[i], cz - qz[i]);
            let r2 = dx * dx + dy * dy + dz * dz;
            // (Np·d)(Nq·d) / r⁴ is (Np·u)(Nq·u) / r²; softened (see the module notes), and a
            // patch on top of another (r = 0) adds nothing: both dot products are 0 there.
            let (fp, fq) = (nx * dx + ny * dy + nz * dz, mx[i] * dx + my[i] * dy + mz[i] * dz);
            let w = fp * fq / (r2 * (r2 + soft + q_soft[i])).max(f32::MIN_POSITIVE);
            over[i] = if fp > 0.0 && fq > 0.0 { w } else { 0.0 };
            under[i] = if fp < 0.0 && fq < 0.0 { w } else { 0.0 };
        }
    }
}

/// The paper's arcs from `saved` (row a, column b: what drawing a first saves of b), weights
/// scaled so that the largest entry is 2⁴⁰ and rounded.
fn arcs(saved: &[f64], n: usize) -> Vec<Arc> {
    let most = saved.iter().copied().fold(0.0, f64::max);
    let scale = if most > 0.0 { (1u64 << 40) as f64 / most } else { 0.0 };
    arcs_of(n, |a, b| (saved[a * n + b] * scale).round() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::order::nehab::overdraw_graph::{ClusteredDraw, one_pass};
    use crate::raster::ViewSet;
    use glam::Vec3;

    /// Scattered ranges are regrouped within each cluster only: every cluster keeps its
    /// triangles, everything outside the ranges stays in place, and inside a range the part in
    /// one cluster follows the curve (its cells never decrease), ties in their first order.
    #[test]
    fn scattered_ranges_are_regrouped_within_their_clusters() {
        // 40 triangles along a line, given in a scrambled order, each its own three vertices.
        let positions: Vec<Vec3> = (0..40)
            .flat_map(|i| {
                let x = ((i * 17) % 40) as f32;
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.5, 0.0, 0.0), Vec3::new(x, 0.5, 0.0)]
            })
            .collect();
        let triangles: Vec<[u32; 3]> = (0..40).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let starts = [0, 10, 25, 40];
        let scattered = [3..18, 30..35];
        let regrouped = along_curve(&positions, Framing::bounds_of(&positions), &triangles, &starts, &scattered);
        let sorted = |ts: &[[u32; 3]]| {
            let mut ts = ts.to_vec();
            ts.sort_unstable();
            ts
        };
        for cluster in starts.windows(2) {
            assert_eq!(sorted(&regrouped[cluster[0]..cluster[1]]), sorted(&triangles[cluster[0]..cluster[1]]));
        }
        let inside = |i: usize| scattered.iter().any(|r| r.contains(&i));
        assert!((0..40).filter(|&i| !inside(i)).all(|i| regrouped[i] == triangles[i]));
        let x = |t: &[u32; 3]| positions[t[0] as usize].x;
        for part in [3..10, 10..18, 30..35] {
            assert!(regrouped[part.clone()].windows(2).all(|w| x(&w[0]) <= x(&w[1])), "{part:?}");
        }
    }

    /// Two squares facing +z, one above the other and offset sideways, and a third far off to
    /// the side: the upper hides the lower from above (the arc the drawn graph has too), and
    /// neither hides the third much.
    #[test]
    fn the_upper_of_two_stacked_squares_goes_first() {
        let square = |x: f32, z: f32| {
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(dx, y)| Vec3::new(x + dx, y, z))
        };
        let positions: Vec<Vec3> = [square(0.0, 0.0), square(0.3, 0.5), square(5.0, 0.0)].concat();
        let quad = |o: u32| [[o, o + 1, o + 2], [o, o + 2, o + 3]];
        let triangles: Vec<[u32; 3]> = [quad(0), quad(4), quad(8)].concat();
        let starts = [0, 2, 4, 6];
        let estimated = patch_arcs(&positions, &triangles, &starts, &[]);
        let upper_first = |arcs: &[Arc]| arcs.iter().find(|a| (a.from, a.to) == (1, 0)).map(|a| a.weight);
        let heaviest = estimated.iter().map(|a| a.weight).max().unwrap();
        assert_eq!(upper_first(&estimated), Some(heaviest), "{estimated:?}");
        let draw = ClusteredDraw { positions: &positions, triangles: &triangles, starts: &starts };
        let cameras = ViewSet::Ico(42).cameras(Framing::of(&positions), 0);
        let drawn = one_pass(draw, &cameras, 64).unwrap().arcs();
        assert!(upper_first(&drawn).is_some(), "{drawn:?}");
    }

    /// On a convex surface no front face hides another: a sphere cut into pieces along its cache
    /// order hides next to nothing of itself, against a second, smaller sphere inside it.
    #[test]
    fn a_convex_surface_hides_next_to_nothing() {
        let sphere = crate::mesh::procedural::generate("sphere:2000", 0).unwrap().unwrap();
        let order = crate::order::forsyth::forsyth(
            &sphere.triangles,
            &crate::mesh::topology::vertex_triangles(&sphere),
            32,
            crate::order::forsyth::Scores::Tuned,
        );
        let triangles = sphere.triangles_in_order(&order);
        let starts: Vec<usize> = (0..=8).map(|k| k * triangles.len() / 8).collect();
        let bounds = Framing::bounds_of(&sphere.positions);
        let alone = saved(&sphere.positions, bounds, &triangles, &starts).into_iter().fold(0.0, f64::max);
        // The same sphere with a copy at half the size inside it, as a ninth piece.
        let n = sphere.positions.len() as u32;
        let inner = sphere.positions.iter().map(|p| *p * 0.5);
        let positions: Vec<Vec3> = sphere.positions.iter().copied().chain(inner).collect();
        let inner = triangles.iter().map(|t| t.map(|v| v + n));
        let nested: Vec<[u32; 3]> = triangles.iter().copied().chain(inner).collect();
        let starts: Vec<usize> = starts.iter().copied().chain([2 * triangles.len()]).collect();
        let inside = saved(&positions, Framing::bounds_of(&positions), &nested, &starts);
        let hidden = (0..8).map(|a| inside[a * 9 + 8]).fold(0.0, f64::max);
        assert!(alone < hidden / 1000.0, "the sphere alone {alone}, over the inner one {hidden}");
    }

    /// Weights are the same whatever the model's scale and place: the estimate is a ratio of
    /// areas, scaled to its largest entry.
    #[test]
    fn weights_do_not_depend_on_scale_or_place() {
        let mesh = crate::mesh::procedural::generate("helix:3", 0).unwrap().unwrap();
        let starts: Vec<usize> = (0..=6).map(|k| k * mesh.triangle_count() / 6).collect();
        let moved: Vec<Vec3> = mesh.positions.iter().map(|p| *p * 4.0 + Vec3::new(10.0, -3.0, 2.0)).collect();
        let a = patch_arcs(&mesh.positions, &mesh.triangles, &starts, &[]);
        let b = patch_arcs(&moved, &mesh.triangles, &starts, &[]);
        assert!(!a.is_empty());
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.from, x.to), (y.from, y.to));
            assert!(x.weight.abs_diff(y.weight) <= x.weight / 1000 + 1, "{x:?} {y:?}");
        }
    }
}
