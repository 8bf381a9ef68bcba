//! Captures the tests build (a pcap written here, packets encoded here) decoded into points,
//! revolutions and the mapper's scans: HDL-32E and VLP-16, single and dual return.

use velodyne::{Calibration, Capture, DataPacket, Echo, Product, ReturnMode, frames};

use crate::common::{ethernet_udp, packet, pcap, write};

/// Two packets whose azimuths wrap between them: two revolutions, 31 returns a block (channel 5
/// has none), each point where the laser's angle and the block's azimuth put it, fired when the
/// manual says (the stamp is the last firing's), and the position packet's sentence read.
#[test]
fn built_packets_decode_to_their_points_and_revolutions() {
    let dir = tempfile::tempdir().unwrap();
    let first = packet(std::array::from_fn(|k| 35_800 + 15 * k as u16), 1_000_000);
    let second = packet(std::array::from_fn(|k| 20 * k as u16), 1_000_553);
    let mut position = vec![0u8; 512];
    position[198..202].copy_from_slice(&999_000u32.to_le_bytes());
    let nmea = b"$GPRMC,220632,A,3707.8324,N,12139.2864,W,000.0,144.7,111212,013.8,E,D*09\r\n";
    position[206..206 + nmea.len()].copy_from_slice(nmea);
    let records = [
        ethernet_udp(8308, &position),
        ethernet_udp(2368, &first.encode()),
        ethernet_udp(2368, &second.encode()),
    ];
    let path = write(dir.path(), "built.pcap", &pcap(1, &records));
    let capture = Capture::read(&path).unwrap();
    assert_eq!(capture.data.len(), 2);
    assert_eq!(capture.data[0], (1, first.clone()));
    assert_eq!(capture.positions[0].1.timestamp_us, 999_000);
    assert!(capture.positions[0].1.nmea.starts_with("$GPRMC,220632,A"));
    let calibration = Calibration::built_in(capture.product()).unwrap();
    let packets: Vec<DataPacket> = capture.data.into_iter().map(|(_, p)| p).collect();
    let f = frames(&packets, &calibration);
    assert_eq!(f.len(), 2);
    assert_eq!(f[0].points.len(), 12 * 31);
    assert_eq!(f[1].points.len(), 12 * 31);
    // Block 1 of the second packet (azimuth 0.2 degree), channel 2 (laser at -29.33 degrees):
    // 12 m away.
    let p = f[1].points[31 + 2];
    assert_eq!((p.laser, p.azimuth_cdeg, p.intensity), (2, 20, 2));
    let (w, a) = ((-29.33f64).to_radians(), 0.2f64.to_radians());
    let expected = [
        12.0 * w.cos() * a.sin(),
        12.0 * w.cos() * a.cos(),
        12.0 * w.sin(),
    ];
    for (got, want) in p.xyz_m.iter().zip(expected) {
        assert!((f64::from(*got) - want).abs() < 1e-5, "{p:?} {expected:?}");
    }
    // The stamp is the last firing (block 11, channel 31); block 1 channel 2 fired 10 firing
    // sequences and 29 lasers before it.
    let before = 10.0 * 46.08 + 29.0 * 1.152;
    assert!(
        (p.time_us - (1_000_553.0 - before)).abs() < 1e-9,
        "{}",
        p.time_us
    );
}

/// A revolution as the mapper's scan: a column per firing sequence, a beam per laser by
/// vertical angle (the HDL-32E's interleaved banks sorted: laser 2 at -29.33 degrees is beam 1),
/// each point in the simulator's sensor frame (azimuth 0 forward along +x) moved to the world.
#[test]
fn a_revolution_becomes_the_mappers_scan() {
    let p = packet(std::array::from_fn(|k| 9_000 + 20 * k as u16), 2_000_000);
    let calibration = Calibration::built_in(Product::Hdl32e).unwrap();
    let f = frames(&[p], &calibration);
    let sensor = nalgebra::Isometry3::translation(5.0, -2.0, 1.5);
    let vehicle = nalgebra::Isometry2::translation(5.0, -2.0);
    let s = velodyne::to_scan(&f[0], &calibration, &sensor, &vehicle).unwrap();
    assert_eq!((s.scan.beams(), s.scan.columns().len()), (32, 12));
    assert_eq!(s.scan.returns().iter().flatten().count(), 12 * 31);
    // Column 3 (azimuth 90.6 degrees: clockwise from forward, so to the right, -y), laser 2.
    let r = s.scan.returns()[3 * 32 + 1].expect("a return");
    let (w, a) = ((-29.33f64).to_radians(), 90.6f64.to_radians());
    let in_sensor = [
        12.0 * w.cos() * a.cos(),
        -12.0 * w.cos() * a.sin(),
        12.0 * w.sin(),
    ];
    let want = [5.0 + in_sensor[0], -2.0 + in_sensor[1], 1.5 + in_sensor[2]];
    for (got, want) in r.point_in_world.iter().zip(want) {
        assert!((got - want).abs() < 1e-4, "{r:?} {want:?}");
    }
    assert!((r.intensity - 2.0 / 255.0).abs() < 1e-6);
    // Channel 5 (laser at -6.67 degrees, beam 18) has no echo.
    assert_eq!(s.scan.returns()[3 * 32 + 18], None);
}

