//! Z-order (Morton) keys of points in a grid over a box: a key that keeps nearby points near each
//! other in a sort, for the CPU raster's triangle locality and the patch graph's regrouping of
//! scattered triangles. Z-order rather than Hilbert: a key is a few shifts, against about a
//! thousand instructions for [`crate::order::curves::hilbert`]'s index, and either keeps a cell's
//! points together.

use glam::Vec3;

/// Cells along the box's longest side: 2¹⁰, so that three axes fit a 30-bit key.
const CELLS: f32 = 1023.0;

/// A grid of cubic cells over a box, its longest side cut into 1024.
#[derive(Clone, Copy)]
pub struct ZOrder {
    lo: Vec3,
    scale: f32,
}

impl ZOrder {
    /// The grid over the box `lo..=hi`.
    pub fn over(lo: Vec3, hi: Vec3) -> ZOrder {
        ZOrder { lo, scale: CELLS / (hi - lo).max_element().max(f32::MIN_POSITIVE) }
    }

    /// The key of `p`'s cell (a point outside the box takes the nearest cell): x in the lowest
    /// bit of each three, then y, then z.
    pub fn key(&self, p: Vec3) -> u32 {
        let q = ((p - self.lo) * self.scale).clamp(Vec3::ZERO, Vec3::splat(CELLS));
        spread(q.x as u32) | spread(q.y as u32) << 1 | spread(q.z as u32) << 2
    }
}

/// The low 10 bits of `x` spread to every third bit (one axis of the key).
fn spread(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    (x | x << 2) & 0x0924_9249
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Along one axis the key grows with the coordinate; the corners of the box are the first
    /// and last keys, and each axis has its own bit.
    #[test]
    fn keys_interleave_the_cells() {
        let grid = ZOrder::over(Vec3::ZERO, Vec3::splat(1023.0));
        assert_eq!(grid.key(Vec3::ZERO), 0);
        assert_eq!(grid.key(Vec3::splat(1023.0)), (1 << 30) - 1);
        assert_eq!([Vec3::X, Vec3::Y, Vec3::Z].map(|axis| grid.key(axis)), [1, 2, 4]);
        let along: Vec<u32> = (0..1024).map(|x| grid.key(Vec3::new(x as f32, 5.0, 9.0))).collect();
        assert!(along.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(grid.key(Vec3::splat(-5.0)), 0, "outside the box: the nearest cell");
    }
}
