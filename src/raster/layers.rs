//! One view's fragments grouped by pixel and sorted by depth, so that the depth test of *any*
//! draw order of the same triangles is replayed without rasterizing again.
//!
//! Under a LESS test into a buffer cleared to 1.0, a fragment passes when its depth is below 1.0
//! and below that of every fragment drawn before it at its pixel. With a pixel's fragments
//! sorted nearest first, a draw order's passes there are counted in one scan: a fragment passes
//! when it is drawn before every nearer one, and of fragments at one depth only the first drawn
//! can pass. A pixel with one fragment passes it in every order, so only the pixels reached by
//! two or more (the contested ones) are kept; the rest are counted once.
//!
//! Rasterizing costs a pass over every triangle; a replay costs a pass over the contested
//! fragments, far fewer on a dense mesh at the images' sizes. `hs17` replays every buffer of
//! every k-means round on its nodes, and the CPU backend counts every method's order of one
//! scene from one rasterization per view ([`super::cpu::CpuRaster`]'s `count_orders`).

use rayon::prelude::*;

use super::ViewCounts;
use super::cpu::Fragment;

/// The order-dependent part of one view: its contested pixels, each with its triangles nearest
/// first; and the pixels with one fragment, which pass it in any order.
#[derive(Debug, Default)]
pub struct DepthLayers {
    /// Per contested pixel, its triangles by increasing depth; [`TIED`] marks a triangle at the
    /// same depth as the one before it.
    triangles: Vec<u32>,
    /// Contested pixel `i`'s entries are `triangles[starts[i]..starts[i + 1]]`.
    starts: Vec<u32>,
    /// Pixels reached by exactly one fragment that can pass (depth below 1.0).
    singles: u64,
}

/// Flags a triangle id in [`DepthLayers::triangles`] (ids stay below 2³¹: meshes are far smaller).
const TIED: u32 = 1 << 31;

/// One thread's scratch for [`DepthLayers::of`], kept from view to view: the pixels' slots, the
/// contested pixels' list, and the fragments grouped by pixel.
#[derive(Default)]
pub struct Sorting {
    slots: Vec<u32>,
    contested: Vec<u32>,
    by_pixel: Vec<(f32, u32)>,
}

