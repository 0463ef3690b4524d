//! `inspc view`: a built plan as one self-contained HTML page (the part in 3D, faces
//! coloured by feature, the points and paths of each setup, the probe at a touch, the
//! touch's accessibility cone, the setup's pose on the table with its fixture) and as
//! still images, one per setup. Entry points: [`scene`] (the data), [`page`], [`png`].
//!
//! The page is `viewer.html` with the scene inlined as JSON: no network at view time,
//! and a Canvas 2D renderer (painter's order) that needs no GPU, so a headless browser
//! renders it as a desktop one does. [`png`] draws the same scene with the same camera
//! in software.
//!
//! **Decision: Canvas 2D, not WebGL.** A headless browser without a GPU renders the
//! page exactly as a desktop one, and the parts (up to about 12 k triangles) draw in
//! milliseconds. A touch's cone is `access::approach_cone` (no D2) at N = 32, sampled
//! on 600 directions of a Fibonacci sphere: a fraction of a second on a real part
//! beside its build.
//!
//! **Decisions a user sees** (issue 50; page and image agree):
//! - *Camera.* Each setup opens from the side its measured faces face: the mean outward
//!   normal of its touched points, turned 30° (to the side showing more of the part)
//!   for a three-quarter view, 20° to 60° above the table; where the normals cancel,
//!   the side that shows most of the part. Dragging keeps the camera 5° to 90° above
//!   the table; the wheel zooms from 0.5 to 16 times the fitted view.
//! - *Depth.* Paths and points are depth-tested against the part and fixture (the
//!   page keeps a software depth buffer beside its painter's order; a point on a face
//!   turned away is behind the solid); what is hidden is drawn at a quarter of its
//!   colour (points as rings), so it stays findable.
//! - *Colours.* Features take light colours ([`FEATURE_COLORS`], CIE L* above 60),
//!   probes dark saturated ones ([`PROBE_COLORS`], L* under 40): they never meet.
//! - *Hold text.* Faces are named as the spec names them (`datum A`, `feature top`,
//!   `stock.bottom`; a face an import only numbered by the side it faces), each once,
//!   wrapped, never cut off.
//! - *Images.* Each PNG has a caption (plan, setup, which way up, how held, probes)
//!   and a legend of its colours, in a built-in 5 × 7 font (`font.rs`).
//!
//! `window.__inspc` holds what the page drew (camera, colours, each point, hidden or
//! not), for `tests/suite/view.rs`.

mod caption;
mod font;
mod raster;
mod words;

pub use raster::png;

use crate::access::{self, Cpu};
use crate::geometry::PartGeometry;
use crate::plan::Hlip;
use crate::{Built, PartData};
use serde::Serialize;

/// What the page and the images show.
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    /// `plan NAME: part NAME`.
    pub title: String,
    /// The part's mesh, part frame (mm).
    pub vertices: Vec<[f32; 3]>,
    /// Its triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's face.
    pub tri_face: Vec<u32>,
    /// The faces: name and the feature they belong to.
    pub faces: Vec<FaceInfo>,
    /// The features, in the part's order, with their colours.
    pub features: Vec<Named>,
    /// The probes of the machine's rack, with their colours and shapes.
    pub probes: Vec<ProbeInfo>,
    /// Every point of the plan: position, normal, face.
    pub points: Vec<PointInfo>,
    /// The setups in order.
    pub setups: Vec<SetupInfo>,
    /// The directions the cones are sampled at (unit vectors, part frame).
    pub sphere: Vec<[f32; 3]>,
}

/// A name and a colour (`#rrggbb`).
#[derive(Debug, Clone, Serialize)]
pub struct Named {
    /// The name.
    pub name: String,
    /// Its colour.
    pub color: String,
}

/// One face.
#[derive(Debug, Clone, Serialize)]
pub struct FaceInfo {
    /// Its name.
    pub name: String,
    /// The feature it belongs to, by index into [`Scene::features`].
    pub feature: Option<usize>,
}

