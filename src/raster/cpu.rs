//! The CPU rasterizer: the project's reference for overdraw counts.
//!
//! Rules, chosen to be exact, deterministic and what a Vulkan GPU does with one sample per pixel:
//! - Vertices are mapped into the camera's unit frame (centred on the model and divided by its
//!   radius, in f64: [`Camera::clip`]), so the counts do not depend on the model's scale or
//!   place, then go through the camera's unit frame → clip transform, the perspective divide and
//!   the viewport transform to an R×R image with y up, then are snapped to 1/256 pixel (8
//!   sub-pixel bits, Vulkan's usual `subPixelPrecisionBits`). Everything after the snap is
//!   integer-exact.
//! - Back faces are culled geometrically: a triangle is drawn only if its snapped projection is
//!   counter-clockwise, i.e. its counter-clockwise normal points toward the viewer. Zero-area
//!   projections are culled too.
//! - A pixel is covered when its centre (i + ½, j + ½) is inside the triangle; a centre exactly on
//!   an edge belongs to the triangle only if that edge is a *top* edge (horizontal, interior below)
//!   or a *left* edge (interior to its right): the top-left rule, so a pixel on an edge shared by
//!   two triangles is covered once.
//! - Depth is the NDC z of the plane through the snapped vertices, evaluated at the pixel centre
//!   in f32. The depth buffer is cleared to 1.0 per view; a fragment passes when z < stored (LESS),
//!   in draw order, and then writes its depth.
//!
//! Per view it counts covered pixels and fragments that pass the depth test.
//! Views run in parallel (rayon), each with its own depth buffer.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::layers::{self, DepthLayers, LaneRanks, Sorting};
use super::views::Camera;
use super::{OrderPicks, RasterBackend, ViewCounts};
use crate::error::{Error, Result};
use crate::mesh::z_order::ZOrder;

/// Sub-pixel bits of the snapped vertex coordinates.
const SUBPIXEL_BITS: u32 = 8;
const ONE: i64 = 1 << SUBPIXEL_BITS;
const HALF: i64 = ONE / 2;
/// Largest image side: keeps snapped coordinates and edge products far from i64 overflow.
pub const MAX_RESOLUTION: u32 = 16384;

/// The reference software rasterizer.
#[derive(Debug, Default, Clone, Copy)]
pub struct CpuRaster;

/// A vertex after projection and snapping: fixed-point window coordinates and NDC depth.
#[derive(Clone, Copy, Default)]
struct ScreenVertex {
    x: i32,
    y: i32,
    z: f32,
}

impl RasterBackend for CpuRaster {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        each_view(positions, cameras, res, Vec::new, |depth, screen, _| {
            draw::<true, _>(screen, triangles, res, depth, CountOnly)
        })
    }

    /// Each view rasterized once, its fragments kept as [`DepthLayers`], and every order picked
    /// for it counted by replaying the depth test: the same counts as drawing each order.
    fn count_orders(
        &self,
        positions: &[Vec3],
        cameras: &[Camera],
        draws: &OrderPicks,
        res: u32,
    ) -> Result<Vec<Vec<ViewCounts>>> {
        let Some(replay) = Replay::new(draws) else {
            return super::count_each_order(self, positions, cameras, draws, res);
        };
        let local = Local::of(positions, draws.triangles);
        let counted = each_view(&local.positions, cameras, res, LayerScratch::default, |scratch, screen, v| {
            replay.counts(&scratch.layers(screen, &local, res), &draws.picks[v])
        });
        named_as_given(counted, positions, cameras, res)
    }
}

/// The orders of an [`OrderPicks`] ready to be replayed on any view's [`DepthLayers`]: the orders
/// every view draws (every static method's) side by side ([`LaneRanks`]), the others
/// (view-dependent methods' buffers) gathered from their own ranks, eight to a scan
/// ([`DepthLayers::counts_each`]).
pub(crate) struct Replay {
    /// The orders every view draws, ascending: lane `i` replays `everywhere[i]`.
    everywhere: Vec<usize>,
    lanes: LaneRanks,
    /// Per order, its ranks, for the others only (empty for those replayed side by side).
    ranks: Vec<Vec<u32>>,
}

impl Replay {
    /// `None` unless every order is a permutation of every triangle: only then is a replay the
    /// same count as a draw.
    pub(crate) fn new(draws: &OrderPicks) -> Option<Replay> {
        let (orders, picks) = (draws.orders, draws.picks);
        if orders.iter().any(|o| o.len() != draws.triangles.len()) {
            return None;
        }
        let mut everywhere: Vec<usize> = picks.first().cloned().unwrap_or_default();
        everywhere.sort_unstable();
        everywhere.dedup();
        everywhere.retain(|o| picks.iter().all(|p| p.contains(o)));
        let lanes = LaneRanks::new(&everywhere.iter().map(|&o| orders[o]).collect::<Vec<_>>());
        let ranks = (0..orders.len())
            .into_par_iter()
            .map(|o| if everywhere.binary_search(&o).is_ok() { Vec::new() } else { layers::ranks(orders[o]) })
            .collect();
        Some(Replay { everywhere, lanes, ranks })
    }

