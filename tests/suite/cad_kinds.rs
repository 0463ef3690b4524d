//! Every surface and curve kind, and every unit case, inspc reads from STEP, each in a
//! small solid made by OpenCASCADE (`tests/cad/make.py`, checked in with OpenCASCADE's
//! own reading of it beside each file): inspc's mesh of the solid must be closed, have
//! the same faces with the same surface kinds and areas, enclose the same volume
//! (outward normals: a face meshed inside out subtracts its share) and fill the same box.

use inspc::geometry::step::{read, Resolution, RESOLUTION};
use inspc::geometry::{qif, RawMesh};
use inspc::model::SurfaceKind;
use serde_json::Value;

/// Finer than parts are meshed at, so that the mesh's areas and volume come within
/// a fraction of a percent of the exact solid's: at 0.5 rad a triangle may lean 15° off
/// a small fillet and count 4 % more area (Schwarz's lantern).
const FINE: Resolution = Resolution {
    chord_mm: 0.01,
    angle_rad: 0.1,
};

/// Each triangle's area and its signed volume against the origin, per face.
fn areas_and_volume(m: &RawMesh) -> (Vec<f64>, f64) {
    let mut areas = vec![0.0; m.groups.len()];
    let mut volume = 0.0;
    for (t, g) in m.triangles.iter().zip(&m.tri_group) {
        let [a, b, c] = t.map(|i| m.vertices[i as usize].coords);
        areas[*g as usize] += 0.5 * (b - a).cross(&(c - a)).norm();
        volume += a.dot(&b.cross(&c)) / 6.0;
    }
    (areas, volume)
}

fn kind_name(k: SurfaceKind) -> &'static str {
    match k {
        SurfaceKind::Plane => "plane",
        SurfaceKind::Cylinder => "cylinder",
        SurfaceKind::Cone => "cone",
        SurfaceKind::Sphere => "sphere",
        SurfaceKind::Freeform => "freeform",
    }
}

fn check(name: &str) {
    check_file(name, "stp");
}

/// The same solid written as QIF 3 (`tests/cad/qif_writer.py`), a document valid
/// against the QIF 3 schemas (where `xmllint` is installed, as in CI).
fn check_qif(name: &str) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cad/").to_string() + name + ".qif";
    crate::qif_results::validate(name, &std::fs::read_to_string(path).unwrap());
    check_file(name, "qif");
}

fn check_file(name: &str, ext: &str) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cad/");
    let bytes = std::fs::read(format!("{dir}{name}.{ext}")).unwrap();
    let read = |res| match ext {
        "qif" => qif::read(&bytes, res),
        _ => read(&bytes, res),
    };
    let want: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}{name}.json")).unwrap())
            .unwrap();
    // At the resolution parts are planned at, the mesh closes too.
    let coarse = read(RESOLUTION).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    assert_eq!(
        coarse.mesh.open_edges, 0,
        "{name}: closed at the planning resolution"
    );
    assert_eq!(
        coarse.mesh.nonmanifold_edges, 0,
        "{name}: manifold at the planning resolution"
    );
    let part = read(FINE).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    let m = &part.mesh;
    assert_eq!(m.open_edges, 0, "{name}: the solid's mesh is closed");
    assert_eq!(m.nonmanifold_edges, 0, "{name}: no edge of three triangles");
    let faces = want["faces"].as_array().unwrap();
    assert_eq!(m.groups.len(), faces.len(), "{name}: face count");

    // Faces matched by kind and area: both sorted the same way.
    let (areas, volume) = areas_and_volume(m);
    let mut got: Vec<(&str, f64)> = m
        .exact
        .iter()
        .zip(&areas)
        .map(|(s, a)| (kind_name(s.kind()), *a))
        .collect();
    let mut expected: Vec<(&str, f64)> = faces
        .iter()
        .map(|f| {
            // inspc reads a torus as a free-form surface.
            let k = f["kind"].as_str().unwrap();
            (
                if k == "torus" { "freeform" } else { k },
                f["area"].as_f64().unwrap(),
            )
        })
        .collect();
    let order = |a: &(&str, f64), b: &(&str, f64)| a.0.cmp(b.0).then(a.1.total_cmp(&b.1));
    got.sort_by(order);
    expected.sort_by(order);
    for (g, e) in got.iter().zip(&expected) {
        assert_eq!(
            g.0, e.0,
            "{name}: surface kinds {got:?} against {expected:?}"
        );
        assert!(
            (g.1 - e.1).abs() <= 0.01 * e.1 + 0.5,
            "{name}: a {} face of {} mm² against OpenCASCADE's {} mm²",
            g.0,
            g.1,
            e.1
        );
    }
    let v = want["volume"].as_f64().unwrap();
    assert!(
        (volume - v).abs() <= 0.01 * v,
        "{name}: the mesh encloses {volume} mm³, OpenCASCADE's solid {v} mm³"
    );
    let bx = &want["box"];
    for k in 0..3 {
        let lo = m
            .vertices
            .iter()
            .map(|p| p[k])
            .fold(f64::INFINITY, f64::min);
        let hi = m
            .vertices
            .iter()
            .map(|p| p[k])
            .fold(f64::NEG_INFINITY, f64::max);
        let (wl, wh) = (bx[0][k].as_f64().unwrap(), bx[1][k].as_f64().unwrap());
        assert!(
            (lo - wl).abs() <= 0.2 && (hi - wh).abs() <= 0.2,
            "{name}: axis {k} spans {lo}..{hi}, OpenCASCADE's {wl}..{wh}"
        );
    }
}