impl DepthLayers {
    /// The memory the layers hold, in bytes.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<DepthLayers>() + 4 * (self.triangles.capacity() + self.starts.capacity())
    }

    /// Groups `fragments` (of an image `res` pixels square) by pixel, a counting sort over the
    /// run of pixels they reach with scratch in `sorting`, and keeps the contested pixels, each
    /// sorted by depth. Fragments at depth 1.0 or beyond (or NaN) can never pass and are left
    /// out.
    pub fn of(fragments: &[Fragment], res: u32, sorting: &mut Sorting) -> DepthLayers {
        debug_assert!(fragments.iter().all(|f| (f.pixel as usize) < res as usize * res as usize));
        let can_pass = |f: &&Fragment| f.depth < 1.0;
        let mut layers = DepthLayers { starts: vec![0], ..DepthLayers::default() };
        // Only the run of pixels between the first and the last reached: a mesh seen whole
        // fills part of the image, and the passes below are over that run, not every pixel.
        let (first, last) =
            fragments.iter().filter(can_pass).fold((u32::MAX, 0), |(lo, hi), f| (lo.min(f.pixel), hi.max(f.pixel)));
        if first > last {
            return layers;
        }
        let (first, span) = (first as usize, (last - first) as usize + 1);
        let Sorting { slots, contested, by_pixel } = sorting;
        slots.clear();
        slots.resize(span + 1, 0);
        for f in fragments.iter().filter(can_pass) {
            slots[f.pixel as usize - first + 1] += 1;
        }
        // Grown, never cleared: every entry read below is written first.
        if contested.len() <= span {
            contested.resize(span + 1, 0);
        }
        // Pixel i's start, from a running sum in a register: summing in place, each slot would
        // wait on the store of the one before (12% of building a view's layers). The same pass
        // counts the pixels with one fragment and lists those with more, without a branch: a
        // branch on each pixel's count (0, 1 or more, in no pattern) and the single count kept
        // in memory were half of this function's time on RobotExpressive (perf). Slot i counts
        // pixel i − 1 (slot 0 counts nothing), and a contested pixel is listed by its slot.
        let (mut running, mut singles, mut listed) = (0, 0, 0);
        for (i, slot) in slots.iter_mut().enumerate() {
            let count = *slot;
            singles += u64::from(count == 1);
            contested[listed] = i as u32;
            listed += usize::from(count >= 2);
            running += count;
            *slot = running;
        }
        let contested = &contested[..listed];
        layers.singles = singles;
        // Scattered with each pixel's start as its cursor, which leaves it at the pixel's end;
        // grown, never cleared, as every entry up to the total is written.
        let total = slots[span] as usize;
        if by_pixel.len() < total {
            by_pixel.resize(total, (0.0, 0));
        }
        for f in fragments.iter().filter(can_pass) {
            let slot = &mut slots[f.pixel as usize - first];
            by_pixel[*slot as usize] = (f.depth, f.triangle);
            *slot += 1;
        }
        layers.starts.reserve(contested.len());
        for &i in contested {
            // Pixel i − 1's entries end where its cursor stopped, and start where pixel i − 2's did.
            let (from, to) = (if i >= 2 { slots[i as usize - 2] } else { 0 }, slots[i as usize - 1]);
            let entries = &mut by_pixel[from as usize..to as usize];
            let nearest_first = |a: &(f32, u32), b: &(f32, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
            if let [a, b] = entries {
                // Two fragments: one compare, not a call to the sort.
                if nearest_first(a, b).is_gt() {
                    std::mem::swap(a, b);
                }
            } else {
                entries.sort_unstable_by(nearest_first);
            }
            for (j, &(depth, t)) in entries.iter().enumerate() {
                let tied = j > 0 && entries[j - 1].0 == depth;
                layers.triangles.push(if tied { t | TIED } else { t });
            }
            layers.starts.push(layers.triangles.len() as u32);
        }
        layers
    }

    /// Fragments passing the depth test over the contested pixels when triangle t is drawn
    /// `rank[t]`-th.
    pub fn contested_passes(&self, rank: &[u32]) -> u32 {
        self.replay(|t| [rank[t]])[0]
    }

    /// [`DepthLayers::contested_passes`] of every order of `ranks`, in order: one scan of the
    /// layers per [`LANES`] orders, with one memory access for a triangle's ranks in all of them.
    /// Replaying many orders on many views (hs17's k buffers on every node, every round; every
    /// method of a run on every view) is bound by those accesses.
    pub fn contested_passes_all(&self, ranks: &LaneRanks) -> Vec<u32> {
        let mut passed = Vec::with_capacity(ranks.orders);
        for (chunk, lanes) in ranks.chunks.iter().enumerate() {
            let used = (ranks.orders - chunk * LANES).min(LANES);
            passed.extend_from_slice(&self.replay_lanes(lanes)[..used]);
        }
        passed
    }

    /// [`DepthLayers::counts`] of each order of `ranks` (each order's plain ranks, [`ranks`]):
    /// [`LANES`] orders a scan, a triangle's rank in each gathered from its own array. For the
    /// view-dependent buffers a view picks (one per hs17 method, say), which no [`LaneRanks`]
    /// holds side by side: scanned one by one, each read every entry and took its branch.
    pub fn counts_each(&self, ranks: &[&[u32]]) -> Vec<ViewCounts> {
        let mut passed = Vec::with_capacity(ranks.len());
        for chunk in ranks.chunks(LANES) {
            match chunk {
                [one] => passed.push(self.contested_passes(one)),
                _ => {
                    let last = chunk.len() - 1;
                    let lanes = self.replay_wide(|t| std::array::from_fn(|l| chunk[l.min(last)][t]));
                    passed.extend_from_slice(&lanes[..chunk.len()]);
                }
            }
        }
        passed.into_iter().map(|p| self.with_contested(p)).collect()
    }

    /// [`DepthLayers::replay`] of one chunk of [`LaneRanks`].
    fn replay_lanes(&self, lanes: &[[u32; LANES]]) -> [u32; LANES] {
        self.replay_wide(|t| lanes[t])
    }

    /// [`DepthLayers::replay`] of [`LANES`] orders, in AVX2 where the processor has it. The
    /// scan's work per fragment is an unsigned minimum and compare of eight lanes: one
    /// instruction each in AVX2, a dozen in the SSE2 that baseline x86-64 compiles to (it has no
    /// unsigned compare, so every lane's sign is flipped first), where the scan was a sixth of a
    /// full `reproduce`. Integer operations either way, so the counts are the same.
    fn replay_wide(&self, rank: impl Fn(usize) -> [u32; LANES]) -> [u32; LANES] {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, checked just above.
            return unsafe { self.replay_avx2(rank) };
        }
        self.replay(rank)
    }

    /// [`DepthLayers::replay`] of [`LANES`] orders compiled for AVX2 (the scan is inlined here).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn replay_avx2(&self, rank: impl Fn(usize) -> [u32; LANES]) -> [u32; LANES] {
        self.replay(rank)
    }

    /// The depth test of `L` orders over the contested pixels, `rank(t)` giving triangle t's rank
    /// in each. Always inlined, so that [`DepthLayers::replay_avx2`] compiles it for AVX2.
    #[inline(always)]
    fn replay<const L: usize>(&self, rank: impl Fn(usize) -> [u32; L]) -> [u32; L] {
        let mut passed = [0u32; L];
        for w in self.starts.windows(2) {
            let entries = &self.triangles[w[0] as usize..w[1] as usize];
            // The earliest draw among strictly nearer fragments, and among those at this depth.
            let (mut nearer, mut group) = ([u32::MAX; L], [u32::MAX; L]);
            for &entry in entries {
                let r = rank((entry & !TIED) as usize);
                if entry & TIED == 0 {
                    for l in 0..L {
                        passed[l] += u32::from(group[l] < nearer[l]);
                        nearer[l] = nearer[l].min(group[l]);
                        group[l] = r[l];
                    }
                } else {
                    for l in 0..L {
                        group[l] = group[l].min(r[l]);
                    }
                }
            }
            for l in 0..L {
                passed[l] += u32::from(group[l] < nearer[l]);
            }
        }
        passed
    }

    /// Each contested pixel's fragments, nearest first, as runs of triangles at one depth.
    pub fn contested(&self) -> impl Iterator<Item = Contested<'_>> {
        self.starts.windows(2).map(|w| Contested { entries: &self.triangles[w[0] as usize..w[1] as usize] })
    }

    /// The view's counts when triangle t is drawn `rank[t]`-th: what drawing them in that order
    /// into a cleared depth buffer counts.
    pub fn counts(&self, rank: &[u32]) -> ViewCounts {
        self.with_contested(self.contested_passes(rank))
    }

    /// [`DepthLayers::counts`] of every order of `ranks`, in order.
    pub fn counts_all(&self, ranks: &LaneRanks) -> Vec<ViewCounts> {
        self.contested_passes_all(ranks).into_iter().map(|p| self.with_contested(p)).collect()
    }

    /// The view's counts when `contested` fragments pass over its contested pixels.
    fn with_contested(&self, contested: u32) -> ViewCounts {
        ViewCounts {
            covered: self.singles + (self.starts.len() - 1) as u64,
            passed: self.singles + u64::from(contested),
        }
    }
}