    /// The counts of the orders `picks` (indices into the orders) on one view's layers.
    pub(crate) fn counts(&self, layers: &DepthLayers, picks: &[usize]) -> Vec<ViewCounts> {
        let side_by_side = layers.counts_all(&self.lanes);
        let others: Vec<&[u32]> =
            picks.iter().filter(|o| self.everywhere.binary_search(o).is_err()).map(|&o| &self.ranks[o][..]).collect();
        let mut others = layers.counts_each(&others).into_iter();
        picks
            .iter()
            .map(|&o| match self.everywhere.binary_search(&o) {
                Ok(lane) => side_by_side[lane],
                Err(_) => others.next().expect("one count for each other order"),
            })
            .collect()
    }
}

/// Every camera's view of `triangles` as [`DepthLayers`], from which the depth test of any
/// order of them is replayed, under exactly the rules [`CpuRaster`] counts by.
pub fn depth_layers(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    cameras: &[Camera],
    res: u32,
) -> Result<Vec<DepthLayers>> {
    let local = Local::of(positions, triangles);
    let layers = each_view(&local.positions, cameras, res, LayerScratch::default, |scratch, screen, _| {
        scratch.layers(screen, &local, res)
    });
    named_as_given(layers, positions, cameras, res)
}

/// `result` of views of renumbered vertices ([`Local`]), with a projection error named as the
/// caller numbers the vertices: the first view's error on the vertices as given.
fn named_as_given<T>(result: Result<T>, positions: &[Vec3], cameras: &[Camera], res: u32) -> Result<T> {
    result.or_else(|e| {
        each_view(positions, cameras, res, || (), |_, _, _| ())?;
        Err(e)
    })
}

/// A mesh renumbered for locality, for what does not depend on the draw order (a view's
/// [`DepthLayers`]: its fragments sorted by depth and triangle id): the triangles in Morton order
/// of their centroids and the vertices by first use, so that consecutive triangles fetch their
/// corners, and write their fragments' pixels, from nearby memory. Measured on one thread, 162
/// views: the 100k Buddha at 512² in 0.62 s against 0.75 s in its own order (vertices renumbered
/// either way); on Xbot subdivided twice at 128² no difference (1.34–1.41 s against 1.28–1.44 s),
/// its order being local already.
struct Local {
    /// The positions, by new vertex number; unused vertices last, so that every vertex is still
    /// projected (and a bad one still fails a view).
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// Each triangle's index in the caller's list.
    ids: Vec<u32>,
}

impl Local {
    fn of(positions: &[Vec3], triangles: &[[u32; 3]]) -> Local {
        let centroid = |t: &[u32; 3]| t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0;
        let (lo, hi) = triangles
            .iter()
            .map(centroid)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(c), hi.max(c)));
        let grid = ZOrder::over(lo, hi);
        let mut keyed: Vec<(u32, u32)> = triangles.iter().zip(0..).map(|(t, i)| (grid.key(centroid(t)), i)).collect();
        radsort::sort_by_key(&mut keyed, |k| k.0);
        let mut number = vec![u32::MAX; positions.len()];
        let mut order: Vec<u32> = Vec::with_capacity(positions.len());
        let triangles = keyed
            .iter()
            .map(|&(_, i)| {
                triangles[i as usize].map(|v| {
                    if number[v as usize] == u32::MAX {
                        number[v as usize] = order.len() as u32;
                        order.push(v);
                    }
                    number[v as usize]
                })
            })
            .collect();
        order.extend((0..positions.len() as u32).filter(|&v| number[v as usize] == u32::MAX));
        Local {
            positions: order.iter().map(|&v| positions[v as usize]).collect(),
            triangles,
            ids: keyed.into_iter().map(|(_, i)| i).collect(),
        }
    }
}

/// One thread's buffers for [`DepthLayers`]: the fragments and the scratch that sorts them.
#[derive(Default)]
struct LayerScratch {
    fragments: Vec<Fragment>,
    sorting: Sorting,
}

impl LayerScratch {
    /// The view's layers of `local`'s triangles, ids as the caller numbers them. Drawn without a
    /// depth test: the layers keep every fragment, and which passed in this order is not used.
    fn layers(&mut self, screen: &[ScreenVertex], local: &Local, res: u32) -> DepthLayers {
        self.fragments.clear();
        let ids = &local.ids;
        draw::<false, _>(screen, &local.triangles, res, &mut Vec::new(), |f: Fragment| {
            self.fragments.push(Fragment { triangle: ids[f.triangle as usize], ..f })
        });
        DepthLayers::of(&self.fragments, res, &mut self.sorting)
    }
}

/// `view(scratch, projected vertices, camera index)` for every camera, views in parallel (each
/// thread with its own `scratch`). The positions go into the unit frame once per run of cameras
/// with one framing (all of them, from a view set), the same f32 values the GPU backend
/// uploads. A failure names the first view that fails, whichever thread met one first.
fn each_view<T: Send, S: Send>(
    positions: &[Vec3],
    cameras: &[Camera],
    res: u32,
    scratch: impl Fn() -> S + Sync + Send,
    view: impl Fn(&mut S, &[ScreenVertex], usize) -> T + Sync + Send,
) -> Result<Vec<T>> {
    check_resolution(res)?;
    let mut out = Vec::with_capacity(cameras.len());
    for run in cameras.chunk_by(|a, b| a.framing == b.framing) {
        let (first, unit) = (out.len(), run[0].framing.unit_positions(positions));
        let run: Vec<T> = run
            .par_iter()
            .enumerate()
            .map_init(
                || (Vec::new(), scratch()),
                |(screen, scratch), (i, camera)| {
                    project(&unit, camera, res, screen)
                        .map_err(|why| Error::usage(format!("view {}: {why}", first + i)))?;
                    Ok(view(scratch, screen, first + i))
                },
            )
            .collect::<Vec<Result<T>>>()
            .into_iter()
            .collect::<Result<_>>()?;
        out.extend(run);
    }
    Ok(out)
}

