//! `inspc view`: on every example and real part, one self-contained page (nothing fetched)
//! and one image per setup; in a real headless Chromium (Debian's), each page loads and
//! draws with no error, and each example's screenshot matches its reference in
//! `tests/view/` within an image-difference threshold (`INSPC_BLESS=1` rewrites them).
//! Without Chromium the browser half says it skipped, unless `INSPC_REQUIRE_CHROMIUM=1`
//! (`.ci/run` sets it where it installed Chromium), when it fails.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The screenshot's size: the page's side panel and a 640 × 480 view.
const WINDOW: (u32, u32) = (890, 480);

fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("INSPC_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
        .iter()
        .map(PathBuf::from)
        .find(|p| p.exists())
}

/// Runs headless Chromium on a page with the flags this network needs (no background
/// connections, no first-run or component fetches) and a fresh profile.
fn browse(chrome: &Path, page: &Path, extra: &[String]) -> std::process::Output {
    let profile = page.with_extension("profile");
    let out = Command::new(chrome)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--force-device-scale-factor=1",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("run chromium");
    let _ = std::fs::remove_dir_all(&profile);
    out
}

fn decode(bytes: &[u8]) -> (u32, u32, Vec<[u8; 3]>) {
    let mut dec = png::Decoder::new(std::io::Cursor::new(bytes));
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut r = dec.read_info().expect("a PNG");
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).expect("a frame");
    let channels = info.color_type.samples();
    let px = buf[..info.buffer_size()]
        .chunks(channels)
        .map(|c| match channels {
            1 | 2 => [c[0]; 3],
            _ => [c[0], c[1], c[2]],
        })
        .collect();
    (info.width, info.height, px)
}

/// The share of pixels that differ by more than 48 in some channel.
fn difference(a: &[u8], b: &[u8]) -> f64 {
    let (wa, ha, pa) = decode(a);
    let (wb, hb, pb) = decode(b);
    assert_eq!((wa, ha), (wb, hb), "the screenshot's size changed");
    let differ = pa
        .iter()
        .zip(&pb)
        .filter(|(x, y)| (0..3).any(|k| x[k].abs_diff(y[k]) > 48))
        .count();
    differ as f64 / pa.len() as f64
}

fn specs() -> Vec<(PathBuf, bool)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out: Vec<(PathBuf, bool)> = std::fs::read_dir(root.join("examples"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "insp"))
        .map(|p| (p, true))
        .collect();
    crate::common::require_shared_parts();
    let quick = !crate::common::slow();
    for name in ["nist_ctc_01", "nist_ctc_02", "nist_ftc_06", "nist_ftc_08"] {
        if quick && matches!(name, "nist_ctc_02" | "nist_ftc_06") {
            continue;
        }
        out.push((root.join(format!("tests/real/{name}.insp")), false));
    }
    out.sort();
    out
}

