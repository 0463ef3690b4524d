//! The VS Code extension (`editors/vscode/`) built and tested with its npm toolchain: its
//! grammar in step with `grammar/insp.pest` and tokenizing real specs, the command it
//! starts serving a spec (this build's `inspc lsp`), and the package (`.vsix`) built.
//! Without npm the test says it skipped, unless `INSPC_REQUIRE_NPM=1` (set by `.ci/run`
//! where npm exists), when it fails.

use std::path::Path;
use std::process::Command;

fn npm(dir: &Path, args: &[&str]) {
    let out = Command::new("npm")
        .args(args)
        .current_dir(dir)
        .env("INSPC", env!("CARGO_BIN_EXE_inspc"))
        .env("npm_config_update_notifier", "false")
        .output()
        .unwrap_or_else(|e| panic!("npm {args:?}: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "npm {args:?} failed:\n{text}");
    eprintln!("npm {args:?}: ok");
}

#[test]
fn the_extension_builds_and_its_tests_pass() {
    if crate::common::skip_unless_slow("the VS Code extension's npm build and tests") {
        return;
    }
    let has_npm = Command::new("npm")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_npm {
        assert!(
            std::env::var_os("INSPC_REQUIRE_NPM").is_none(),
            "INSPC_REQUIRE_NPM is set but npm is not found"
        );
        eprintln!("skipped: npm is not installed");
        return;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("editors/vscode");
    if !dir.join("node_modules").exists() {
        npm(&dir, &["ci", "--no-audit", "--no-fund"]);
    }
    npm(&dir, &["test"]);
    let _ = std::fs::remove_file(dir.join("dist/inspc.vsix"));
    npm(&dir, &["run", "package"]);
    let vsix = std::fs::metadata(dir.join("dist/inspc.vsix")).expect("the package");
    assert!(vsix.len() > 10_000, "a {} byte package", vsix.len());
}
