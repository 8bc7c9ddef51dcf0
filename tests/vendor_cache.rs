//! The GPU vendors' cache models (`nvidia`, `amd`, `intel`) against the numbers published for
//! real GPUs: Kapoulkine, "Optimal grid rendering is not optimal" (2017), measured vertex-shader
//! invocations of a 100×100 quad grid on NVIDIA, AMD and Intel GPUs in four orders, for "cache
//! sizes" c from 3 to 200: striped (columns of c − 2 quads, row by row), the same with a row of
//! degenerate triangles that loads each strip's first row ("optimal", Castaño's order), Tipsify
//! (meshoptimizer's `optimizeVertexCacheFifo(c)`) and meshoptimizer's `optimizeVertexCache`. The
//! post quotes ATVR = invocations ÷ 10,201 vertices at a few points; each test below checks one.
//! Kerbl et al. 2018 measured the batch sizes with an index buffer that repeats one triangle:
//! the step test checks those. Run with `--nocapture` to see every number beside the published one.

use triorder::measure::cache::{CacheModel, simulate};
use triorder::measure::vendor::Vendor;

const GRID: u32 = 100;
const VERTICES: usize = ((GRID + 1) * (GRID + 1)) as usize;

/// The quads of columns `x0..x1`, row by row, two triangles each; with `load_row`, first a
/// degenerate triangle per column that loads the strip's top row.
fn strip(out: &mut Vec<[u32; 3]>, x0: u32, x1: u32, load_row: bool) {
    if load_row {
        out.extend((x0..x1).map(|x| [x, x, x + 1]));
    }
    let id = |y: u32, x: u32| (GRID + 1) * y + x;
    for y in 0..GRID {
        for x in x0..x1 {
            out.push([id(y, x), id(y + 1, x), id(y, x + 1)]);
            out.push([id(y, x + 1), id(y + 1, x), id(y + 1, x + 1)]);
        }
    }
}

/// The grid in vertical strips narrow enough for a cache of `c` to hold a strip's row and the
/// next: split at `x0 + c − 2` until fewer than `c` vertex columns remain. `optimal` adds the
/// degenerate row where a strip's two rows would not fit otherwise (2·quads + 1 > c).
fn striped(c: u32, optimal: bool) -> Vec<[u32; 3]> {
    fn split(out: &mut Vec<[u32; 3]>, x0: u32, x1: u32, c: u32, optimal: bool) {
        if x1 - x0 + 1 < c {
            strip(out, x0, x1, optimal && 2 * (x1 - x0) + 1 > c);
        } else {
            split(out, x0, x0 + c - 2, c, optimal);
            split(out, x0 + c - 2, x1, c, optimal);
        }
    }
    let mut out = Vec::new();
    split(&mut out, 0, GRID, c, optimal);
    out
}

/// The plain grid (one strip) reordered by `reorder` (meshoptimizer's optimizers).
fn reordered(reorder: impl Fn(&[u32]) -> Vec<u32>) -> Vec<[u32; 3]> {
    let mut plain = Vec::new();
    strip(&mut plain, 0, GRID, false);
    let flat: Vec<u32> = plain.iter().flatten().copied().collect();
    reorder(&flat).chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}

fn tipsify(c: u32) -> Vec<[u32; 3]> {
    reordered(|flat| meshopt::optimize_vertex_cache_fifo(flat, VERTICES, c))
}

/// Invocations ÷ grid vertices, as the post reports.
fn atvr(vendor: Vendor, triangles: &[[u32; 3]]) -> f64 {
    simulate(CacheModel::Vendor(vendor), triangles, VERTICES).misses as f64 / VERTICES as f64
}

/// The cache size in `sizes` whose order gives the lowest ATVR, and that ATVR.
fn best(vendor: Vendor, sizes: std::ops::RangeInclusive<u32>, order: impl Fn(u32) -> Vec<[u32; 3]>) -> (u32, f64) {
    sizes.map(|c| (c, atvr(vendor, &order(c)))).min_by(|a, b| a.1.total_cmp(&b.1)).unwrap()
}

