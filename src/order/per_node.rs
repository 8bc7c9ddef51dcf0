//! Orders that depend on the keyframe and the view: several index buffers and the table that picks
//! one per draw (Han & Sander 2017, §3.3 "Runtime selection").
//!
//! The table is indexed by keyframe, polar angle θ and azimuth φ of the direction from the model's
//! (framed) centre to the eye. θ is measured from +Y, the up axis of glTF, in [`POLAR_STEPS`]
//! values from 0 to π inclusive (the poles are cells of their own), and φ = atan2(z, x) in
//! [`AZIMUTH_STEPS`] values around the circle. A query rounds f, θ and φ to the nearest stored
//! values, as the paper does, so the choice costs a few arithmetic operations and one load. Each
//! cell holds the buffer of the optimization viewpoint nearest to the cell's direction ("we use
//! values from the closest original viewpoint when populating the table"). With 10° steps the
//! cells are finer than the 17° spacing of the 162 icosahedron viewpoints the paper optimizes for.

use glam::Vec3;

use super::Order;

/// Polar-angle samples from 0 to π inclusive: 10° apart.
pub const POLAR_STEPS: usize = 19;
/// Azimuth samples around the circle: 10° apart.
pub const AZIMUTH_STEPS: usize = 36;

/// The runtime choice of index buffer by (keyframe, θ, φ).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lookup {
    frames: usize,
    /// `frames × POLAR_STEPS × AZIMUTH_STEPS` buffer ids, frame-major.
    table: Vec<u16>,
}

impl Lookup {
    /// Every (frame, direction) uses buffer 0: what a single static order needs.
    pub fn uniform(frames: usize) -> Lookup {
        Lookup { frames, table: vec![0; frames * POLAR_STEPS * AZIMUTH_STEPS] }
    }

    /// Frame `f` uses buffer `buffer_of_frame[f]` from every direction.
    pub fn per_frame(buffer_of_frame: &[u16]) -> Lookup {
        let cells = POLAR_STEPS * AZIMUTH_STEPS;
        Lookup {
            frames: buffer_of_frame.len(),
            table: buffer_of_frame.iter().flat_map(|&b| std::iter::repeat_n(b, cells)).collect(),
        }
    }

    /// Fills every cell of every frame from the nearest of `viewpoints` (unit directions):
    /// `assignment[f * viewpoints.len() + v]` is the buffer frame `f` uses from viewpoint `v`.
    pub fn nearest(viewpoints: &[Vec3], assignment: &[u16]) -> Lookup {
        assert!(!viewpoints.is_empty() && assignment.len().is_multiple_of(viewpoints.len()));
        let frames = assignment.len() / viewpoints.len();
        let nearest: Vec<usize> = cell_directions()
            .map(|d| {
                (0..viewpoints.len()).max_by(|&a, &b| d.dot(viewpoints[a]).total_cmp(&d.dot(viewpoints[b]))).unwrap()
            })
            .collect();
        let table =
            (0..frames).flat_map(|f| nearest.iter().map(move |&v| assignment[f * viewpoints.len() + v])).collect();
        Lookup { frames, table }
    }

    /// The buffer to draw keyframe `frame` with, seen from `direction` (centre → eye, any
    /// length; a zero direction reads as looking down from +Y). Frames past the end clamp.
    #[inline]
    pub fn buffer(&self, frame: usize, direction: Vec3) -> usize {
        let d = direction.normalize_or(Vec3::Y);
        let polar = d.y.clamp(-1.0, 1.0).acos() * ((POLAR_STEPS - 1) as f32 / std::f32::consts::PI);
        let azimuth = d.z.atan2(d.x).rem_euclid(std::f32::consts::TAU) * (AZIMUTH_STEPS as f32 / std::f32::consts::TAU);
        let (i, j) = (polar.round() as usize, azimuth.round() as usize % AZIMUTH_STEPS);
        let f = frame.min(self.frames - 1);
        usize::from(self.table[(f * POLAR_STEPS + i) * AZIMUTH_STEPS + j])
    }

    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Every cell's buffer id, frame-major, then θ, then φ.
    pub fn cells(&self) -> &[u16] {
        &self.table
    }
}

