//! Each kind of bad description gives its typed error, naming the file and the link (or the line
//! and column for the sidecar TOML).

use aircraft::urdf::parts_from_str;
use aircraft::{Error, Vehicle, VehicleSpec};

fn robot(body: &str) -> String {
    format!(r#"<?xml version="1.0"?><robot name="t">{body}</robot>"#)
}

fn link(name: &str, geometry: &str) -> String {
    format!(
        r#"<link name="{name}"><collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry>{geometry}</geometry></collision></link>"#
    )
}

fn fixed(name: &str, parent: &str, child: &str) -> String {
    format!(
        r#"<joint name="{name}" type="fixed"><parent link="{parent}"/><child link="{child}"/><origin xyz="1 0 0" rpy="0 0 0"/></joint>"#
    )
}

fn err(urdf: &str) -> (Error, String) {
    let e = parts_from_str(urdf, "bad.urdf").expect_err("must fail");
    let msg = e.to_string();
    assert!(msg.starts_with("bad.urdf"), "{msg}");
    (e, msg)
}

const BOX: &str = r#"<box size="1 1 1"/>"#;

#[test]
fn missing_parent_or_child_link() {
    let (e, msg) = err(&robot(&format!(
        "{}{}",
        link("base", BOX),
        fixed("j", "ghost", "base")
    )));
    assert!(
        matches!(e, Error::MissingLink { role: "parent", .. }),
        "{msg}"
    );
    assert!(msg.contains("`ghost`") && msg.contains("`j`"), "{msg}");
    let (e, msg) = err(&robot(&format!(
        "{}{}",
        link("base", BOX),
        fixed("j", "base", "wing")
    )));
    assert!(
        matches!(e, Error::MissingLink { role: "child", .. }),
        "{msg}"
    );
    assert!(msg.contains("`wing`"), "{msg}");
}

#[test]
fn zero_negative_and_nan_sizes_name_the_link() {
    for (geometry, what) in [
        (r#"<box size="1 0 1"/>"#, "box size y"),
        (r#"<cylinder radius="-0.3" length="1"/>"#, "cylinder radius"),
        (r#"<cylinder radius="0.3" length="0"/>"#, "cylinder length"),
        (r#"<sphere radius="NaN"/>"#, "sphere radius"),
        (r#"<capsule radius="0.1" length="-2"/>"#, "capsule length"),
    ] {
        let (e, msg) = err(&robot(&format!(
            "{}{}{}",
            link("base", BOX),
            link("wing", geometry),
            fixed("j", "base", "wing")
        )));
        assert!(matches!(e, Error::BadNumber { .. }), "{msg}");
        assert!(msg.contains("link `wing`") && msg.contains(what), "{msg}");
    }
}

#[test]
fn nan_origin_is_rejected() {
    let urdf = robot(
        r#"<link name="base"><collision><origin xyz="0 NaN 0" rpy="0 0 0"/><geometry><box size="1 1 1"/></geometry></collision></link>"#,
    );
    let (e, msg) = err(&urdf);
    assert!(matches!(e, Error::BadNumber { .. }), "{msg}");
    assert!(
        msg.contains("link `base`") && msg.contains("origin xyz"),
        "{msg}"
    );
}

#[test]
fn mesh_is_unsupported() {
    let (e, msg) = err(&robot(&link(
        "fuselage",
        r#"<mesh filename="fuselage.stl"/>"#,
    )));
    assert!(matches!(e, Error::UnsupportedGeometry { .. }), "{msg}");
    assert!(
        msg.contains("link `fuselage`") && msg.contains("mesh"),
        "{msg}"
    );
}

#[test]
fn no_collision_geometry() {
    let (e, msg) = err(&robot(
        r#"<link name="base"/><link name="b"/><joint name="j" type="fixed"><parent link="base"/><child link="b"/></joint>"#,
    ));
    assert!(matches!(e, Error::NoCollisionGeometry { .. }), "{msg}");
}

#[test]
fn malformed_trees() {
    // Two roots.
    let (e, msg) = err(&robot(&format!("{}{}", link("a", BOX), link("b", BOX))));
    assert!(
        matches!(e, Error::Tree { .. }) && msg.contains("link `b`"),
        "{msg}"
    );
    // A link with two parents.
    let (e, msg) = err(&robot(&format!(
        "{}{}{}{}{}",
        link("a", BOX),
        link("b", BOX),
        link("c", BOX),
        fixed("j1", "a", "c"),
        fixed("j2", "b", "c")
    )));
    assert!(
        matches!(e, Error::Tree { .. }) && msg.contains("link `c`"),
        "{msg}"
    );
    // A cycle.
    let (e, msg) = err(&robot(&format!(
        "{}{}{}{}",
        link("a", BOX),
        link("b", BOX),
        fixed("j1", "a", "b"),
        fixed("j2", "b", "a")
    )));
    assert!(matches!(e, Error::Tree { .. }), "{msg}");
    // A duplicate link.
    let (e, msg) = err(&robot(&format!("{}{}", link("a", BOX), link("a", BOX))));
    assert!(
        matches!(e, Error::Tree { .. }) && msg.contains("twice"),
        "{msg}"
    );
}

#[test]
fn invalid_xml_is_a_urdf_error() {
    let (e, _) = err("<robot name=\"t\"><link name=\"a\">");
    assert!(matches!(e, Error::Urdf { .. }));
}

#[test]
fn joint_chain_is_composed_from_the_root() {
    // base -> arm (1 m forward, yawed 90 degrees) -> tip (1 m along the arm's x, 0.5 m up).
    let urdf = robot(&format!(
        r#"<link name="base"/>
        <link name="arm"/>
        <link name="tip"><collision><origin xyz="0 0 0.5" rpy="0 0 0"/><geometry><box size="2 0.2 0.2"/></geometry></collision></link>
        <joint name="a" type="fixed"><parent link="base"/><child link="arm"/><origin xyz="1 0 0" rpy="0 0 {yaw}"/></joint>
        <joint name="b" type="revolute"><parent link="arm"/><child link="tip"/><origin xyz="1 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#,
        yaw = std::f64::consts::FRAC_PI_2
    ));
    let parts = parts_from_str(&urdf, "chain.urdf").expect("parses");
    assert_eq!(parts.len(), 1);
    let t = parts[0].vehicle_from_part.translation.vector;
    assert!(
        (t - nalgebra::Vector3::new(1.0, 1.0, 0.5)).norm() < 1e-12,
        "{t}"
    );
    // The 2 m box now runs along y.
    let (lo, hi) = parts[0].footprint().bounds();
    assert!((hi.y - lo.y - 2.0).abs() < 1e-9 && (hi.x - lo.x - 0.2).abs() < 1e-9);
    assert!((parts[0].underside_m() - 0.4).abs() < 1e-12);
}

const SPEC: &str = r#"name = "t"
urdf = "t.urdf"
heights_of_interest_m = [0.0, 0.7]

[motion]
steering = "front_wheels"
wheelbase_m = 2.625
max_steering_angle_rad = 0.5537
max_steering_rate_rad_s = 0.5
max_speed_m_s = 8.33
max_reverse_speed_m_s = 1.0
max_acceleration_m_s2 = 1.0
max_deceleration_m_s2 = 3.0
max_centripetal_acceleration_m_s2 = 2.0

[lidar]
xyz_m = [0.5, 0.0, 2.15]
"#;

#[test]
fn sidecar_parses_and_errors_carry_line_and_column() {
    let spec = VehicleSpec::from_str(SPEC, "t.toml").expect("parses");
    assert_eq!(spec.lidar.rpy_rad, [0.0; 3]);
    assert_eq!(spec.fit, aircraft::FitOptions::default());
    assert_eq!(
        spec.overhead_clearance_m,
        aircraft::DEFAULT_OVERHEAD_CLEARANCE_M
    );
    // An unknown field on line 9.
    let text = SPEC.replace("max_speed_m_s = 8.33", "max_speed_kmh = 30.0");
    match VehicleSpec::from_str(&text, "t.toml") {
        Err(Error::Toml {
            file,
            line,
            column,
            message,
        }) => {
            assert_eq!(
                (file.as_str(), line, column),
                ("t.toml", 10, 1),
                "{message}"
            );
            assert!(message.contains("max_speed_kmh"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // A syntax error on line 2.
    let text = SPEC.replace("urdf = \"t.urdf\"", "urdf = t.urdf");
    match VehicleSpec::from_str(&text, "t.toml") {
        Err(e @ Error::Toml { line: 2, .. }) => assert!(e.to_string().starts_with("t.toml:2:")),
        other => panic!("{other:?}"),
    }
    // Values that parse but make no sense name the field.
    for (from, to, field) in [
        ("[0.0, 0.7]", "[0.0, 0.7, 0.5]", "heights_of_interest_m"),
        ("[0.0, 0.7]", "[0.2]", "heights_of_interest_m"),
        (
            "wheelbase_m = 2.625",
            "wheelbase_m = -2.625",
            "motion.wheelbase_m",
        ),
        (
            "max_steering_angle_rad = 0.5537",
            "max_steering_angle_rad = 2.0",
            "motion.max_steering_angle_rad",
        ),
        ("[0.5, 0.0, 2.15]", "[0.5, nan, 2.15]", "lidar"),
        (
            "heights_of_interest_m = [0.0, 0.7]",
            "heights_of_interest_m = [0.0, 0.7]\noverhead_clearance_m = -0.1",
            "overhead_clearance_m",
        ),
        (
            "heights_of_interest_m = [0.0, 0.7]",
            "heights_of_interest_m = [0.0, 0.7]\noverhead_clearance_m = inf",
            "overhead_clearance_m",
        ),
        (
            "heights_of_interest_m = [0.0, 0.7]",
            "heights_of_interest_m = [0.0, 0.7]\nwingspan_m = -1.0",
            "wingspan_m",
        ),
    ] {
        let e = VehicleSpec::from_str(&SPEC.replace(from, to), "t.toml").expect_err(field);
        assert!(matches!(e, Error::Field { .. }), "{e}");
        assert!(e.to_string().contains(field), "{e}");
    }
}

#[test]
fn a_wingspan_far_from_the_parts_span_is_refused() {
    let shipped = |file: &str| {
        std::fs::read_to_string(format!("{}/vehicles/{file}", env!("CARGO_MANIFEST_DIR")))
            .expect("shipped file")
    };
    let (spec, urdf) = (shipped("a320.toml"), shipped("a320.urdf"));
    let wide = spec.replace("wingspan_m = 35.8", "wingspan_m = 40.0");
    let e = Vehicle::from_strs(&wide, "a320.toml", &urdf, "a320.urdf").expect_err("refused");
    assert_eq!(
        e.to_string(),
        "a320.toml: field `wingspan_m`: 40 m is more than 1 m from the span of the URDF's parts (36.58 m)"
    );
}

#[test]
fn sidecar_naming_a_missing_urdf_is_an_io_error_with_the_path() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("t.toml");
    std::fs::write(&path, SPEC).expect("write");
    let e = aircraft::Vehicle::from_file(&path).expect_err("no urdf");
    assert!(matches!(e, Error::Io { .. }));
    assert!(e.to_string().contains("t.urdf"), "{e}");
}
