//! What an ordering returns: index buffers, each a permutation of the triangles drawn in clusters,
//! and the table that picks one per draw. A static method returns one buffer used for every
//! frame from every view; keyframe- and view-dependent methods return several (Han & Sander 2017,
//! §3.3 "Runtime selection").
//!
//! The table is indexed by keyframe, polar angle θ and azimuth φ of the direction from the model's
//! (framed) centre to the eye. θ is measured from +Y, the up axis of glTF, in evenly spaced values
//! from 0 to π inclusive (the poles are cells of their own), and φ = atan2(z, x) in twice as many
//! values around the circle. A query rounds f, θ and φ to the nearest stored values, as the paper
//! does, so the choice costs a few arithmetic operations and one load. Each cell holds the buffer
//! of the optimization viewpoint nearest to the cell's direction ("we use values from the closest
//! original viewpoint when populating the table"). The angular step is a third of the spacing of
//! the viewpoints (at most [`MAX_STEP_DEGREES`]), so a query from a viewpoint's own direction
//! rounds to a cell that viewpoint fills: 5° for the paper's 162 viewpoints, 2.7° for 642.

use glam::Vec3;

use super::Order;

/// The coarsest angular step of a table: 10°.
pub const MAX_STEP_DEGREES: f32 = 10.0;

/// The runtime choice of index buffer by (keyframe, θ, φ).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lookup {
    frames: usize,
    /// θ samples from 0 to π inclusive; φ has `2 (polar − 1)` samples (one when `polar` is 1).
    polar: usize,
    /// `frames × polar × azimuth` buffer ids, frame-major.
    table: Vec<u16>,
}

impl Lookup {
    /// Every frame and direction uses buffer 0: what a single static order needs, for any number
    /// of frames (frames past the table's one clamp to it).
    pub fn uniform() -> Lookup {
        Lookup { frames: 1, polar: 1, table: vec![0] }
    }

    /// Frame `f` uses buffer `buffer_of_frame[f]` from every direction.
    pub fn per_frame(buffer_of_frame: &[u16]) -> Lookup {
        Lookup { frames: buffer_of_frame.len(), polar: 1, table: buffer_of_frame.to_vec() }
    }

    /// Fills every cell of every frame from the nearest of `viewpoints` (unit directions):
    /// `assignment[f * viewpoints.len() + v]` is the buffer frame `f` uses from viewpoint `v`.
    pub fn nearest(viewpoints: &[Vec3], assignment: &[u16]) -> Lookup {
        assert!(!viewpoints.is_empty() && assignment.len().is_multiple_of(viewpoints.len()));
        let frames = assignment.len() / viewpoints.len();
        // Mean angular spacing of n points spread over the sphere: √(4π / n).
        let spacing = (4.0 * std::f32::consts::PI / viewpoints.len() as f32).sqrt();
        let step = (spacing / 3.0).min(MAX_STEP_DEGREES.to_radians());
        // The smallest whole number of steps no longer than `step` (a hair of slack for rounding).
        let polar = (std::f32::consts::PI / step - 1e-4).ceil() as usize + 1;
        let nearest: Vec<usize> = cell_directions(polar)
            .map(|d| {
                (0..viewpoints.len()).max_by(|&a, &b| d.dot(viewpoints[a]).total_cmp(&d.dot(viewpoints[b]))).unwrap()
            })
            .collect();
        let table =
            (0..frames).flat_map(|f| nearest.iter().map(move |&v| assignment[f * viewpoints.len() + v])).collect();
        Lookup { frames, polar, table }
    }

    /// The buffer to draw keyframe `frame` with, seen from `direction` (centre → eye, any
    /// length; a zero direction reads as looking down from +Y). Frames past the end clamp.
    #[inline]
    pub fn buffer(&self, frame: usize, direction: Vec3) -> usize {
        let (polar, azimuth) = (self.polar, azimuth_steps(self.polar));
        let d = direction.normalize_or(Vec3::Y);
        let theta = d.y.clamp(-1.0, 1.0).acos() * ((polar - 1) as f32 / std::f32::consts::PI);
        let phi = d.z.atan2(d.x).rem_euclid(std::f32::consts::TAU) * (azimuth as f32 / std::f32::consts::TAU);
        let (i, j) = (theta.round() as usize, phi.round() as usize % azimuth);
        let f = frame.min(self.frames - 1);
        usize::from(self.table[(f * polar + i) * azimuth + j])
    }

    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Cells per keyframe: θ samples × φ samples.
    pub fn cells_per_frame(&self) -> usize {
        self.polar * azimuth_steps(self.polar)
    }

    /// Every cell's buffer id, frame-major, then θ, then φ.
    pub fn cells(&self) -> &[u16] {
        &self.table
    }
}

fn azimuth_steps(polar: usize) -> usize {
    (2 * (polar - 1)).max(1)
}