/// The triangle seen at each pixel (row-major, row 0 at the bottom), `u32::MAX` where none: the
/// index into `triangles` of the last fragment to pass the depth test there, under exactly the
/// rules [`CpuRaster`] counts by. Figures use it to draw a mesh as the measurements see it.
pub fn visible_triangles(positions: &[Vec3], triangles: &[[u32; 3]], camera: &Camera, res: u32) -> Result<Vec<u32>> {
    check_resolution(res)?;
    let mut screen = Vec::new();
    project(&camera.framing.unit_positions(positions), camera, res, &mut screen).map_err(Error::usage)?;
    let mut seen = vec![u32::MAX; res as usize * res as usize];
    draw::<true, _>(&screen, triangles, res, &mut Vec::new(), |f: Fragment| {
        if f.passed {
            seen[f.pixel as usize] = f.triangle
        }
    });
    Ok(seen)
}

/// The fragments that pass the depth test at each pixel (row-major, row 0 at the bottom) when
/// `triangles` are drawn in order: the overdraw picture of one view, counted under exactly the
/// rules [`CpuRaster`] counts by.
pub fn shaded_per_pixel(positions: &[Vec3], triangles: &[[u32; 3]], camera: &Camera, res: u32) -> Result<Vec<u32>> {
    check_resolution(res)?;
    let mut screen = Vec::new();
    project(&camera.framing.unit_positions(positions), camera, res, &mut screen).map_err(Error::usage)?;
    let mut shaded = vec![0u32; res as usize * res as usize];
    draw::<true, _>(&screen, triangles, res, &mut Vec::new(), |f: Fragment| {
        if f.passed {
            shaded[f.pixel as usize] += 1
        }
    });
    Ok(shaded)
}

/// One front-facing fragment: which pixel, which triangle (index into the drawn list), its depth,
/// and whether it passed the depth test when the list was drawn in order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fragment {
    pub pixel: u32,
    pub triangle: u32,
    pub depth: f32,
    pub passed: bool,
}

/// Every front-facing fragment of `triangles` seen by `camera`, in draw order, appended to `out`
/// (cleared first), under exactly the rules [`CpuRaster`] counts by. With the fragments of a view
/// in hand, the depth test of *any* other draw order can be replayed without rasterizing again,
/// which is what makes the one-pass cluster overdraw graph possible.
pub fn fragments(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    camera: &Camera,
    res: u32,
    out: &mut Vec<Fragment>,
) -> Result<()> {
    check_resolution(res)?;
    let mut screen = Vec::new();
    project(&camera.framing.unit_positions(positions), camera, res, &mut screen).map_err(Error::usage)?;
    out.clear();
    draw::<true, _>(&screen, triangles, res, &mut Vec::new(), |f| out.push(f));
    Ok(())
}

/// Whether `camera` sees every vertex of `positions` without clipping and without projecting far
/// off screen: the condition [`CpuRaster`] refuses a view for, with the same message.
pub fn check_projection(positions: &[Vec3], camera: &Camera, res: u32) -> std::result::Result<(), String> {
    project(&camera.framing.unit_positions(positions), camera, res, &mut Vec::new())
}

/// An image side the rasterizer can draw: 1 to [`MAX_RESOLUTION`] pixels.
fn check_resolution(res: u32) -> Result<()> {
    if (1..=MAX_RESOLUTION).contains(&res) {
        Ok(())
    } else {
        Err(Error::usage(format!("resolution {res} is outside 1..={MAX_RESOLUTION}")))
    }
}

/// Projects and snaps every vertex of `unit` (positions already in the camera's unit frame,
/// [`crate::mesh::Framing::unit_positions`]) into `out`. Fails if a vertex lies outside the depth
/// range (it would need clipping, which the view sets are framed never to need) or far off
/// screen.
fn project(unit: &[Vec3], camera: &Camera, res: u32, out: &mut Vec<ScreenVertex>) -> std::result::Result<(), String> {
    let lanes = Lanes::new(camera, res);
    // Four at a time, the last quad padded with copies of the last vertex (their lanes dropped).
    let (quads, rest) = unit.as_chunks::<4>();
    let last = rest.first().map(|_| std::array::from_fn(|k| rest[k.min(rest.len() - 1)]));
    // One pass without early exits (faults are folded into a mask, so the loop has no branch),
    // then, in the rare case of a fault, a second pass to name the first bad vertex.
    let mut faults = 0;
    out.clear();
    out.reserve(unit.len() + 3);
    for quad in quads.iter().chain(&last) {
        let (vertices, outside, far) = lanes.snap(quad);
        faults |= outside | far;
        out.extend_from_slice(&vertices);
    }
    out.truncate(unit.len());
    if faults == 0 {
        return Ok(());
    }
    let (i, outside) = quads
        .iter()
        .chain(&last)
        .enumerate()
        .find_map(|(i, quad)| {
            let (_, outside, far) = lanes.snap(quad);
            let lane = (outside | far).trailing_zeros();
            (lane < 4).then(|| (4 * i + lane as usize, outside >> lane & 1 != 0))
        })
        .expect("a fault has a vertex");
    Err(if outside {
        format!("vertex {i} lies outside the camera's depth range (clipping is not supported)")
    } else {
        format!("vertex {i} projects far outside the image")
    })
}

