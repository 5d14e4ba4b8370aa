//! The failures of a batch: which items failed and why, for the summary a
//! batch ends with. One failing item does not stop the others; the caller
//! ends with a failure (a non-zero exit) when this list is not empty.

/// The items of a batch that failed, in item order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Failures {
    /// `(item label, reason)`.
    pub list: Vec<(String, String)>,
}

impl Failures {
    /// No failures yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Notes that `item` failed because of `reason`.
    pub fn push(&mut self, item: impl Into<String>, reason: impl std::fmt::Display) {
        self.list.push((item.into(), reason.to_string()));
    }

    /// Whether nothing failed.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// How many items failed.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The summary for people: `N of M runs failed:` and one line per
    /// failure (`  item: reason`, a reason of several lines indented under
    /// it); empty when nothing failed.
    pub fn summary(&self, total: usize, what: &str) -> String {
        self.summary_as(total, what, "failed")
    }

    /// [`Failures::summary`] saying `N of M {what} {verb}:` (`would
    /// fail`, for a check that runs nothing).
    pub fn summary_as(&self, total: usize, what: &str, verb: &str) -> String {
        if self.list.is_empty() {
            return String::new();
        }
        let mut s = format!("{} of {total} {what} {verb}:\n", self.list.len());
        // Three or more items that failed for one reason (a mistake every
        // run of a sweep shares) share one line, the reason once.
        let mut reasons: Vec<(&str, Vec<&str>)> = Vec::new();
        for (item, reason) in &self.list {
            match reasons.iter_mut().find(|(r, _)| *r == reason.as_str()) {
                Some((_, items)) => items.push(item),
                None => reasons.push((reason, vec![item])),
            }
        }
        let mut line = |who: &str, reason: &str| {
            let mut lines = reason.lines();
            s.push_str(&format!("  {who}: {}\n", lines.next().unwrap_or("")));
            for l in lines {
                s.push_str(&format!("      {l}\n"));
            }
        };
        for (reason, items) in reasons {
            match items.len() {
                n if n >= 3 => line(&format!("{} … {} ({n} items)", items[0], items[n - 1]), reason),
                _ => items.iter().for_each(|who| line(who, reason)),
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_lists_every_failure_with_its_reason() {
        let mut f = Failures::new();
        assert_eq!(f.summary(3, "runs"), "");
        f.push("mass=5000", "`display.mass`: 5000 is above 300\n  at g.toml:4");
        f.push("mass=7", "no such file");
        assert_eq!(f.len(), 2);
        assert_eq!(
            f.summary(9, "runs"),
            "2 of 9 runs failed:\n  mass=5000: `display.mass`: 5000 is above 300\n        at g.toml:4\n  mass=7: no such file\n"
        );
    }

    #[test]
    fn items_failing_for_one_reason_share_its_line() {
        let mut f = Failures::new();
        for m in [1, 2, 3, 4] {
            f.push(format!("m={m}"), "bad type");
        }
        f.push("m=5", "other");
        f.push("m=6", "other");
        assert_eq!(
            f.summary_as(6, "sweep runs", "would fail"),
            "6 of 6 sweep runs would fail:\n  m=1 … m=4 (4 items): bad type\n  m=5: other\n  m=6: other\n"
        );
    }
}
