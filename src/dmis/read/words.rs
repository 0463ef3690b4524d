//! The major words of DMIS: those the standard defines, those inspc's virtual CMM runs,
//! and vendor extensions known by name.
//!
//! The standard's words are the statement index of ANSI/DMIS 105.2 part 1 (5.3), §6;
//! the list agrees with the statement set of the DMIS test files NIST published with
//! its DMIS test suite and the "Supported DMIS Commands" tables vendors publish. A word
//! outside it is a vendor extension: named as such where its vendor is known, else an
//! unknown statement. Either is read (its parameters kept) and reported, never dropped
//! without a word.

/// Every major word of DMIS 5.3 (sorted, for a binary search).
const STANDARD: &[&str] = &[
    "ACLRAT",
    "ALGDEF",
    "ASSIGN",
    "BADTST",
    "BOUND",
    "CALIB",
    "CALL",
    "CASE",
    "CLMPID",
    "CLMPSN",
    "CLOSE",
    "CMPNTGRP",
    "CNFRPT",
    "CONST",
    "CRGDEF",
    "CRMODE",
    "CROSCL",
    "CRSLCT",
    "CUTCOM",
    "CZONE",
    "CZSLCT",
    "DATDEF",
    "DATSET",
    "DATTRGDEF",
    "DECL",
    "DECPL",
    "DELETE",
    "DEVICE",
    "DFTCAS",
    "DISPLY",
    "DMEHW",
    "DMEID",
    "DMESW",
    "DMESWI",
    "DMESWV",
    "DMISMD",
    "DMISMN",
    "DO",
    "ELSE",
    "ENDAS",
    "ENDCAS",
    "ENDDO",
    "ENDFIL",
    "ENDGO",
    "ENDIF",
    "ENDMAC",
    "ENDMES",
    "ENDSEL",
    "ENDSIMREQT",
    "ENDXTN",
    "EQUATE",
    "ERROR",
    "EVAL",
    "EXTENS",
    "EXTFIL",
    "FEAT",
    "FEDRAT",
    "FILDEF",
    "FILNAM",
    "FINPOS",
    "FIXTID",
    "FIXTSN",
    "FLY",
    "FROM",
    "GEOALG",
    "GEOM",
    "GOHOME",
    "GOTARG",
    "GOTO",
    "GROUP",
    "IF",
    "INCLUD",
    "ITERAT",
    "JUMPTO",
    "KEYCHAR",
    "LITDEF",
    "LOCATE",
    "LOTID",
    "MACRO",
    "MEAS",
    "MFGDEV",
    "MODE",
    "OBTAIN",
    "OPEN",
    "OPERID",
    "OUTPUT",
    "PAMEAS",
    "PARTID",
    "PARTRV",
    "PARTSN",
    "PATH",
    "PAUSE",
    "PLANID",
    "POP",
    "PRCOMP",
    "PREVOP",
    "PROCID",
    "PROMPT",
    "PSTHRU",
    "PTBUFF",
    "PTMEAS",
    "PUSH",
    "QISDEF",
    "RAPID",
    "READ",
    "RECALL",
    "REFMNT",
    "REPORT",
    "RESUME",
    "RMEAS",
    "ROTAB",
    "ROTATE",
    "ROTDEF",
    "ROTSET",
    "SAVE",
    "SCNMOD",
    "SCNSET",
    "SELECT",
    "SENSOR",
    "SIMREQT",
    "SNSDEF",
    "SNSET",
    "SNSGRP",
    "SNSLCT",
    "SNSMNT",
    "TECOMP",
    "TEXT",
    "THLDEF",
    "TOL",
    "TOOLDF",
    "TRANS",
    "UNITS",
    "VALUE",
    "VFORM",
    "WINDEF",
    "WKPLAN",
    "WRIST",
    "WRITE",
    "XTERN",
    "XTRACT",
];

/// Vendor extensions seen in published programs, with their vendor.
const VENDOR: &[(&str, &str)] = &[
    (
        "LIGHTOPTION",
        "a vision sensor's lighting (vendor vision extension)",
    ),
    ("W3D", "a vendor's 3D scanning extension"),
    ("SNSDEF_EXT", "a vendor's sensor definition"),
];

/// What inspc's virtual CMM runs (`inspc simulate`). Statements that set what a real
/// controller needs and a virtual one has no use for are run as accepted: feed rates
/// (`FEDRAT`, `ACLRAT`), probe compensation (`PRCOMP`: the virtual CMM always
/// compensates), the work plane, decimals shown, identification (`FILNAM`, `PARTID`, …)
/// and the results file (`DEVICE`, `OPEN`, `CLOSE`, `DISPLY`: results go where
/// `--report` says).
const RUN: &[&str] = &[
    "ACLRAT", "CLOSE", "CONST", "DATDEF", "DATSET", "DECPL", "DEVICE", "DISPLY", "DMISMD",
    "DMISMN", "ENDFIL", "ENDMES", "FEAT", "FEDRAT", "FILNAM", "GOTO", "MEAS", "MODE", "OPEN",
    "OUTPUT", "PAMEAS", "PARTID", "PARTRV", "PARTSN", "PATH", "PAUSE", "PLANID", "PRCOMP",
    "PTMEAS", "RECALL", "ROTATE", "SAVE", "SNSDEF", "SNSET", "SNSLCT", "TEXT", "TOL", "TRANS",
    "UNITS", "WKPLAN",
];

/// What a major word is to inspc.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Word {
    /// A DMIS statement the virtual CMM runs.
    Runs,
    /// A DMIS statement the virtual CMM reads but does not run.
    Reads,
    /// A vendor extension, with what it is for.
    Vendor(&'static str),
    /// Neither DMIS nor a known extension.
    Unknown,
}

/// What `major` is.
pub fn word(major: &str) -> Word {
    if RUN.binary_search(&major).is_ok() {
        return Word::Runs;
    }
    if STANDARD.binary_search(&major).is_ok() {
        return Word::Reads;
    }
    match VENDOR.iter().find(|(w, _)| *w == major) {
        Some((_, what)) => Word::Vendor(what),
        None => Word::Unknown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lists_are_sorted_and_run_only_dmis() {
        assert!(STANDARD.windows(2).all(|w| w[0] < w[1]));
        assert!(RUN.windows(2).all(|w| w[0] < w[1]));
        for w in RUN {
            assert!(STANDARD.contains(w), "{w}");
        }
        assert_eq!(word("GOTO"), Word::Runs);
        assert_eq!(word("IF"), Word::Reads);
        assert!(matches!(word("LIGHTOPTION"), Word::Vendor(_)));
        assert_eq!(word("FROBNICATE"), Word::Unknown);
    }
}