/// A camera's transform split into lanes: `m[r][c]` holds the matrix entry of row `r`, column
/// `c` in all four lanes, so four vertices go through it at once, one a lane. Each lane does the
/// operations of `view_proj * p.extend(1.0)` in glam's order (the columns scaled by x, y, z and 1
/// and summed left to right; scaling by 1 is exact and left out), so a vertex snaps to the same
/// bits as transformed alone; projecting took a sixth of drawing a dense mesh's views, 51
/// instructions a vertex one at a time.
struct Lanes {
    m: [[Vec4; 4]; 4],
    /// Sub-pixels per NDC unit.
    scale: Vec4,
    /// Farther off the image than this (in sub-pixels) a vertex is refused.
    limit: Vec4,
}

impl Lanes {
    fn new(camera: &Camera, res: u32) -> Lanes {
        let columns = camera.view_proj.to_cols_array_2d();
        Lanes {
            m: std::array::from_fn(|r| std::array::from_fn(|c| Vec4::splat(columns[c][r]))),
            scale: Vec4::splat(0.5 * res as f32 * ONE as f32),
            limit: Vec4::splat((8 * i64::from(res) * ONE) as f32),
        }
    }

    /// Four vertices through the camera, the perspective divide and the viewport, snapped; and
    /// their faults, bit `k` for the `k`-th: the ones outside the depth range (behind the eye or
    /// past the far plane), and the ones farther than `limit` off the image.
    fn snap(&self, quad: &[Vec3; 4]) -> ([ScreenVertex; 4], u32, u32) {
        let (x, y, z) = (
            Vec4::from_array(quad.map(|p| p.x)),
            Vec4::from_array(quad.map(|p| p.y)),
            Vec4::from_array(quad.map(|p| p.z)),
        );
        let clip = |[mx, my, mz, mw]: &[Vec4; 4]| ((*mx * x + *my * y) + *mz * z) + *mw;
        let [cx, cy, cz, cw] = self.m.each_ref().map(clip);
        let (nx, ny, nz) = (cx / cw, cy / cw, cz / cw);
        let (sx, sy) = ((nx + Vec4::ONE) * self.scale, (ny + Vec4::ONE) * self.scale);
        let inside_depth = cw.cmpgt(Vec4::ZERO) & nz.cmpge(Vec4::ZERO) & nz.cmple(Vec4::ONE);
        let near = sx.abs().cmplt(self.limit) & sy.abs().cmplt(self.limit);
        let (rx, ry, nz) = (round4(sx), round4(sy), nz.to_array());
        let vertices = std::array::from_fn(|k| ScreenVertex { x: rx[k], y: ry[k], z: nz[k] });
        (vertices, !inside_depth.bitmask() & 0xf, !near.bitmask() & 0xf)
    }
}

