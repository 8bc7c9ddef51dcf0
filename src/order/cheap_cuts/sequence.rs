//! Steps 6 and 7 of `cheap-cuts` (its module lists every step): the pieces' order from the
//! feedback arc set improved by moving whole runs of pieces, never putting more of the overdraw
//! graph's weight backward. Step 6 draws pieces that follow each other in the cache order together
//! again (so those cuts cost no hits); step 7 moves each such run to where its arcs put the least
//! weight backward.

use std::ops::RangeInclusive;

use crate::order::nehab::overdraw_graph::Arc;

/// The pieces' order from the feedback arc set, each piece's place in it, and the graph's arcs as
/// a matrix of signed weights. Its two passes (steps 6 and 7) never raise the weight the order
/// puts backward, the overdraw the graph predicts.
pub(super) struct Sequence {
    pub(super) sequence: Vec<u32>,
    position: Vec<usize>,
    /// Row `p`, entry `q`: the weight of the arcs between pieces `p` and `q`, signed, positive
    /// where they want `p` first. Dense, as the graph is: the patch graph joins most pairs of
    /// pieces (Xbot: 33k arcs among 282 pieces), and the passes sum a run's arcs over every other
    /// place, which reads a row in the sequence's order instead of scattering each arc to the
    /// place its piece has now. With neighbour lists, steps 6 and 7 took 3.6 ms on Xbot and 7.3 ms
    /// on BrainStem; with the matrix 1.8 and 3.2 ms, the same orders (scratch timers, medians of
    /// 9, AMD EPYC). The graph was a matrix of this size already while it was built, but this one
    /// lives beside the list of arcs: at the default 512 pieces it is 2 MB; at the most, 4096, it
    /// is 134 MB, and cheap-cuts' peak memory on happy_buddha_100k at `budget=1,min=1,
    /// clusters=4096` rose from 227 to 346 MB (1.40 to 1.28 s).
    weight: Vec<i64>,
    /// Scratch for [`Sequence::move_block`]: a block's rows summed.
    summed: Vec<i64>,
}

impl Sequence {
    pub(super) fn new(sequence: Vec<u32>, arcs: &[Arc]) -> Sequence {
        let n = sequence.len();
        let mut weight = vec![0; n * n];
        for arc in arcs {
            let (from, to, w) = (arc.from as usize, arc.to as usize, arc.weight as i64);
            weight[from * n + to] += w;
            weight[to * n + from] -= w;
        }
        let mut sequence =
            Sequence { position: vec![0; n], sequence, weight, summed: Vec::with_capacity(n) };
        sequence.place();
        sequence
    }

    /// Piece `p`'s row of signed weights.
    fn row(&self, p: u32) -> &[i64] {
        let n = self.sequence.len();
        &self.weight[p as usize * n..(p as usize + 1) * n]
    }

    fn place(&mut self) {
        for (i, &piece) in self.sequence.iter().enumerate() {
            self.position[piece as usize] = i;
        }
    }

    /// Step 6: pieces that follow each other in the cache order put back together wherever that
    /// breaks no more of the graph's arcs.
    ///
    /// A cut is priced as a cold start, but a piece drawn right after its predecessor in the cache
    /// order starts with that predecessor's vertices cached and loses nothing. The greedy order
    /// rarely keeps such successions even where no arc joins the two pieces (neighbours on the
    /// surface seldom overlap in a view): on the five tuning models it kept 3–7 of 63–277 while
    /// 17–249 of them had no arc. So, for each piece in cache order, the run of pieces already
    /// drawn together that it ends and the run its successor starts are joined, moving one run to
    /// the other (whichever move puts less arc weight backward; the successor's run on a tie), when
    /// the move puts no more weight backward than before; passes repeat until none moves.
    pub(super) fn keep_successions(&mut self) {
        let pieces = self.sequence.len() as u32;
        // Every move joins a succession and breaks none (whole runs move), so this ends.
        loop {
            let mut moved = false;
            for c in 0..pieces.saturating_sub(1) {
                moved |= self.join(c);
            }
            if !moved {
                return;
            }
        }
    }

    /// Whether the pieces at `i` and `i + 1` follow each other in the cache order.
    fn succession(&self, i: usize) -> bool {
        self.sequence[i + 1] == self.sequence[i] + 1
    }

    /// The change in backward weight when the pieces at `block` move to the other side of those
    /// at `across`: every pair between the two flips; `later` when the block moves after them.
    fn flip(&self, block: RangeInclusive<usize>, across: RangeInclusive<usize>, later: bool) -> i64 {
        let across = &self.sequence[across];
        let flipped = block
            .map(|i| {
                let row = self.row(self.sequence[i]);
                across.iter().map(|&other| row[other as usize]).sum::<i64>()
            })
            .sum::<i64>();
        if later { flipped } else { -flipped }
    }

