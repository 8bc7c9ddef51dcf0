//! Procedural meshes, named like files: `grid:16x8`, `disk:950`, `sphere:20480`, `helix:4`,
//! `layers:8`.
//!
//! The papers we reproduce test on synthetic meshes as well as scans: Bogomjakov & Gotsman 2002
//! order a regular 16×8 grid (Fig. 2) and an irregular 950-triangle disk (Fig. 4); Nehab et al.
//! 2006 explain overdraw cycles with a helix (Fig. 5); Forsyth's vertex-cache tests use a
//! geodesic sphere. Generating them instead of shipping files keeps them exact, and giving them
//! file-like names lets every command that takes a mesh path take one of them too.
//!
//! A spec is `NAME:ARGS`. [`generate`] answers `None` for anything whose text before the first
//! `:` is not one of the five names, so the caller treats it as a path (`models/bunny.ply`,
//! `foo:bar` and `C:\mesh.obj` are all paths). A spec with a known name but malformed arguments is
//! an error, never a path. Every generator is deterministic: the same spec (and, for `disk`, the
//! same seed) gives the same mesh bit for bit. All triangles are counter-clockwise seen from
//! their front (outside) side.

use std::collections::HashMap;

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};

use super::{Mesh, VertexAttributes};
use crate::error::{Error, Result};

/// Largest triangle count a spec may ask for (2^26): far beyond any test in the papers, small
/// enough that a typo like `grid:100000x100000` is an error instead of exhausting memory.
pub const MAX_TRIANGLES: u64 = 1 << 26;

/// Radius of the helix's centre line around the z axis (`helix:T`).
pub const HELIX_RADIUS: f32 = 1.0;
/// Rise of the helix's centre line per turn (`helix:T`).
pub const HELIX_PITCH: f32 = 0.6;
/// Radius of the tube swept along the helix (`helix:T`). Twice this (0.5) is less than the pitch,
/// so consecutive turns leave a 0.1 gap and never intersect.
pub const HELIX_TUBE_RADIUS: f32 = 0.25;
/// Rings of the tube per turn of the helix (`helix:T`).
pub const HELIX_SEGMENTS_PER_TURN: u32 = 48;
/// Sides of the tube's polygonal cross-section (`helix:T`).
pub const HELIX_SIDES: u32 = 12;

/// A parsed procedural spec, checked but not yet built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Grid { w: u64, h: u64 },
    Disk { n: u64 },
    Sphere { f: u64 },
    Helix { turns: u64 },
    Layers { k: u64 },
}

impl Shape {
    /// The triangle count the shape will have, `None` on overflow.
    fn triangles(self) -> Option<u64> {
        let (segments, sides) = (u64::from(HELIX_SEGMENTS_PER_TURN), u64::from(HELIX_SIDES));
        match self {
            Shape::Grid { w, h } => w.checked_mul(h)?.checked_mul(2),
            Shape::Disk { n } => Some(n),
            Shape::Sphere { f } => f.checked_mul(f)?.checked_mul(20),
            Shape::Helix { turns } => turns.checked_mul(2 * segments * sides)?.checked_add(2 * sides),
            Shape::Layers { k } => k.checked_mul(2),
        }
    }
}

/// Parses and checks `spec` without building anything: `None` if it is not procedural (then it
/// is a path), else whether it is well formed and within [`MAX_TRIANGLES`].
fn shape(spec: &str) -> Option<Result<Shape>> {
    let (kind, args) = spec.split_once(':')?;
    let parsed = match kind {
        "grid" => parse::<2>(spec, args, "width and height must be integers ≥ 1, as in grid:16x8")
            .map(|[w, h]| Shape::Grid { w, h }),
        "disk" => parse::<1>(spec, args, "the triangle count must be an integer ≥ 1, as in disk:950")
            .map(|[n]| Shape::Disk { n }),
        "sphere" => parse::<1>(spec, args, "the triangle count must be an integer ≥ 1, as in sphere:20480")
            .map(|[n]| Shape::Sphere { f: (((n as f64) / 20.0).sqrt().round() as u64).max(1) }),
        "helix" => parse::<1>(spec, args, "the number of turns must be an integer ≥ 1, as in helix:4")
            .map(|[turns]| Shape::Helix { turns }),
        "layers" => parse::<1>(spec, args, "the number of layers must be an integer ≥ 1, as in layers:8")
            .map(|[k]| Shape::Layers { k }),
        _ => return None,
    };
    Some(parsed.and_then(|shape| match shape.triangles() {
        Some(t) if t <= MAX_TRIANGLES => Ok(shape),
        _ => Err(Error::input(spec, format!("too large: at most {MAX_TRIANGLES} triangles are supported"))),
    }))
}

