//! The median of a sample, one definition for every crate: the middle
//! value of an odd count, the mean of the two middle values of an even one
//! ([`median_in_place`]), or the upper of the two ([`upper_median_in_place`],
//! always one of the values).

/// Median of `v` (reordered in place; `None` when empty): the middle value
/// of an odd count, the mean of the two middle values of an even count.
/// Values are ordered by [`f64::total_cmp`]; callers pass finite values.
/// `O(n)` by selection, not a sort.
pub fn median_in_place(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let n = v.len();
    let (below, &mut hi, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        return Some(hi);
    }
    let lo = below.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some(0.5 * (lo + hi))
}

/// The upper median of `v` (reordered in place; `None` when empty): the
/// value of rank `⌊n/2⌋` (0-based) by [`f64::total_cmp`], the middle value
/// of an odd count and the upper of the two middle values of an even one —
/// always one of the values. The EM spike test's robust centre and spread
/// (`aeromag_em::detection::impulse`) take it: its threshold was set by
/// measurements with this statistic.
pub fn upper_median_in_place(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let m = v.len() / 2;
    Some(*v.select_nth_unstable_by(m, f64::total_cmp).1)
}

#[cfg(test)]
mod tests {
    use super::{median_in_place, upper_median_in_place};

    #[test]
    fn median_of_odd_even_and_empty_counts() {
        assert_eq!(median_in_place(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median_in_place(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median_in_place(&mut [7.0]), Some(7.0));
        assert_eq!(median_in_place(&mut []), None);
        assert_eq!(upper_median_in_place(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(upper_median_in_place(&mut [4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(upper_median_in_place(&mut []), None);
    }
}
