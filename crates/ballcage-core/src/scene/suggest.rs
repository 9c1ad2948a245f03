//! "did you mean …?" for a misspelt key or name in a scene.
//!
//! serde words an unknown key as ``unknown field `jionts`, expected one of
//! `joints`, `hinge`, …`` (or ``expected `a` or `b` ``), and an unknown
//! name of a fixed set (an integrator, a law) as ``unknown variant `rk5`,
//! …``. `with_suggestion` appends the nearest valid word, by edit distance,
//! when one is close enough to be a slip of the keyboard.

/// `reason` with "; did you mean `x`?" appended when it reports an unknown
/// field or variant and a valid one is close to it; `reason` unchanged
/// otherwise.
pub(crate) fn with_suggestion(reason: String) -> String {
    match suggestion(&reason) {
        Some(word) => format!("{reason}; did you mean `{word}`?"),
        None => reason,
    }
}

fn suggestion(reason: &str) -> Option<&str> {
    let rest = reason
        .strip_prefix("unknown field `")
        .or_else(|| reason.strip_prefix("unknown variant `"))?;
    let (given, rest) = rest.split_once('`')?;
    let (_, expected) = rest.split_once("expected")?;
    let candidates = expected.split('`').skip(1).step_by(2);
    nearest(given, candidates)
}

/// The candidate closest to `given` by edit distance (case-insensitive), if
/// it is within a third of `given`'s length (at least 1, at most 3 edits).
fn nearest<'a>(given: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let given = given.to_lowercase();
    let limit = (given.chars().count() / 3).clamp(1, 3);
    candidates
        .map(|c| (edit_distance(&given, &c.to_lowercase()), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

/// Levenshtein distance with adjacent transpositions (optimal string
/// alignment), over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut rows = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in rows.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in rows[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (rows[i - 1][j] + 1)
                .min(rows[i][j - 1] + 1)
                .min(rows[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(rows[i - 2][j - 2] + 1);
            }
            rows[i][j] = d;
        }
    }
    rows[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distances_by_hand() {
        assert_eq!(edit_distance("jionts", "joints"), 1); // one transposition
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("dt", "dt"), 0);
    }

    #[test]
    fn a_slip_gets_the_nearest_key() {
        let reason =
            "unknown field `jionts`, expected one of `joints`, `hinge`, `pitch`".to_string();
        assert_eq!(
            with_suggestion(reason),
            "unknown field `jionts`, expected one of `joints`, `hinge`, `pitch`; did you mean `joints`?"
        );
        let two = "unknown field `duraton`, expected `duration` or `dt`".to_string();
        assert!(with_suggestion(two).ends_with("did you mean `duration`?"));
        let variant =
            "unknown variant `SDIRK`, expected one of `euler`, `rk4`, `sdirk2`".to_string();
        assert!(with_suggestion(variant).ends_with("did you mean `sdirk2`?"));
    }

    #[test]
    fn no_suggestion_when_nothing_is_close_or_the_reason_is_another() {
        let far = "unknown field `colour`, expected one of `joints`, `hinge`".to_string();
        assert_eq!(with_suggestion(far.clone()), far);
        let other = "invalid type: string \"abc\", expected a number".to_string();
        assert_eq!(with_suggestion(other.clone()), other);
    }
}
