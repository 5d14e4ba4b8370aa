//! Mesh-gradient rendering (chapter 4): rendered F^sq against the analytic
//! gradient of the Gaussian scene over the mesh resolution, for both slope
//! estimates ([`evflow_nodes::mesh::fidelity::gradient_fidelity`], the
//! figures of `evflow report mesh`); cost is the ray cast and estimate per
//! tick.

use super::curve::{Curve, WorkPoint};
use super::{PrecisionError, Size};
use evflow_nodes::mesh::fidelity::{gradient_fidelity, ScanPlan};

/// The generated scene's default `resolution` and the `mesh.gradient`
/// node's default `slope`.
pub const DEFAULT: (usize, &str) = (48, "secant");

/// The curve on the Gaussian scene `2B2H` (the scene's default).
pub fn curve(size: Size) -> Result<Curve, PrecisionError> {
    let resolutions: &[usize] = match size {
        Size::Ci => &[4, 8, 16, 48],
        Size::Full => &[4, 8, 16, 32, 48, 64, 128, 256, 512],
    };
    let rows = gradient_fidelity("2B2H", resolutions, &ScanPlan::standard());
    let mut points = Vec::new();
    for slope in ["secant", "normal"] {
        for r in &rows {
            let (us, err) = if slope == "secant" {
                (r.tick_us_secant, r.rms_fsq_secant)
            } else {
                (r.tick_us_normal, r.rms_fsq_normal)
            };
            points.push(WorkPoint {
                setting: format!("{slope}, {} cells", r.resolution),
                series: slope.into(),
                error: err,
                cost: us * 1e-6,
                // A BVH ray cast visits about log₂(triangles) nodes.
                work: (r.triangles.max(2) as f64).log2(),
            });
        }
    }
    Ok(Curve {
        name: "mesh-gradient".into(),
        computation: "mesh.gradient (Gaussian 2B2H scene)".into(),
        knob: "slope × cells per 6 cm side".into(),
        error_unit: "RMS error of F^sq, √N".into(),
        cost_unit: "tick".into(),
        reference: "the analytic Gaussian surface (exact)".into(),
        reference_error: 0.0,
        baseline: None,
        default: format!("{}, {} cells", DEFAULT.1, DEFAULT.0),
        points,
    })
}
