//! `hs17`: Han & Sander 2017, "Triangle Reordering for Efficient Rendering in Complex Scenes"
//! (JCGT 6(3)), §3 and Algorithm 1, our own implementation: k index buffers for an animated mesh
//! and the lookup table that picks one per keyframe and view.
//!
//! 1. **Patches** (§3.1): Tipsify, cut by fast linear clustering with λ (`sander07`'s first two
//!    stages); every buffer is an order of these patches, so each keeps their ACMR.
//! 2. **Nodes** (§3.2): one per (keyframe, viewpoint), the viewpoints being the `views`
//!    icosahedron directions at 3× the animation's radius, seen with a perspective camera (the
//!    same camera `random:N` evaluation views use), each frame framed at its own centre.
//! 3. **Bootstrapping**: `clusters` viewpoints drawn at random (seeded), a draw rejected while it
//!    lies within [`MIN_SEPARATION`] of one already drawn ("we ensure no two initial viewpoints are
//!    within a small distance threshold"); each starts a buffer that sorts the patches front to
//!    back by the distance from the viewpoint to the patch centroid averaged over all frames.
//! 4. **Node assignment** (step 1): each node goes to the buffer that draws it with the fewest
//!    fragments passing the depth test. The paper renders the node with each buffer and reads an
//!    occlusion query; we rasterize each node once, before the loop, with our CPU rasterizer
//!    (the rules of every overdraw measurement here) and keep, per pixel reached by two or more
//!    fragments, its triangles nearest first. A buffer's count is then a scan of those lists:
//!    a fragment passes when its triangle is drawn before every nearer one. That is exactly the
//!    count k renders per round would give, for one rasterization per node per run. A node whose
//!    buffer ties for the fewest keeps it, so ties alone never move a node.
//! 5. **Buffer computation** (step 2): for each cluster, patches sorted by increasing integrated
//!    distance d(p) = Σ over its nodes of |viewpoint − centroid of p at the node's frame|.
//! 6. Steps 1–2 repeat until no node changes cluster, or until [`STALL_ROUNDS`] rounds in a row
//!    fail to lower the fragments that pass summed over all nodes (both reported as converged),
//!    or `iterations` rounds (reported as not converged); the buffers and assignment returned are
//!    those of the round with the fewest fragments. Step 2 does not minimize what step 1
//!    measures, so the assignments need not settle. On Soldier (k = 5, 162 views at 128²) the
//!    total falls 2–3% over the first five or so rounds; then 1–4% of the nodes keep moving
//!    between buffers whose counts differ by a few fragments, and the total wanders within ±0.5%
//!    with no trend. Two of its four clips ran to the old cap of 50 rounds, and one found its
//!    lowest total in round 5. The paper reports 2–6 rounds; the stall rule stops where the
//!    descent does.
//!
//! `mode=single` optimizes each clip on its own (k buffers per clip, the paper's "single");
//! `mode=joint` one set of k buffers for all frames of all clips. Buffers that end with no node
//! are dropped, so the buffer count is what the lookup can pick. A static mesh is an animation
//! of one frame, and the result is then k view-dependent buffers.
//!
//! Every distance, direction and rasterization is taken in the unit frame the cameras see the
//! keyframes in (centred, divided by the animation's radius, in f64: [`crate::mesh::Framing`]),
//! so the buffers and the lookup do not depend on the model's units or place. In world
//! coordinates the f32 distances of a 1e-30 model underflowed to zero (every patch tied), and a
//! 1e30 model was refused as needing clipping.

use std::ops::Range;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

use super::key_sort::sort_by_key;
use super::sander07::{LAMBDA, patches};
use super::tipsify::FIFO_CACHE;
use super::{Clustered, Lookup, Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::{Error, Result};
use crate::mesh::scene::SharedWork;
use crate::mesh::{Frames, Scene};
use crate::raster::cpu::depth_layers;
use crate::raster::layers::{DepthLayers, LaneRanks};
use crate::raster::naming_mesh;
use crate::raster::views::{Camera, icosphere_directions, perspective};

const CLUSTERS: ParamInfo = ParamInfo {
    name: "clusters",
    default: "5",
    kind: ParamKind::Int { min: 1, max: 64 },
    help: "k, the number of index buffers (per clip with mode=single)",
};

const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "162",
    kind: ParamKind::Choice(&["12", "42", "162", "642"]),
    help: "icosahedron viewpoints optimized for (nodes = keyframes × views)",
};

