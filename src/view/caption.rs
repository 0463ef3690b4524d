//! The caption and legend of a setup's image (`inspc view --png`), drawn with the
//! built-in font: the caption on top says which plan, which setup, which way up and how
//! the part is held, and with which probes; the legend below gives each colour used —
//! the features, the faces no feature names, each probe's paths and points.

use super::font::{wrap, Image, ADVANCE, GLYPH_H};
use super::Scene;

/// The text's colour.
pub(crate) const TEXT: [u8; 3] = [34, 34, 34];

/// Font pixels per image pixel, the space around the text and between lines (px).
const SCALE: usize = 2;
const PAD: usize = 8;
const LINE: usize = GLYPH_H * SCALE + 4;

/// A legend swatch's side and the gap after an entry (px).
const SWATCH: usize = 14;
const GAP: usize = 18;

/// `#rrggbb` as RGB (grey for anything else).
pub(crate) fn rgb8(c: &str) -> [u8; 3] {
    let v = c
        .strip_prefix('#')
        .filter(|h| h.len() == 6)
        .and_then(|h| u32::from_str_radix(h, 16).ok())
        .unwrap_or(0x888888);
    [(v >> 16) as u8, (v >> 8) as u8, v as u8]
}

/// The caption's lines before wrapping.
fn caption_text(scene: &Scene, setup: usize) -> Vec<String> {
    let Some(s) = scene.setups.get(setup) else {
        return Vec::new();
    };
    let mut probes: Vec<String> = Vec::new();
    for g in &s.groups {
        let Some(p) = scene.probes.get(g.probe) else {
            continue;
        };
        let name = if g.a != 0.0 || g.b != 0.0 {
            format!("{} at A {} B {}", p.name, g.a, g.b)
        } else {
            p.name.clone()
        };
        if !probes.contains(&name) {
            probes.push(name);
        }
    }
    vec![
        format!(
            "{} - setup {} of {}",
            scene.title,
            setup + 1,
            scene.setups.len()
        ),
        format!("{}, held by {}", s.up, s.held_by),
        format!("probes: {}", probes.join(", ")),
    ]
}

/// Draws the caption along the image's top; returns the height it takes (px).
pub(crate) fn caption(image: &mut Image, scene: &Scene, setup: usize) -> usize {
    let width = image.w.saturating_sub(2 * PAD) / (ADVANCE * SCALE);
    let lines: Vec<String> = caption_text(scene, setup)
        .iter()
        .flat_map(|l| wrap(l, width))
        .collect();
    for (i, l) in lines.iter().enumerate() {
        image.text(PAD, PAD + i * LINE, l, SCALE, TEXT);
    }
    PAD + lines.len() * LINE
}

/// The legend's entries: a name and its colour.
fn legend_entries(scene: &Scene, setup: usize) -> Vec<(String, [u8; 3])> {
    let mut out: Vec<(String, [u8; 3])> = scene
        .features
        .iter()
        .map(|f| (f.name.clone(), rgb8(&f.color)))
        .collect();
    if scene.faces.iter().any(|f| f.feature.is_none()) {
        out.push(("other faces".into(), rgb8(super::OTHER_FACES)));
    }
    let Some(s) = scene.setups.get(setup) else {
        return out;
    };
    let mut used: Vec<usize> = s.groups.iter().map(|g| g.probe).collect();
    used.sort_unstable();
    used.dedup();
    for p in used.iter().filter_map(|k| scene.probes.get(*k)) {
        out.push((format!("probe {} path, points", p.name), rgb8(&p.color)));
    }
    out
}

/// Draws the legend along the image's bottom, its entries in rows, and a last line on
/// what is faint; returns the height it takes (px).
pub(crate) fn legend(image: &mut Image, scene: &Scene, setup: usize) -> usize {
    let entries = legend_entries(scene, setup);
    let char_w = ADVANCE * SCALE;
    let max_chars = image.w.saturating_sub(2 * PAD + SWATCH + 6) / char_w;
    // Lay the entries out in rows first: the legend's height places it.
    let mut rows: Vec<Vec<(String, [u8; 3], usize)>> = vec![Vec::new()];
    let mut x = PAD;
    for (name, color) in entries {
        let name: String = name.chars().take(max_chars.max(1)).collect();
        let w = SWATCH + 6 + name.chars().count() * char_w;
        if x + w > image.w.saturating_sub(PAD) && x > PAD {
            rows.push(Vec::new());
            x = PAD;
        }
        if let Some(row) = rows.last_mut() {
            row.push((name, color, x));
        }
        x += w + GAP;
    }
    let note = "paths and points behind the part are drawn faintly";
    let height = (rows.len() + 1) * LINE + PAD;
    let y0 = image.h.saturating_sub(height);
    for (i, row) in rows.iter().enumerate() {
        let y = y0 + i * LINE;
        for (name, color, x) in row {
            image.fill(*x, y, SWATCH, SWATCH, *color);
            image.text(x + SWATCH + 6, y, name, SCALE, TEXT);
        }
    }
    image.text(PAD, y0 + rows.len() * LINE, note, SCALE, TEXT);
    height
}