#[test]
fn every_example_and_real_part_views_in_a_headless_browser() {
    let chrome = chromium().filter(|_| !crate::common::skip_unless_slow("the pages in Chromium"));
    if chrome.is_none() && crate::common::slow() {
        assert!(
            std::env::var_os("INSPC_REQUIRE_CHROMIUM").is_none(),
            "INSPC_REQUIRE_CHROMIUM is set but Chromium is not found"
        );
        eprintln!("the browser checks are skipped: Chromium is not installed");
    }
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let dir = std::env::temp_dir().join(format!("inspc-view-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    for (spec, reference) in specs() {
        let name = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let page = dir.join(format!("{name}.html"));
        let images = dir.join(format!("{name}_png"));
        let out = Command::new(env!("CARGO_BIN_EXE_inspc"))
            .arg("view")
            .arg(&spec)
            .arg("-o")
            .arg(&page)
            .arg("--png")
            .arg(&images)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "inspc view {name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let html = std::fs::read_to_string(&page).unwrap();
        // Self-contained: no address to fetch anything from.
        for bad in [
            "src=\"http",
            "href=\"http",
            "<link",
            "@import",
            "fetch(",
            "XMLHttpRequest",
        ] {
            assert!(!html.contains(bad), "{name}: the page holds `{bad}`");
        }
        let setups = std::fs::read_dir(&images).unwrap().count();
        assert!(setups >= 1, "{name}: no image");
        for k in 1..=setups {
            let png = std::fs::read(images.join(format!("{name}_setup{k}.png"))).unwrap();
            let (w, h, px) = decode(&png);
            assert_eq!((w, h), (960, 720));
            // The part is drawn: a good share of the image is not background.
            let drawn = px.iter().filter(|p| **p != [248, 248, 248]).count();
            assert!(
                drawn > px.len() / 20,
                "{name} setup {k}: {drawn} pixels drawn"
            );
        }
        let Some(chrome) = &chrome else { continue };
        let dom = browse(
            chrome,
            &page,
            &["--dump-dom".into(), "--virtual-time-budget=5000".into()],
        );
        let dom = String::from_utf8_lossy(&dom.stdout);
        if !dom.contains("<div id=\"status\">ready</div>") {
            let status = dom
                .split("id=\"status\">")
                .nth(1)
                .and_then(|s| s.split('<').next());
            failures.push(format!("{name}: the page says {status:?}"));
            continue;
        }
        if !reference {
            continue;
        }
        let shot = dir.join(format!("{name}.png"));
        let size = format!("--window-size={},{}", WINDOW.0, WINDOW.1);
        browse(
            chrome,
            &page,
            &[size, format!("--screenshot={}", shot.display())],
        );
        let shot = std::fs::read(&shot).expect("a screenshot");
        let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/view/{name}.png"));
        if bless {
            std::fs::write(&golden, &shot).unwrap();
            continue;
        }
        let Ok(expected) = std::fs::read(&golden) else {
            failures.push(format!(
                "{name}: no reference {} (bless with INSPC_BLESS=1)",
                golden.display()
            ));
            continue;
        };
        let d = difference(&expected, &shot);
        eprintln!(
            "view {name}: {:.3} % of pixels differ from the reference",
            100.0 * d
        );
        if d > 0.02 {
            failures.push(format!(
                "{name}: {:.2} % of the screenshot's pixels differ from {}",
                100.0 * d,
                golden.display()
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The class of strings that reach the page: face, feature, probe, holder and plan names
/// holding `</script>`, `<!--<script>`, quotes, ampersands and U+2028. The scene inlined
/// in the page's script holds no `<` (nor `>`, `&`, U+2028/2029) and reads back as the
/// scene; the title holds none of `<>"'&` raw; the rest of the page is the template's.
#[test]
fn hostile_names_cannot_leave_the_pages_script() {
    use inspc::view::{page, FaceInfo, GroupInfo, Mesh, Named, ProbeInfo, Scene, SetupInfo};
    const NAMES: &[&str] = &[
        "</script><script>alert(1)</script>",
        "<!--<script>",
        "a\"b'c&amp;d",
        "x\u{2028}y\u{2029}z",
        "/*{{SCENE}}*/null {{TITLE}}",
        "]]><![CDATA[",
    ];
    let named = |k: usize| NAMES[k % NAMES.len()].to_string();
    let scene = Scene {
        title: format!("plan {}: part {}", named(0), named(1)),
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
        tri_face: vec![0],
        faces: (0..NAMES.len())
            .map(|k| FaceInfo {
                name: named(k),
                feature: Some(k),
            })
            .collect(),
        features: (0..NAMES.len())
            .map(|k| Named {
                name: named(k + 1),
                color: named(k + 2),
            })
            .collect(),
        probes: vec![ProbeInfo {
            name: named(3),
            color: named(4),
            tip: 1.0,
            components: vec![],
        }],
        points: vec![],
        setups: vec![SetupInfo {
            held_by: named(4),
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            table: 0.0,
            fixture: Mesh::default(),
            groups: vec![GroupInfo {
                probe: 0,
                a: 0.0,
                b: 0.0,
                direction: [0.0, 0.0, 1.0],
                path: vec![],
                touches: vec![(0, named(5))],
            }],
            yaw: 0.0,
        }],
        sphere: vec![],
    };
    let html = page(&scene);
    let template = include_str!("../../src/view/viewer.html");
    let (head, rest) = template.split_once("{{TITLE}}").unwrap();
    let (middle, tail) = rest.split_once("/*{{SCENE}}*/null").unwrap();
    assert!(
        html.starts_with(head) && html.ends_with(tail),
        "the template kept"
    );
    let title = &html[head.len()..html.find(middle).expect("the template's middle")];
    assert!(!title.contains(['<', '>', '"', '\'']), "{title}");
    let json = &html[head.len() + title.len() + middle.len()..html.len() - tail.len()];
    for c in ['<', '>', '&', '\u{2028}', '\u{2029}'] {
        assert!(!json.contains(c), "{c:?} raw in the script: {json}");
    }
    let back: serde_json::Value = serde_json::from_str(json).expect("the scene's JSON");
    assert_eq!(back, serde_json::to_value(&scene).unwrap());
}
