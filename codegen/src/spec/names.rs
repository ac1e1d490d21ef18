//! Names: what can be a Rust module name, and the bounded "did you mean" suggestions.

use super::MAX_NAME_LEN;

/// `true` when `s` matches `[a-z][a-z0-9_]*` (usable as a Rust module name).
pub(crate) fn is_module_name(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && s.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// Maps any string to `[a-z][a-z0-9_]*`: lower-cased, other characters → `_`, runs of `_`
/// collapsed, leading/trailing `_` trimmed, prefixed with `m_` when it would not start with a
/// letter (`"mechanism"` when empty).
pub(crate) fn sanitize_name(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        let c = c.to_ascii_lowercase();
        let c = if c.is_ascii_lowercase() || c.is_ascii_digit() {
            c
        } else {
            '_'
        };
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    let out = out.trim_matches('_').to_owned();
    match out.chars().next() {
        None => "mechanism".into(),
        Some(c) if c.is_ascii_lowercase() => out,
        Some(_) => format!("m_{out}"),
    }
}

/// `did you mean "x"?` for the candidate closest to `word`, when close enough.
pub(crate) fn suggest_hint(word: &str, candidates: &[&str]) -> Option<String> {
    closest(word, candidates).map(|c| format!("did you mean \"{c}\"?"))
}

/// The edit-distance cells one [`closest`] call may fill (about a millisecond): with many long
/// candidates the first ones are compared, not all.
pub(super) const SUGGEST_BUDGET: usize = 1 << 18;

/// The candidate with the smallest edit distance (transpositions count 1) to `word`, if that
/// distance is at most a third of the word's length (at least 1); ties go to the first. Words
/// and candidates longer than [`MAX_NAME_LEN`] characters take no part.
pub(crate) fn closest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let word: Vec<char> = word.to_lowercase().chars().collect();
    if word.len() > MAX_NAME_LEN {
        return None;
    }
    let mut best: Option<(usize, &str)> = None;
    let mut budget = SUGGEST_BUDGET;
    for c in candidates {
        // Only a strictly closer candidate replaces the best so far.
        let bound = match best {
            None => (word.len() / 3).max(1),
            Some((0, _)) => break,
            Some((d, _)) => d - 1,
        };
        if c.len() > 4 * MAX_NAME_LEN {
            continue;
        }
        let cand: Vec<char> = c.to_lowercase().chars().collect();
        if cand.len() > MAX_NAME_LEN || cand.len().abs_diff(word.len()) > bound {
            continue;
        }
        let cost = (word.len() + 1) * (cand.len() + 1);
        if cost > budget {
            break;
        }
        budget -= cost;
        if let Some(d) = edit_distance_within(&word, &cand, bound) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// The optimal-string-alignment distance (Levenshtein plus adjacent transpositions) of `a` and
/// `b` when it is at most `bound`. Three rows, and an early exit once a whole row is past the
/// bound (the distance never falls below a row's minimum).
pub(super) fn edit_distance_within(a: &[char], b: &[char], bound: usize) -> Option<usize> {
    let m = b.len();
    let mut before: Vec<usize> = vec![0; m + 1];
    let mut prev: Vec<usize> = (0..=m).collect();
    let mut cur: Vec<usize> = vec![0; m + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(before[j - 2] + 1);
            }
            cur[j] = v;
        }
        if cur.iter().all(|&v| v > bound) {
            return None;
        }
        std::mem::swap(&mut before, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    Some(prev[m]).filter(|&d| d <= bound)
}