    /// Joins the run of pieces ending with `c` and the run starting with `c + 1`, if one of the
    /// two moves to the other without putting more arc weight backward; whether it moved.
    fn join(&mut self, c: u32) -> bool {
        let (end, next) = (self.position[c as usize], self.position[c as usize + 1]);
        if next == end + 1 {
            return false;
        }
        let n = self.sequence.len();
        // A = [a, end] (the run ending with c), B = [next, b] (the run starting with c + 1).
        let a = (0..end).rev().take_while(|&i| self.succession(i)).last().unwrap_or(end);
        let b = (next..n - 1).take_while(|&i| self.succession(i)).last().map_or(next, |i| i + 1);
        let (change, block, to) = if next > end {
            // A, gap, B: B moves back behind A, or A on before B, across the gap.
            let b_back = self.flip(next..=b, end + 1..=next - 1, false);
            let a_on = self.flip(a..=end, end + 1..=next - 1, true);
            if b_back <= a_on { (b_back, next..=b, end + 1) } else { (a_on, a..=end, next) }
        } else {
            // B, gap, A: B moves on behind A across the gap and A, or A back before B across B
            // and the gap.
            let b_on = self.flip(next..=b, b + 1..=end, true);
            let a_back = self.flip(a..=end, next..=a - 1, false);
            if b_on <= a_back { (b_on, next..=b, end + 1) } else { (a_back, a..=end, next) }
        };
        if change > 0 {
            return false;
        }
        let len = block.end() - block.start() + 1;
        self.move_to(block.clone(), if to > *block.start() { to - len } else { to });
        true
    }

    /// Step 7: each run of pieces that follow each other in the cache order moved as one to the
    /// place where its arcs put the least weight backward, while any move lowers it. A run moves
    /// whole and never into another, so no succession step 6 kept is broken (a move can make
    /// one).
    pub(super) fn move_runs(&mut self) {
        let mut moved = true;
        while moved {
            moved = false;
            let mut next = 0;
            while next < self.sequence.len() {
                // The whole run at `next`: a move before it may have shifted a run's tail here.
                let (mut first, mut last) = (next, next);
                while first > 0 && self.succession(first - 1) {
                    first -= 1;
                }
                while last + 1 < self.sequence.len() && self.succession(last) {
                    last += 1;
                }
                moved |= self.move_block(first, last);
                next = last + 1;
            }
        }
    }

    /// Moves the pieces at `a..=b` together to where their arcs put the least weight backward, if
    /// that is less than where they are; whether they moved. With them taken out, placing them
    /// before the others' place `g` puts backward their arcs from the pieces before `g` and to
    /// the pieces after `g`: from one place to the next that changes by the signed weight of the
    /// arcs passed.
    fn move_block(&mut self, a: usize, b: usize) -> bool {
        let mut summed = std::mem::take(&mut self.summed);
        let row = if a == b {
            self.row(self.sequence[a])
        } else {
            summed.clear();
            summed.extend_from_slice(self.row(self.sequence[a]));
            for &piece in &self.sequence[a + 1..=b] {
                summed.iter_mut().zip(self.row(piece)).for_each(|(sum, w)| *sum += w);
            }
            &summed
        };
        // Place `g` puts the block before the others' `g`th piece; the places between two pieces
        // that follow each other are skipped: going there would break a succession. Where the
        // block is now, place `a`, it puts `here` backward.
        let len = b - a + 1;
        let others = self.sequence.len() - len;
        let other = |place: usize| self.sequence[if place < a { place } else { place + len }];
        let (mut best, mut to, mut sum, mut here) = (0, 0, 0, 0);
        for (place, &piece) in self.sequence[..a].iter().chain(&self.sequence[b + 1..]).enumerate() {
            sum += row[piece as usize];
            if place + 1 == a {
                here = sum;
            }
            if sum < best && (place + 1 == others || other(place + 1) != piece + 1) {
                (best, to) = (sum, place + 1);
            }
        }
        self.summed = summed;
        if best >= here {
            return false;
        }
        self.move_to(a..=b, to);
        true
    }