/// Whether `spec` names a procedural mesh and is valid, without building it (cheap: for
/// checking experiment specs before any work). `None` when `spec` is a path.
pub fn check(spec: &str) -> Option<Result<()>> {
    shape(spec).map(|s| s.map(drop))
}

/// The triangles `spec` will have, without building it; `None` when it is not a valid procedural
/// spec (a sharded run's cost estimate needs the count before the mesh).
pub fn triangle_count(spec: &str) -> Option<u64> {
    shape(spec)?.ok()?.triangles()
}

/// The mesh named by `spec`, or `None` if `spec` does not start with `grid:`, `disk:`,
/// `sphere:`, `helix:` or `layers:` (then it is a file path). `seed` is used by `disk` only.
/// The mesh is named `spec`; a malformed spec gives an [`Error::Input`] naming it and showing
/// the expected form.
pub fn generate(spec: &str, seed: u64) -> Option<Result<Mesh>> {
    Some(shape(spec)?.and_then(|shape| match shape {
        Shape::Grid { w, h } => grid(spec, w, h),
        Shape::Disk { n } => disk(spec, n, seed),
        Shape::Sphere { f } => sphere(spec, f),
        Shape::Helix { turns } => helix(spec, turns),
        Shape::Layers { k } => layers(spec, k),
    }))
}

/// The `K` integers ≥ 1 of `args`, separated by `x` (`16x8` for `K = 2`, `950` for `K = 1`).
/// Only ASCII digits are accepted (no sign, no spaces); `expected` is the error otherwise.
fn parse<const K: usize>(spec: &str, args: &str, expected: &str) -> Result<[u64; K]> {
    let mut values = [0; K];
    let mut parts = args.split('x');
    for value in &mut values {
        *value = parts
            .next()
            .filter(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|p| p.parse::<u64>().ok())
            .filter(|&v| v >= 1)
            .ok_or_else(|| Error::input(spec, expected))?;
    }
    if parts.next().is_some() {
        return Err(Error::input(spec, expected));
    }
    Ok(values)
}

/// `grid:WxH`, the regular triangulated grid of Bogomjakov & Gotsman 2002, Fig. 2 (16×8 there):
/// W×H unit squares in the z = 0 plane, x in 0..=W, y in 0..=H.
///
/// Vertex `y*(W+1) + x` is at `(x, y, 0)`. Square (x, y), numbered `s = y*W + x` (row-major, y
/// outer), has corners a = (x, y), b = (x+1, y), c = (x+1, y+1), d = (x, y+1) and is split by
/// its `a`–`c` diagonal (lower-left to upper-right, "/") — the same diagonal in every square, so
/// every interior vertex has degree 6. Triangle `2s` is `[a, b, c]` (the lower-right half, below
/// the diagonal) and triangle `2s + 1` is `[a, c, d]` (the upper-left half, above it); both are
/// counter-clockwise seen from +z. Draw order is therefore a row-by-row raster that always runs
/// in +x (not a snake).
fn grid(spec: &str, w: u64, h: u64) -> Result<Mesh> {
    let (w, h) = (w as u32, h as u32);
    let positions = (0..=h).flat_map(|y| (0..=w).map(move |x| Vec3::new(x as f32, y as f32, 0.0))).collect();
    let vertex = |x: u32, y: u32| y * (w + 1) + x;
    let triangles = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            let (a, b, c, d) = (vertex(x, y), vertex(x + 1, y), vertex(x + 1, y + 1), vertex(x, y + 1));
            [[a, b, c], [a, c, d]]
        })
        .collect();
    Mesh::new(spec, positions, triangles, VertexAttributes::default())
}

