//! One computation's work-precision curve: its points (setting → error
//! against a reference, cost), the Pareto front of cost against error, the
//! cheapest setting within a tolerance of the best error, and how far the
//! shipped default sits from the front.

/// One setting of a computation, measured.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkPoint {
    /// The setting, as the table prints it (e.g. `exact × 16`).
    pub setting: String,
    /// The family of settings it belongs to (one line of the figure).
    pub series: String,
    /// Error against the curve's reference (the curve's `error_unit`).
    pub error: f64,
    /// Measured run time per unit of work, s (the curve's `cost_unit`).
    pub cost: f64,
    /// The same cost counted instead of timed (multiply-adds, sub-steps,
    /// triangles … per unit of work): deterministic, for the tests' orderings.
    pub work: f64,
}

/// A computation's curve.
#[derive(Debug, Clone)]
pub struct Curve {
    /// Short name: the `--only` word and the PNG's file stem.
    pub name: String,
    /// What is computed (the table's first column).
    pub computation: String,
    /// The knob the points turn.
    pub knob: String,
    /// What the error is (e.g. "relative RMS").
    pub error_unit: String,
    /// What one unit of work is (e.g. "output sample").
    pub cost_unit: String,
    /// The reference the error is measured against.
    pub reference: String,
    /// The reference's own error (0 for an exact one; else measured
    /// against a still finer reference).
    pub reference_error: f64,
    /// The error with the computation left out, where that means something
    /// (e.g. the display with no actuation); every setting should beat it.
    pub baseline: Option<f64>,
    /// The setting of the shipped default (one point's `setting`).
    pub default: String,
    /// Every setting measured, in the order measured.
    pub points: Vec<WorkPoint>,
}

/// How a point's cost is read: measured time or counted work.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostBy {
    /// [`WorkPoint::cost`].
    Time,
    /// [`WorkPoint::work`].
    Work,
}

impl CostBy {
    fn of(self, p: &WorkPoint) -> f64 {
        match self {
            CostBy::Time => p.cost,
            CostBy::Work => p.work,
        }
    }
}

/// The indices of the points on the Pareto front of (cost, error): those no
/// other point beats on both (at most the same cost and a smaller error, or
/// a smaller cost and at most the same error), cheapest first. Points with a
/// non-finite error or cost are never on it.
pub fn front(points: &[WorkPoint], by: CostBy) -> Vec<usize> {
    let ok = |p: &WorkPoint| p.error.is_finite() && by.of(p).is_finite();
    let mut idx: Vec<usize> = (0..points.len()).filter(|&i| ok(&points[i])).collect();
    idx.sort_by(|&a, &b| {
        let (pa, pb) = (&points[a], &points[b]);
        by.of(pa).total_cmp(&by.of(pb)).then(pa.error.total_cmp(&pb.error))
    });
    let mut out = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        if points[i].error < best {
            best = points[i].error;
            out.push(i);
        }
    }
    out
}

/// The smallest finite error of the points.
pub fn best_error(points: &[WorkPoint]) -> Option<f64> {
    points.iter().map(|p| p.error).filter(|e| e.is_finite()).min_by(f64::total_cmp)
}

/// The index of the cheapest point whose error is within `tolerance`
/// (0.1 = 10 %) of the best error; ties on cost go to the smaller error.
pub fn cheapest_within(points: &[WorkPoint], tolerance: f64, by: CostBy) -> Option<usize> {
    let best = best_error(points)?;
    let limit = best * (1.0 + tolerance);
    (0..points.len()).filter(|&i| points[i].error <= limit && by.of(&points[i]).is_finite()).min_by(|&a, &b| {
        by.of(&points[a]).total_cmp(&by.of(&points[b])).then(points[a].error.total_cmp(&points[b].error))
    })
}

/// How far point `i` sits above the front: its error divided by the
/// smallest error any point reaches at no more than its cost (1 = on the
/// front; 3 = three times the error the front offers for that cost).
pub fn front_gap(points: &[WorkPoint], i: usize, by: CostBy) -> f64 {
    let p = &points[i];
    let c = by.of(p);
    let reachable = points
        .iter()
        .filter(|q| by.of(q) <= c && q.error.is_finite())
        .map(|q| q.error)
        .min_by(f64::total_cmp)
        .unwrap_or(p.error);
    if reachable > 0.0 {
        p.error / reachable
    } else if p.error > 0.0 {
        f64::INFINITY
    } else {
        1.0
    }
}

