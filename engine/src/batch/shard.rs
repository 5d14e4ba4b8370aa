//! `K/N`: the K-th of N deterministic slices of a batch, so that N jobs of
//! a cluster's job array (or N processes of `xargs -P`) share one sweep or
//! report and `evflow merge` joins what they wrote.
//!
//! The slices are contiguous runs of the item list in its own (sorted,
//! deterministic) order, as equal as they can be: with L items, the first
//! `L mod N` slices hold `⌈L/N⌉` items, the rest `⌊L/N⌋`. Contiguous
//! rather than round-robin so that the merged output is the shards'
//! outputs one after another, in K order.

use std::ops::Range;

/// One slice of N: `k` counts from 1, as `$SLURM_ARRAY_TASK_ID` does in
/// `sbatch --array=1-N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, 1..=n.
    pub k: usize,
    /// How many slices.
    pub n: usize,
}

/// Why a `K/N` could not be read.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("shard `{0}`: expected K/N with 1 ≤ K ≤ N (e.g. 3/8)")]
pub struct ShardError(pub String);

impl Shard {
    /// The whole batch as one slice.
    pub const ALL: Shard = Shard { k: 1, n: 1 };

    /// Parses `K/N`.
    pub fn parse(s: &str) -> Result<Shard, ShardError> {
        let bad = || ShardError(s.to_string());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if n == 0 || k == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }

    /// The indices of this slice among `len` items.
    pub fn range(&self, len: usize) -> Range<usize> {
        let (q, r) = (len / self.n, len % self.n);
        let i = self.k - 1;
        let start = i * q + i.min(r);
        start..start + q + usize::from(i < r)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_cover_every_item_once_in_order_and_differ_by_at_most_one() {
        for len in 0..30 {
            for n in 1..12 {
                let ranges: Vec<Range<usize>> = (1..=n).map(|k| Shard { k, n }.range(len)).collect();
                let all: Vec<usize> = ranges.iter().cloned().flatten().collect();
                assert_eq!(all, (0..len).collect::<Vec<_>>(), "{len} items, {n} shards");
                let sizes: Vec<usize> = ranges.iter().map(|r| r.len()).collect();
                let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                assert!(hi - lo <= 1, "{sizes:?}");
            }
        }
        assert_eq!(Shard { k: 2, n: 4 }.range(9), 3..5);
        assert_eq!(Shard::ALL.range(7), 0..7);
    }

    #[test]
    fn k_of_n_parses_and_bad_ones_are_refused() {
        assert_eq!(Shard::parse("3/8"), Ok(Shard { k: 3, n: 8 }));
        assert_eq!(Shard::parse(" 1 / 1 "), Ok(Shard::ALL));
        for bad in ["0/4", "5/4", "1/0", "3", "a/b", "-1/4", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Shard { k: 2, n: 5 }.to_string(), "2/5");
    }
}
