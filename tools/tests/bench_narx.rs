//! `evflow bench narx` end to end on a small size: it trains, prints its
//! table, and its export holds the exact lab data (bit for bit), the
//! initial weights of the network, and an error-per-epoch curve whose last
//! budget is the trained model itself.

use evflow_nodes::narx::labdata::{rbs, Lab};
use std::path::Path;
use std::process::Command;

fn read_csv(path: &Path) -> (Vec<f64>, Vec<f64>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("force_N,actuation"));
    lines
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse::<f64>().unwrap(), b.parse::<f64>().unwrap())
        })
        .unzip()
}

#[test]
fn bench_narx_exports_the_data_it_trained_on() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "bench",
        "narx",
        "--samples",
        "1200",
        "--heldout",
        "400",
        "--epochs",
        "3",
        "--inference-samples",
        "5000",
        "--curve",
        "--export",
        dir.path().to_str().unwrap(),
    ];
    let o = Command::new(env!("CARGO_BIN_EXE_evflow")).args(args).output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("| training wall time (fit, one core) |") && out.contains("M samples/s"), "{out}");

    // The training recording is the lab's, bit for bit.
    let (x, u) = read_csv(&dir.path().join("train.csv"));
    let want_u = rbs(1200, 1);
    let want_x = Lab::default().force(&want_u);
    assert_eq!(u, want_u);
    assert!(x.iter().zip(&want_x).all(|(a, b)| a.to_bits() == b.to_bits()) && x.len() == 1200);
    let (xh, _) = read_csv(&dir.path().join("heldout.csv"));
    assert_eq!(xh.len(), 400);

    let setup: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("setup.json")).unwrap()).unwrap();
    let rust: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("rust.json")).unwrap()).unwrap();
    // 15 inputs (1 feedback + 10 + d + 1 with d = 3 on the lab) into 15-10-5-1.
    let inputs = setup["delays"]["feedback"].as_u64().unwrap()
        + setup["delays"]["input"].as_u64().unwrap()
        + setup["delays"]["lookahead"].as_u64().unwrap()
        + 1;
    let params = 15 * (inputs + 1) + 10 * 16 + 5 * 11 + 6;
    assert_eq!(setup["initial_weights"].as_array().unwrap().len() as u64, params);
    assert_eq!(rust["weights"].as_array().unwrap().len() as u64, params);
    assert_ne!(setup["initial_weights"], rust["weights"]);

    // Budgets 0 … 3; the last is the trained model (training is deterministic).
    let curve = rust["curve"].as_array().unwrap();
    assert_eq!(rust["epochs"], 3);
    assert_eq!(curve.len(), 4);
    assert_eq!(curve[3]["heldout"], rust["heldout"]);
    assert_eq!(curve[0]["seconds"], 0.0);
    let secs: Vec<f64> = curve.iter().map(|c| c["seconds"].as_f64().unwrap()).collect();
    assert!(secs.windows(2).all(|w| w[0] < w[1]), "{secs:?}");
}
