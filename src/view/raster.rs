//! Still images of a scene (`inspc view --png`): the page's default view of one setup,
//! drawn in software — a z-buffer, flat shading, the table, the fixture, the path and the
//! points, depth-tested against the part with what it hides drawn faintly — under a
//! caption and over a legend (`caption.rs`), and written as PNG.

use super::caption;
use super::font::Image;
use super::Scene;

/// The yaws tried for a setup whose measured faces face no one side (degrees): from
/// the front-left, and round the part.
pub(crate) const YAWS: [f32; 4] = [-35.0, 55.0, 145.0, -125.0];

/// How much of its colour a path or point hidden behind the part keeps.
const HIDDEN_ALPHA: f32 = 0.25;

type V = [f32; 3];

/// Where the camera looks from: its turn about the vertical and its elevation above the
/// table (degrees).
#[derive(Debug, Clone, Copy)]
struct Camera {
    yaw: f32,
    pitch: f32,
}

/// A part-frame vector in the machine frame (`r`'s rows).
pub(crate) fn rotate(r: &[[f32; 3]; 3], p: &V) -> V {
    [
        r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2],
        r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2],
        r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2],
    ]
}

fn sub(a: &V, b: &V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: &V, b: &V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn hex(c: &str) -> [f32; 3] {
    caption::rgb8(c).map(f32::from)
}

/// Machine frame → view: turned by the yaw about z, then seen from the front and above
/// at the pitch; x right and y up on the screen, z towards the viewer (who sits at
/// (-sin yaw, -cos yaw) across the table). The page's `view` is the same.
fn view(p: &V, cam: Camera) -> V {
    let (sy, cy) = cam.yaw.to_radians().sin_cos();
    let (sp, cp) = cam.pitch.to_radians().sin_cos();
    let x = cy * p[0] - sy * p[1];
    let y = sy * p[0] + cy * p[1];
    [x, sp * y + cp * p[2], -cp * y + sp * p[2]]
}

struct Canvas {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
    z: Vec<f32>,
    /// Per pixel, whether the part's surface is what shows there.
    part: Vec<bool>,
    /// Whether what is drawn now is the part.
    drawing_part: bool,
}

impl Canvas {
    fn plot(&mut self, x: i32, y: i32, depth: f32, c: [f32; 3]) {
        if x < 0 || y < 0 || x as usize >= self.w || y as usize >= self.h {
            return;
        }
        let k = y as usize * self.w + x as usize;
        if depth >= self.z[k] {
            self.z[k] = depth;
            self.part[k] = self.drawing_part;
            self.rgb[3 * k..3 * k + 3].copy_from_slice(&c.map(|v| v.clamp(0.0, 255.0) as u8));
        }
    }

    /// A triangle in screen coordinates (x, y in pixels, z larger nearer).
    fn triangle(&mut self, a: V, b: V, c: V, color: [f32; 3]) {
        let minx = a[0].min(b[0]).min(c[0]).floor().max(0.0) as i32;
        let maxx = a[0].max(b[0]).max(c[0]).ceil().min(self.w as f32 - 1.0) as i32;
        let miny = a[1].min(b[1]).min(c[1]).floor().max(0.0) as i32;
        let maxy = a[1].max(b[1]).max(c[1]).ceil().min(self.h as f32 - 1.0) as i32;
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() < 1e-9 {
            return;
        }
        for y in miny..=maxy {
            for x in minx..=maxx {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
                let w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < -1e-4 || w1 < -1e-4 || w2 < -1e-4 {
                    continue;
                }
                let z = w0 * a[2] + w1 * b[2] + w2 * c[2];
                self.plot(x, y, z, color);
            }
        }
    }

    /// A pixel of a path or point: where the part (or anything drawn) is nearer than
    /// `depth`, blended faintly over it without taking its depth.
    fn overlay(&mut self, x: i32, y: i32, depth: f32, c: [f32; 3]) {
        if x < 0 || y < 0 || x as usize >= self.w || y as usize >= self.h {
            return;
        }
        let k = y as usize * self.w + x as usize;
        if depth >= self.z[k] {
            self.plot(x, y, depth, c);
            return;
        }
        for (i, v) in c.iter().enumerate() {
            let old = self.rgb[3 * k + i] as f32;
            self.rgb[3 * k + i] = (old + (v - old) * HIDDEN_ALPHA).clamp(0.0, 255.0) as u8;
        }
    }

    /// A line drawn over everything nearer than `lift` behind it, faintly where hidden.
    fn line(&mut self, a: V, b: V, color: [f32; 3], lift: f32) {
        let steps = ((b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil() as usize).max(1);
        for k in 0..=steps {
            let t = k as f32 / steps as f32;
            let p = [
                a[0] + (b[0] - a[0]) * t,
                a[1] + (b[1] - a[1]) * t,
                a[2] + (b[2] - a[2]) * t + lift,
            ];
            self.overlay(p[0].round() as i32, p[1].round() as i32, p[2], color);
        }
    }

    /// A touched point: a 5 × 5 square in the probe's colour ringed in white, depth-
    /// tested like a line; `facing` is its normal's view z: a point on a face turned
    /// away is behind the solid whatever the depth test says near an edge.
    fn marker(&mut self, p: V, facing: f32, color: [f32; 3], lift: f32) {
        let lift = if facing < 0.0 {
            f32::NEG_INFINITY
        } else {
            lift
        };
        let (x, y) = (p[0] as i32, p[1] as i32);
        for dx in -3..=3i32 {
            for dy in -3..=3i32 {
                let c = if dx.abs() == 3 || dy.abs() == 3 {
                    [255.0; 3]
                } else {
                    color
                };
                self.overlay(x + dx, y + dy, p[2] + lift, c);
            }
        }
    }
}

/// The PNG of setup `setup` (from 0) at `width` × `height` pixels: its caption on top,
/// the view from the setup's default camera, its legend below; `None` when the scene
/// has no such setup.
pub fn png(scene: &Scene, setup: usize, width: u32, height: u32) -> Option<Vec<u8>> {
    let s = scene.setups.get(setup)?;
    let cam = Camera {
        yaw: s.yaw,
        pitch: s.pitch,
    };
    let (w, h) = (width as usize, height as usize);
    let mut rgb = vec![248u8; w * h * 3];
    let mut image = Image {
        w,
        h,
        rgb: &mut rgb,
    };
    let top = caption::caption(&mut image, scene, setup);
    let bottom = caption::legend(&mut image, scene, setup);
    // The view keeps at least half the image, whatever the caption and legend hold.
    let view_h = (h.saturating_sub(top + bottom)).max(h / 2);
    let top = top.min(h - view_h);
    let c = draw(scene, setup, w, view_h, cam)?;
    rgb[3 * w * top..3 * w * (top + view_h)].copy_from_slice(&c.rgb);
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().ok()?;
        writer.write_image_data(&rgb).ok()?;
    }
    Some(out)
}

/// The yaw of `yaws` (degrees) from which, at `pitch`, most of the part shows in setup
/// `setup`: a fixture beside the part (an angle plate) hides it from one side. The
/// first of equals.
pub(crate) fn best_yaw(scene: &Scene, setup: usize, pitch: f32, yaws: &[f32]) -> f32 {
    let mut best = (0, yaws.first().copied().unwrap_or(0.0));
    for &yaw in yaws {
        let cam = Camera { yaw, pitch };
        let shown =
            draw(scene, setup, 160, 120, cam).map_or(0, |c| c.part.iter().filter(|p| **p).count());
        if shown > best.0 {
            best = (shown, yaw);
        }
    }
    best.1
}

/// Draws setup `setup` from `cam`.
fn draw(scene: &Scene, setup: usize, w: usize, h: usize, cam: Camera) -> Option<Canvas> {
    let s = scene.setups.get(setup)?;
    let view = |p: &V| view(p, cam);
    let r = &s.rotation;
    let part: Vec<V> = scene.vertices.iter().map(|p| view(&rotate(r, p))).collect();
    let fixture: Vec<V> = s
        .fixture
        .vertices
        .iter()
        .map(|p| view(&rotate(r, p)))
        .collect();
    // The table: a square under the part at the table's height, a third wider.
    let m: Vec<V> = scene.vertices.iter().map(|p| rotate(r, p)).collect();
    let lo = |k: usize| m.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
    let hi = |k: usize| m.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max);
    let (cx, cy) = ((lo(0) + hi(0)) / 2.0, (lo(1) + hi(1)) / 2.0);
    let half = (hi(0) - lo(0)).max(hi(1) - lo(1)) * 0.67 + 10.0;
    let tz = s.table;
    let table: Vec<V> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .iter()
        .map(|[a, b]| view(&[cx + a * half, cy + b * half, tz]))
        .collect();
    // Fit everything drawn into the image with a margin.
    let all = part.iter().chain(&table).chain(&fixture);
    let (mut x0, mut x1, mut y0, mut y1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    for p in all {
        x0 = x0.min(p[0]);
        x1 = x1.max(p[0]);
        y0 = y0.min(p[1]);
        y1 = y1.max(p[1]);
    }
    let scale = 0.9 * (w as f32 / (x1 - x0).max(1e-3)).min(h as f32 / (y1 - y0).max(1e-3));
    let (mx, my) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let screen = |p: &V| -> V {
        [
            w as f32 / 2.0 + (p[0] - mx) * scale,
            h as f32 / 2.0 - (p[1] - my) * scale,
            p[2] * scale,
        ]
    };
    let mut c = Canvas {
        w,
        h,
        rgb: vec![248; w * h * 3],
        z: vec![f32::NEG_INFINITY; w * h],
        part: vec![false; w * h],
        drawing_part: false,
    };
    let shade = |n: V, base: [f32; 3]| {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-12);
        let light = [0.3f32, 0.5, 0.81];
        let l = ((n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len).abs();
        base.map(|v| v * (0.45 + 0.55 * l))
    };
    let tri = |c: &mut Canvas, vs: &[V], t: &[u32; 3], base: [f32; 3]| {
        let (a, b, d) = (vs[t[0] as usize], vs[t[1] as usize], vs[t[2] as usize]);
        let n = cross(&sub(&b, &a), &sub(&d, &a));
        c.triangle(screen(&a), screen(&b), screen(&d), shade(n, base));
    };
    tri(&mut c, &table, &[0, 1, 2], [205.0, 208.0, 212.0]);
    tri(&mut c, &table, &[0, 2, 3], [205.0, 208.0, 212.0]);
    for t in &s.fixture.triangles {
        tri(&mut c, &fixture, t, [150.0, 140.0, 125.0]);
    }
    let grey = hex(super::OTHER_FACES);
    c.drawing_part = true;
    for (k, t) in scene.triangles.iter().enumerate() {
        let face = scene.tri_face[k] as usize;
        let color = scene.faces[face]
            .feature
            .map_or(grey, |f| hex(&scene.features[f].color));
        tri(&mut c, &part, t, color);
    }
    c.drawing_part = false;
    // Paths and points over the surfaces they run along.
    let lift = 2.0 * scale;
    for g in &s.groups {
        let color = hex(&scene.probes[g.probe].color);
        let path: Vec<V> = g
            .path
            .iter()
            .map(|p| screen(&view(&rotate(r, p))))
            .collect();
        for pair in path.windows(2) {
            c.line(pair[0], pair[1], color, lift);
        }
        for (k, _) in &g.touches {
            let point = &scene.points[*k];
            let p = screen(&view(&rotate(r, &point.p)));
            c.marker(p, view(&rotate(r, &point.n))[2], color, lift);
        }
    }
    Some(c)
}