impl Curve {
    /// The index of the shipped default's point.
    pub fn default_index(&self) -> Option<usize> {
        self.points.iter().position(|p| p.setting == self.default)
    }

    /// The shipped default's point.
    pub fn default_point(&self) -> Option<&WorkPoint> {
        self.default_index().map(|i| &self.points[i])
    }

    /// The smallest error any setting reaches.
    pub fn best_error(&self) -> Option<f64> {
        best_error(&self.points)
    }

    /// The cheapest (measured time) setting within 10 % of the best error.
    pub fn cheapest(&self) -> Option<&WorkPoint> {
        cheapest_within(&self.points, 0.1, CostBy::Time).map(|i| &self.points[i])
    }

    /// The points of one series, in the order measured.
    pub fn series(&self) -> Vec<(String, Vec<&WorkPoint>)> {
        let mut out: Vec<(String, Vec<&WorkPoint>)> = Vec::new();
        for p in &self.points {
            match out.iter_mut().find(|(s, _)| *s == p.series) {
                Some((_, v)) => v.push(p),
                None => out.push((p.series.clone(), vec![p])),
            }
        }
        out
    }

    /// The errors of one series in the order measured (coarse to fine).
    pub fn errors_of(&self, series: &str) -> Vec<f64> {
        self.points.iter().filter(|p| p.series == series).map(|p| p.error).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(setting: &str, error: f64, cost: f64) -> WorkPoint {
        WorkPoint { setting: setting.into(), series: "s".into(), error, cost, work: cost * 10.0 }
    }

    fn sample() -> Vec<WorkPoint> {
        vec![
            p("a", 1.0, 1.0),
            p("b", 0.1, 2.0),
            p("c", 0.5, 3.0), // dominated by b
            p("d", 0.01, 4.0),
            p("e", 0.0105, 8.0), // within 10 % of the best, dearer than d
            p("f", 0.0100, 16.0),
            p("g", f64::NAN, 0.5),
        ]
    }

    #[test]
    fn the_front_keeps_the_undominated_points_cheapest_first() {
        let pts = sample();
        let f: Vec<&str> = front(&pts, CostBy::Time).iter().map(|&i| pts[i].setting.as_str()).collect();
        assert_eq!(f, ["a", "b", "d"]);
        // Counted work orders the same way here.
        assert_eq!(front(&pts, CostBy::Work), front(&pts, CostBy::Time));
    }

    #[test]
    fn the_cheapest_within_ten_percent_of_the_best() {
        let pts = sample();
        assert_eq!(best_error(&pts), Some(0.01));
        assert_eq!(cheapest_within(&pts, 0.1, CostBy::Time), Some(3));
        // Within 0 %: still d (the best itself, and the cheaper of the two at 0.01).
        assert_eq!(cheapest_within(&pts, 0.0, CostBy::Time), Some(3));
        // Within 1100 %: b (0.1 ≤ 0.12) is the cheapest.
        assert_eq!(cheapest_within(&pts, 11.0, CostBy::Time), Some(1));
        // Within 10000 %: a.
        assert_eq!(cheapest_within(&pts, 100.0, CostBy::Time), Some(0));
        assert_eq!(cheapest_within(&[], 0.1, CostBy::Time), None);
    }

    #[test]
    fn the_gap_to_the_front() {
        let pts = sample();
        assert_eq!(front_gap(&pts, 1, CostBy::Time), 1.0);
        assert!((front_gap(&pts, 2, CostBy::Time) - 5.0).abs() < 1e-12);
        assert!((front_gap(&pts, 4, CostBy::Time) - 1.05).abs() < 1e-12);
    }

    #[test]
    fn a_curve_finds_its_default_and_series() {
        let c = Curve {
            name: "x".into(),
            computation: "x".into(),
            knob: "k".into(),
            error_unit: "rel".into(),
            cost_unit: "sample".into(),
            reference: "exact".into(),
            reference_error: 0.0,
            baseline: None,
            default: "d".into(),
            points: sample(),
        };
        assert_eq!(c.default_point().map(|p| p.error), Some(0.01));
        assert_eq!(c.cheapest().map(|p| p.setting.as_str()), Some("d"));
        assert_eq!(c.series().len(), 1);
        assert_eq!(c.errors_of("s").len(), 7);
    }
}
