//! Ignored unless asked, as CI asks (`-- --ignored shared_data`): VeloView's real HDL-32E
//! recording in `../shared/data/velodyne` against VeloView's own expected values.

use std::path::PathBuf;

use velodyne::{Calibration, Capture, DataPacket, Product, frames};

/// VeloView's expected values for its real HDL-32E recording (`monterey.test`, Kitware's
/// VeloView at f3efc9b): 19 revolutions, the points of five of them, and four points of
/// revolution 8 to 1 mm. Reads `../shared/data`; run with `--ignored`, as CI does.
#[test]
#[ignore = "reads ../shared/data"]
fn shared_data_monterey_reproduces_veloviews_values() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/velodyne");
    let capture = Capture::read(&dir.join("monterey-first-100-packets.pcap")).unwrap();
    assert_eq!(capture.product(), Product::Hdl32e);
    assert_eq!((capture.data.len(), capture.positions.len()), (2702, 299));
    let expected = std::fs::read_to_string(dir.join("monterey.test")).unwrap();
    let calibration = Calibration::built_in(Product::Hdl32e).unwrap();
    let packets: Vec<DataPacket> = capture.data.into_iter().map(|(_, p)| p).collect();
    let f = frames(&packets, &calibration);
    let mut frame = 0usize;
    let mut checked = 0;
    for line in expected.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["frame_count", n] => assert_eq!(f.len(), n.parse::<usize>().unwrap()),
            ["frame", n] => frame = n.parse().unwrap(),
            ["point_count", n] => assert_eq!(f[frame].points.len(), n.parse::<usize>().unwrap()),
            ["point_values", i, x, y, z, intensity, _] => {
                let p = f[frame].points[i.parse::<usize>().unwrap()];
                for (got, want) in p.xyz_m.iter().zip([x, y, z]) {
                    let want: f64 = want.parse().unwrap();
                    assert!((f64::from(*got) - want).abs() < 1e-3, "{line}: {p:?}");
                }
                assert_eq!(p.intensity, intensity.parse::<u8>().unwrap(), "{line}");
                checked += 1;
            }
            _ => {}
        }
    }
    assert_eq!(checked, 4);
    // VeloView's own calibration file for the sensor: the same table, the same points.
    let xml = Calibration::from_veloview_xml(&dir.join("HDL-32.xml"), 32).unwrap();
    for (a, b) in xml.vertical_deg.iter().zip(&calibration.vertical_deg) {
        assert!((a - b).abs() < 0.01, "{a} {b}");
    }
    let g = frames(&packets, &xml);
    assert_eq!(g.len(), f.len());
    for (p, q) in g[8].points.iter().zip(&f[8].points) {
        for (a, b) in p.xyz_m.iter().zip(q.xyz_m) {
            assert!((a - b).abs() < 1e-3, "{p:?} {q:?}");
        }
    }
    // A whole revolution as the mapper's scan: a column per firing, every return kept.
    let s = velodyne::to_scan(
        &f[8],
        &calibration,
        &nalgebra::Isometry3::identity(),
        &nalgebra::Isometry2::identity(),
    )
    .unwrap();
    assert!((1842..=1844).contains(&s.scan.columns().len()));
    assert_eq!(s.scan.returns().iter().flatten().count(), f[8].points.len());
}