/// One probe: its colour and its components from the tip centre along its axis.
#[derive(Debug, Clone, Serialize)]
pub struct ProbeInfo {
    /// Its label in the rack.
    pub name: String,
    /// Its colour.
    pub color: String,
    /// The tip ball's radius (mm).
    pub tip: f32,
    /// Stylus, extensions, body: `[from, to, radius]` along the axis (mm).
    pub components: Vec<[f32; 3]>,
}

/// One point of the plan.
#[derive(Debug, Clone, Serialize)]
pub struct PointInfo {
    /// Contact position.
    pub p: [f32; 3],
    /// Surface normal.
    pub n: [f32; 3],
    /// Its face, by index into [`Scene::faces`].
    pub face: u32,
}

/// One setup.
#[derive(Debug, Clone, Serialize)]
pub struct SetupInfo {
    /// What holds the part, its faces named as the spec names them.
    pub held_by: String,
    /// Which way up the part stands (`part +z up`).
    pub up: String,
    /// Part frame → machine frame (rows).
    pub rotation: [[f32; 3]; 3],
    /// The table's height along the setup's up direction (part frame, mm).
    pub table: f32,
    /// The fixture's solids as one mesh, part frame.
    pub fixture: Mesh,
    /// Its (probe, orientation) groups in order.
    pub groups: Vec<GroupInfo>,
    /// The default camera's turn about the vertical (degrees): from the side the
    /// setup's measured faces face.
    pub yaw: f32,
    /// The default camera's elevation above the table (degrees).
    pub pitch: f32,
}

/// A triangle mesh.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Mesh {
    /// Vertices.
    pub vertices: Vec<[f32; 3]>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// One group of touches under one probe and orientation.
#[derive(Debug, Clone, Serialize)]
pub struct GroupInfo {
    /// The probe, by index into [`Scene::probes`].
    pub probe: usize,
    /// Head angles (degrees).
    pub a: f32,
    /// Head angle B.
    pub b: f32,
    /// The probe direction, tip to head, part frame.
    pub direction: [f32; 3],
    /// The tip centre's path: entry, each touch's way in and out, exit.
    pub path: Vec<[f32; 3]>,
    /// The touches: point index and its cone over [`Scene::sphere`] (`1` free, `0`
    /// blocked), of the probe at that point.
    pub touches: Vec<(usize, String)>,
}

/// Feature colours: light and soft (ColorBrewer's qualitative Set3 without its grey,
/// which is the faces no feature names), so no feature can take a probe's colour.
pub(crate) const FEATURE_COLORS: &[&str] = &[
    "#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5",
    "#bc80bd", "#ccebc5", "#ffed6f",
];

/// Probe colours: dark and saturated (CIE L* under 40, every feature colour's above
/// 60), so a path or point reads against any face and never as a feature.
pub(crate) const PROBE_COLORS: &[&str] = &[
    "#1a1a1a", "#08519c", "#7a0177", "#006d2c", "#8c2d04", "#4a1486",
];

/// The faces no feature names.
pub(crate) const OTHER_FACES: &str = "#afb2b6";

/// How many directions a cone is sampled at.
const SPHERE: usize = 600;

/// Cube-map resolution of the cones shown.
const CONE_N: u32 = 32;

fn f3(v: &[f64; 3]) -> [f32; 3] {
    // Rounded to a micrometre: the same text on every machine.
    let r = |x: f64| ((x * 1e3).round() / 1e3) as f32;
    [r(v[0]), r(v[1]), r(v[2])]
}