const RES: ParamInfo = ParamInfo {
    name: "res",
    default: "128",
    kind: ParamKind::Int { min: 16, max: 4096 },
    help: "side of the square images nodes are rasterized at during optimization",
};

const MODE: ParamInfo = ParamInfo {
    name: "mode",
    default: "single",
    kind: ParamKind::Choice(&["single", "joint"]),
    help: "single: k buffers for each clip; joint: k buffers shared by all clips",
};

const ITERATIONS: ParamInfo = ParamInfo {
    name: "iterations",
    default: "50",
    kind: ParamKind::Int { min: 1, max: 1000 },
    help: "most node-assignment rounds before stopping unconverged (reported)",
};

pub static METHOD: Method = Method {
    name: "hs17",
    summary: "animated: Tipsify patches ordered by k-means over (keyframe, viewpoint) nodes; k buffers + lookup",
    source: "Han & Sander 2017, §3 and Algorithm 1",
    peer: false,
    per_node: true,
    cost: Cost::Heavy,
    params: &[
        CLUSTERS,
        LAMBDA,
        VIEWS,
        RES,
        MODE,
        ITERATIONS,
        FIFO_CACHE,
        ParamInfo { name: "seed", default: "", kind: ParamKind::Seed, help: "picks the initial viewpoints" },
    ],
    build,
};

/// Smallest angle (radians) between two initial viewpoints: 30°. With the rejection capped at
/// [`SEPARATION_TRIES`] draws, a k too large to spread that far still gets k distinct viewpoints.
const MIN_SEPARATION: f32 = std::f32::consts::PI / 6.0;
const SEPARATION_TRIES: usize = 100;

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Hs17 {
        clusters: params.int(&CLUSTERS) as usize,
        lambda: params.float(&LAMBDA),
        views: params.word(&VIEWS).parse().expect("the schema lists only numbers"),
        res: params.int(&RES) as u32,
        joint: params.word(&MODE) == "joint",
        max_iterations: params.int(&ITERATIONS) as usize,
        cache: params.int(&FIFO_CACHE) as u32,
        seed: params.seed(),
    })
}

struct Hs17 {
    clusters: usize,
    lambda: f64,
    views: u32,
    res: u32,
    joint: bool,
    max_iterations: usize,
    cache: u32,
    seed: u64,
}

impl Ordering for Hs17 {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mut clock = Clock::start();
        let keyframes = &scene.frames;
        let patches = patches(&scene.mesh, &scene.topology.vertex_triangles, self.cache, self.lambda);
        clock.lap("patches");
        let directions = icosphere_directions(self.views);
        let cameras: Vec<Camera> = directions.iter().map(|&d| perspective(keyframes.framing, d)).collect();
        let scene = Nodes {
            name: &scene.mesh.name,
            shared: &scene.shared,
            triangles: &scene.mesh.triangles,
            keyframes,
            patches: &patches,
            spans: Span::of(&patches),
            cameras: &cameras,
        };
        let groups: Vec<Range<usize>> = if self.joint {
            std::iter::once(0..keyframes.len()).collect()
        } else {
            keyframes.clips.iter().map(|(_, r)| r.clone()).collect()
        };

        let mut buffers: Vec<Clustered> = Vec::new();
        let mut assignment = vec![0u16; keyframes.len() * cameras.len()];
        let (mut iterations, mut converged, mut reused) = (0, true, 0.0);
        for frames in groups {
            let result = self.kmeans(&scene, frames.clone(), &mut clock)?;
            reused += result.reused;
            iterations = iterations.max(result.iterations);
            converged &= result.converged;
            // Keep the buffers some node uses, numbered after the previous groups' buffers.
            let mut id = vec![u16::MAX; result.buffers.len()];
            for &c in &result.assignment {
                if id[c as usize] == u16::MAX {
                    id[c as usize] = u16::try_from(buffers.len())
                        .map_err(|_| Error::usage("hs17: more than 65535 index buffers".to_string()))?;
                    buffers.push(result.buffers[c as usize].clone());
                }
            }
            let start = frames.start * cameras.len();
            for (slot, &c) in assignment[start..].iter_mut().zip(&result.assignment) {
                *slot = id[c as usize];
            }
        }
        let lookup = Lookup::nearest(&directions, &assignment);
        Ok(Orders { buffers, lookup, iterations: Some(iterations), converged, phases: clock.phases, reused })
    }
}