/// The unit direction of each (θ, φ) cell, θ-major.
pub fn cell_directions() -> impl Iterator<Item = Vec3> {
    (0..POLAR_STEPS).flat_map(|i| {
        let theta = i as f32 * std::f32::consts::PI / (POLAR_STEPS - 1) as f32;
        (0..AZIMUTH_STEPS).map(move |j| {
            let phi = j as f32 * std::f32::consts::TAU / AZIMUTH_STEPS as f32;
            Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        })
    })
}

/// What a keyframe- and view-dependent method returns; a static method is one buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeOrders {
    /// The index buffers, each a permutation of the triangles.
    pub buffers: Vec<Order>,
    pub lookup: Lookup,
    /// Optimization loop iterations (k-means rounds), for methods that iterate; with several
    /// independent optimizations (one per clip) the largest.
    pub iterations: Option<usize>,
    /// False when an iterative method stopped at its iteration cap rather than converging.
    pub converged: bool,
    /// Where the ordering's time went: `(phase, seconds)`, for methods that say.
    pub phases: Vec<(&'static str, f64)>,
}

impl NodeOrders {
    /// One buffer used for all `frames` keyframes from every direction.
    pub fn single(order: Order, frames: usize) -> NodeOrders {
        NodeOrders {
            buffers: vec![order],
            lookup: Lookup::uniform(frames),
            iterations: None,
            converged: true,
            phases: vec![],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_rounds_to_the_nearest_cell() {
        let viewpoints = [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::NEG_Z];
        // Two frames: frame 0 uses buffer v for viewpoint v, frame 1 uses buffer 7 everywhere.
        let assignment: Vec<u16> = (0..6).chain([7; 6]).collect();
        let lookup = Lookup::nearest(&viewpoints, &assignment);
        assert_eq!(lookup.frames(), 2);
        for (v, &d) in viewpoints.iter().enumerate() {
            assert_eq!(lookup.buffer(0, d * 5.0), v, "{d}");
            assert_eq!(lookup.buffer(0, (d + Vec3::splat(0.1)).normalize()), v, "{d} nudged");
            assert_eq!(lookup.buffer(1, d), 7);
            assert_eq!(lookup.buffer(9, d), 7, "frames past the end clamp");
        }
        assert_eq!(lookup.buffer(0, Vec3::ZERO), 0, "a zero direction reads as +Y");
        // Just below the φ = 2π seam rounds to φ = 0 (+X).
        assert_eq!(lookup.buffer(0, Vec3::new(1.0, 0.0, -0.01)), 2);
        assert!(lookup.cells().iter().all(|&b| b < 8));
    }

    #[test]
    fn per_frame_and_uniform_tables() {
        let lookup = Lookup::per_frame(&[3, 1, 2]);
        for d in cell_directions() {
            assert_eq!([0, 1, 2].map(|f| lookup.buffer(f, d)), [3, 1, 2]);
        }
        assert!(Lookup::uniform(4).cells().iter().all(|&b| b == 0));
    }

    #[test]
    fn cell_directions_are_unit_and_the_lookup_finds_each_cell_again() {
        let dirs: Vec<Vec3> = cell_directions().collect();
        assert_eq!(dirs.len(), POLAR_STEPS * AZIMUTH_STEPS);
        // A table whose cell i holds i (poles excepted, where every φ is the same direction).
        let table: Vec<u16> = (0..dirs.len() as u16).collect();
        let lookup = Lookup { frames: 1, table };
        for (i, d) in dirs.iter().enumerate().skip(AZIMUTH_STEPS).take(dirs.len() - 2 * AZIMUTH_STEPS) {
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert_eq!(lookup.buffer(0, *d), i);
        }
    }
}