/// `disk:N`, an irregular planar mesh like Bogomjakov & Gotsman 2002, Fig. 4 (509 vertices and
/// 950 triangles, boundary on a circle): exactly N triangles in the unit disk of the z = 0 plane,
/// counter-clockwise seen from +z. The only generator that uses the seed.
///
/// A triangulated disk with B boundary and I interior vertices has 2I + B − 2 triangles, so we
/// take B ≈ 2.15·√N boundary points (which makes their spacing match the interior spacing),
/// with B's parity chosen so that I = (N + 2 − B)/2 is whole. `disk:950` gives B = 66, I = 443:
/// 509 vertices, as in the paper. Vertices 0..B are evenly on the unit circle, counter-clockwise
/// from (1, 0); vertices B.. are interior points drawn uniformly from a smaller disk (inside the
/// boundary polygon) by dart throwing with a minimum distance (shrunk by 10% whenever 1,000
/// darts in a row miss), which spreads them evenly without a lattice. The points are
/// Delaunay-triangulated; draw order is the triangulator's output order. For N ≤ 3 (or whenever
/// B would reach N + 2) there are no interior points and the polygon is fanned by the
/// triangulation.
fn disk(spec: &str, n: u64, seed: u64) -> Result<Mesh> {
    let boundary_guess = ((2.15 * (n as f64).sqrt()).round() as u64).max(3);
    let boundary = if boundary_guess >= n + 2 { n + 2 } else { boundary_guess + (n + boundary_guess) % 2 };
    let interior = (n + 2 - boundary) / 2;

    let mut points: Vec<[f64; 2]> = (0..boundary)
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / boundary as f64;
            [angle.cos(), angle.sin()]
        })
        .collect();
    if interior > 0 {
        scatter_interior(&mut points, boundary, interior as usize, seed);
    }
    // Positions are f32: triangulate and orient the rounded points, so what we check is what we store.
    let positions: Vec<Vec3> = points.iter().map(|&[x, y]| Vec3::new(x as f32, y as f32, 0.0)).collect();
    let flat: Vec<delaunator::Point> =
        positions.iter().map(|p| delaunator::Point { x: f64::from(p.x), y: f64::from(p.y) }).collect();
    let triangulation = delaunator::triangulate(&flat);
    let mut triangles = Vec::with_capacity(triangulation.len());
    for t in triangulation.triangles.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| &flat[i]);
        let area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        let ids = [t[0] as u32, t[1] as u32, t[2] as u32];
        triangles.push(match area2 {
            a if a > 0.0 => ids,
            a if a < 0.0 => [ids[0], ids[2], ids[1]],
            _ => return Err(Error::input(spec, "the triangulation produced a degenerate triangle")),
        });
    }
    if triangles.len() as u64 != n {
        let got = triangles.len();
        return Err(Error::input(spec, format!("the triangulation produced {got} triangles instead of {n}")));
    }
    Mesh::new(spec, positions, triangles, VertexAttributes::default())
}

/// Appends `count` interior points to the `boundary` points on the unit circle already in
/// `points`, by seeded dart throwing with a minimum distance to every point so far.
fn scatter_interior(points: &mut Vec<[f64; 2]>, boundary: u64, count: usize, seed: u64) {
    // Stay a margin inside the boundary polygon, whose edges are cos(π/B) from the centre.
    let inner_edge = (std::f64::consts::PI / boundary as f64).cos();
    let hex_spacing = (2.0 * std::f64::consts::PI / (3f64.sqrt() * (count + boundary as usize) as f64)).sqrt();
    let mut min_distance = 0.65 * hex_spacing;
    let radius = inner_edge - 0.5 * min_distance;
    let mut grid = PointGrid::new(min_distance, points.len() + count);
    for (i, &p) in points.iter().enumerate() {
        grid.insert(i as u32, p);
    }
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let mut misses = 0;
    let target = points.len() + count;
    while points.len() < target {
        let r = radius * rng.random::<f64>().sqrt();
        let angle = std::f64::consts::TAU * rng.random::<f64>();
        let p = [r * angle.cos(), r * angle.sin()];
        if grid.any_within(p, min_distance, points) {
            misses += 1;
            if misses == 1000 {
                min_distance *= 0.9;
                misses = 0;
            }
            continue;
        }
        misses = 0;
        grid.insert(points.len() as u32, p);
        points.push(p);
    }
}

