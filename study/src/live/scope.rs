//! What a live study covers: lab profiles, texture samples, virtual users,
//! the gain sweep, the grid its models and cells are built on, and the
//! settings of the live synthesis — one serializable scope, used by the
//! study's config, its shard record and its merge.

use super::row::Chain;
use crate::exact;
use serde::{Deserialize, Serialize};

/// A virtual user: the strokes `sim.user` makes with this seed and these ranges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct User {
    /// A short name for tables.
    pub name: String,
    /// `sim.user`'s seed.
    pub seed: u64,
    /// Cruising speeds, cm/s: [slowest, fastest].
    pub speed: [f64; 2],
    /// Pressures as masses, g: [lightest, heaviest].
    pub mass: [f64; 2],
    /// Length of a stroke, cm.
    #[serde(with = "exact")]
    pub travel_cm: f64,
}

impl User {
    /// The default users: the dissertation's conditions; slow and heavy;
    /// fast and light; short strokes that reverse three times as often.
    /// Every user reverses at both ends of its stroke.
    pub fn defaults() -> Vec<User> {
        let u = |name: &str, seed, speed, mass, travel_cm| User { name: name.into(), seed, speed, mass, travel_cm };
        vec![
            u("person", 1, [3.0, 7.0], [60.0, 110.0], 8.0),
            u("slow-heavy", 2, [1.5, 3.5], [100.0, 160.0], 8.0),
            u("fast-light", 3, [7.0, 12.0], [30.0, 60.0], 8.0),
            u("short-strokes", 4, [3.0, 7.0], [60.0, 110.0], 2.5),
        ]
    }

    /// The values of graphs/texture-live-quality.toml and
    /// graphs/texture-live-play.toml for this user (a seed past `i64::MAX`
    /// becomes −1, which `sim.user` refuses by name).
    pub fn sets(&self) -> crate::graphs::Sets {
        crate::graphs::Sets::new()
            .int("user_seed", i64::try_from(self.seed).unwrap_or(-1))
            .num("speed_min", self.speed[0])
            .num("speed_max", self.speed[1])
            .num("mass_min", self.mass[0])
            .num("mass_max", self.mass[1])
            .num("travel", self.travel_cm * 1e-2)
    }

    /// Checks the ranges (within `sim.user`'s limits, low ≤ high).
    pub fn validate(&self) -> Result<(), String> {
        let ok =
            |r: [f64; 2], lo: f64, hi: f64| r[0] <= r[1] && r.iter().all(|v| v.is_finite() && (lo..=hi).contains(v));
        if !ok(self.speed, 0.0, 50.0) {
            return Err(format!("user {}: speeds {:?} cm/s must be 0–50, slowest first", self.name, self.speed));
        }
        if !ok(self.mass, 1.0, 1000.0) {
            return Err(format!("user {}: masses {:?} g must be 1–1000, lightest first", self.name, self.mass));
        }
        if !(self.travel_cm.is_finite() && (0.1..=100.0).contains(&self.travel_cm)) {
            return Err(format!("user {}: a stroke of {} cm is not 0.1–100 cm", self.name, self.travel_cm));
        }
        Ok(())
    }
}

/// The live synthesis' settings (`synth.live` in graphs/texture-live-quality.toml).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LiveSettings {
    /// Samples the target is read ahead (the horizon is one more).
    pub lookahead: usize,
    /// Optimizer iterations per tick.
    pub iterations: usize,
    /// The carrier's offset, in units of the least that renders every trough.
    #[serde(with = "exact")]
    pub offset: f64,
}

impl Default for LiveSettings {
    fn default() -> Self {
        Self { lookahead: 15, iterations: 4, offset: 0.25 }
    }
}

/// Everything that must agree across the shards of one live study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LiveScope {
    /// Lab profiles, by name (`nominal` or graphs/lab/NAME.toml).
    pub profiles: Vec<String>,
    /// Texture samples.
    pub samples: Vec<String>,
    /// Virtual users.
    pub users: Vec<User>,
    /// The overall gain sweep, applied to every chain alike (each chain is
    /// bounded by `limit` to |u| ≤ 1 after its gain).
    pub gains: Vec<f64>,
    /// The trained loads of each profile's grid, g.
    pub masses: Vec<f64>,
    /// The trained speeds of each profile's grid, cm/s.
    pub speeds: Vec<f64>,
    /// NARX training epochs at most (the library's inverse models).
    pub epochs: u32,
    /// Iterations of the optimized synthesis (the library's optimized cells).
    pub iterations: usize,
    /// Run seconds per user.
    #[serde(with = "exact")]
    pub seconds: f64,
    /// Whether the stroke's achievable floor is computed.
    pub floor: bool,
    /// Iterations per start of the stroke's floor.
    pub floor_iterations: usize,
    /// The live synthesis' settings.
    pub live: LiveSettings,
    /// The chains played, beside nothing (which always is). With the live
    /// synthesis alone, each profile's library is the live synthesis' own
    /// ([`super::library`]: forward models and forces, no inverse models
    /// or cells).
    #[serde(default = "every_chain")]
    pub chains: Vec<Chain>,
}

