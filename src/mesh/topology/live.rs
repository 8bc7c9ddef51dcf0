//! Per-vertex lists of the triangles an ordering has not emitted yet, for orderings that grow
//! fans and strips vertex by vertex (`hoppe`, `kcache`).

use super::{Csr, NONE};

/// Each mesh vertex's triangles not yet emitted, compacted lazily: an emitted triangle is
/// dropped (swap-remove) the first time a scan meets it, so over a whole run the removals cost
/// O(F) and a scan costs what is still there. Keeps high-valence vertices ("hubs": a fan centre
/// of 10⁵ triangles) from making every scan through them O(valence) again and again.
pub struct LiveLists {
    offsets: Vec<u32>,
    len: Vec<u32>,
    items: Vec<u32>,
}

impl LiveLists {
    pub fn new(vertex_triangles: &Csr) -> LiveLists {
        let offsets = vertex_triangles.offsets().to_vec();
        let len = offsets.windows(2).map(|w| w[1] - w[0]).collect();
        LiveLists { offsets, len, items: vertex_triangles.items().to_vec() }
    }

    /// Entries still listed for `v` (an upper bound on its remaining triangles).
    pub fn len(&self, v: u32) -> usize {
        self.len[v as usize] as usize
    }

    /// Up to `limit` remaining triangles of `v` (`done` tells emitted ones, which are dropped).
    pub fn live(&mut self, v: u32, limit: usize, done: impl Fn(u32) -> bool) -> &[u32] {
        let base = self.offsets[v as usize] as usize;
        let mut len = self.len[v as usize] as usize;
        let mut i = 0;
        while i < len && i < limit {
            if done(self.items[base + i]) {
                len -= 1;
                self.items[base + i] = self.items[base + len];
            } else {
                i += 1;
            }
        }
        self.len[v as usize] = len as u32;
        &self.items[base..base + i]
    }

    /// Into `out`, sorted: the remaining triangles using `w` whose vertices are all `cached`,
    /// right after `w` was pushed into a FIFO holding `ring`. Scans either `w`'s list or those
    /// of the other cached vertices (keeping the triangles that use `w`), whichever is shorter.
    pub fn completed_by(
        &mut self,
        w: u32,
        ring: &[u32],
        triangles: &[[u32; 3]],
        done: impl Fn(u32) -> bool,
        cached: impl Fn(u32) -> bool,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let others = ring.iter().filter(|&&u| u != NONE && u != w).map(|&u| self.len(u)).sum::<usize>();
        if self.len(w) <= others {
            for &t in self.live(w, usize::MAX, &done) {
                if triangles[t as usize].iter().all(|&x| cached(x)) {
                    out.push(t);
                }
            }
        } else {
            for &u in ring.iter().filter(|&&u| u != NONE && u != w) {
                for &t in self.live(u, usize::MAX, &done) {
                    let tri = triangles[t as usize];
                    if tri.contains(&w) && tri.iter().all(|&x| cached(x)) {
                        out.push(t);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}
