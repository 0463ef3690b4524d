//! `inspc view`: on every example and real part, one self-contained page (nothing fetched)
//! and one image per setup; in a real headless Chromium (Debian's), each page loads and
//! draws with no error, and each example's screenshot matches its reference in
//! `tests/view/` within an image-difference threshold (`INSPC_BLESS=1` rewrites them).
//! Without Chromium the browser half says it skipped, unless `INSPC_REQUIRE_CHROMIUM=1`
//! (`.ci/run` sets it where it installed Chromium), when it fails.
//!
//! What a metrologist expects of it (issue 50), checked on the same pages: each image
//! has a caption and a legend of its colours; in the browser (`tests/view/probe.js`
//! drives the page and reads its `window.__inspc` hook and canvas) the camera stays
//! above the table and the zoom within bounds, points behind the part are not drawn
//! over it, probes and features never share a colour, the hold text names faces as the
//! spec does and is never cut off, and each setup opens from the side its measured
//! faces face.

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

/// The scene inlined in a page written by `inspc view`.
fn page_scene(html: &str) -> serde_json::Value {
    let json = html
        .split_once("const SCENE = ")
        .and_then(|(_, rest)| rest.split_once(";\nconst status"))
        .map(|(json, _)| json)
        .expect("the page's scene");
    serde_json::from_str(json).expect("the scene's JSON")
}

fn rgb8(hex: &str) -> [u8; 3] {
    let v = u32::from_str_radix(hex.trim_start_matches('#'), 16).expect("a #rrggbb colour");
    [(v >> 16) as u8, (v >> 8) as u8, v as u8]
}

