//! "Did you mean …?" — the closest valid name to a misspelt one.

/// Edit distance (Levenshtein) between two strings, by characters.
pub fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// The candidate closest to `wrong`, if it is close enough to be a likely
/// typo (distance at most a third of the length, at least 2), or if one
/// candidate contains the other.
pub fn closest<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let limit = (wrong.chars().count() / 3).max(2);
    let lw = wrong.to_lowercase();
    candidates
        .into_iter()
        .map(|c| {
            let lc = c.to_lowercase();
            let d = if lc == lw { 0 } else { distance(&lw, &lc) };
            let contains = lw.len() >= 3 && (lc.contains(&lw) || lw.contains(&lc));
            (c, d, contains)
        })
        .filter(|(_, d, contains)| *d <= limit || *contains)
        .min_by_key(|(c, d, _)| (*d, c.len()))
        .map(|(c, _, _)| c)
}

/// `help` text naming the closest candidate, or listing the valid ones.
pub fn help<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str> + Clone) -> String {
    match closest(wrong, candidates.clone()) {
        Some(c) => format!("did you mean `{c}`?"),
        None => {
            let all: Vec<&str> = candidates.into_iter().collect();
            if all.is_empty() {
                "there is none".to_string()
            } else {
                format!("valid: {}", all.join(", "))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_known_values() {
        assert_eq!(distance("kitten", "sitting"), 3);
        assert_eq!(distance("", "abc"), 3);
        assert_eq!(distance("cutoff", "cutoff"), 0);
    }

    #[test]
    fn closest_finds_typos() {
        let c = ["cutoff", "order", "kind"];
        assert_eq!(closest("cutof", c), Some("cutoff"));
        assert_eq!(closest("ordr", c), Some("order"));
        assert_eq!(closest("zzzzzz", c), None);
        assert_eq!(closest("butterwort", ["butterworth", "gain"]), Some("butterworth"));
    }
}
