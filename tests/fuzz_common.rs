//! What the fuzz tests share (`fuzz_loader.rs`, `fuzz_numbers.rs`): the
//! deterministic proptest configuration of `cargo test`, the opt-in
//! open-ended run (`EVFLOW_FUZZ_CASES`, `EVFLOW_FUZZ_SEED`), and saving a
//! failing case for the corpus.

use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, RngSeed};
use std::path::Path;
use std::sync::OnceLock;

/// The seed of the deterministic run (any fixed value; changing it draws
/// another fixed set of cases).
pub const CI_SEED: u64 = 0x00E7_F10A;

/// The deterministic configuration of `cargo test` with `cases` cases:
/// fixed seed and algorithm (set here, so no `PROPTEST_*` variable can
/// change the draw), and no failure file written into the source tree —
/// the corpus keeps failures instead.
pub fn ci_config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        max_shrink_iters: 200,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(CI_SEED),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// The opt-in open-ended run, from `EVFLOW_FUZZ_CASES` / `EVFLOW_FUZZ_SEED`:
/// `Some((seed, cases))` when either is set (`default_cases` when only the
/// seed is). One seed per test process, so one printed seed replays the
/// whole run; `who` names the test in what is printed.
pub fn fuzz_env(who: &str, default_cases: u32) -> Option<(u64, u32)> {
    static RUN: OnceLock<Option<(u64, u32)>> = OnceLock::new();
    *RUN.get_or_init(|| {
        let var = |name: &str| std::env::var(name).ok().filter(|v| !v.trim().is_empty());
        let (cases, seed) = (var("EVFLOW_FUZZ_CASES"), var("EVFLOW_FUZZ_SEED"));
        if cases.is_none() && seed.is_none() {
            return None;
        }
        let cases = cases.map_or(default_cases, |v| {
            v.trim().parse().unwrap_or_else(|_| panic!("EVFLOW_FUZZ_CASES={v}: expected a whole number of cases"))
        });
        let seed = seed.map_or_else(fresh_seed, |v| {
            v.trim().parse().unwrap_or_else(|_| panic!("EVFLOW_FUZZ_SEED={v}: expected an unsigned 64-bit integer"))
        });
        eprintln!("{who}: seed {seed}, {cases} cases per property (EVFLOW_FUZZ_SEED={seed} replays this run)");
        Some((seed, cases))
    })
}

/// A seed that differs from run to run (std's per-process hash keys mixed
/// with the clock).
pub fn fresh_seed() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos()));
    h.finish()
}

/// The configuration the property tests run with: the deterministic one
/// (`ci_cases` cases) unless open-ended fuzzing was asked for.
pub fn config(who: &str, ci_cases: u32) -> ProptestConfig {
    match fuzz_env(who, ci_cases) {
        Some((seed, cases)) => ProptestConfig { cases, rng_seed: RngSeed::Fixed(seed), ..ci_config(ci_cases) },
        None => ci_config(ci_cases),
    }
}

/// Runs `f`; on a panic, `text` is saved to `<target>/tmp/<who>/<property>.<ext>`
/// (overwritten, so after shrinking it holds the minimal case, and the
/// path printed once per property) before the panic goes on.
pub fn or_save<T>(who: &str, property: &str, ext: &str, text: &str, f: impl FnOnce() -> T) -> T {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(v) => v,
        Err(panic) => {
            let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(who);
            let path = dir.join(format!("{property}.{ext}"));
            static TOLD: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
            if std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, text)).is_ok() {
                let mut told = TOLD.lock().unwrap_or_else(|e| e.into_inner());
                if !told.iter().any(|p| p == property) {
                    told.push(property.to_string());
                    eprintln!("{who}: the failing case is in {} (add it to tests/fuzz_corpus/)", path.display());
                }
            }
            std::panic::resume_unwind(panic)
        }
    }
}