    /// Moves the pieces at `block` so that they start at `to` once moved (a place among the
    /// others), keeping every piece's place current.
    fn move_to(&mut self, block: RangeInclusive<usize>, to: usize) {
        let (a, b) = (*block.start(), *block.end());
        let len = b - a + 1;
        let range = if to < a {
            self.sequence[to..=b].rotate_right(len);
            to..=b
        } else {
            self.sequence[a..to + len].rotate_left(len);
            a..=to + len - 1
        };
        for i in range {
            self.position[self.sequence[i] as usize] = i;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::order::nehab::feedback_arc_set::backward_weight;

    fn arc(from: u32, to: u32, weight: u64) -> Arc {
        Arc { from, to, weight }
    }

    fn joined(sequence: Vec<u32>, arcs: &[Arc]) -> Vec<u32> {
        let mut sequence = Sequence::new(sequence, arcs);
        sequence.keep_successions();
        sequence.sequence
    }

    fn successions(sequence: &[u32]) -> usize {
        sequence.windows(2).filter(|w| w[1] == w[0] + 1).count()
    }

    /// With no arcs every piece follows its predecessor again; an arc that a join would break
    /// stops that join, and the other run moves instead where it can.
    #[test]
    fn successions_are_joined_unless_an_arc_objects() {
        assert_eq!(joined(vec![2, 0, 3, 1], &[]), [0, 1, 2, 3]);
        // 2 must precede 1: joining 0–1 moves 0 (crossing nothing it has an arc with), and 1–2
        // cannot be joined either way without drawing 1 before 2.
        assert_eq!(joined(vec![0, 2, 1], &[arc(2, 1, 5)]), [2, 0, 1]);
    }

    /// Shuffled sequences of 2–15 pieces with random arcs between about half of the pairs.
    fn random_graphs() -> Vec<(Vec<u32>, Vec<Arc>)> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |bound: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % bound
        };
        (0..200)
            .map(|_| {
                let n = 2 + next(14) as u32;
                let mut sequence: Vec<u32> = (0..n).collect();
                for i in (1..sequence.len()).rev() {
                    sequence.swap(i, next(i as u64 + 1) as usize);
                }
                let mut arcs = Vec::new();
                for a in 0..n {
                    for b in a + 1..n {
                        match next(4) {
                            0 => arcs.push(arc(a, b, 1 + next(9))),
                            1 => arcs.push(arc(b, a, 1 + next(9))),
                            _ => {}
                        }
                    }
                }
                (sequence, arcs)
            })
            .collect()
    }

    fn is_permutation(sequence: &[u32]) -> bool {
        let mut sorted = sequence.to_vec();
        sorted.sort_unstable();
        sorted == (0..sequence.len() as u32).collect::<Vec<_>>()
    }

    /// On random graphs the result is a permutation, the backward weight never grows and no
    /// succession is lost.
    #[test]
    fn joining_never_puts_more_weight_backward() {
        for (sequence, arcs) in random_graphs() {
            let joined = joined(sequence.clone(), &arcs);
            assert!(is_permutation(&joined));
            assert!(backward_weight(&joined, &arcs) <= backward_weight(&sequence, &arcs), "{sequence:?} {arcs:?}");
            assert!(successions(&joined) >= successions(&sequence));
        }
    }

    /// After the joins, moving runs gives a permutation, puts no more weight backward, keeps every
    /// succession, and leaves no run that a move of its own would lower the weight by (checked
    /// against every place the run could go without splitting another).
    #[test]
    fn moving_runs_leaves_no_run_a_move_would_improve() {
        let mut moved_any = false;
        for (sequence, arcs) in random_graphs() {
            let mut state = Sequence::new(sequence, &arcs);
            state.keep_successions();
            let joined = state.sequence.clone();
            state.move_runs();
            let moved = state.sequence;
            moved_any |= moved != joined;
            assert!(is_permutation(&moved));
            let weight = backward_weight(&moved, &arcs);
            assert!(weight <= backward_weight(&joined, &arcs), "{joined:?} {arcs:?}");
            assert!(successions(&moved) >= successions(&joined), "{joined:?} -> {moved:?} {arcs:?}");
            let mut first = 0;
            while first < moved.len() {
                let mut last = first;
                while last + 1 < moved.len() && moved[last + 1] == moved[last] + 1 {
                    last += 1;
                }
                let mut rest = moved.clone();
                let run: Vec<u32> = rest.drain(first..=last).collect();
                for to in 0..=rest.len() {
                    if 0 < to && to < rest.len() && rest[to] == rest[to - 1] + 1 {
                        continue;
                    }
                    let mut other = rest.clone();
                    other.splice(to..to, run.iter().copied());
                    assert!(backward_weight(&other, &arcs) >= weight, "{moved:?}: run at {first} to {to}, {arcs:?}");
                }
                first = last + 1;
            }
        }
        assert!(moved_any, "no run ever moved: the test tests nothing");
    }
}
