//! The standard library, embedded in the binary from `stdlib/`.
//!
//! **Decision: catalogue figures** in `stdlib/` are Renishaw's published ranges
//! (PH9/PH10: A 0–105°, B ±180°, 7.5° steps, 720 orientations) and rounded envelopes;
//! the stdlib's comments say so.

/// Every standard module: its `use` name and its source.
pub const STD_MODULES: &[(&str, &str)] = &[
    ("std::heads", include_str!("../../stdlib/heads.insp")),
    ("std::styli", include_str!("../../stdlib/styli.insp")),
    ("std::probes", include_str!("../../stdlib/probes.insp")),
    ("std::cmms", include_str!("../../stdlib/cmms.insp")),
    (
        "std::hierarchies",
        include_str!("../../stdlib/hierarchies.insp"),
    ),
    ("std::sampling", include_str!("../../stdlib/sampling.insp")),
    ("std::fixtures", include_str!("../../stdlib/fixtures.insp")),
    ("std::scanners", include_str!("../../stdlib/scanners.insp")),
];

/// The names of the standard modules.
pub fn std_module_names() -> impl Iterator<Item = &'static str> + Clone {
    STD_MODULES.iter().map(|(n, _)| *n)
}
