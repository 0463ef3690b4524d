//! The integration tests, as one binary: one link instead of one per file, and its tests
//! run side by side (the long golden cases beside the accessibility checks). Run a part
//! with `cargo test --test suite <module>::`, e.g. `cargo test --test suite cases::`.

mod common;

mod access;
mod architecture;
mod cad_hostile;
mod cad_kinds;
mod cases;
mod catalogue;
mod cli;
mod cluster_props;
mod density;
mod diag_files;
mod diagnostics;
mod dmis_foreign;
mod examples;
mod fmt;
mod fpoints;
mod geometry_props;
mod gpu;
mod grammar;
mod import;
mod lsp;
mod mesh_fuzz;
mod no_panic;
mod qif;
mod qif_results;
mod replan;
mod room;
mod sampling;
mod scan;
mod simulate;
mod step;
mod tours;
mod verify;
mod view;
mod vscode;
mod workholding;
