//! Which conditions of a texture sample are trained (the cells of its grid)
//! and which are validated by interpolation: dissertation Fig. 5.6 and, for
//! the rippled paper, Fig. 6.8.

use super::setup::Cond;

/// A sample's trained grid and its validation conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPlan {
    /// Trained loads m_i, g.
    pub loads: Vec<f64>,
    /// Trained velocities v_j, cm/s.
    pub speeds: Vec<f64>,
    /// Untrained (load, velocity) conditions to validate.
    pub validate: Vec<(f64, f64)>,
}

impl GridPlan {
    /// Fig. 5.6 (3×3 grid, corners trained, the m₂ row and v₂ column
    /// validated) or, for the rippled paper, Fig. 6.8 (60/110 g × 3–7 cm/s
    /// trained, 85 g at 3.5–6.5 cm/s validated).
    pub fn of(sample: &str) -> Self {
        if sample == "rippled-paper" {
            Self {
                loads: vec![60.0, 110.0],
                speeds: vec![3.0, 4.0, 5.0, 6.0, 7.0],
                validate: vec![(85.0, 3.5), (85.0, 4.5), (85.0, 5.5), (85.0, 6.5)],
            }
        } else {
            Self {
                loads: vec![60.0, 110.0],
                speeds: vec![3.0, 7.0],
                validate: vec![(85.0, 3.0), (85.0, 5.0), (85.0, 7.0), (60.0, 5.0), (110.0, 5.0)],
            }
        }
    }

    /// Whether a condition at velocity `v` is interpolated over velocity
    /// (the schemes differ only there).
    pub fn velocity_interpolated(&self, v: f64) -> bool {
        !self.speeds.contains(&v)
    }

    /// The trained conditions, load by load.
    pub fn trained(&self) -> Vec<Cond> {
        self.loads.iter().flat_map(|&mass| self.speeds.iter().map(move |&speed| Cond { mass, speed })).collect()
    }
}

/// Every trained condition of the plans, each once, in order of appearance.
pub fn trained_conditions(plans: &[GridPlan]) -> Vec<Cond> {
    let mut conds: Vec<Cond> = Vec::new();
    for c in plans.iter().flat_map(GridPlan::trained) {
        if !conds.contains(&c) {
            conds.push(c);
        }
    }
    conds
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plans_are_the_dissertations_and_share_their_corners() {
        let felt = GridPlan::of("felt-fabric");
        assert_eq!(felt.trained().len(), 4);
        assert!(felt.velocity_interpolated(5.0) && !felt.velocity_interpolated(7.0));
        let rippled = GridPlan::of("rippled-paper");
        assert_eq!(rippled.trained().len(), 10);
        // The corners of Fig. 5.6 are among Fig. 6.8's trained conditions: 10 distinct in all.
        assert_eq!(trained_conditions(&[felt, rippled]).len(), 10);
    }
}