#[test]
fn a_closed_b_spline_extruded() {
    check("extrusion_bspline");
}

#[test]
fn an_ellipse_extruded() {
    check("extrusion_ellipse");
}

#[test]
fn a_circle_extruded_on_a_slant() {
    check("extrusion_oblique");
}

#[test]
fn a_b_spline_revolved_once_round() {
    check("revolution_bspline");
}

#[test]
fn a_b_spline_revolved_part_way() {
    check("revolution_partial");
}

#[test]
fn a_b_spline_revolved_from_its_axis() {
    check("revolution_pole");
}

#[test]
fn parabola_and_hyperbola_edges() {
    check("conics");
}

#[test]
fn rational_b_spline_faces_with_poles() {
    check("nurbs");
}

#[test]
fn an_offset_surface() {
    check("offset");
}

#[test]
fn a_cylinder_face_without_a_seam() {
    check("seamless_cylinder");
}

#[test]
fn lengths_in_inches() {
    check("unit_inch");
}

#[test]
fn lengths_in_metres() {
    check("unit_metre");
}

#[test]
fn angles_in_degrees() {
    check("unit_degree");
}

#[test]
fn analytic_surfaces_written_as_swept_and_offset_ones() {
    // Each kind must come out as the analytic surface it is (the fixture's
    // OpenCASCADE reading names them), with every face's normal outward.
    check("disguised");
}

#[test]
fn bezier_curves_and_surfaces() {
    check("bezier");
}

#[test]
fn a_quasi_uniform_b_spline() {
    check("quasi_uniform");
}

#[test]
fn a_uniform_b_spline() {
    check("uniform");
}

#[test]
fn qif_extrude23_of_a_nurbs_curve() {
    check_qif("extrusion_bspline");
}

#[test]
fn qif_extrude23_of_an_elliptic_arc() {
    check_qif("extrusion_ellipse");
}

#[test]
fn qif_revolution23() {
    check_qif("revolution_bspline");
}

#[test]
fn qif_revolution23_to_a_pole() {
    check_qif("revolution_pole");
}

#[test]
fn qif_parabolic_and_hyperbolic_arcs() {
    check_qif("conics");
}

#[test]
fn qif_nurbs23_with_the_control_points_v_fastest() {
    check_qif("nurbs");
}

#[test]
fn qif_offset23() {
    check_qif("offset");
}

#[test]
fn a_revolved_line_given_beyond_its_apex() {
    // The cone's line passes the axis: the face is on the nappe its own points say.
    check("disguised_far");
}

#[test]
fn an_offset_of_an_extruded_ellipse() {
    check("offset_ellipse");
}

#[test]
fn composite_curves_of_trimmed_stretches() {
    // Every edge's curve is two stretches of its line or circle, trimmed by parameter,
    // by point, and against the basis's sense with the segment turned back.
    check("composite");
}

#[test]
fn an_offset_curve_swept() {
    check("offset_curve");
}

#[test]
fn qif_spline13_and_spline23_polynomial_pieces() {
    // Every edge a Spline13 and every face a Spline23, normalised or not in turn, the
    // patches and their coefficients v-fastest (the STEP file has them as B-splines).
    check_qif("spline");
    check("spline");
}

#[test]
fn qif_ruled23_between_two_b_splines() {
    check_qif("ruled");
}

#[test]
fn a_wall_thinner_than_the_chord_meshes_by_the_fallback() {
    // At the planning resolution the chords of the wall's two sides cross in the end
    // faces' parameters and Delaunay refuses them (tess.rs's unit test); ear clipping
    // meshes them, closed, with their area.
    check("thin_wall");
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cad/");
    let part = read(
        &std::fs::read(format!("{dir}thin_wall.stp")).unwrap(),
        RESOLUTION,
    )
    .unwrap();
    let want: Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}thin_wall.json")).unwrap())
            .unwrap();
    let (areas, _) = areas_and_volume(&part.mesh);
    let planes: Vec<f64> = part
        .mesh
        .exact
        .iter()
        .zip(&areas)
        .filter(|(s, _)| s.kind() == SurfaceKind::Plane)
        .map(|(_, a)| *a)
        .collect();
    let exact = want["faces"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["kind"] == "plane")
        .unwrap()["area"]
        .as_f64()
        .unwrap();
    assert_eq!(planes.len(), 2);
    for a in planes {
        assert!(
            (a - exact).abs() <= 0.01 * exact,
            "an end face of {a} mm² against {exact} mm²"
        );
    }
}