/// Points of [-1, 1]² bucketed in square cells at least `cell` wide, so that every point closer
/// than `cell` to a query lies in the 3×3 cells around it. Each cell is a linked list (`head`,
/// then `next` per point): two `u32`s per point and one per cell, however many points.
struct PointGrid {
    cells: usize,
    head: Vec<u32>,
    next: Vec<u32>,
}

impl PointGrid {
    const NONE: u32 = u32::MAX;

    fn new(cell: f64, capacity: usize) -> PointGrid {
        let cells = ((2.0 / cell).floor() as usize).max(1);
        PointGrid { cells, head: vec![Self::NONE; cells * cells], next: Vec::with_capacity(capacity) }
    }

    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let c = |v: f64| (((v + 1.0) * 0.5 * self.cells as f64) as usize).min(self.cells - 1);
        (c(p[0]), c(p[1]))
    }

    /// Adds point `i` (the next id: ids are 0, 1, 2, … in insertion order) at `p`.
    fn insert(&mut self, i: u32, p: [f64; 2]) {
        let (x, y) = self.cell_of(p);
        let cell = &mut self.head[y * self.cells + x];
        self.next.push(*cell);
        *cell = i;
    }

    /// Whether some inserted point (positions in `points`) is closer than `distance` to `p`;
    /// `distance` must not exceed the cell width.
    fn any_within(&self, p: [f64; 2], distance: f64, points: &[[f64; 2]]) -> bool {
        let (cx, cy) = self.cell_of(p);
        let last = self.cells - 1;
        for y in cy.saturating_sub(1)..=(cy + 1).min(last) {
            for x in cx.saturating_sub(1)..=(cx + 1).min(last) {
                let mut j = self.head[y * self.cells + x];
                while j != Self::NONE {
                    let q = points[j as usize];
                    if (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) < distance * distance {
                        return true;
                    }
                    j = self.next[j as usize];
                }
            }
        }
        false
    }
}