/// A VLP-16 block holds two 16-laser firing sequences: two columns of the scan, every return
/// kept (16 beams by angle, -15 degrees the lowest).
#[test]
fn a_vlp16_block_is_two_columns() {
    let mut p = packet(std::array::from_fn(|k| 40 * k as u16), 9_000);
    p.product = Product::Vlp16;
    let calibration = Calibration::built_in(Product::Vlp16).unwrap();
    let f = frames(&[p], &calibration);
    let s = velodyne::to_scan(
        &f[0],
        &calibration,
        &nalgebra::Isometry3::identity(),
        &nalgebra::Isometry2::identity(),
    )
    .unwrap();
    assert_eq!((s.scan.beams(), s.scan.columns().len()), (16, 24));
    assert_eq!(s.scan.returns().iter().flatten().count(), f[0].points.len());
    assert_eq!(f[0].points.len(), 12 * 31);
    // Channel 16 (laser 0 of the second sequence, -15 degrees) is beam 0 of column 1.
    let r = s.scan.returns()[16].expect("a return");
    assert!((r.range_m - 26.0).abs() < 1e-3, "{r:?}");
}

/// In dual-return mode a block pair repeats an azimuth; where the second repeats the first's
/// distance (one echo), the return is counted once and marked last and strongest; where they
/// differ, both are kept, the first block's marked last, the second's strongest. A single-return
/// packet's points carry its mode.
#[test]
fn dual_return_pairs_count_a_single_echo_once_and_mark_both_echoes() {
    let mut p = packet(std::array::from_fn(|k| 100 * (k as u16 / 2)), 5_000);
    p.return_mode = ReturnMode::Dual;
    // Block 1 (the pair of block 0) has a farther echo on channel 0.
    p.blocks[1].channels[0].0 += 500;
    let calibration = Calibration::built_in(Product::Hdl32e).unwrap();
    let f = frames(&[p.clone()], &calibration);
    assert_eq!(f.len(), 1);
    let points = &f[0].points;
    assert_eq!(points.len(), 6 * 31 + 1);
    let of = |echo: Echo| points.iter().filter(|q| q.echo == echo).count();
    assert_eq!(of(Echo::LastAndStrongest), 6 * 31 - 1);
    assert_eq!((of(Echo::Last), of(Echo::DualStrongest)), (1, 1));
    let (last, strongest) = (
        points.iter().find(|q| q.echo == Echo::Last).unwrap(),
        points
            .iter()
            .find(|q| q.echo == Echo::DualStrongest)
            .unwrap(),
    );
    // One laser's firing: the same laser and firing, the strongest 500 units (1 m) farther.
    assert_eq!(
        (last.laser, last.firing),
        (strongest.laser, strongest.firing)
    );
    assert!((strongest.distance_m - last.distance_m - 1.0).abs() < 1e-4);
    for (mode, echo) in [
        (ReturnMode::Strongest, Echo::Strongest),
        (ReturnMode::Last, Echo::Last),
    ] {
        p.return_mode = mode;
        let f = frames(&[p.clone()], &calibration);
        assert!(f[0].points.iter().all(|q| q.echo == echo), "{mode:?}");
    }
}

/// The VLP-16's precision azimuth (its manual, appendix: as VeloView and the ROS driver place
/// its returns): each laser fired on from the block's azimuth by the gap to the next block times
/// its firing time over the block's 110.592 us - the second 16-laser sequence half a gap on,
/// each laser 2.304 us after the one before; the last block of a packet by the gap before it. In
/// dual-return mode a pair's blocks share their azimuth and the gap is to the next pair.
#[test]
fn vlp16_returns_are_placed_at_their_precision_azimuth() {
    let calibration = Calibration::built_in(Product::Vlp16).unwrap();
    // Blocks 0.4 degrees apart (the VLP-16 at 600 rpm).
    let mut p = packet(std::array::from_fn(|k| 1_000 + 40 * k as u16), 9_000);
    p.product = Product::Vlp16;
    let f = frames(&[p.clone()], &calibration);
    let azimuth_deg = |q: &velodyne::Point| {
        f64::from(q.xyz_m[0])
            .atan2(f64::from(q.xyz_m[1]))
            .to_degrees()
    };
    // Channel j's point of block k (31 a block: channel 5 has no echo).
    let at =
        |points: &[velodyne::Point], k: usize, j: usize| points[k * 31 + j - usize::from(j > 5)];
    for (k, j, want_deg) in [
        (0, 0, 10.0),
        (0, 15, 10.0 + 0.4 * 15.0 * 2.304 / 110.592),
        (0, 16, 10.2),
        (0, 31, 10.2 + 0.4 * 15.0 * 2.304 / 110.592),
        (4, 16, 11.6 + 0.2),
        (11, 16, 14.4 + 0.2),
    ] {
        let q = at(&f[0].points, k, j);
        assert_eq!(q.laser as usize, j % 16);
        let got = azimuth_deg(&q);
        assert!(
            (got - want_deg).abs() < 1e-4,
            "block {k} channel {j}: {got} against {want_deg}"
        );
    }
    // Dual return: pairs at one azimuth, 0.4 degrees a pair; the gap is to the next pair.
    let mut dual = packet(std::array::from_fn(|k| 1_000 + 40 * (k / 2) as u16), 9_000);
    dual.product = Product::Vlp16;
    dual.return_mode = ReturnMode::Dual;
    for b in dual.blocks.iter_mut().skip(1).step_by(2) {
        for c in b.channels.iter_mut().filter(|c| c.0 > 0) {
            c.0 += 100; // a second, farther echo on every channel that had one
        }
    }
    let f = frames(&[dual], &calibration);
    let q = at(&f[0].points, 1, 16);
    assert!((azimuth_deg(&q) - 10.2).abs() < 1e-4, "{}", azimuth_deg(&q));
}
