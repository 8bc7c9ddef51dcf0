//! Stable sorts of indices by `f64` keys in [`f64::total_cmp`]'s order, ties in index order: the
//! depth and distance sorts of `front-to-back`, `translucent-per-view` and `hs17`.
//!
//! Neither compares through the index: hs17's step 2 sorts every patch once per changed cluster
//! per round, and at λ 3 a patch is a triangle (786k on Xbot subdivided twice), where a stable
//! comparison sort of indices by their keys took a third of the run; `translucent-per-view` sorts
//! every triangle once per viewpoint, 162 times, where it took most of the method's time. Which
//! sort each uses was measured (Intel Xeon, `triorder eval`): a radix sort of (key, index, payload)
//! for hs17 (its buffers phase 4.8–5.1 s on that Xbot at λ 3, 5.9 s sorting the keys' ordered bits
//! with the index as integers); those integers, unstably sorted, for the depth sorts
//! (`translucent-per-view` on dragon_vrip_res2 0.9 s, 1.3–1.5 s by radix; the same on
//! sphere:800000, 3.0–3.2 s).

use super::Order;

/// The indices of `keyed` (key, payload) pairs sorted by increasing key, ties by index, each with
/// its payload: a radix sort (`radsort`: stable, so ties stay in index order, and it skips the
/// bytes every key shares).
pub(crate) fn sort_by_key(keyed: impl Iterator<Item = (f64, u32)>) -> Vec<(u32, u32)> {
    let mut entries: Vec<(f64, u32, u32)> = keyed.zip(0..).map(|((k, payload), i)| (k, i, payload)).collect();
    radsort::sort_by_key(&mut entries, |e| e.0);
    entries.into_iter().map(|(_, i, payload)| (i, payload)).collect()
}

/// The indices of `keys` by increasing key, ties in index order: an unstable sort of (key bits,
/// index) pairs, where the index breaks ties as a stable sort would.
pub(crate) fn by_increasing(keys: &[f64]) -> Order {
    let mut entries: Vec<(u64, u32)> = keys.iter().map(|&k| ordered_bits(k)).zip(0..).collect();
    entries.sort_unstable();
    entries.into_iter().map(|(_, i)| i).collect()
}

/// `x`'s bits, reordered so that unsigned comparison orders them as [`f64::total_cmp`] does.
fn ordered_bits(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 { !bits } else { bits | 1 << 63 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Keys with repeats, both zeros, both infinities and both NaNs.
    const KEYS: [f64; 11] = [3.5, -0.0, 0.0, -2.0, f64::INFINITY, 1e-300, -1e300, 3.5, f64::NAN, -f64::NAN, 0.0];

    fn comparison_sorted(keys: &[f64]) -> Vec<usize> {
        let mut expected: Vec<usize> = (0..keys.len()).collect();
        expected.sort_by(|&a, &b| keys[a].total_cmp(&keys[b]).then(a.cmp(&b)));
        expected
    }

    /// The radix keys order floats as `total_cmp` does, and the sort breaks ties by index.
    #[test]
    fn sorting_by_key_is_total_order_then_index() {
        let expected = comparison_sorted(&KEYS);
        let sorted = sort_by_key(KEYS.iter().map(|&k| (k, 0)).zip(100..).map(|((k, _), p)| (k, p)));
        assert_eq!(sorted.iter().map(|&(i, _)| i as usize).collect::<Vec<_>>(), expected);
        assert!(sorted.iter().all(|&(i, payload)| payload == 100 + i));
        assert_eq!(&expected[..3], &[9, 6, 3]);
    }

    /// The same on many keys with many ties, spread over several bytes of the radix.
    #[test]
    fn by_increasing_is_the_stable_comparison_sort() {
        let mut keys = KEYS.to_vec();
        keys.extend((0..5000u64).map(|i| ((i * 2_654_435_761) % 97) as f64 * 0.37 - 12.0));
        let sorted: Vec<usize> = by_increasing(&keys).into_iter().map(|i| i as usize).collect();
        assert_eq!(sorted, comparison_sorted(&keys));
    }
}