/// What every k-means run shares: the (keyframe, viewpoint) nodes and the patches.
struct Nodes<'a> {
    /// The mesh's name, for errors.
    name: &'a str,
    /// Where the scene's rasterized nodes are kept for the other hs17 orderings of it.
    shared: &'a SharedWork,
    triangles: &'a [[u32; 3]],
    keyframes: &'a Frames,
    patches: &'a Clustered,
    /// Each patch's place in `patches`, packed for [`Nodes::assemble`].
    spans: Vec<Span>,
    cameras: &'a [Camera],
}

/// Where a patch lies in the patch order, with its first triangle: one memory access per patch
/// when a buffer is assembled in a sequence that visits them at random (at λ 3 most patches are
/// one triangle, and looking up the bounds and then the triangle took two cache misses each).
#[derive(Clone, Copy)]
struct Span {
    first: u32,
    start: u32,
    len: u32,
}

impl Span {
    fn of(patches: &Clustered) -> Vec<Span> {
        patches
            .starts
            .windows(2)
            .map(|w| Span { first: patches.order[w[0]], start: w[0] as u32, len: (w[1] - w[0]) as u32 })
            .collect()
    }

    /// The patch's triangle if it has one only, else `u32::MAX`.
    fn alone(&self) -> u32 {
        if self.len == 1 { self.first } else { u32::MAX }
    }
}

impl Nodes<'_> {
    fn patch_count(&self) -> usize {
        self.patches.cluster_count()
    }

    /// The buffer drawing the patches in `sequence`, each patch a cluster.
    fn buffer(&self, sequence: &[u32]) -> Clustered {
        self.assemble(sequence.iter().map(|&p| (p, self.spans[p as usize].alone())))
    }

    /// The patches by increasing `keys` (one per patch), and the buffer drawing them so.
    ///
    /// Each patch's one triangle, if it has one only, travels with it through the sort (for free:
    /// an entry is 16 bytes either way), so that at λ 3, where nearly every patch is one
    /// triangle, the buffer is written without looking the patches up in random order.
    fn sorted(&self, keys: impl Iterator<Item = f64>) -> (Vec<u32>, Clustered) {
        let sorted = sort_by_key(keys.zip(self.spans.iter().map(Span::alone)));
        let buffer = self.assemble(sorted.iter().copied());
        (sorted.into_iter().map(|(p, _)| p).collect(), buffer)
    }

    /// The buffer drawing `(patch, its lone triangle or u32::MAX)` in sequence.
    fn assemble(&self, sequence: impl ExactSizeIterator<Item = (u32, u32)>) -> Clustered {
        let mut order = Vec::with_capacity(self.patches.order.len());
        let mut starts = Vec::with_capacity(sequence.len() + 1);
        starts.push(0);
        for (p, alone) in sequence {
            match alone {
                u32::MAX => {
                    let Span { start, len, .. } = self.spans[p as usize];
                    order.extend_from_slice(&self.patches.order[start as usize..(start + len) as usize]);
                }
                t => order.push(t),
            }
            starts.push(order.len());
        }
        Clustered { order, starts }
    }
}

/// Rounds in a row without a new lowest total of passing fragments after which the k-means
/// stops (module notes, step 6).
const STALL_ROUNDS: usize = 3;

/// One k-means over the nodes of a run of frames.
struct KMeans {
    buffers: Vec<Clustered>,
    /// Per node `(frame − first) × views + view`: its cluster.
    assignment: Vec<u16>,
    iterations: usize,
    converged: bool,
    /// Seconds of node rasterization reused from an earlier ordering of the scene.
    reused: f64,
}

