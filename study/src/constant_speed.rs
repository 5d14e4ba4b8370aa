//! The constant-speed stretches of a texture recording as the reports
//! compare them (§5.1.1): runs within 2 % of the set speed, less their
//! first 100 ms (the high-pass filter's response to the reversal), each
//! less its mean (the friction's sign flips between passes) and faded in
//! and out over 50 ms so that the joins add no steps, concatenated.

use super::StudyError;
use evflow_nodes::recording::format::Recording;
use std::path::Path;

/// The constant-speed segments of `force` (the module's rule), `velocity` in m/s.
pub fn constant_speed(force: &[f64], velocity: &[f64], speed_cm_s: f64, rate: f64) -> Vec<f64> {
    let settle = (0.1 * rate) as usize;
    let fade = settle / 2;
    let mut kept = Vec::new();
    let mut run: Vec<f64> = Vec::new();
    let flush = |run: &mut Vec<f64>, kept: &mut Vec<f64>| {
        if run.len() > 2 * settle {
            let seg = &run[settle..];
            let mean = seg.iter().sum::<f64>() / seg.len() as f64;
            let n = seg.len();
            kept.extend(seg.iter().enumerate().map(|(i, f)| {
                let edge = i.min(n - 1 - i);
                let w = if edge < fade {
                    0.5 - 0.5 * (std::f64::consts::PI * edge as f64 / fade as f64).cos()
                } else {
                    1.0
                };
                w * (f - mean)
            }));
        }
        run.clear();
    };
    for (f, v) in force.iter().zip(velocity) {
        if (v.abs() * 100.0 - speed_cm_s).abs() <= 0.02 * speed_cm_s {
            run.push(*f);
        } else {
            flush(&mut run, &mut kept);
        }
    }
    flush(&mut run, &mut kept);
    kept
}

/// The rate and the constant-speed force of `rec` (channels `force` and
/// `velocity`), a recording of graphs/record-textures.toml at `speed_cm_s`
/// read from `what`.
pub fn of_recording(rec: &Recording, speed_cm_s: f64, what: &Path) -> Result<(f64, Vec<f64>), StudyError> {
    let missing = |c: &str| StudyError::Recording(format!("{}: no `{c}` channel", what.display()));
    let force = rec.channel("force").ok_or_else(|| missing("force"))?;
    let velocity = rec.channel("velocity").ok_or_else(|| missing("velocity"))?;
    Ok((rec.rate(), constant_speed(force, velocity, speed_cm_s, rec.rate())))
}

#[cfg(test)]
mod tests {
    use super::constant_speed;

    #[test]
    fn keeps_the_constant_speed_runs_settled_centred_and_faded() {
        // Two 1 s runs at 5 cm/s in opposite directions with offsets ±0.1 N,
        // separated by a reversal: 2 × 900 samples kept, each with mean ~0,
        // starting and ending at 0.
        let rate = 1000.0;
        let mut f = Vec::new();
        let mut v = Vec::new();
        for (dir, off) in [(1.0, 0.1), (-1.0, -0.1)] {
            for k in 0..1000 {
                f.push(off + 0.01 * (k as f64 * 0.3).sin());
                v.push(dir * 0.05);
            }
            for _ in 0..50 {
                f.push(0.0);
                v.push(0.0);
            }
        }
        let kept = constant_speed(&f, &v, 5.0, rate);
        assert_eq!(kept.len(), 1800);
        for seg in kept.chunks(900) {
            assert!(seg[0].abs() < 1e-12 && seg[899].abs() < 1e-3);
            assert!(seg.iter().sum::<f64>().abs() / 900.0 < 1e-3);
        }
    }
}
