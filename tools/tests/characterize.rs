//! `graphs/characterize.toml` end to end: the device characterization of
//! dissertation §3.1.2 on the simulated lab finds the square law of
//! electrovibration, and draws its two figures.

use std::path::Path;
use std::process::Command;

#[test]
fn static_friction_increase_is_quadratic_in_intensity() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_evflow"))
        .current_dir(root)
        .args([
            "run",
            "graphs/characterize.toml",
            "--quiet",
            "--set",
            "passes=2",
            "--sweep",
            "intensity=0.25,0.5,0.75,1.0",
        ])
        .arg("--out")
        .arg(dir.path())
        .arg("--csv")
        .arg(&csv)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for png in ["characterize-vibratory.png", "characterize-static.png"] {
        assert!(dir.path().join(png).exists(), "{png} missing:\n{stdout}");
    }
    // The square law y = a + b·x² of the static increase is reported with
    // its R², with no linear term.
    let line = stdout.lines().find(|l| l.contains("static.increase: square fit")).expect("fit line");
    let r2: f64 = line.rsplit("R² = ").next().unwrap().trim().parse().unwrap();
    assert!(r2 > 0.99, "{line}");
    assert!(line.contains("·x^2") && !line.contains("·x ") && !line.contains("·x,"), "{line}");

    let table = std::fs::read_to_string(&csv).unwrap();
    let head: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let (ci, cs, cv) = (col("intensity"), col("static.increase"), col("vib.pp_mean"));
    let rows: Vec<Vec<f64>> =
        table.lines().skip(1).map(|l| l.split(',').map(|c| c.parse().unwrap_or(f64::NAN)).collect()).collect();
    assert_eq!(rows.len(), 4);
    // Square law: doubling the intensity from 0.5 to 1.0 quadruples the
    // increase (within the lab's noise and leakage), and both measures grow.
    let inc = |i: usize| rows[i][cs];
    let ratio = inc(3) / inc(1);
    assert!((3.3..4.7).contains(&ratio), "static increase 1.0 vs 0.5: ratio {ratio}");
    for k in 1..4 {
        assert!(rows[k][ci] > rows[k - 1][ci]);
        assert!(inc(k) > inc(k - 1), "static increase not increasing: {table}");
    }
    assert!(rows[3][cv] > rows[0][cv], "vibration at 1.0 not above 0.25: {table}");
}