/// `sphere:N`, a closed geodesic sphere of about N triangles, as in Forsyth's vertex-cache tests
/// ("Sphere" is `sphere:20480`): each face of an icosahedron is split into f×f triangles, with
/// f = max(1, round(√(N/20))), and every vertex pushed out to the unit sphere. 20f² triangles
/// and 10f² + 2 shared vertices (closed, manifold), counter-clockwise seen from outside.
///
/// The icosahedron's 12 vertices are the normalised (0, ±1, ±φ), (±1, ±φ, 0), (±φ, 0, ±1) in that
/// order (signs − before +, first coordinate outer); its 20 faces are the vertex triples at
/// mutual edge length, in lexicographic order, each wound outward. Face [A, B, C] is subdivided
/// as points A + (B−A)·i/f + (C−A)·j/f for i + j ≤ f, drawn face by face, row by row (i outer, j
/// inner): for each (i, j) the "upward" triangle [(i,j), (i+1,j), (i,j+1)] then, if i + j < f − 1,
/// the "downward" one [(i+1,j), (i+1,j+1), (i,j+1)]. Vertices are numbered in order of first
/// use.
fn sphere(spec: &str, f: u64) -> Result<Mesh> {
    let f = f as u32;
    let (corners, faces) = icosahedron();
    // A point of a face is Σ weightₖ·cornerₖ / f with integer weights: keyed by its sorted
    // (corner, weight) pairs it is the same vertex on every face that shares it.
    let mut ids: HashMap<[(u32, u32); 3], u32> = HashMap::new();
    let mut positions = Vec::with_capacity(10 * (f as usize).pow(2) + 2);
    let mut vertex = |face: [u32; 3], i: u32, j: u32| -> u32 {
        let mut key = [(face[0], f - i - j), (face[1], i), (face[2], j)]
            .map(|(c, w)| if w == 0 { (u32::MAX, 0) } else { (c, w) });
        key.sort_unstable();
        *ids.entry(key).or_insert_with(|| {
            let sum: DVec3 =
                key.iter().filter(|&&(_, w)| w > 0).map(|&(c, w)| corners[c as usize] * f64::from(w)).sum();
            positions.push(sum.normalize().as_vec3());
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::with_capacity(20 * (f as usize).pow(2));
    for face in faces {
        for i in 0..f {
            for j in 0..f - i {
                triangles.push([vertex(face, i, j), vertex(face, i + 1, j), vertex(face, i, j + 1)]);
                if i + j + 1 < f {
                    triangles.push([vertex(face, i + 1, j), vertex(face, i + 1, j + 1), vertex(face, i, j + 1)]);
                }
            }
        }
    }
    Mesh::new(spec, positions, triangles, VertexAttributes::default())
}

/// The unit icosahedron: its 12 corners and its 20 faces, wound counter-clockwise from outside.
fn icosahedron() -> ([DVec3; 12], Vec<[u32; 3]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut corners = [DVec3::ZERO; 12];
    for (k, (s, t)) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)].into_iter().enumerate() {
        corners[k] = DVec3::new(0.0, s, t * phi);
        corners[4 + k] = DVec3::new(s, t * phi, 0.0);
        corners[8 + k] = DVec3::new(s * phi, 0.0, t);
    }
    // Unnormalised, neighbouring corners are exactly 2 apart and the others at least 2φ.
    let adjacent = |a: usize, b: usize| corners[a].distance(corners[b]) < 2.5;
    let mut faces = Vec::with_capacity(20);
    for a in 0..12 {
        for b in a + 1..12 {
            for c in b + 1..12 {
                if adjacent(a, b) && adjacent(b, c) && adjacent(a, c) {
                    let (pa, pb, pc) = (corners[a], corners[b], corners[c]);
                    let outward = (pb - pa).cross(pc - pa).dot(pa + pb + pc) > 0.0;
                    let (a, b, c) = (a as u32, b as u32, c as u32);
                    faces.push(if outward { [a, b, c] } else { [a, c, b] });
                }
            }
        }
    }
    (corners.map(DVec3::normalize), faces)
}

/// `helix:T`, the helix of Nehab et al. 2006, Fig. 5, whose turns occlude each other cyclically
/// (turn t hides turn t+1 from one side and is hidden by it from the other), so that no
/// view-independent cluster order is free of overdraw.
///
/// A closed tube of radius [`HELIX_TUBE_RADIUS`] (0.25), with a [`HELIX_SIDES`]-gon (12) cross
/// section, swept along the helix c(θ) = (R cos θ, R sin θ, P·θ/2π) for θ in 0..=2πT, with R =
/// [`HELIX_RADIUS`] (1) and pitch P = [`HELIX_PITCH`] (0.6): the tube's diameter (0.5) is most
/// of the pitch, so seen from the side each half-turn overlaps the turns above and below it,
/// yet consecutive turns never touch. It has S·T + 1 rings, S = [`HELIX_SEGMENTS_PER_TURN`] (48),
/// ring s at θ = 2πs/S with vertex `12s + k` at c(θ) + r(cos φₖ·u + sin φₖ·v), φₖ = 2πk/12,
/// u = (cos θ, sin θ, 0) pointing away from the z axis and v the unit vector ⟂ to u and to the
/// tangent with positive z. Two cap centres follow: vertex `12(S·T+1)` = c(0) and the next one
/// = c(2πT). Triangles: for each segment s (ring s to s+1) and side k, `[a_k, b_k, a_k+1]` and
/// `[a_k+1, b_k, b_k+1]` (a = ring s, b = ring s+1, k+1 modulo 12); then the start cap's fan
/// `[c(0), a_k, a_k+1]` over ring 0 and the end cap's fan `[c(2πT), b_k+1, b_k]` over the last
/// ring. That is 12(48T + 1) + 2 vertices and 1152T + 24 triangles, closed and wound outward.
fn helix(spec: &str, turns: u64) -> Result<Mesh> {
    let rings = (u64::from(HELIX_SEGMENTS_PER_TURN) * turns + 1) as u32;
    let sides = HELIX_SIDES;
    let (radius, rise) = (f64::from(HELIX_RADIUS), f64::from(HELIX_PITCH) / std::f64::consts::TAU);
    let centre = |theta: f64| DVec3::new(radius * theta.cos(), radius * theta.sin(), rise * theta);
    let angle_of_ring = |s: u32| std::f64::consts::TAU * f64::from(s) / f64::from(HELIX_SEGMENTS_PER_TURN);
    let mut positions = Vec::with_capacity((rings * sides + 2) as usize);
    for s in 0..rings {
        let theta = angle_of_ring(s);
        let u = DVec3::new(theta.cos(), theta.sin(), 0.0);
        // u × tangent, normalised: (rise·sin θ, −rise·cos θ, R)/|tangent|.
        let v = DVec3::new(rise * theta.sin(), -rise * theta.cos(), radius).normalize();
        for k in 0..sides {
            let phi = std::f64::consts::TAU * f64::from(k) / f64::from(sides);
            let p = centre(theta) + f64::from(HELIX_TUBE_RADIUS) * (phi.cos() * u + phi.sin() * v);
            positions.push(p.as_vec3());
        }
    }
    let (start, end) = (rings * sides, rings * sides + 1);
    positions.push(centre(0.0).as_vec3());
    positions.push(centre(angle_of_ring(rings - 1)).as_vec3());

    let at = |s: u32, k: u32| s * sides + k % sides;
    let mut triangles = Vec::with_capacity((2 * (rings - 1) * sides + 2 * sides) as usize);
    for s in 0..rings - 1 {
        for k in 0..sides {
            let (a0, a1, b0, b1) = (at(s, k), at(s, k + 1), at(s + 1, k), at(s + 1, k + 1));
            triangles.push([a0, b0, a1]);
            triangles.push([a1, b0, b1]);
        }
    }
    triangles.extend((0..sides).map(|k| [start, at(0, k), at(0, k + 1)]));
    triangles.extend((0..sides).map(|k| [end, at(rings - 1, k + 1), at(rings - 1, k)]));
    Mesh::new(spec, positions, triangles, VertexAttributes::default())
}

/// `layers:K`, the worst case for overdraw: K unit squares [0, 1]² stacked along z, layer i at
/// z = i (i = 0..K), all facing +z. Layer i has vertices 4i..4i+4 at (0,0), (1,0), (1,1), (0,1)
/// and triangles 2i = `[4i, 4i+1, 4i+2]` and 2i+1 = `[4i, 4i+2, 4i+3]`, counter-clockwise seen
/// from +z, drawn layer 0 first. Seen from +z, layer 0 is the farthest, so this order is back
/// to front: with depth test LESS and one sample per pixel every layer passes the test at every
/// covered pixel, and under a projection along −z (where all layers cover the same pixels) the
/// overdraw ratio (shaded samples / covered samples) is exactly K. Reversing the order gives 1.
fn layers(spec: &str, k: u64) -> Result<Mesh> {
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let positions = (0..k as u32).flat_map(|i| corners.map(|(x, y)| Vec3::new(x, y, i as f32))).collect();
    let triangles =
        (0..k as u32).flat_map(|i| [[4 * i, 4 * i + 1, 4 * i + 2], [4 * i, 4 * i + 2, 4 * i + 3]]).collect();
    Mesh::new(spec, positions, triangles, VertexAttributes::default())
}