/// CIE L*a*b* of an sRGB colour (D65).
fn lab(c: [u8; 3]) -> [f64; 3] {
    let lin = |v: u8| {
        let v = v as f64 / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    let [r, g, b] = c.map(lin);
    let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
    let f = |t: f64| {
        if t > 0.008856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The CIE76 colour difference: about 2.3 is just noticeable, 30 plainly another colour.
fn delta_e(a: [u8; 3], b: [u8; 3]) -> f64 {
    let (a, b) = (lab(a), lab(b));
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The caption's text colour (`src/view/caption.rs`).
const TEXT: [u8; 3] = [34, 34, 34];

/// Setup `k`'s image has a caption (text along its top, nothing else there) and a legend
/// with a swatch of each feature's colour and each of the setup's probes' colour.
fn check_caption_and_legend(
    name: &str,
    k: usize,
    png: &[u8],
    scene: &serde_json::Value,
) -> Vec<String> {
    let (w, h, px) = decode(png);
    let (w, h) = (w as usize, h as usize);
    let mut bad = Vec::new();
    let band = &px[..w * 30];
    let text = band.iter().filter(|p| **p == TEXT).count();
    if text < 150 || band.iter().any(|p| *p != TEXT && *p != [248; 3]) {
        bad.push(format!(
            "{name} setup {k}: no caption along the top ({text} text pixels)"
        ));
    }
    let setup = &scene["setups"][k - 1];
    let mut colors: Vec<String> = scene["features"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["color"].as_str().unwrap().to_string())
        .collect();
    for g in setup["groups"].as_array().unwrap() {
        let p = g["probe"].as_u64().unwrap() as usize;
        colors.push(scene["probes"][p]["color"].as_str().unwrap().to_string());
    }
    // A swatch: an 8 × 8 block of exactly the colour in the bottom quarter.
    let swatch = |c: [u8; 3]| {
        (h * 3 / 4..h - 8).any(|y| {
            (0..w - 8).any(|x| (0..8).all(|dy| (0..8).all(|dx| px[(y + dy) * w + x + dx] == c)))
        })
    };
    for c in colors {
        if !swatch(rgb8(&c)) {
            bad.push(format!("{name} setup {k}: the legend has no swatch of {c}"));
        }
    }
    bad
}

/// The page as a user drives it (`tests/view/probe.js`): returns the failures and how
/// many points facing away from the camera it checked.
fn check_page_as_a_user(
    chrome: &Path,
    page: &Path,
    html: &str,
    name: &str,
) -> (Vec<String>, usize) {
    let at = html.rfind("</body>").expect("the page's end");
    let probe = format!(
        "{}<script>\n{}</script>\n{}",
        &html[..at],
        include_str!("../view/probe.js"),
        &html[at..]
    );
    let driven = page.with_file_name(format!("{name}_driven.html"));
    std::fs::write(&driven, probe).unwrap();
    let dom = browse(
        chrome,
        &driven,
        &["--dump-dom".into(), "--virtual-time-budget=5000".into()],
    );
    let dom = String::from_utf8_lossy(&dom.stdout);
    let Some(json) = dom
        .split_once("<pre id=\"inspc-test\">")
        .and_then(|(_, rest)| rest.split_once("</pre>"))
        .map(|(json, _)| {
            json.replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&nbsp;", " ")
                .replace("&amp;", "&")
        })
    else {
        return (vec![format!("{name}: the driven page wrote no result")], 0);
    };
    let seen: serde_json::Value = serde_json::from_str(&json).expect("probe.js's JSON");
    if let Some(e) = seen["error"].as_str() {
        return (vec![format!("{name}: driving the page failed: {e}")], 0);
    }
    let mut bad = check_camera(name, &seen);
    bad.extend(check_palette(name, &seen["palette"]));
    bad.extend(check_held(name, &seen));
    let (occlusion, back) = check_occlusion(name, &seen);
    bad.extend(occlusion);
    (bad, back)
}

/// Item 1: a drag far up keeps the camera 5° or more above the table, a drag far down
/// stops it looking straight down, and the wheel keeps the zoom within 0.25 to 20 times
/// the fitted view. Item 6: each setup's default camera looks from the side its
/// measured faces face (within about 45° of their mean normal, where they agree).
fn check_camera(name: &str, seen: &serde_json::Value) -> Vec<String> {
    let mut bad = Vec::new();
    let d = &seen["drag"];
    let (up, down) = (d["up"].as_f64().unwrap(), d["down"].as_f64().unwrap());
    if !(5.0 - 1e-9..=90.0 + 1e-9).contains(&up) || !(5.0 - 1e-9..=90.0 + 1e-9).contains(&down) {
        bad.push(format!(
            "{name}: dragging takes the camera to {up:.1}° and {down:.1}° of elevation"
        ));
    }
    let (zout, zin) = (d["out"].as_f64().unwrap(), d["in"].as_f64().unwrap());
    if !(0.25..=20.0).contains(&zout) || !(0.25..=20.0).contains(&zin) {
        bad.push(format!("{name}: the wheel zooms to {zout} and {zin}"));
    }
    for (k, s) in seen["setups"].as_array().unwrap().iter().enumerate() {
        let v = |x: &serde_json::Value| -> Vec<f64> {
            x.as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_f64().unwrap())
                .collect()
        };
        let (m, eye) = (v(&s["mean_normal"]), v(&s["camera"]["eye"]));
        let len = m.iter().map(|x| x * x).sum::<f64>().sqrt();
        let pitch = s["camera"]["pitch"].as_f64().unwrap();
        let facing = m.iter().zip(&eye).map(|(a, b)| a * b).sum::<f64>() / len.max(1e-12);
        if pitch < 5.0 || (len >= 0.3 && facing < 0.7) {
            bad.push(format!("{name} setup {}: the camera ({eye:?}, {pitch:.1}° up) looks away from the measured faces' mean normal {m:?}", k + 1));
        }
    }
    bad
}

/// Item 3: every probe's colour is plainly another colour than every feature's and the
/// unnamed faces' (CIE76 ΔE ≥ 30), and the probes' differ from each other.
fn check_palette(name: &str, palette: &serde_json::Value) -> Vec<String> {
    let list = |k: &str| -> Vec<String> {
        palette[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_str().unwrap().to_string())
            .collect()
    };
    let mut faces = list("features");
    faces.push(palette["other"].as_str().unwrap().to_string());
    let probes = list("probes");
    let mut bad = Vec::new();
    for (i, p) in probes.iter().enumerate() {
        for f in &faces {
            let d = delta_e(rgb8(p), rgb8(f));
            if d < 30.0 {
                bad.push(format!(
                    "{name}: probe colour {p} and face colour {f} differ by ΔE {d:.1}"
                ));
            }
        }
        if probes[..i].contains(p) {
            bad.push(format!("{name}: two probes share {p}"));
        }
    }
    bad
}

/// Item 4: the hold text is never cut off, and names no face by an import's number
/// (`face_105`) outside brackets.
fn check_held(name: &str, seen: &serde_json::Value) -> Vec<String> {
    let mut bad = Vec::new();
    for (k, s) in seen["setups"].as_array().unwrap().iter().enumerate() {
        let held = s["held"].as_str().unwrap();
        let mut bare = String::new();
        let mut depth = 0;
        for c in held.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                c if depth == 0 => bare.push(c),
                _ => {}
            }
        }
        let numbered = bare
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .any(|w| {
                w.strip_prefix("face_")
                    .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
            });
        if !s["held_fits"].as_bool().unwrap() || numbered || !held.starts_with("held by ") {
            bad.push(format!(
                "{name} setup {}: the hold text {held:?} is cut off or names a face by its number",
                k + 1
            ));
        }
    }
    bad
}

/// Item 2: with the paths and the probe hidden, a point on a face turned away from the
/// camera (behind the solid) is reported hidden and its centre is not painted in its
/// probe's colour, unless another point in view is drawn over it; a point in view
/// shows its colour, unless another is drawn over it. Returns the failures and how many points facing away were checked.
fn check_occlusion(name: &str, seen: &serde_json::Value) -> (Vec<String>, usize) {
    let markers = seen["markers"].as_array().unwrap();
    let f = |m: &serde_json::Value, k: &str| m[k].as_f64().unwrap();
    let mut bad = Vec::new();
    let mut back = 0;
    for m in markers {
        let color = rgb8(m["color"].as_str().unwrap());
        let px: Vec<u8> = m["pixel"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as u8)
            .collect();
        // A point in view is filled with its colour exactly (its centre has no edge to
        // smooth); one behind the part is a faint ring around what is there.
        let shows = (0..3).all(|i| px[i].abs_diff(color[i]) <= 8);
        let hidden = m["hidden"].as_bool().unwrap();
        let covered = markers.iter().any(|o| {
            o["setup"] == m["setup"]
                && !std::ptr::eq(o, m)
                && !o["hidden"].as_bool().unwrap()
                && (f(o, "x") - f(m, "x")).hypot(f(o, "y") - f(m, "y")) < 8.0
        });
        if f(m, "nz") < -0.2 {
            back += 1;
            if !hidden || (shows && !covered) {
                bad.push(format!(
                    "{name}: a point behind the part is drawn over it: {m}"
                ));
            }
        } else if !hidden && !shows && !covered {
            bad.push(format!(
                "{name}: a point in view is not drawn in its colour: {m}"
            ));
        }
    }
    (bad, back)
}

/// The binary to run: `INSPC_BIN` where a target directory shared by several checkouts
/// may hold another's build by the time the test runs, else Cargo's.
fn inspc() -> PathBuf {
    std::env::var_os("INSPC_BIN")
        .map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_inspc")), PathBuf::from)
}

/// Each setup's image: its size, the part drawn, its caption and legend.
fn check_images(name: &str, images: &Path, scene: &serde_json::Value) -> Vec<String> {
    let mut failures = Vec::new();
    let setups = std::fs::read_dir(images).unwrap().count();
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
        failures.extend(check_caption_and_legend(name, k, &png, scene));
    }
    failures
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
    // Asked for by name, the browser runs without INSPC_SLOW too.
    let required = std::env::var_os("INSPC_REQUIRE_CHROMIUM").is_some();
    let chrome = chromium()
        .filter(|_| required || !crate::common::skip_unless_slow("the pages in Chromium"));
    if chrome.is_none() && (required || crate::common::slow()) {
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
    let mut back_facing = 0;
    for (spec, reference) in specs() {
        let name = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let page = dir.join(format!("{name}.html"));
        let images = dir.join(format!("{name}_png"));
        let out = Command::new(inspc())
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
        let scene = page_scene(&html);
        failures.extend(check_images(&name, &images, &scene));
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
        let (bad, back) = check_page_as_a_user(chrome, &page, &html, &name);
        failures.extend(bad);
        back_facing += back;
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
    assert!(
        chrome.is_none() || back_facing > 0,
        "no point behind a part was checked"
    );
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
            up: named(5),
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
            pitch: 30.0,
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