/// One contested pixel of a [`DepthLayers`]: its fragments' triangles, nearest first.
#[derive(Clone, Copy)]
pub struct Contested<'a> {
    entries: &'a [u32],
}

impl<'a> Contested<'a> {
    /// Every fragment's triangle, nearest first (ties in their sorted order).
    pub fn triangles(self) -> impl Iterator<Item = u32> + 'a {
        self.entries.iter().map(|&e| e & !TIED)
    }

    /// Per fragment, nearest first: its triangle and the index of its depth among the pixel's
    /// distinct depths (equal for fragments at one depth, rising with depth).
    pub fn by_depth(self) -> impl Iterator<Item = (u32, u32)> + 'a {
        self.entries.iter().scan(0u32, |depth, &e| {
            *depth += u32::from(e & TIED == 0);
            Some((e & !TIED, *depth - 1))
        })
    }
}

/// Orders replayed together by one scan of [`DepthLayers::contested_passes_all`].
const LANES: usize = 8;

/// Several permutations of the same triangles as ranks side by side, [`LANES`] orders a chunk:
/// `chunks[c][t][i]` is triangle t's rank in order `c × LANES + i`; lanes past the last order
/// repeat the chunk's last.
pub struct LaneRanks {
    chunks: Vec<Vec<[u32; LANES]>>,
    orders: usize,
}

/// Triangles per parallel piece when [`LaneRanks::new`] interleaves the ranks.
const INTERLEAVE_PIECE: usize = 1 << 14;

impl LaneRanks {
    /// Each order's ranks are scattered into a plain array of their own, the orders in
    /// parallel, then interleaved in parallel over the triangles. Scattering straight into the
    /// interleaved rows wrote one 32-byte row at random per triangle and lane, one order after
    /// another: on hs17's 786k-triangle Xbot that was 5.7 s of a run's serial time.
    pub fn new(orders: &[&[u32]]) -> LaneRanks {
        let plain: Vec<Vec<u32>> = orders.par_iter().map(|o| ranks(o)).collect();
        let chunks = plain
            .chunks(LANES)
            .map(|chunk| {
                let mut rank = vec![[0; LANES]; chunk[0].len()];
                rank.par_chunks_mut(INTERLEAVE_PIECE).enumerate().for_each(|(piece, rows)| {
                    let (start, len) = (piece * INTERLEAVE_PIECE, rows.len());
                    for (lane, column) in (0..LANES).map(|lane| (lane, &chunk[lane.min(chunk.len() - 1)])) {
                        for (row, &r) in rows.iter_mut().zip(&column[start..start + len]) {
                            row[lane] = r;
                        }
                    }
                });
                rank
            })
            .collect();
        LaneRanks { chunks, orders: orders.len() }
    }
}

