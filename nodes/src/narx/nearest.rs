//! The trained condition nearest to a user's (load, velocity): how forces
//! first picks the inverse model that turns an interpolated force into an
//! actuation (`narx.grid`, `evflow report interp --cells narx`).

/// Index of the condition of `grid` — (load g, velocity cm/s) pairs —
/// nearest to (`load`, `velocity`), each axis measured in units of its span
/// over the grid (a single-valued axis counts in its own units). A tie goes
/// to the earlier entry; non-finite inputs count as the grid's first entry.
/// `None` for an empty grid.
pub fn nearest(grid: &[(f64, f64)], load: f64, velocity: f64) -> Option<usize> {
    let first = grid.first()?;
    let span = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = grid.iter().map(f).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
        if hi > lo {
            hi - lo
        } else {
            1.0
        }
    };
    let (sm, sv) = (span(|c| c.0), span(|c| c.1));
    let (m, v) = if load.is_finite() && velocity.is_finite() { (load, velocity) } else { *first };
    let d = |c: &(f64, f64)| ((c.0 - m) / sm).hypot((c.1 - v) / sv);
    let mut best = 0;
    for (k, c) in grid.iter().enumerate().skip(1) {
        if d(c) < d(&grid[best]) - 1e-12 {
            best = k;
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::nearest;

    #[test]
    fn picks_by_span_normalized_distance_and_breaks_ties_to_the_first() {
        let corners = [(60.0, 3.0), (60.0, 7.0), (110.0, 3.0), (110.0, 7.0)];
        assert_eq!(nearest(&corners, 62.0, 3.5), Some(0));
        assert_eq!(nearest(&corners, 100.0, 6.0), Some(3));
        // 85 g is halfway in load; 4 cm/s is a quarter of the way in speed.
        assert_eq!(nearest(&corners, 85.0, 4.0), Some(0), "tie in load: the earlier entry");
        assert_eq!(nearest(&corners, 85.0, 6.5), Some(1));
        // Halfway in speed ties to the earlier entry; just past it, the faster model.
        assert_eq!(nearest(&corners, 70.0, 5.0), Some(0));
        assert_eq!(nearest(&corners, 70.0, 5.1), Some(1));
        assert_eq!(nearest(&corners, f64::NAN, 5.0), Some(0));
        assert_eq!(nearest(&[(85.0, 5.0)], 1e9, -1e9), Some(0));
        assert_eq!(nearest(&[], 85.0, 5.0), None);
    }
}