/// The scene of one built plan.
pub fn scene(model: &crate::model::Model, data: &PartData, built: &Built) -> Scene {
    let hlip: &Hlip = &built.hlip;
    let plan = &model.plans[built.plan];
    let part = &model.parts[plan.part.0];
    let g: &PartGeometry = &data.geometry;
    let face_feature = face_features(data, g);
    let features = part
        .features
        .iter()
        .enumerate()
        .map(|(k, f)| Named {
            name: f.name.clone(),
            color: FEATURE_COLORS[k % FEATURE_COLORS.len()].to_string(),
        })
        .collect();
    let cmm = &model.cmms[plan.cmm.0];
    let shapes = access::scan::sensor_shapes(model, cmm);
    let probes = probe_infos(&shapes);
    let points: Vec<PointInfo> = hlip
        .points
        .iter()
        .map(|p| PointInfo {
            p: f3(&p.position.coords.into()),
            n: f3(&p.normal.into()),
            face: p.face.0 as u32,
        })
        .collect();
    let sphere = fibonacci_sphere(SPHERE);
    let scene3 = access::Scene::of_part(g);
    let cones = Cones {
        scene: &scene3,
        opts: access::ConeOptions {
            n: CONE_N,
            preferred: access::axes(),
            ..access::ConeOptions::default()
        },
        sphere: &sphere,
    };
    let names = crate::plan::Names::new(model, g, crate::model::PlanId(built.plan));
    let mut setups = Vec::new();
    for sp in &built.llip.setups {
        let s = &hlip.setups[sp.setup];
        let groups = sp
            .groups
            .iter()
            .map(|gp| group_info(hlip, gp, &shapes[gp.probe.0], &cones))
            .collect();
        setups.push(SetupInfo {
            held_by: words::held_by(&names, &face_feature, s),
            up: words::up_words(&s.up),
            rotation: s
                .rotation
                .map(|r| r.map(|x| ((x * 1e6).round() / 1e6) as f32)),
            table: ((s.table * 1e3).round() / 1e3) as f32,
            fixture: fixture_mesh(s),
            groups,
            yaw: 0.0,
            pitch: 0.0,
        });
    }
    let mut scene = Scene {
        title: format!("plan {}: part {}", plan.name, part.name),
        vertices: g.vertices.iter().map(|v| f3(&v.coords.into())).collect(),
        triangles: g.triangles.clone(),
        tri_face: g.tri_face.clone(),
        faces: g
            .faces
            .iter()
            .enumerate()
            .map(|(k, f)| FaceInfo {
                name: f.name.clone(),
                feature: face_feature[k],
            })
            .collect(),
        features,
        probes,
        points,
        setups,
        sphere,
    };
    for k in 0..scene.setups.len() {
        let (yaw, pitch) = default_camera(&scene, k);
        scene.setups[k].yaw = yaw;
        scene.setups[k].pitch = pitch;
    }
    scene
}

/// The default camera's elevation bounds (degrees): above the table, never straight
/// down, where a part's sides vanish.
const PITCH_MIN_DEG: f32 = 20.0;
const PITCH_MAX_DEG: f32 = 60.0;

/// The default camera's turn off the measured faces' mean direction (degrees): a
/// three-quarter view, which shows depth where a head-on one shows a flat face.
const YAW_OFFSET_DEG: f32 = 30.0;