fn every_chain() -> Vec<Chain> {
    Chain::ALL.to_vec()
}

impl LiveScope {
    /// The report's defaults: every profile of the simulated lab, the six
    /// samples of §5.3, the four default users.
    pub fn defaults() -> Self {
        Self {
            profiles: ["nominal", "stiff", "display-b", "relaxing", "resonant"].map(String::from).to_vec(),
            samples: [
                "dotted-sheet",
                "chair-fabric",
                "felt-fabric",
                "painting-canvas",
                "plastic-sheet",
                "scrunched-paper",
            ]
            .map(String::from)
            .to_vec(),
            users: User::defaults(),
            gains: vec![0.4, 0.6, 0.8, 1.0, 1.2],
            masses: vec![60.0, 110.0],
            speeds: vec![3.0, 7.0],
            epochs: 200,
            iterations: 100,
            seconds: 8.0,
            floor: true,
            floor_iterations: 100,
            live: LiveSettings::default(),
            chains: every_chain(),
        }
    }

    /// Whether only the live synthesis is played (its own library is enough).
    pub fn live_only(&self) -> bool {
        self.chains == [Chain::Live]
    }

    /// Checks what a run needs: something to run, positive gains, valid users.
    pub fn validate(&self) -> Result<(), String> {
        if self.profiles.is_empty() || self.samples.is_empty() || self.users.is_empty() {
            return Err("a live study needs at least one profile, sample and user".into());
        }
        if self.gains.is_empty() || self.gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
            return Err("the gains must be positive numbers, at least one".into());
        }
        if self.masses.is_empty() || self.speeds.is_empty() {
            return Err("the grid needs at least one mass and one speed".into());
        }
        if !(self.seconds.is_finite() && (2.0..=600.0).contains(&self.seconds)) {
            return Err(format!("{} s per user: choose 2–600 s (E_s needs whole one-second segments)", self.seconds));
        }
        if self.chains.is_empty() {
            return Err("name at least one chain to play beside nothing".into());
        }
        if self.live.lookahead > 63 {
            return Err(format!("a look-ahead of {} samples: at most 63", self.live.lookahead));
        }
        let mut names = std::collections::BTreeSet::new();
        for u in &self.users {
            u.validate()?;
            if !names.insert(u.name.as_str()) {
                return Err(format!("two users are named {}", u.name));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_cover_slow_fast_heavy_light_and_frequent_reversals() {
        let s = LiveScope::defaults();
        s.validate().unwrap();
        let lo = s.users.iter().map(|u| u.speed[0]).fold(f64::INFINITY, f64::min);
        let hi = s.users.iter().map(|u| u.speed[1]).fold(0.0, f64::max);
        assert!(lo < 3.0 && hi > 7.0, "slower and faster than the grid");
        let light = s.users.iter().map(|u| u.mass[0]).fold(f64::INFINITY, f64::min);
        let heavy = s.users.iter().map(|u| u.mass[1]).fold(0.0, f64::max);
        assert!(light < 60.0 && heavy > 110.0, "lighter and heavier than the grid");
        assert!(s.users.iter().any(|u| u.travel_cm < 4.0), "short strokes reverse often");
        assert_eq!(s.profiles.len(), 5);
        let back: LiveScope = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn bad_scopes_say_what_is_wrong() {
        let mut s = LiveScope::defaults();
        s.users[1].speed = [5.0, 2.0];
        assert!(s.validate().unwrap_err().contains("slow-heavy"));
        let mut s = LiveScope::defaults();
        s.gains = vec![0.0];
        assert!(s.validate().unwrap_err().contains("gains"));
        let mut s = LiveScope::defaults();
        s.users[1].name = "person".into();
        assert!(s.validate().unwrap_err().contains("two users"));
    }
}