impl Hs17 {
    fn kmeans(&self, scene: &Nodes, frames: Range<usize>, clock: &mut Clock) -> Result<KMeans> {
        let views = scene.cameras.len();
        // Patch centroids, patch-major: centroids[p * frames + f].
        let centroids = patch_centroids(scene, frames.clone());
        let frame_count = frames.len();
        let average: Vec<Vec3> =
            centroids.chunks(frame_count).map(|c| c.iter().sum::<Vec3>() / c.len() as f32).collect();
        let centroids = Centroids::of(&centroids, frame_count);
        clock.lap("centroids");

        // Each buffer's patch sequence, and the buffer it draws.
        let (mut sequences, mut buffers): (Vec<Vec<u32>>, Vec<Clustered>) = self
            .initial_viewpoints(views, scene.cameras)
            .par_iter()
            .map(|&v| scene.sorted(average.iter().map(|c| f64::from(c.distance(scene.cameras[v].unit_eye())))))
            .unzip();
        let (frame_nodes, reused) = rasterize_nodes(scene, frames.clone(), self.res)?;
        let nodes: Vec<&DepthLayers> = frame_nodes.iter().flat_map(|f| f.iter()).collect();
        clock.lap("rasterization");
        clock.charge("rasterization", reused);
        let mut assignment: Vec<u16> = vec![u16::MAX; nodes.len()];
        // Step 2's integrated distance d(p) of every patch for every cluster, a column per
        // cluster (`integrated[c × patches + p]`), summed over the nodes `counted` in that cluster.
        let k = buffers.len();
        let patch_count = scene.patch_count();
        let mut integrated = vec![0.0f64; patch_count * k];
        let mut counted: Vec<u16> = vec![u16::MAX; nodes.len()];
        let mut iteration = 0;
        // The round with the fewest passing fragments so far: its fragments, buffers (as patch
        // sequences, a fraction of their size) and assignment (a buffer set and the assignment
        // made from it, so the lookup stays true to the buffers); and the rounds since it.
        let mut best: Option<(u64, Vec<Vec<u32>>, Vec<u16>)> = None;
        let mut stalled = 0;
        loop {
            iteration += 1;
            let (next, passed) = assign(&nodes, &buffers, &assignment);
            clock.lap("assignment");
            let settled = next == assignment;
            assignment = next;
            if best.as_ref().is_none_or(|b| passed < b.0) {
                best = Some((passed, sequences.clone(), assignment.clone()));
                stalled = 0;
            } else {
                stalled += 1;
            }
            let converged = settled || stalled == STALL_ROUNDS;
            if converged || iteration == self.max_iterations {
                let (_, sequences, assignment) = best.expect("one round has run");
                let buffers = sequences.iter().map(|s| scene.buffer(s)).collect();
                return Ok(KMeans { buffers, assignment, iterations: iteration, converged, reused });
            }
            // Step 2 for the clusters whose nodes changed: the integrated distances follow the
            // nodes that moved (a few percent of them after the first rounds), so a round costs
            // patches × moved nodes rather than patches × nodes. In f64, where sums of these f32
            // distances (between 1 and 8 or so, from viewpoints at three radii) are exact, so
            // adding and taking away a node leaves the sum a recount would give.
            let moved: Vec<usize> = (0..nodes.len()).filter(|&n| counted[n] != assignment[n]).collect();
            let moves: Vec<Move> = moved
                .iter()
                .map(|&n| Move {
                    eye: scene.cameras[n % views].unit_eye(),
                    frame: n / views,
                    from: usize::from(counted[n]),
                    to: usize::from(assignment[n]),
                })
                .collect();
            integrate(&mut integrated, k, &centroids, &moves);
            let mut changed = vec![false; k];
            for &n in &moved {
                for c in [counted[n], assignment[n]] {
                    if let Some(flag) = changed.get_mut(usize::from(c)) {
                        *flag = true;
                    }
                }
                counted[n] = assignment[n];
            }
            // A cluster left with no node keeps its buffer. The clusters are sorted in parallel:
            // at λ 3 each sort is of every triangle, and one after another they were the largest
            // serial part of a run.
            let resorted: Vec<usize> = (0..k).filter(|&c| changed[c] && assignment.contains(&(c as u16))).collect();
            let sorted: Vec<(Vec<u32>, Clustered)> = resorted
                .par_iter()
                .map(|&c| scene.sorted(integrated[c * patch_count..(c + 1) * patch_count].iter().copied()))
                .collect();
            for (c, (sequence, buffer)) in resorted.into_iter().zip(sorted) {
                (sequences[c], buffers[c]) = (sequence, buffer);
            }
            clock.lap("buffers");
        }
    }

