//! VeloView calibration files: read, their corrections applied to the points, and hostile ones
//! refused naming the file, the line or the lasers.

use velodyne::{Calibration, Product, frames};

use crate::common::{packet, write};

/// A VeloView calibration file of `lasers` lasers, each at the HDL-32E's angle, laser 0 with
/// the corrections given (degrees and centimetres, as VeloView writes them).
fn veloview_xml(lasers: usize, rot_deg: f64, dist_cm: f64, vert_text: &str) -> String {
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    let mut x = String::from(
        "<?xml version=\"1.0\"?>\n<!DOCTYPE boost_serialization>\n<boost_serialization>\n<DB>\n\t<distLSB_>0.2</distLSB_>\n\t<points_>\n",
    );
    for i in 0..lasers {
        let (rot, dist) = if i == 0 {
            (rot_deg, dist_cm)
        } else {
            (0.0, 0.0)
        };
        let vert = if i == 3 {
            vert_text.to_string()
        } else {
            table.vertical_deg[i].to_string()
        };
        x += &format!(
            "\t\t<item>\n\t\t\t<px>\n\t\t\t\t<id_>{i}</id_>\n\t\t\t\t<rotCorrection_>{rot}</rotCorrection_>\n\t\t\t\t<vertCorrection_>{vert}</vertCorrection_>\n\t\t\t\t<distCorrection_>{dist}</distCorrection_>\n\t\t\t\t<vertOffsetCorrection_>0</vertOffsetCorrection_>\n\t\t\t\t<horizOffsetCorrection_>0</horizOffsetCorrection_>\n\t\t\t</px>\n\t\t</item>\n"
        );
    }
    x + "\t</points_>\n</DB>\n</boost_serialization>\n"
}

/// A VeloView calibration file read: the table it holds, its corrections applied (laser 0 turned
/// 90 degrees and 10 cm farther); one missing lasers, one with a word for an angle and one that
/// is not XML are errors naming the file, the line or the lasers.
#[test]
fn veloview_calibration_files_are_read_and_applied() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(
        dir.path(),
        "hdl32.xml",
        veloview_xml(32, 90.0, 10.0, "-8").as_bytes(),
    );
    let c = Calibration::from_veloview_xml(&file, 32).unwrap();
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    assert_eq!(c.vertical_deg, table.vertical_deg);
    assert_eq!((c.rotation_deg[0], c.distance_offset_m[0]), (90.0, 0.1));
    assert!((c.distance_unit_m - 0.002).abs() < 1e-12);
    // Block azimuth 0 and laser 0 (10 m, -30.67 degrees): turned to azimuth -90 (VeloView's -x),
    // 10.1 m away.
    let mut p = packet([0; 12], 0);
    p.blocks[0].channels[0].0 = 5000;
    let f = frames(std::slice::from_ref(&p), &c);
    let q = f[0].points[0];
    let w = (-30.67f64).to_radians();
    let want = [-10.1 * w.cos(), 0.0, 10.1 * w.sin()];
    for (got, want) in q.xyz_m.iter().zip(want) {
        assert!((f64::from(*got) - want).abs() < 1e-5, "{q:?} {want:?}");
    }
    // Hostile files.
    let short = write(
        dir.path(),
        "short.xml",
        veloview_xml(16, 0.0, 0.0, "-8").as_bytes(),
    );
    let e = Calibration::from_veloview_xml(&short, 32)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("short.xml") && e.contains("lasers missing: [16, 17"),
        "{e}"
    );
    let word = write(
        dir.path(),
        "word.xml",
        veloview_xml(32, 0.0, 0.0, "minus eight").as_bytes(),
    );
    let e = Calibration::from_veloview_xml(&word, 32)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("word.xml: line 41: vertCorrection_: \"minus eight\""),
        "{e}"
    );
    let junk = write(dir.path(), "junk.xml", b"<DB><px></DB>");
    let e = Calibration::from_veloview_xml(&junk, 32)
        .unwrap_err()
        .to_string();
    assert!(e.contains("junk.xml: line 1: not XML"), "{e}");
}