/// Each lane rounded half away from zero, as [`f32::round`], for values below 2³¹ in magnitude
/// (beyond, a vertex is refused as far off the image and the values are not used). Written out
/// because `f32::round` is a libc call on baseline x86-64 (no SSE4.1), which cost 7% of an
/// overdraw count; on x86-64 in one SSE2 register, without the checks a saturating `as i32` adds.
#[cfg(target_arch = "x86_64")]
fn round4(v: Vec4) -> [i32; 4] {
    use std::arch::x86_64::*;
    // SAFETY: these are SSE and SSE2 instructions, part of every x86-64 processor (the target's
    // baseline); none touches memory.
    unsafe {
        let v: __m128 = v.into();
        let whole = _mm_cvttps_epi32(v);
        // Exact: `whole` and `v` share their sign and `whole` drops only the fraction.
        let fraction = _mm_sub_ps(v, _mm_cvtepi32_ps(whole));
        // Comparison masks are −1 where true.
        let up = _mm_castps_si128(_mm_cmpge_ps(fraction, _mm_set1_ps(0.5)));
        let down = _mm_castps_si128(_mm_cmple_ps(fraction, _mm_set1_ps(-0.5)));
        std::mem::transmute::<__m128i, [i32; 4]>(_mm_add_epi32(_mm_sub_epi32(whole, up), down))
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn round4(v: Vec4) -> [i32; 4] {
    v.to_array().map(|x| {
        let whole = x as i32;
        let fraction = x - whole as f32;
        whole + i32::from(fraction >= 0.5) - i32::from(fraction <= -0.5)
    })
}

/// An edge function `E(p) = (b − a) × (p − a)`, positive inside a counter-clockwise triangle,
/// evaluated at the first pixel centre of a box and stepped per pixel.
#[derive(Clone, Copy)]
struct Edge {
    /// Value at the current row start, minus 1 if the edge is not top-left (so `>= 0` tests inside).
    row: i64,
    step_x: i64,
    step_y: i64,
}

/// Boxes at least this many pixels wide (less one) are drawn a row's run at a time, solved
/// from the edge functions with three divisions, rather than testing every pixel of the box:
/// there the tests outside the triangle and the mispredicted branches at its borders cost more.
const SPAN_FROM: i64 = 4;

impl Edge {
    /// The pixel steps `k` from the row's start where `row + k·step_x ≥ 0`, as an inclusive
    /// range (empty when the first exceeds the second): exactly the pixels the per-pixel test
    /// passes. The definition, dividing on each row, that [`EdgeRows`] is checked against.
    #[cfg(test)]
    fn inside(&self) -> (i64, i64) {
        match self.step_x {
            // k ≥ ⌈−row / step⌉
            s if s > 0 => (-self.row.div_euclid(s), i64::MAX),
            // k ≤ ⌊row / −step⌋
            s if s < 0 => (i64::MIN, self.row.div_euclid(-s)),
            _ if self.row >= 0 => (i64::MIN, i64::MAX),
            _ => (1, 0),
        }
    }

    /// [`Edge::inside`] of this row and every row below it in turn ([`EdgeRows`]).
    fn rows(&self) -> EdgeRows {
        // A horizontal edge (no step in x) tests `row ≥ 0`, which is `⌊row / 1⌋ ≥ 0`.
        let divisor = self.step_x.abs().max(1);
        EdgeRows {
            quotient: self.row.div_euclid(divisor),
            remainder: self.row.rem_euclid(divisor),
            step_quotient: self.step_y.div_euclid(divisor),
            step_remainder: self.step_y.rem_euclid(divisor),
            divisor,
            sign: self.step_x.signum(),
        }
    }

    fn new(a: ScreenVertex, b: ScreenVertex, px: i64, py: i64) -> Edge {
        let (dx, dy) = (i64::from(b.x - a.x), i64::from(b.y - a.y));
        // y up: a top edge runs right-to-left horizontally; a left edge runs downward.
        let top_left = ((dy == 0) & (dx < 0)) | (dy < 0);
        let value = dx * (py - i64::from(a.y)) - dy * (px - i64::from(a.x));
        Edge { row: value - i64::from(!top_left), step_x: -dy * ONE, step_y: dx * ONE }
    }
}

/// An edge's run bound from row to row without a division per row: `⌊row / |step_x|⌋` kept as a
/// quotient and remainder and stepped by those of `step_y`. Dividing anew on every row (three
/// 64-bit divisions a row) was most of the cost of drawing the large triangles of a coarse mesh.
#[derive(Clone, Copy, Default)]
struct EdgeRows {
    quotient: i64,
    remainder: i64,
    step_quotient: i64,
    step_remainder: i64,
    divisor: i64,
    sign: i64,
}

impl EdgeRows {
    /// What [`Edge::inside`] gives on the current row.
    fn inside(&self) -> (i64, i64) {
        match self.sign {
            1 => (-self.quotient, i64::MAX),
            -1 => (i64::MIN, self.quotient),
            _ if self.quotient >= 0 => (i64::MIN, i64::MAX),
            _ => (1, 0),
        }
    }

    fn next_row(&mut self) {
        self.quotient += self.step_quotient;
        self.remainder += self.step_remainder;
        if self.remainder >= self.divisor {
            self.remainder -= self.divisor;
            self.quotient += 1;
        }
    }
}

/// Where [`draw`] sends each fragment: any closure, or [`CountOnly`] when only the counts matter,
/// which lets a run of pixels be depth-tested four at a time.
trait FragmentSink {
    /// No fragment is looked at: [`draw`] may count without making them.
    const COUNTS_ONLY: bool = false;
    fn fragment(&mut self, fragment: Fragment);
}

impl<F: FnMut(Fragment)> FragmentSink for F {
    fn fragment(&mut self, fragment: Fragment) {
        self(fragment)
    }
}

/// Counting alone (the overdraw measure, [`CpuRaster::count`]).
struct CountOnly;

impl FragmentSink for CountOnly {
    const COUNTS_ONLY: bool = true;
    fn fragment(&mut self, _: Fragment) {}
}

/// A triangle's depth along one row: at pixel `x`, `zy + dzdx · (x + 0.5 − ax)`.
#[derive(Clone, Copy)]
struct Plane {
    zy: f32,
    dzdx: f32,
    ax: f32,
}

impl Plane {
    fn at(&self, x: i64) -> f32 {
        self.zy + self.dzdx * (x as f32 + 0.5 - self.ax)
    }
}

/// The depth test of pixels `from..=to` of a row (`row` starts at the row's first pixel and runs
/// at least three pixels past `to`), counted into `counts`: what drawing them one by one counts,
/// to the bit. Four at a time in SSE2 (the x86-64 baseline), with no branch on the test's
/// outcome, which on overlapping surfaces is a coin toss per pixel; each lane computes the depth
/// with [`Plane::at`]'s operations in its order, so the values are the same.
#[cfg(target_arch = "x86_64")]
fn depth_test_run(row: &mut [f32], from: i64, to: i64, plane: Plane, counts: &mut ViewCounts) {
    use std::arch::x86_64::*;
    if from > to {
        return;
    }
    let (from, to) = (from as usize, to as usize);
    assert!(to + 3 < row.len());
    // SAFETY: SSE2 is part of every x86-64 processor; every load and store reads or writes four
    // pixels from `x ≤ to`, in bounds by the assertion; lanes past `to` are written back unchanged.
    unsafe {
        let (zy, dzdx, ax, half) =
            (_mm_set1_ps(plane.zy), _mm_set1_ps(plane.dzdx), _mm_set1_ps(plane.ax), _mm_set1_ps(0.5));
        let (one, steps) = (_mm_set1_ps(1.0), _mm_setr_epi32(0, 1, 2, 3));
        let (mut passed, mut covered) = (_mm_setzero_si128(), _mm_setzero_si128());
        let mut x = from;
        while x <= to {
            let lanes = _mm_add_epi32(_mm_set1_epi32(x as i32), steps);
            let within = _mm_castsi128_ps(_mm_cmpgt_epi32(_mm_set1_epi32(to as i32 + 1), lanes));
            let z = _mm_add_ps(zy, _mm_mul_ps(dzdx, _mm_sub_ps(_mm_add_ps(_mm_cvtepi32_ps(lanes), half), ax)));
            let at = row.as_mut_ptr().add(x);
            let d = _mm_loadu_ps(at);
            let pass = _mm_and_ps(_mm_cmplt_ps(z, d), within);
            let first = _mm_and_ps(pass, _mm_cmpeq_ps(d, one));
            _mm_storeu_ps(at, _mm_or_ps(_mm_and_ps(pass, z), _mm_andnot_ps(pass, d)));
            // A true lane is −1: subtracting counts it.
            passed = _mm_sub_epi32(passed, _mm_castps_si128(pass));
            covered = _mm_sub_epi32(covered, _mm_castps_si128(first));
            x += 4;
        }
        let sum = |v: __m128i| {
            let mut lanes = [0u32; 4];
            _mm_storeu_si128(lanes.as_mut_ptr().cast(), v);
            lanes.iter().map(|&l| u64::from(l)).sum::<u64>()
        };
        counts.passed += sum(passed);
        counts.covered += sum(covered);
    }
}

/// [`depth_test_run`] one pixel at a time, where there is no SSE2.
#[cfg(not(target_arch = "x86_64"))]
fn depth_test_run(row: &mut [f32], from: i64, to: i64, plane: Plane, counts: &mut ViewCounts) {
    for x in from..=to {
        depth_test(&mut row[x as usize], plane.at(x), counts);
    }
}

/// One fragment at depth `z` tested (LESS) against the stored depth `d` and counted: whether it
/// passed. A pixel is covered when its first fragment passes (the cleared depth is 1.0).
#[inline(always)]
fn depth_test(d: &mut f32, z: f32, counts: &mut ViewCounts) -> bool {
    let passed = z < *d;
    if passed {
        counts.covered += u64::from(*d == 1.0);
        *d = z;
        counts.passed += 1;
    }
    passed
}

/// Draws `triangles` in order into a cleared depth buffer and counts; `on_fragment` sees every
/// front-facing fragment, passed or not. With [`CountOnly`] no fragment is made, and a wide
/// triangle's rows are depth-tested four pixels at a time ([`depth_test_run`]). Without
/// `DEPTH_TEST` there is no depth buffer: every fragment is reported as not passed, and nothing
/// is counted.
fn draw<const DEPTH_TEST: bool, S: FragmentSink>(
    v: &[ScreenVertex],
    triangles: &[[u32; 3]],
    res: u32,
    depth: &mut Vec<f32>,
    mut on_fragment: S,
) -> ViewCounts {
    let n = res as usize;
    if DEPTH_TEST {
        depth.clear();
        // Padded by three pixels, so that four read from the last row's last pixel stay in bounds.
        depth.resize(n * n + 3, 1.0);
    }
    let mut counts = ViewCounts::default();
    let last = i64::from(res) - 1;
    for (t, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        // Back faces first: half the triangles, and a test whose outcome neighbouring triangles
        // share, so the branch is well predicted.
        let (abx, aby) = (i64::from(b.x - a.x), i64::from(b.y - a.y));
        let (acx, acy) = (i64::from(c.x - a.x), i64::from(c.y - a.y));
        let area = abx * acy - aby * acx;
        if area <= 0 {
            continue;
        }
        // Pixel index range whose centres (i·ONE + HALF) can lie inside the bounding box; most
        // small triangles of a dense mesh cover no centre and stop here.
        let first = |lo: i32| (i64::from(lo) - HALF + ONE - 1).div_euclid(ONE).max(0);
        let final_ = |hi: i32| (i64::from(hi) - HALF).div_euclid(ONE).min(last);
        let (x0, x1) = (first(a.x.min(b.x).min(c.x)), final_(a.x.max(b.x).max(c.x)));
        let (y0, y1) = (first(a.y.min(b.y).min(c.y)), final_(a.y.max(b.y).max(c.y)));
        if x0 > x1 || y0 > y1 {
            continue;
        }
        let (px, py) = (x0 * ONE + HALF, y0 * ONE + HALF);
        let mut edges = [Edge::new(b, c, px, py), Edge::new(c, a, px, py), Edge::new(a, b, px, py)];
        // A box around one pixel centre that the triangle misses (common for the small triangles
        // of a dense mesh) needs no depth plane.
        if x0 == x1 && y0 == y1 && (edges[0].row | edges[1].row | edges[2].row) < 0 {
            continue;
        }
        // Depth plane z = za + dzdx·(x − ax) + dzdy·(y − ay), in pixel units, from the snapped vertices.
        let inv_area = 1.0 / area as f64;
        let (dz1, dz2) = (f64::from(b.z - a.z), f64::from(c.z - a.z));
        let dzdx = ((dz1 * acy as f64 - dz2 * aby as f64) * inv_area * ONE as f64) as f32;
        let dzdy = ((dz2 * abx as f64 - dz1 * acx as f64) * inv_area * ONE as f64) as f32;
        // Offsets from vertex a stay small, so f32 keeps the plane accurate.
        let (ax, ay) = (a.x as f32 / ONE as f32, a.y as f32 / ONE as f32);
        let wide = x1 - x0 >= SPAN_FROM;
        let mut runs = if wide { edges.map(|e| e.rows()) } else { [EdgeRows::default(); 3] };
        for y in y0..=y1 {
            let row = y as usize * n;
            let plane = Plane { zy: a.z + dzdy * (y as f32 + 0.5 - ay), dzdx, ax };
            // The row's run of inside pixels, solved from the edge functions: no test per pixel.
            let run = |runs: &mut [EdgeRows; 3]| {
                let (lo, hi) = runs.iter_mut().fold((0, x1 - x0), |(lo, hi), e| {
                    let (from, to) = e.inside();
                    e.next_row();
                    (lo.max(from), hi.min(to))
                });
                (x0 + lo, x0 + hi)
            };
            if DEPTH_TEST && S::COUNTS_ONLY && wide {
                let (from, to) = run(&mut runs);
                depth_test_run(&mut depth[row..], from, to, plane, &mut counts);
            } else {
                let mut fragment = |x: i64| {
                    let z = plane.at(x);
                    let passed = DEPTH_TEST && depth_test(&mut depth[row + x as usize], z, &mut counts);
                    let pixel = (row + x as usize) as u32;
                    on_fragment.fragment(Fragment { pixel, triangle: t as u32, depth: z, passed });
                };
                if wide {
                    let (from, to) = run(&mut runs);
                    (from..=to).for_each(&mut fragment);
                } else {
                    let (mut e0, mut e1, mut e2) = (edges[0].row, edges[1].row, edges[2].row);
                    for x in x0..=x1 {
                        if (e0 | e1 | e2) >= 0 {
                            fragment(x);
                        }
                        e0 += edges[0].step_x;
                        e1 += edges[1].step_x;
                        e2 += edges[2].step_x;
                    }
                }
            }
            for e in &mut edges {
                e.row += e.step_y;
            }
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The run `Edge::inside` solves is exactly the pixels the per-pixel test passes, for edges
    /// in every direction, through and beside pixel centres.
    #[test]
    fn an_edges_inside_run_is_what_the_pixel_test_passes() {
        let vertex = |x: i32, y: i32| ScreenVertex { x, y, z: 0.5 };
        let points = [(0, 0), (37 * ONE as i32 / 3, 5), (-300, 2_000), (4_000, -77), (ONE as i32 * 9, ONE as i32 * 9)];
        let mut checked = 0;
        for &(ax, ay) in &points {
            for &(bx, by) in &points {
                for (px, py) in [(HALF, HALF), (3 * ONE + HALF, HALF), (-2 * ONE + HALF, 7 * ONE + HALF)] {
                    let edge = Edge::new(vertex(ax, ay), vertex(bx, by), px, py);
                    let (from, to) = edge.inside();
                    for k in -40i64..40 {
                        let passes = edge.row + k * edge.step_x >= 0;
                        assert_eq!(passes, (from..=to).contains(&k), "edge {ax},{ay} → {bx},{by}, step {k}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, points.len() * points.len() * 3 * 80);
    }

    /// Counting alone, with runs depth-tested four at a time, counts what drawing fragment by
    /// fragment counts and leaves the same depths, to the bit: on meshes with small and large
    /// triangles, drawn in an order that makes them overlap, at a resolution whose rows end
    /// between two groups of four pixels.
    #[test]
    fn counting_alone_counts_what_each_fragment_counts() {
        use crate::mesh::{Framing, procedural};
        use crate::raster::views::ViewSet;
        let mut checked = 0;
        for spec in ["sphere:2000", "sphere:80", "disk:300"] {
            let mesh = procedural::generate(spec, 0).unwrap().unwrap();
            // Two copies side by side, overlapping, drawn in turn, so that fragments fail too, and
            // each triangle of the first drawn twice, so that depths tie.
            let nv = mesh.positions.len() as u32;
            let shifted = mesh.positions.iter().map(|p| *p + Vec3::new(0.6, 0.3, 0.4));
            let positions: Vec<Vec3> = mesh.positions.iter().copied().chain(shifted).collect();
            let order: Vec<[u32; 3]> = mesh.triangles.iter().flat_map(|&t| [t, t.map(|i| i + nv), t]).rev().collect();
            let framing = Framing::of(&positions);
            let mut hidden = 0;
            for camera in ViewSet::Random(6).cameras(framing, 1) {
                for res in [64, 257] {
                    let mut screen = Vec::new();
                    project(&framing.unit_positions(&positions), &camera, res, &mut screen).unwrap();
                    let (mut alone, mut each) = (Vec::new(), Vec::new());
                    let counted = draw::<true, _>(&screen, &order, res, &mut alone, CountOnly);
                    let drawn = draw::<true, _>(&screen, &order, res, &mut each, |_: Fragment| {});
                    assert_eq!(counted, drawn, "{spec} at {res}²");
                    hidden += counted.passed - counted.covered;
                    let bits = |d: &[f32]| d.iter().map(|z| z.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&alone), bits(&each), "{spec} at {res}²");
                    checked += 1;
                }
            }
            assert!(hidden > 0, "{spec}: some fragments are drawn over");
        }
        assert_eq!(checked, 3 * 6 * 2);
    }

    /// Rounding is `f32::round`'s (half away from zero) over the range snapped coordinates take.
    #[test]
    fn rounding_is_half_away_from_zero() {
        let mut values = vec![0.5, -0.5, 1.5, -1.5, 2.5, 0.49999997, -0.49999997, 8_388_607.5, -8_388_607.5];
        values.extend((-4000..4000).map(|i| i as f32 * 0.37 + 0.125));
        values.extend((0..2000).map(|i| (i as f32 - 1000.0) * 33_554.43));
        for quad in values.chunks(4) {
            let lanes: [f32; 4] = std::array::from_fn(|k| *quad.get(k).unwrap_or(&0.0));
            assert_eq!(round4(Vec4::from_array(lanes)), lanes.map(|x| x.round() as i32), "{lanes:?}");
        }
    }

    /// Four vertices a lane at a time snap to the same bits as each alone through the camera's
    /// matrix (`view_proj * p.extend(1.0)`, the perspective divide, the viewport, `f32::round`),
    /// with the same faults: behind the eye, past the far plane, far off the image.
    #[test]
    fn lanes_snap_as_the_matrix_does_one_vertex() {
        use crate::mesh::Framing;
        use crate::raster::views::{ViewSet, perspective};
        let framing = Framing::of(&[Vec3::splat(-1.0), Vec3::splat(1.0)]);
        let mut cameras = ViewSet::Ico(42).cameras(framing, 0);
        cameras.extend(ViewSet::Random(8).cameras(framing, 3));
        cameras.push(perspective(framing, Vec3::new(0.3, -0.8, 0.5)));
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0
        };
        let mut points: Vec<Vec3> = (0..4000).map(|_| Vec3::new(next(), next(), next()) * 1.2).collect();
        // Past the far plane, behind the eye, and far off to one side.
        points.extend([Vec3::splat(40.0), Vec3::splat(-40.0), Vec3::new(0.0, 30.0, 0.0), Vec3::ZERO]);
        let (mut faults, mut checked) = (0, 0);
        for camera in &cameras {
            for res in [64, 512] {
                let lanes = Lanes::new(camera, res);
                let (scale, limit) = (0.5 * res as f32 * ONE as f32, (8 * i64::from(res) * ONE) as f32);
                for quad in points.as_chunks::<4>().0 {
                    let (vertices, outside, far) = lanes.snap(quad);
                    let fault = std::array::from_fn::<u8, 4, _>(|k| (outside >> k & 1 | (far >> k & 1) << 1) as u8);
                    for ((p, v), f) in quad.iter().zip(vertices).zip(fault) {
                        let clip = camera.view_proj * p.extend(1.0);
                        let ndc = clip / Vec4::splat(clip.w);
                        let (x, y) = ((ndc.x + 1.0) * scale, (ndc.y + 1.0) * scale);
                        let outside = !((clip.w > 0.0) & (ndc.z >= 0.0) & (ndc.z <= 1.0));
                        let far = !((x.abs() < limit) & (y.abs() < limit));
                        assert_eq!(f, u8::from(outside) | u8::from(far) << 1, "{p} fault");
                        if f == 0 {
                            assert_eq!(
                                (v.x, v.y, v.z.to_bits()),
                                (x.round() as i32, y.round() as i32, ndc.z.to_bits()),
                                "{p}"
                            );
                            checked += 1;
                        }
                        faults += usize::from(f != 0);
                    }
                }
            }
        }
        assert!(checked > 100_000 && faults >= cameras.len() * 2, "{checked} snapped, {faults} faults");
    }

    /// Stepped row by row, [`EdgeRows`] gives what [`Edge::inside`] gives on each row, for edges
    /// in every direction (horizontal and vertical ones included), steps of either sign.
    #[test]
    fn an_edges_runs_stepped_row_by_row_are_its_inside_runs() {
        let vertex = |x: i32, y: i32| ScreenVertex { x, y, z: 0.5 };
        let points = [(0, 0), (37 * ONE as i32 / 3, 5), (-300, 2_000), (4_000, -77), (0, 2_000), (4_000, 0)];
        let mut rows = 0;
        for &(ax, ay) in &points {
            for &(bx, by) in &points {
                let mut edge = Edge::new(vertex(ax, ay), vertex(bx, by), HALF, -5 * ONE + HALF);
                let mut runs = edge.rows();
                for _ in 0..60 {
                    assert_eq!(runs.inside(), edge.inside(), "edge {ax},{ay} → {bx},{by}, row value {}", edge.row);
                    edge.row += edge.step_y;
                    runs.next_row();
                    rows += 1;
                }
            }
        }
        assert_eq!(rows, points.len() * points.len() * 60);
    }
}