/// Per triangle, its position in `order` (a permutation of `0..order.len()`).
pub fn ranks(order: &[u32]) -> Vec<u32> {
    let mut rank = vec![0; order.len()];
    for (i, &t) in order.iter().enumerate() {
        rank[t as usize] = i as u32;
    }
    rank
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 scan counts what the portable one counts, on layers with ties, singles and
    /// pixels of many fragments, for chunks of orders that use every lane and fewer (a processor
    /// without AVX2 never runs that scan, and checks the one it dispatches to).
    #[test]
    fn the_avx2_replay_counts_as_the_portable_one() {
        let (n, res) = (500u32, 16u32);
        let mut seed = 7u64;
        let mut next = |m: u32| {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 33) % u64::from(m)) as u32
        };
        let fragments: Vec<Fragment> = (0..4000)
            .map(|_| Fragment {
                pixel: next(res * res),
                triangle: next(n),
                depth: [0.25, 0.5, 0.75, 1.0][next(4) as usize] + next(3) as f32 * 0.01,
                passed: false,
            })
            .collect();
        let layers = DepthLayers::of(&fragments, res, &mut Sorting::default());
        assert!(layers.triangles.iter().any(|&e| e & TIED != 0), "the test needs ties");
        let orders: Vec<Vec<u32>> =
            (0..11u32).map(|s| (0..n).map(|i| (i * (2 * s + 1) + 3 * s) % n).collect()).collect();
        let slices: Vec<&[u32]> = orders.iter().map(|o| &o[..]).collect();
        let lanes = LaneRanks::new(&slices);
        let portable: Vec<u32> = lanes.chunks.iter().flat_map(|c| layers.replay(|t| c[t])).collect();
        let dispatched: Vec<u32> = lanes.chunks.iter().flat_map(|c| layers.replay_lanes(c)).collect();
        assert_eq!(dispatched, portable);
        let plain: Vec<Vec<u32>> = orders.iter().map(|o| ranks(o)).collect();
        let one_by_one: Vec<u32> = plain.iter().map(|r| layers.contested_passes(r)).collect();
        assert_eq!(layers.contested_passes_all(&lanes), one_by_one);
        // Gathered from plain ranks, in chunks of eight, three and one.
        let plain: Vec<&[u32]> = plain.iter().map(|r| &r[..]).collect();
        let each: Vec<ViewCounts> = one_by_one.iter().map(|&p| layers.with_contested(p)).collect();
        assert_eq!(layers.counts_each(&plain), each);
        assert_eq!(layers.counts_each(&plain[..1]), each[..1]);
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: checked just above.
            let avx2: Vec<u32> = lanes.chunks.iter().flat_map(|c| unsafe { layers.replay_avx2(|t| c[t]) }).collect();
            assert_eq!(avx2, portable);
        }
    }

    /// Every lane holds its order's ranks, across pieces of the interleaving and across chunks
    /// of [`LANES`] orders; lanes past the last order repeat the chunk's last.
    #[test]
    fn lane_ranks_are_each_orders_ranks() {
        let n = 2 * INTERLEAVE_PIECE as u32 + 123;
        let orders: Vec<Vec<u32>> = (0..11u64)
            .map(|s| (0..n).map(|i| ((u64::from(i) * 7919 + s * 104_729) % u64::from(n)) as u32).collect())
            .collect();
        let slices: Vec<&[u32]> = orders.iter().map(|o| &o[..]).collect();
        let lanes = LaneRanks::new(&slices);
        assert_eq!((lanes.orders, lanes.chunks.len()), (11, 2));
        for (o, order) in orders.iter().enumerate() {
            let plain = ranks(order);
            for lane in (o % LANES..LANES).take(if o == 10 { LANES - 2 } else { 1 }) {
                let column: Vec<u32> = lanes.chunks[o / LANES].iter().map(|row| row[lane]).collect();
                assert_eq!(column, plain, "order {o}, lane {lane}");
            }
        }
    }
}