    /// `clusters` distinct viewpoint indices, drawn with the separation rule (directions seen from
    /// the framing's centre).
    fn initial_viewpoints(&self, views: usize, cameras: &[Camera]) -> Vec<usize> {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(self.seed);
        let k = self.clusters.min(views);
        let mut chosen: Vec<usize> = Vec::with_capacity(k);
        let direction = |v: usize| cameras[v].direction();
        while chosen.len() < k {
            let mut pick = rng.random_range(0..views);
            for _ in 0..SEPARATION_TRIES {
                let far = chosen.iter().all(|&c| direction(c).angle_between(direction(pick)) >= MIN_SEPARATION);
                if far && !chosen.contains(&pick) {
                    break;
                }
                pick = rng.random_range(0..views);
            }
            if !chosen.contains(&pick) {
                chosen.push(pick);
            }
        }
        chosen
    }
}

/// Per patch, per frame of `frames`: the mean of its triangles' corners, in the unit frame the
/// cameras see the keyframes in (centred, divided by the animation's radius, in f64), so the
/// distances to the viewpoints neither underflow nor overflow in f32 and do not depend on the
/// model's scale or place.
fn patch_centroids(scene: &Nodes, frames: Range<usize>) -> Vec<Vec3> {
    let framing = scene.keyframes.framing;
    let starts = &scene.patches.starts;
    (0..scene.patch_count())
        .into_par_iter()
        .flat_map_iter(|p| {
            let tris = &scene.patches.order[starts[p]..starts[p + 1]];
            let corners = 3.0 * tris.len() as f32;
            frames.clone().map(move |f| {
                let positions = &scene.keyframes.frames[f];
                tris.iter()
                    .flat_map(|&t| scene.triangles[t as usize])
                    .map(|v| framing.to_unit(positions[v as usize]))
                    .sum::<Vec3>()
                    / corners
            })
        })
        .collect()
}

/// Every node of `frames` rasterized once, per frame: node `(f − first) × views + v` is frame f
/// seen by camera v. The depth test of any buffer is then replayed from these
/// ([`DepthLayers::contested_passes`]). A frame's nodes are rasterized by the first hs17 ordering
/// of the scene that needs them and kept for the others (every λ, mode, seed and cluster count
/// draws the same nodes); also returns the seconds that reusing them saved, as they cost then.
fn rasterize_nodes(scene: &Nodes, frames: Range<usize>, res: u32) -> Result<(Vec<Arc<Vec<DepthLayers>>>, f64)> {
    let mut reused = 0.0;
    let nodes = frames
        .map(|f| {
            let key = format!("hs17 nodes: frame {f}, {} viewpoints, {res}²", scene.cameras.len());
            let (nodes, saved) = scene.shared.get_or_compute(&key, || {
                depth_layers(&scene.keyframes.frames[f], scene.triangles, scene.cameras, res)
                    .map_err(|e| naming_mesh(scene.name, e))
            })?;
            reused += saved.unwrap_or(0.0);
            Ok(nodes)
        })
        .collect::<Result<_>>()?;
    Ok((nodes, reused))
}

/// The patch centroids of each frame, coordinate by coordinate (`x[f × patches + p]`), so that a
/// node's distances to every patch are one loop the compiler vectorizes.
struct Centroids {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    patches: usize,
}

impl Centroids {
    /// From patch-major centroids (`centroids[p × frames + f]`).
    fn of(centroids: &[Vec3], frames: usize) -> Centroids {
        let patches = centroids.len() / frames.max(1);
        let coordinate = |axis: usize| -> Vec<f32> {
            (0..frames).flat_map(|f| (0..patches).map(move |p| centroids[p * frames + f][axis])).collect()
        };
        Centroids { x: coordinate(0), y: coordinate(1), z: coordinate(2), patches }
    }
}

