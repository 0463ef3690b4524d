//! "Did you mean …": the one helper every unknown-name diagnostic uses.

/// The candidate closest to `name`, if it is close enough to be a plausible typo.
///
/// Close enough means an edit distance of at most a third of the name's length
/// (at least 1), or a case-insensitive match. Ties go to the first candidate, so the
/// answer is deterministic given the candidates' order.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    let limit = (name.chars().count() / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for cand in candidates {
        if cand == name {
            continue;
        }
        let d = if cand.eq_ignore_ascii_case(name) {
            0
        } else {
            edit_distance(name, cand)
        };
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, cand));
        }
    }
    best.map(|(_, c)| c.to_string())
}

/// A help line for an unknown name: the suggestion if there is one, otherwise the list of
/// what is known (up to eight names).
pub fn help_for_unknown<'a>(
    what: &str,
    name: &str,
    candidates: impl IntoIterator<Item = &'a str> + Clone,
) -> String {
    if let Some(s) = did_you_mean(name, candidates.clone()) {
        return format!("did you mean `{s}`?");
    }
    let all: Vec<&str> = candidates.into_iter().collect();
    if all.is_empty() {
        return format!("no {what} is declared here");
    }
    let shown: Vec<String> = all.iter().take(8).map(|c| format!("`{c}`")).collect();
    let more = if all.len() > 8 {
        format!(" and {} more", all.len() - 8)
    } else {
        String::new()
    };
    format!("known {}: {}{more}", plural(what), shown.join(", "))
}

/// Edit distance over characters where swapping two neighbours counts as one edit
/// (optimal string alignment), so `widht` is one edit from `width`.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[a.len()][b.len()]
}

/// The plural of a noun naming a kind of item (`property` → `properties`).
fn plural(what: &str) -> String {
    match what.strip_suffix('y') {
        Some(stem) if !stem.ends_with(['a', 'e', 'o', 'u']) => format!("{stem}ies"),
        _ if what.ends_with('s') || what.ends_with('x') => format!("{what}es"),
        _ => format!("{what}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(
            did_you_mean("widht", ["width", "depth"]),
            Some("width".into())
        );
        assert_eq!(did_you_mean("TP20", ["PH6", "PH10MQ"]), None);
        assert_eq!(did_you_mean("mM", ["mm", "cm"]), Some("mm".into()));
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
