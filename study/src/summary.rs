//! What a study's rows add up to: per profile, how each method stands
//! against the floors, the repeat baseline and fair playback.

use super::row::{Method, Reading, Row};

/// Which E_s reading and which gain rule a summary uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Table 5.1's gain, Welch reading.
    Table51Welch,
    /// Table 5.1's gain, rect reading.
    Table51Rect,
    /// Best gain, Welch reading.
    BestWelch,
    /// Best gain, rect reading.
    BestRect,
}

impl Basis {
    /// Every basis.
    pub const ALL: [Basis; 4] = [Basis::Table51Welch, Basis::Table51Rect, Basis::BestWelch, Basis::BestRect];

    /// A label.
    pub fn label(&self) -> &'static str {
        match self {
            Basis::Table51Welch => "Table 5.1 gain, Welch E_s",
            Basis::Table51Rect => "Table 5.1 gain, rect E_s",
            Basis::BestWelch => "best gain, Welch E_s",
            Basis::BestRect => "best gain, rect E_s",
        }
    }

    /// Welch or rect.
    pub fn welch(&self) -> bool {
        matches!(self, Basis::Table51Welch | Basis::BestWelch)
    }

    /// Picks the reading.
    pub fn of(&self, r: Reading) -> f64 {
        if self.welch() {
            r.welch
        } else {
            r.rect
        }
    }
}

/// A method's E_s on a row under `basis`.
pub fn es(row: &Row, m: Method, basis: Basis) -> Option<f64> {
    let c = row.method(m)?.chosen;
    Some(match basis {
        Basis::Table51Welch => c.table51.welch,
        Basis::Table51Rect => c.table51.rect,
        Basis::BestWelch => c.best_welch.welch,
        Basis::BestRect => c.best_rect.rect,
    })
}

/// How one method stands over a set of rows.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Standing {
    /// Rows.
    pub rows: usize,
    /// Mean E_s.
    pub mean: f64,
    /// Mean of E_s / achievable floor (NaN without floors).
    pub mean_over_floor: f64,
    /// Largest E_s / achievable floor.
    pub worst_over_floor: f64,
    /// Rows within 1.3× of the achievable floor.
    pub within_1_3: usize,
    /// Rows within 2× of the achievable floor.
    pub within_2: usize,
    /// Mean of E_s / display floor.
    pub mean_over_display_floor: f64,
    /// Mean of E_s / repeat baseline.
    pub mean_over_repeat: f64,
    /// Rows with E_s below fair playback's.
    pub beats_playback: usize,
}

/// How `m` stands over `rows` under `basis`.
pub fn standing(rows: &[&Row], m: Method, basis: Basis) -> Standing {
    let mut s = Standing { worst_over_floor: f64::NAN, ..Standing::default() };
    let (mut sum, mut sum_f, mut sum_d, mut sum_r, mut nf) = (0.0, 0.0, 0.0, 0.0, 0);
    let mut worst: f64 = 0.0;
    for r in rows {
        let Some(e) = es(r, m, basis) else { continue };
        s.rows += 1;
        sum += e;
        sum_d += e / basis.of(r.display_floor);
        sum_r += e / basis.of(r.repeat);
        if let Some(f) = r.floor() {
            let ratio = e / basis.of(f);
            sum_f += ratio;
            nf += 1;
            worst = worst.max(ratio);
            s.within_1_3 += usize::from(ratio <= 1.3);
            s.within_2 += usize::from(ratio <= 2.0);
        }
        if let Some(p) = es(r, Method::Playback, basis) {
            s.beats_playback += usize::from(e < p);
        }
    }
    let n = s.rows.max(1) as f64;
    s.mean = sum / n;
    s.mean_over_display_floor = sum_d / n;
    s.mean_over_repeat = sum_r / n;
    if nf > 0 {
        s.mean_over_floor = sum_f / nf as f64;
        s.worst_over_floor = worst;
    } else {
        s.mean_over_floor = f64::NAN;
    }
    s
}
