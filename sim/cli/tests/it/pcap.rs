//! `taxi-sim scan --pcap`, `map --pcap` and `compare-lidar` end to end on a capture built here:
//! an HDL-32E standing 1.8 m above flat ground, two revolutions and a bit. Bad arguments exit 2
//! with a message naming them.

use velodyne::packet::{Block, CHANNELS};
use velodyne::{Calibration, DataPacket, Product, ReturnMode};

fn taxi_sim(args: &[&str]) -> (i32, String, String) {
    crate::taxi_sim_in(std::path::Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// The capture: each laser aimed down returns from the ground 1.8 m below, the rest nothing.
fn capture(path: &std::path::Path) {
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    let datagrams: Vec<(f64, u16, Vec<u8>)> = (0..(1800 * 2 + 600) / 12)
        .map(|p| {
            let blocks = std::array::from_fn(|k| {
                let mut channels = [(0u16, 0u8); CHANNELS];
                for (j, c) in channels.iter_mut().enumerate() {
                    let w = table.vertical_deg[j].to_radians();
                    if w < -0.02 && 1.8 / (-w).sin() < 100.0 {
                        *c = ((1.8 / (-w).sin() / 0.002).round() as u16, 30);
                    }
                }
                Block {
                    azimuth_cdeg: (((p * 12 + k) % 1800) * 20) as u16,
                    channels,
                }
            });
            let packet = DataPacket {
                blocks,
                timestamp_us: 553 * p as u32,
                return_mode: ReturnMode::Strongest,
                product: Product::Hdl32e,
            };
            (553e-6 * p as f64, 2368, packet.encode())
        })
        .collect();
    std::fs::write(path, velodyne::pcap_bytes(&datagrams)).unwrap();
}

#[test]
fn a_capture_scans_maps_and_compares() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("ground.pcap");
    capture(&file);
    let f = file.to_str().unwrap();
    let ply = dir.path().join("rev1.ply");
    let (code, out, err) = taxi_sim(&["scan", "--pcap", f, "--out", ply.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("revolution 1 of 3") && out.contains("1.80 m above the ground"),
        "{out}"
    );
    // Every laser aimed down returns, 1800 firings a revolution; 20 bytes a vertex.
    let table = Calibration::built_in(Product::Hdl32e).unwrap();
    let down = table.vertical_deg.iter().filter(|w| **w < -1.0).count() as u64;
    let size = std::fs::metadata(&ply).unwrap().len();
    assert!(
        size > down * 1800 * 20 && size < down * 1800 * 20 + 1000,
        "{size}"
    );
    let map = dir.path().join("map");
    let scenario = "../../scenarios/straight_cone_under_wing.toml";
    let (code, out, err) = taxi_sim(&[
        "map",
        scenario,
        "--pcap",
        f,
        "--pose",
        "5,5,90",
        "--out",
        map.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("mapped 1 revolutions"), "{out}");
    assert!(map.join("level0.yaml").exists() && map.join("manifest.json").exists());
    // The same without a scenario, the vehicle named: the same map, manifest for manifest.
    let by_vehicle = dir.path().join("map_by_vehicle");
    let (code, out, err) = taxi_sim(&[
        "map",
        "--vehicle",
        "iara_car_fake_wing",
        "--pcap",
        f,
        "--pose",
        "5,5,90",
        "--out",
        by_vehicle.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("mapped 1 revolutions"), "{out}");
    let manifest = |d: &std::path::Path| {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("manifest.json")).unwrap())
                .unwrap();
        (
            v["occupied_cells"].clone(),
            v["level_heights_m"].clone(),
            v["blocks"].clone(),
        )
    };
    assert_eq!(manifest(&map), manifest(&by_vehicle));
    // A vehicle and no data: the mapping drive needs a scenario; said so.
    let (code, _, err) = taxi_sim(&["map", "--vehicle", "praetor600"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--from-bag BAG or --pcap FILE"), "{err}");
    let (code, out, err) = taxi_sim(&["compare-lidar", "--pcap", f]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("| height above the fitted ground; pitch, roll | 1.800 m; "),
        "{out}"
    );
}

#[test]
fn bad_pcap_arguments_exit_2_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("ground.pcap");
    capture(&file);
    let f = file.to_str().unwrap();
    let out = dir.path().join("x.ply");
    let (code, _, err) = taxi_sim(&[
        "scan",
        "--pcap",
        f,
        "--revolution",
        "7",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--revolution 7") && err.contains("has 3 (0 to 2)"),
        "{err}"
    );
    let scenario = "../../scenarios/straight_cone_under_wing.toml";
    let (code, _, err) = taxi_sim(&["map", scenario, "--pcap", f, "--pose", "1,2"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--pose 1,2"), "{err}");
    // A moving sensor's poses that end before the capture's revolutions: the revolution named.
    let poses = dir.path().join("poses.csv");
    std::fs::write(&poses, "time_s,x_m,y_m,yaw_deg\n0,0,0,0\n0.01,1,0,0\n").unwrap();
    let map = dir.path().join("map");
    let (code, _, err) = taxi_sim(&[
        "map",
        scenario,
        "--pcap",
        f,
        "--poses",
        poses.to_str().unwrap(),
        "--out",
        map.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("ground.pcap")
            && err.contains("full revolution 0")
            && err.contains("outside the poses"),
        "{err}"
    );
    let (code, _, err) = taxi_sim(&[
        "map",
        scenario,
        "--pcap",
        f,
        "--pose",
        "1,2,0",
        "--poses",
        poses.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--poses") || err.contains("--pose"), "{err}");
    let (code, _, err) = taxi_sim(&["compare-lidar", "--pcap", scenario]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("straight_cone_under_wing.toml") && err.contains("not a pcap"),
        "{err}"
    );
}

/// `scan SCENARIO --out FILE.pcap`: the simulator's VLP-16 written as a capture that `scan
/// --pcap` reads back (the revolutions, the sensor's height from the ground), the same file cut
/// inside its last packet read up to the cut with a line saying what was skipped; a LiDAR model
/// that is not one, or a revolution count of 0, exit 2 naming the flag.
#[test]
fn a_scenario_written_as_a_capture_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let pcap = dir.path().join("vlp16.pcap");
    let (code, out, err) = taxi_sim(&[
        "scan",
        "../../scenarios/straight_cone_under_wing.toml",
        "--lidar-model",
        "vlp-16",
        "--revolutions",
        "2",
        "--out",
        pcap.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("2 revolution(s)") && out.contains("in 150 data packets"),
        "{out}"
    );
    let ply = dir.path().join("back.ply");
    let (code, out, err) = taxi_sim(&[
        "scan",
        "--pcap",
        pcap.to_str().unwrap(),
        "--revolution",
        "0",
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // The Praetor's LiDAR stands 2.15 m up on the straight road's flat ground.
    assert!(
        out.contains("revolution 0 of 2")
            && out.contains("in 1800 firings of 16 lasers, the sensor 2.15 m"),
        "{out}"
    );
    let bytes = std::fs::read(&pcap).unwrap();
    let cut = dir.path().join("cut.pcap");
    std::fs::write(&cut, &bytes[..bytes.len() - 500]).unwrap();
    let (code, _, err) = taxi_sim(&[
        "scan",
        "--pcap",
        cut.to_str().unwrap(),
        "--revolution",
        "0",
        "--out",
        ply.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("cut short: the file ends inside it (the first packet 149)"),
        "{err}"
    );
    for (flag, value) in [("--lidar-model", "vlp-32"), ("--revolutions", "0")] {
        let (code, _, err) = taxi_sim(&[
            "scan",
            "../../scenarios/straight_cone_under_wing.toml",
            flag,
            value,
            "--out",
            pcap.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{flag}: {err}");
        assert!(err.contains(flag), "{flag}: {err}");
    }
}