/// Setup `k`'s default camera (yaw, pitch in degrees): from the side its measured faces
/// face — the mean outward normal of its touched points in the machine frame, turned
/// [`YAW_OFFSET_DEG`] to whichever side shows more of the part, its elevation kept
/// within [`PITCH_MIN_DEG`]..[`PITCH_MAX_DEG`]. Where the normals cancel or all point
/// up, the side that shows most of the part ([`raster::best_yaw`]) at 30° (or the
/// mean's elevation).
fn default_camera(scene: &Scene, k: usize) -> (f32, f32) {
    let s = &scene.setups[k];
    let mut m = [0f32; 3];
    let mut n = 0usize;
    for g in &s.groups {
        for (p, _) in &g.touches {
            let v = raster::rotate(&s.rotation, &scene.points[*p].n);
            (0..3).for_each(|i| m[i] += v[i]);
            n += 1;
        }
    }
    let m = m.map(|x| x / n.max(1) as f32);
    let (h, len) = (
        m[0].hypot(m[1]),
        (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt(),
    );
    if len < 0.15 {
        return (raster::best_yaw(scene, k, 30.0, &raster::YAWS), 30.0);
    }
    let pitch = m[2]
        .atan2(h)
        .to_degrees()
        .clamp(PITCH_MIN_DEG, PITCH_MAX_DEG);
    if h < 0.15 * len {
        return (raster::best_yaw(scene, k, pitch, &raster::YAWS), pitch);
    }
    // The viewer sits at (-sin yaw, -cos yaw) across the table (raster::view).
    let yaw = (-m[0]).atan2(-m[1]).to_degrees();
    let turn = |d: f32| ((yaw + d + 540.0).rem_euclid(360.0) - 180.0).round();
    let tries = [turn(-YAW_OFFSET_DEG), turn(YAW_OFFSET_DEG)];
    (raster::best_yaw(scene, k, pitch, &tries), pitch)
}

/// Per face, the first feature (in the part's order) that names it.
fn face_features(data: &PartData, g: &PartGeometry) -> Vec<Option<usize>> {
    let mut face_feature: Vec<Option<usize>> = vec![None; g.faces.len()];
    for (k, faces) in data.feature_faces.iter().enumerate() {
        for f in faces {
            face_feature[f.0].get_or_insert(k);
        }
    }
    face_feature
}

/// The probes of the rack with their colours and components.
fn probe_infos(shapes: &[access::ProbeShape]) -> Vec<ProbeInfo> {
    shapes
        .iter()
        .enumerate()
        .map(|(k, s)| ProbeInfo {
            name: s.name.clone(),
            color: PROBE_COLORS[k % PROBE_COLORS.len()].to_string(),
            tip: s.tip_radius as f32,
            components: s
                .first
                .iter()
                .map(|c| [c.a as f32, c.b as f32, c.radius as f32])
                .collect(),
        })
        .collect()
}

/// What the cones of the touches are computed in and shown at: the part's scene, the
/// options, and the directions sampled.
struct Cones<'a> {
    scene: &'a access::Scene,
    opts: access::ConeOptions,
    sphere: &'a [[f32; 3]],
}

/// One group as the page shows it: its tip centre's path and the cone of each touch of
/// probe `shape`.
fn group_info(
    hlip: &Hlip,
    gp: &crate::path::GroupPath,
    shape: &access::ProbeShape,
    cones: &Cones,
) -> GroupInfo {
    let mut path: Vec<[f32; 3]> = gp.entry.iter().map(f3).collect();
    let mut touches = Vec::new();
    for b in &gp.blocks {
        for t in &b.touches {
            path.extend(t.via.iter().map(f3));
            path.push(f3(&t.standoff));
            let p = &hlip.points[t.point];
            let c = p.position + p.normal * shape.tip_radius;
            path.push(f3(&c.coords.into()));
            path.push(f3(&t.standoff));
            touches.push(t.point);
        }
        // A scanner's passes: the focus moves along each.
        for p in &b.passes {
            path.extend(p.via.iter().map(f3));
            path.push(f3(&p.start));
            path.push(f3(&p.end));
        }
    }
    path.extend(gp.exit.iter().map(f3));
    GroupInfo {
        probe: gp.probe.0,
        a: gp.a as f32,
        b: gp.b as f32,
        direction: f3(&gp.direction),
        path,
        touches: touch_cones(hlip, &touches, shape, cones),
    }
}

/// Per touch (a point index), its cone over the sampled directions: `1` where the
/// probe `shape` is free, `0` where it is blocked.
fn touch_cones(
    hlip: &Hlip,
    touches: &[usize],
    shape: &access::ProbeShape,
    cones: &Cones,
) -> Vec<(usize, String)> {
    use rayon::prelude::*;
    touches
        .par_iter()
        .map(|&k| {
            let p = &hlip.points[k];
            let f = crate::sample::Fpoint {
                face: p.face,
                position: p.position,
                normal: p.normal,
            };
            let cone = access::approach_cone(&Cpu, cones.scene, &f, shape, &cones.opts);
            let bits: String = cones
                .sphere
                .iter()
                .map(|d| {
                    let v = crate::geometry::V3::new(d[0] as f64, d[1] as f64, d[2] as f64);
                    match &cone {
                        Some(c) if c.contains(&v) => '1',
                        _ => '0',
                    }
                })
                .collect();
            (k, bits)
        })
        .collect()
}

