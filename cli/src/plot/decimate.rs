//! Reducing long series to what one pixel column can show, without hiding spikes.

use std::ops::Range;

/// Indices (ascending) of the points worth drawing when `x_px` (horizontal position in pixels)
/// and `y` (any unit) are drawn as one line at one-pixel resolution. Each run of consecutive
/// points falling in the same pixel column (`floor(x_px)`) keeps its first, lowest, highest and
/// last point, in input order, so spikes stay visible and the line joins the next column where
/// it really does. The first and last points are always kept; a series of `n` points sorted by
/// `x` spanning `w` columns keeps at most `4 w`. Unsorted input is handled (columns then repeat).
/// Only the common length of the two slices is used; values are expected finite (split the
/// series at NaN/inf points first).
pub fn decimate_min_max(x_px: &[f64], y: &[f64]) -> Vec<usize> {
    let n = x_px.len().min(y.len());
    let column = |i: usize| x_px[i].floor();
    let mut keep = Vec::new();
    let mut start = 0;
    while start < n {
        let col = column(start);
        let (mut low, mut high) = (start, start);
        let mut end = start + 1;
        while end < n && column(end) == col {
            if y[end] < y[low] {
                low = end;
            }
            if y[end] > y[high] {
                high = end;
            }
            end += 1;
        }
        let mut group = [start, low, high, end - 1];
        group.sort_unstable();
        for i in group {
            if keep.last() != Some(&i) {
                keep.push(i);
            }
        }
        start = end;
    }
    keep
}

/// Splits the common length of `x` and `y` into maximal runs of points where both are finite
/// (and, with `positive_only`, both positive, for log axes). Returns the runs and the number of
/// points left out.
pub(crate) fn finite_runs(x: &[f64], y: &[f64], positive_only: bool) -> (Vec<Range<usize>>, usize) {
    let usable = |v: f64| v.is_finite() && (!positive_only || v > 0.0);
    let n = x.len().min(y.len());
    let mut runs = Vec::new();
    let mut skipped = 0;
    let mut start = None;
    for i in 0..n {
        if usable(x[i]) && usable(y[i]) {
            start.get_or_insert(i);
        } else {
            skipped += 1;
            if let Some(s) = start.take() {
                runs.push(s..i);
            }
        }
    }
    if let Some(s) = start {
        runs.push(s..n);
    }
    (runs, skipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_extremes_first_and_last() {
        // 100 000 points over 500 px: slow sine, plus one-sample spikes.
        let n = 100_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64 * 500.0 / n as f64).collect();
        let mut y: Vec<f64> = (0..n).map(|i| (i as f64 * 1e-4).sin()).collect();
        y[12_345] = 9.0;
        y[77_777] = -9.0;
        let keep = decimate_min_max(&x, &y);
        assert!(keep.len() <= 4 * 500, "{}", keep.len());
        assert!(keep.len() >= 2 * 500);
        assert_eq!(keep.first(), Some(&0));
        assert_eq!(keep.last(), Some(&(n - 1)));
        assert!(keep.contains(&12_345) && keep.contains(&77_777));
        assert!(keep.windows(2).all(|w| w[0] < w[1]));
        // Every column's own minimum and maximum survive.
        for col in 0..500 {
            let in_col: Vec<usize> = (0..n).filter(|&i| x[i].floor() as usize == col).collect();
            let kept: Vec<f64> = keep
                .iter()
                .filter(|i| in_col.contains(i))
                .map(|&i| y[i])
                .collect();
            let max = in_col.iter().map(|&i| y[i]).fold(f64::MIN, f64::max);
            let min = in_col.iter().map(|&i| y[i]).fold(f64::MAX, f64::min);
            assert!(kept.contains(&max) && kept.contains(&min), "column {col}");
            if col > 20 {
                break; // the full scan is quadratic; twenty columns make the point
            }
        }
    }

    #[test]
    fn short_and_empty_inputs() {
        assert!(decimate_min_max(&[], &[]).is_empty());
        assert_eq!(decimate_min_max(&[3.2], &[1.0]), [0]);
        assert_eq!(decimate_min_max(&[0.1, 0.2], &[1.0, 1.0]), [0, 1]);
        assert_eq!(
            decimate_min_max(&[0.1, 0.2, 0.3], &[1.0]),
            [0],
            "common length only"
        );
        // Unsorted x: columns revisited are new runs, nothing is lost.
        assert_eq!(
            decimate_min_max(&[0.5, 5.5, 0.6], &[1.0, 2.0, 3.0]),
            [0, 1, 2]
        );
    }

    #[test]
    fn runs_split_at_non_finite_points() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY, 4.0];
        assert_eq!(finite_runs(&x, &y, false), (vec![0..1, 2..4, 5..6], 2));
        let y = [1.0, 0.0, 2.0, -3.0, 4.0, 5.0];
        assert_eq!(finite_runs(&x, &y, true), (vec![2..3, 4..6], 3));
        assert_eq!(finite_runs(&[], &[], false), (vec![], 0));
    }
}
