//! Step 8 of `cheap-cuts` (its module lists every step): each run of pieces, as steps 6 and 7
//! left them, redrawn by Forsyth's greedy over its own triangles, from the cache the runs before
//! it left, and kept where that misses no more in any costed FIFO than the run's slice of the
//! cache order.
//!
//! A run's slice was drawn by a greedy that saw the whole mesh: its border vertices counted the
//! live triangles of the pieces around it, which are now drawn elsewhere, so the greedy left
//! them for later, and its first triangles were chosen for the cache its predecessor in the cache
//! order had filled, which the cut has emptied. Redrawn over its own triangles (valences count
//! the run's triangles only), the greedy finishes those vertices inside the run, and it starts
//! from the cache that is really there: empty for almost every run, as the run drawn before is
//! seldom a neighbour on the surface (scratch counters at `23ae6af`: 1 of 222 runs on Xbot, 2 of
//! 243 on BrainStem, 17 of 118 on bun_zipper and 15 of 153 on horse start with one of their own
//! vertices cached), so it starts at its best-scoring triangle, on its border; otherwise on a
//! vertex the two share. Each run keeps the redrawn order
//! where it misses no more than the slice, given what the runs before it left there, in every
//! FIFO the cuts were costed in: the `cache` entries, and Intel's 128 when `far` holds the cuts
//! to it (the redrawn one on 189 of 222 runs on Xbot, 67 of 118 on bun_zipper, at the defaults).
//! The runs' sequence, and with it the overdraw graph's order, is unchanged. Judged by the first
//! FIFO alone, the redraw had given back a little of what `far` bought under Intel's (bun_zipper
//! at `far=0.005`: 1.4% above the best ordering instead of 1.3%, rocker-arm 1.7% at OVR 1.113
//! instead of 1.4% at 1.072).

use crate::mesh::topology::Csr;
use crate::order::Clustered;
use crate::order::forsyth::{Redraw, Scores};

/// `runs`, a partition of the triangles in drawing order (each run a slice of the cache order),
/// each either as it is or redrawn by Forsyth's greedy at LRU `lru` from the cache the runs before
/// it left: redrawn where that misses no more in any FIFO of `caches` sizes; one cluster per run.
pub(super) fn redraw_runs(
    triangles: &[[u32; 3]],
    vertex_triangles: &Csr,
    runs: &[&[u32]],
    lru: usize,
    caches: &[u32],
) -> Clustered {
    let in_order = runs.concat();
    let mut redraw = Redraw::new(triangles, vertex_triangles, &in_order, lru, Scores::Tuned);
    let mut fifos: Vec<Fifo> = caches.iter().map(|&size| Fifo::new(triangles, vertex_triangles.rows(), size)).collect();
    let mut order = Vec::with_capacity(in_order.len());
    let mut starts = Vec::with_capacity(runs.len() + 1);
    let mut redrawn = Vec::new();
    for &run in runs {
        starts.push(order.len());
        redrawn.clear();
        redraw.redraw(run, &order, &mut redrawn);
        // In each FIFO the slice is tried and taken back, then the redrawn order tried and left
        // in: it is kept more often, and taken back only where the slice wins.
        let mut redrawn_wins = true;
        for fifo in &mut fifos {
            let slice = fifo.trial(run);
            fifo.undo();
            redrawn_wins &= fifo.trial(&redrawn) <= slice;
        }
        let kept = if redrawn_wins { &redrawn[..] } else { run };
        for fifo in &mut fifos {
            if !redrawn_wins {
                fifo.undo();
                fifo.trial(run);
            }
            fifo.commit();
        }
        order.extend_from_slice(kept);
    }
    starts.push(order.len());
    Clustered { order, starts }
}

/// A FIFO vertex cache that can try a sequence of triangles and take it back.
struct Fifo<'a> {
    triangles: &'a [[u32; 3]],
    /// Per vertex, the miss count before its last load: it is cached while at most `size` misses
    /// (its own included) have been counted since. The count starts past `size`, so that a stamp
    /// of 0 reads as never loaded, with no separate test.
    stamp: Vec<u32>,
    misses: u32,
    size: u32,
    /// The stamps the trial in progress overwrote, and the count before it: what
    /// [`Fifo::undo`] puts back.
    undo: Vec<(u32, u32)>,
    before: u32,
}

