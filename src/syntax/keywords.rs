//! The words the grammar reserves, in one list for every stage that writes or checks a
//! name (the language server's rename, `inspc import`); a test reads them from
//! `grammar/insp.pest`.

/// The grammar's keywords (`grammar/insp.pest`, the `kw_` rules and `block_kw`): a name
/// spelt like one would read as the keyword where the keyword may stand.
pub(crate) const KEYWORDS: &[&str] = &[
    "use",
    "part",
    "plan",
    "hierarchy",
    "required",
    "units",
    "stock",
    "mesh",
    "cut",
    "add",
    "face",
    "feature",
    "datum",
    "frame",
    "tolerance",
    "group",
    "segment",
    "step_face",
    "qif_face",
    "select",
    "prefer",
    "forbid",
    "sample",
    "with",
    "cmm",
    "head",
    "probe",
    "stylus",
    "body",
    "extension",
    "sampling",
    "fixture",
    "scanner",
];

#[cfg(test)]
mod tests {
    /// KEYWORDS lists exactly the grammar's keywords.
    #[test]
    fn keywords_are_the_grammars() {
        let grammar = include_str!("../../grammar/insp.pest");
        let mut words: Vec<&str> = Vec::new();
        for line in grammar.lines() {
            let line = line.trim_start();
            if line.starts_with("kw_") || line.starts_with("block_kw") {
                words.extend(line.split('"').skip(1).step_by(2));
            }
        }
        let mut reserved = super::KEYWORDS.to_vec();
        words.sort_unstable();
        reserved.sort_unstable();
        assert_eq!(words, reserved);
    }
}