/// A node that changed cluster since the integrated distances were last summed: its viewpoint,
/// its frame (counted from the run's first) and its clusters before (out of range when it had
/// none) and now.
struct Move {
    eye: Vec3,
    frame: usize,
    from: usize,
    to: usize,
}

/// Patches per parallel piece of [`integrate`]: a piece's columns and centroids stay in cache
/// while every move is added.
const PIECE: usize = 4096;

/// Follows `moves` in the integrated distances (`k` columns of `centroids.patches`): each moved
/// node's distance to every patch centroid at its frame taken from its old cluster's column and
/// added to its new one's. Each distance is `(eye − centroid).length()` in f32 as glam computes
/// it, so the sums are those a recount would give (module notes: in f64 they are exact).
fn integrate(integrated: &mut [f64], k: usize, centroids: &Centroids, moves: &[Move]) {
    let patches = centroids.patches;
    if patches == 0 {
        return;
    }
    let mut columns: Vec<_> = integrated.chunks_mut(patches).map(|c| c.chunks_mut(PIECE)).collect();
    let pieces: Vec<Vec<&mut [f64]>> =
        (0..patches.div_ceil(PIECE)).map(|_| columns.iter_mut().filter_map(Iterator::next).collect()).collect();
    pieces.into_par_iter().enumerate().for_each_init(
        || vec![0.0f64; PIECE],
        |distances, (piece, mut columns)| {
            debug_assert_eq!(columns.len(), k);
            let start = piece * PIECE;
            let len = columns[0].len();
            for m in moves {
                let at = m.frame * patches + start;
                let (x, y, z) = (&centroids.x[at..at + len], &centroids.y[at..at + len], &centroids.z[at..at + len]);
                for (((d, &x), &y), &z) in distances.iter_mut().zip(x).zip(y).zip(z) {
                    let (dx, dy, dz) = (x - m.eye.x, y - m.eye.y, z - m.eye.z);
                    *d = f64::from((dx * dx + dy * dy + dz * dz).sqrt());
                }
                if let Some(from) = columns.get_mut(m.from) {
                    from.iter_mut().zip(&*distances).for_each(|(s, d)| *s -= d);
                }
                columns[m.to].iter_mut().zip(&*distances).for_each(|(s, d)| *s += d);
            }
        },
    );
}

/// Step 1: each node to the buffer with the fewest passing fragments; a node keeps its
/// `previous` buffer when that one ties for the fewest. Also returns those fewest fragments
/// summed over the nodes: what the assignment minimizes.
fn assign(nodes: &[&DepthLayers], buffers: &[Clustered], previous: &[u16]) -> (Vec<u16>, u64) {
    let orders: Vec<&[u32]> = buffers.iter().map(|b| b.order.as_slice()).collect();
    let ranks = LaneRanks::new(&orders);
    let chosen: Vec<(u16, u32)> = nodes
        .par_iter()
        .zip(previous)
        .map(|(node, &before)| {
            let passed = node.contested_passes_all(&ranks);
            let best = *passed.iter().min().expect("at least one buffer");
            let keep = passed.get(usize::from(before)).is_some_and(|&p| p == best);
            (if keep { before } else { passed.iter().position(|&p| p == best).unwrap() as u16 }, best)
        })
        .collect();
    (chosen.iter().map(|c| c.0).collect(), chosen.iter().map(|c| u64::from(c.1)).sum())
}

/// Wall time per phase, summed over laps.
struct Clock {
    phases: Vec<(&'static str, f64)>,
    last: Instant,
}

impl Clock {
    fn start() -> Clock {
        Clock { phases: Vec::new(), last: Instant::now() }
    }

    /// Charges the time since the previous lap to `phase`.
    fn lap(&mut self, phase: &'static str) {
        let now = Instant::now();
        let seconds = now.duration_since(self.last).as_secs_f64();
        self.last = now;
        self.charge(phase, seconds);
    }

    /// Adds `seconds` to `phase`.
    fn charge(&mut self, phase: &'static str, seconds: f64) {
        match self.phases.iter_mut().find(|(p, _)| *p == phase) {
            Some((_, s)) => *s += seconds,
            None => self.phases.push((phase, seconds)),
        }
    }
}