impl<'a> Fifo<'a> {
    fn new(triangles: &'a [[u32; 3]], vertex_count: usize, size: u32) -> Fifo<'a> {
        Fifo { triangles, stamp: vec![0; vertex_count], misses: size + 1, size, undo: Vec::new(), before: size + 1 }
    }

    /// Draws `order`'s triangles (ids into `triangles`) as a trial, to be kept by
    /// [`Fifo::commit`] or taken back by [`Fifo::undo`]; the misses it took.
    fn trial(&mut self, order: &[u32]) -> u32 {
        self.before = self.misses;
        for &t in order {
            for v in self.triangles[t as usize] {
                let stamp = &mut self.stamp[v as usize];
                if self.misses - *stamp > self.size {
                    self.undo.push((v, *stamp));
                    *stamp = self.misses;
                    self.misses += 1;
                }
            }
        }
        self.misses - self.before
    }

    fn undo(&mut self) {
        for (v, stamp) in self.undo.drain(..).rev() {
            self.stamp[v as usize] = stamp;
        }
        self.misses = self.before;
    }

    fn commit(&mut self) {
        self.undo.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::cache::{CacheModel, simulate};
    use crate::mesh::procedural;
    use crate::mesh::topology::vertex_triangles;

    /// The trial FIFO counts what the project's simulator counts, and a trial leaves no trace.
    #[test]
    fn the_fifo_counts_what_the_simulator_counts() {
        let mesh = procedural::generate("sphere:3000", 5).unwrap().unwrap();
        let order: Vec<u32> = (0..mesh.triangle_count() as u32).rev().collect();
        for size in [3, 16, 32] {
            let mut fifo = Fifo::new(&mesh.triangles, mesh.vertex_count(), size);
            let (head, tail) = order.split_at(order.len() / 3);
            fifo.trial(head);
            fifo.commit();
            let tried = fifo.trial(tail);
            fifo.undo();
            assert_eq!(fifo.trial(tail), tried, "size {size}: taking a trial back left a trace");
            fifo.commit();
            let expected = simulate(CacheModel::Fifo(size), &mesh.triangles_in_order(&order), mesh.vertex_count());
            assert_eq!(u64::from(fifo.misses - size - 1), expected.misses, "size {size}");
        }
    }

    /// Every run comes back with its own triangles, each once, the runs in their sequence; and no
    /// run's kept order misses more in the FIFO than its slice of the cache order would have.
    #[test]
    fn runs_keep_their_triangles_and_their_sequence() {
        let mesh = procedural::generate("sphere:4000", 9).unwrap().unwrap();
        let n = mesh.triangle_count() as u32;
        // Runs cut from an order with gaps between them, drawn in a shuffled sequence.
        let order: Vec<u32> = (0..n).collect();
        let bounds = [0, 500, 1300, 1350, 2600, n as usize];
        let pieces: Vec<&[u32]> = bounds.windows(2).map(|w| &order[w[0]..w[1]]).collect();
        let runs: Vec<&[u32]> = [3, 0, 4, 1, 2].iter().map(|&i| pieces[i]).collect();
        let out = redraw_runs(&mesh.triangles, &vertex_triangles(&mesh), &runs, 20, &[16]);
        assert_eq!(out.starts.len(), runs.len() + 1);
        for (w, run) in out.starts.windows(2).zip(&runs) {
            let mut got = out.order[w[0]..w[1]].to_vec();
            got.sort_unstable();
            assert_eq!(got, run.to_vec());
        }
        // Step by step, no run's kept order misses more than its slice would have.
        let mut fifo = Fifo::new(&mesh.triangles, mesh.vertex_count(), 16);
        for (w, run) in out.starts.windows(2).zip(&runs) {
            let kept = &out.order[w[0]..w[1]];
            let slice = fifo.trial(run);
            fifo.undo();
            assert!(fifo.trial(kept) <= slice);
            fifo.commit();
        }
    }
}