/// `n` directions spread evenly over the sphere (a Fibonacci lattice).
fn fibonacci_sphere(n: usize) -> Vec<[f32; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            f3(&[r * t.cos(), r * t.sin(), z])
        })
        .collect()
}

/// A setup's fixture solids as one triangle mesh, part frame.
fn fixture_mesh(s: &crate::plan::SetupNode) -> Mesh {
    let mut m = Mesh::default();
    for solid in &s.fixture {
        let (vs, ts) = solid.triangles();
        let base = m.vertices.len() as u32;
        m.vertices.extend(vs.iter().map(|v| f3(&v.coords.into())));
        m.triangles
            .extend(ts.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }
    m
}

/// The page: `viewer.html` with the scene inlined: the title as HTML text, the scene
/// as JSON in the page's `<script>`, each through its one escaping function. The
/// template is cut at its two places once, so nothing a name holds is read as a place.
pub fn page(scene: &Scene) -> String {
    let data = serde_json::to_string(scene).unwrap_or_else(|_| "null".into());
    let (head, rest) = TEMPLATE
        .split_once("{{TITLE}}")
        .expect("viewer.html has a title place");
    let (middle, tail) = rest
        .split_once("/*{{SCENE}}*/null")
        .expect("viewer.html has a scene place");
    let mut out = String::with_capacity(TEMPLATE.len() + data.len());
    out.push_str(head);
    out.push_str(&html_text(&scene.title));
    out.push_str(middle);
    out.push_str(&script_json(&data));
    out.push_str(tail);
    out
}

const TEMPLATE: &str = include_str!("viewer.html");

/// Text in HTML (element content or a quoted attribute): the five characters the HTML
/// spec gives meaning there as character references.
fn html_text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON made safe inside a `<script>` element. In the HTML tokenizer's script-data states
/// `</script` ends the element, and `<!--` followed by `<script` switches to the "double
/// escaped" state, where the page's own `</script>` no longer closes it and the page
/// stays blank (WHATWG HTML, "Restrictions for contents of script elements"): with no
/// `<` in the text neither can happen. `>` and `&`
/// go too (`-->` and character references in XHTML), and U+2028/U+2029, which end a
/// line in JavaScript before ES2019. Each becomes its `\uXXXX` escape, which is only
/// legal inside a JSON string: JSON's punctuation never holds them, so the data reads
/// back the same.
fn script_json(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        match c {
            '<' => out.push_str("\\u003c"),
            '>' => out.push_str("\\u003e"),
            '&' => out.push_str("\\u0026"),
            '\u{2028}' => out.push_str("\\u2028"),
            '\u{2029}' => out.push_str("\\u2029"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// CIE L* of an sRGB colour.
    fn lightness(hex: &str) -> f64 {
        let [r, g, b] = caption::rgb8(hex).map(|v| {
            let v = v as f64 / 255.0;
            if v <= 0.04045 {
                v / 12.92
            } else {
                ((v + 0.055) / 1.055).powf(2.4)
            }
        });
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        116.0
            * if y > 0.008856 {
                y.cbrt()
            } else {
                7.787 * y + 16.0 / 116.0
            }
            - 16.0
    }

    #[test]
    fn probes_and_features_never_share_a_colour() {
        for f in FEATURE_COLORS.iter().chain([&OTHER_FACES]) {
            assert!(
                lightness(f) > 60.0,
                "feature colour {f}: L* {}",
                lightness(f)
            );
        }
        for p in PROBE_COLORS {
            assert!(lightness(p) < 40.0, "probe colour {p}: L* {}", lightness(p));
        }
        let mut all: Vec<&str> = FEATURE_COLORS.iter().chain(PROBE_COLORS).copied().collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), FEATURE_COLORS.len() + PROBE_COLORS.len());
    }
}