/// The unit direction of each (θ, φ) cell of a table with `polar` θ samples, θ-major.
fn cell_directions(polar: usize) -> impl Iterator<Item = Vec3> {
    let azimuth = azimuth_steps(polar);
    (0..polar).flat_map(move |i| {
        let theta = i as f32 * std::f32::consts::PI / (polar - 1).max(1) as f32;
        (0..azimuth).map(move |j| {
            let phi = j as f32 * std::f32::consts::TAU / azimuth as f32;
            Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        })
    })
}

/// A draw order made of clusters drawn one after another: cluster `i` is
/// `order[starts[i]..starts[i + 1]]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Clustered {
    pub order: Order,
    pub starts: Vec<usize>,
}

impl Clustered {
    /// An order that is one cluster.
    pub fn single(order: Order) -> Clustered {
        let starts = vec![0, order.len()];
        Clustered { order, starts }
    }

    /// The clusters drawn in the given sequence.
    pub fn concat<'a>(clusters: impl Iterator<Item = &'a [u32]>) -> Clustered {
        let mut starts = Vec::with_capacity(clusters.size_hint().0 + 1);
        starts.push(0);
        let mut order = Vec::new();
        for cluster in clusters {
            // A cluster of one triangle (every patch of Tipsify's at λ 3) is pushed: there a
            // `memcpy` call per cluster cost several times the copy.
            match cluster {
                [t] => order.push(*t),
                _ => order.extend_from_slice(cluster),
            }
            starts.push(order.len());
        }
        Clustered { order, starts }
    }

    pub fn cluster_count(&self) -> usize {
        self.starts.len() - 1
    }
}

/// What an ordering returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Orders {
    /// The index buffers, each a permutation of the triangles with the clusters it was built from
    /// (one cluster for methods without).
    pub buffers: Vec<Clustered>,
    /// Which buffer draws each (frame, view).
    pub lookup: Lookup,
    /// Optimization loop iterations (k-means rounds), for methods that iterate; with several
    /// independent optimizations (one per clip) the largest.
    pub iterations: Option<usize>,
    /// False when an iterative method stopped at its iteration cap rather than converging.
    pub converged: bool,
    /// Where the ordering's time went: `(phase, seconds)`, for methods that say.
    pub phases: Vec<(&'static str, f64)>,
    /// Seconds of work an earlier ordering of the same scene had done and this one reused
    /// ([`crate::mesh::scene::SharedWork`]), at what it cost then: added to the time the ordering
    /// is reported to take, so that it is the time it takes on its own.
    pub reused: f64,
}

impl Orders {
    /// The one buffer of a static method, or `None` when the orders have several.
    pub fn single(&self) -> Option<&Clustered> {
        match self.buffers.as_slice() {
            [one] => Some(one),
            _ => None,
        }
    }
}

/// One buffer, drawn for every frame from every direction.
impl From<Clustered> for Orders {
    fn from(buffer: Clustered) -> Orders {
        Orders {
            buffers: vec![buffer],
            lookup: Lookup::uniform(),
            iterations: None,
            converged: true,
            phases: vec![],
            reused: 0.0,
        }
    }
}

/// One buffer of one cluster.
impl From<Order> for Orders {
    fn from(order: Order) -> Orders {
        Clustered::single(order).into()
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
        for d in cell_directions(19) {
            assert_eq!([0, 1, 2].map(|f| lookup.buffer(f, d)), [3, 1, 2]);
        }
        assert_eq!(lookup.cells_per_frame(), 1);
        assert!(Lookup::uniform().cells().iter().all(|&b| b == 0));
        assert_eq!(Lookup::uniform().buffer(7, Vec3::X), 0, "any frame");
    }

    #[test]
    fn the_step_follows_the_viewpoint_spacing() {
        let step = |n: usize| {
            let lookup = Lookup::nearest(&vec![Vec3::Y; n], &vec![0; n]);
            180.0 / (lookup.polar - 1) as f32
        };
        assert_eq!(step(12), 10.0);
        assert!((5.0..5.4).contains(&step(162)), "{}", step(162));
        assert!((2.5..2.8).contains(&step(642)), "{}", step(642));
    }

    #[test]
    fn cell_directions_are_unit_and_the_lookup_finds_each_cell_again() {
        let polar = 19;
        let dirs: Vec<Vec3> = cell_directions(polar).collect();
        let azimuth = azimuth_steps(polar);
        assert_eq!(dirs.len(), polar * azimuth);
        // A table whose cell i holds i (poles excepted, where every φ is the same direction).
        let table: Vec<u16> = (0..dirs.len() as u16).collect();
        let lookup = Lookup { frames: 1, polar, table };
        for (i, d) in dirs.iter().enumerate().skip(azimuth).take(dirs.len() - 2 * azimuth) {
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert_eq!(lookup.buffer(0, *d), i);
        }
    }
}