#[test]
fn nvidia_reproduces_the_published_grid_numbers() {
    // "Striped is best at cache size 6, ATVR 1.53."
    let (c, value) = best(Vendor::Nvidia, 3..=40, |c| striped(c, false));
    eprintln!("nvidia: striped best at c = {c}, ATVR {value:.3} (published: c = 6, 1.53)");
    assert_eq!(c, 6);
    assert!((value - 1.53).abs() < 0.005, "{value}");
    // "Striped and optimal both go above 2 from cache size 11."
    for optimal in [false, true] {
        let value = atvr(Vendor::Nvidia, &striped(11, optimal));
        eprintln!(
            "nvidia: {} at c = 11, ATVR {value:.3} (published: above 2)",
            if optimal { "optimal" } else { "striped" }
        );
        assert!(value > 2.0, "{value}");
    }
    // "Tipsify is best at cache size 14, ATVR 1.60." meshoptimizer's Tipsify has changed since
    // 2017, so the order is not the post's: the place of the optimum is checked, not its value.
    let (c, value) = best(Vendor::Nvidia, 3..=40, tipsify);
    eprintln!("nvidia: tipsify best at c = {c}, ATVR {value:.3} (published: c = 14, 1.60)");
    assert_eq!(c, 14);
}

/// Kerbl et al. 2018 found the batch sizes by drawing one triangle T times: NVIDIA shades it
/// again every 32 triangles (96 indices), AMD every 128 (384 indices); an Intel GPU with a FIFO
/// never does.
#[test]
fn batches_restart_where_the_step_measurements_say() {
    let invocations = |vendor: Vendor, t: usize| simulate(CacheModel::Vendor(vendor), &vec![[0, 1, 2]; t], 3).misses;
    assert_eq!([32, 33, 64, 65].map(|t| invocations(Vendor::Nvidia, t)), [3, 6, 6, 9]);
    assert_eq!([128, 129, 256, 257].map(|t| invocations(Vendor::Amd, t)), [3, 6, 6, 9]);
    assert_eq!([1, 2000].map(|t| invocations(Vendor::Intel, t)), [3, 3]);
}

/// The AMD model does not reproduce the post's AMD numbers: it puts the striped optimum at
/// c = 9 with ATVR 1.27 where the GPU gave c = 8 and 1.21, and Tipsify's at c = 14 with 1.33
/// where the GPU gave c = 16 and 1.25 (paper-figures/README.md says so). Kerbl et al. measured a
/// Radeon R7 200, the post an unnamed AMD GPU; AMD does not document its policy. This test keeps
/// the gap in sight: it fails if the model moves, so the documented numbers stay true.
#[test]
fn amd_misses_the_published_grid_numbers_by_the_documented_amount() {
    let (c, value) = best(Vendor::Amd, 3..=40, |c| striped(c, false));
    eprintln!("amd: striped best at c = {c}, ATVR {value:.3} (published: c = 8, 1.21)");
    let (tc, tvalue) = best(Vendor::Amd, 3..=40, tipsify);
    eprintln!("amd: tipsify best at c = {tc}, ATVR {tvalue:.3} (published: c = 16, 1.25)");
    assert_eq!((c, format!("{value:.2}")), (9, "1.27".to_string()));
    assert_eq!(tc, 14);
}

#[test]
fn intel_reproduces_the_published_grid_numbers() {
    // "The optimal order reaches ATVR 1."
    let value = atvr(Vendor::Intel, &striped(128, true));
    eprintln!("intel: optimal at c = 128, ATVR {value:.4} (published: 1.0)");
    assert!((value - 1.0).abs() < 1e-9, "{value}");
    // "Striped breaks down at cache size 66."
    let (at65, at66) = (atvr(Vendor::Intel, &striped(65, false)), atvr(Vendor::Intel, &striped(66, false)));
    eprintln!("intel: striped at c = 65 and 66, ATVR {at65:.3} and {at66:.3} (published: breaks down at 66)");
    assert!(at65 < 1.05 && at66 > 1.5, "{at65} {at66}");
    // "Tipsify reaches 1.007 at cache size 128": today's Tipsify gives another order (see the
    // NVIDIA test), so this one is shown, not checked.
    let value = atvr(Vendor::Intel, &tipsify(128));
    eprintln!("intel: tipsify at c = 128, ATVR {value:.4} (published: 1.007)");
}
