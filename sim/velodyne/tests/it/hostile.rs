//! Hostile captures refused with errors naming the file, the packet and what is wrong; other
//! traffic and other link layers read as the sensor's own packets.

use velodyne::{Capture, VelodyneError};

use crate::common::{ethernet_udp, packet, pcap, write};

fn error_of(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "hostile.pcap", bytes);
    let e = Capture::read(&path).expect_err("an error");
    let text = e.to_string();
    assert!(text.contains("hostile.pcap"), "{text}");
    assert!(!matches!(e, VelodyneError::Io { .. }), "{text}");
    text
}

/// Hostile captures: each a clear error naming the file, the packet and what is wrong.
#[test]
fn hostile_captures_are_located_errors() {
    let good = packet([0; 12], 0).encode();
    let whole = pcap(1, &[ethernet_udp(2368, &good), ethernet_udp(2368, &good)]);
    // Cut inside the first packet: nothing to read, and the error says so.
    let e = error_of(&whole[..24 + 16 + 600]);
    assert!(
        e.contains("no Velodyne data packets")
            && e.contains("1 cut short: the file ends inside it (the first packet 0)"),
        "{e}"
    );
    // Not a capture at all.
    let e = error_of(b"# not a capture\n");
    assert!(e.contains("not a pcap"), "{e}");
    // Another link type (IEEE 802.11).
    let e = error_of(&pcap(105, &[ethernet_udp(2368, &good)]));
    assert!(
        e.contains("packet 0") && e.contains("link type 105 not supported"),
        "{e}"
    );
    // Only packets of a sensor not read here (product byte 0x28, a VLP-32C).
    let mut other = good.clone();
    other[1205] = 0x28;
    let e = error_of(&pcap(1, &[ethernet_udp(2368, &other)]));
    assert!(
        e.contains("no Velodyne data packets")
            && e.contains("1 to port 2368 of a sensor not read here (product byte not 0x21 or 0x22) (the first packet 0)"),
        "{e}"
    );
    // Only a packet with a block whose flag is not 0xEEFF (an HDL-64E's lower bank).
    let mut lower = good.clone();
    lower[300] = 0xff;
    lower[301] = 0xdd;
    let e = error_of(&pcap(1, &[ethernet_udp(2368, &lower)]));
    assert!(
        e.contains("no Velodyne data packets") && e.contains("block flag other than 0xeeff"),
        "{e}"
    );
    // A VLP-16 packet among HDL-32E ones.
    let mut vlp = good.clone();
    vlp[1205] = 0x22;
    let e = error_of(&pcap(
        1,
        &[ethernet_udp(2368, &good), ethernet_udp(2368, &vlp)],
    ));
    assert!(
        e.contains("packet 1") && e.contains("another sensor"),
        "{e}"
    );
    // Only a packet cut by the capture's snap length: skipped, so no data, and the error says
    // what was skipped.
    let mut snapped = pcap(1, &[ethernet_udp(2368, &good)[..200].to_vec()]);
    snapped[24 + 12..24 + 16].copy_from_slice(&1248u32.to_le_bytes());
    let e = error_of(&snapped);
    assert!(
        e.contains("no Velodyne data packets")
            && e.contains("1 cut short by the capture's snap length (the first packet 0)"),
        "{e}"
    );
    // No data packets at all.
    let e = error_of(&pcap(1, &[ethernet_udp(53, b"dns")]));
    assert!(e.contains("no Velodyne data packets"), "{e}");
}

/// Odd packets among good ones are skipped and counted by why, as VeloView reads on past them:
/// a position packet whose IPv4 header claims more bytes than it has (a recording tool's quirk
/// seen in a real VLP-16 capture), a data packet cut by the snap length, an IPv4 fragment to the
/// data port, a datagram to the data port of another length, data packets no sensor would send,
/// and a last packet the file ends inside; the good packets decode as they do without them.
#[test]
fn odd_packets_among_good_ones_are_skipped_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let good: Vec<Vec<u8>> = (0..3u16)
        .map(|k| ethernet_udp(2368, &packet([100 * k; 12], u32::from(k)).encode()))
        .collect();
    let clean = Capture::read(&write(dir.path(), "clean.pcap", &pcap(1, &good))).unwrap();
    assert_eq!(clean.skipped.total(), 0);
    let mut position = ethernet_udp(8308, &[0u8; 512]);
    position[14 + 2..14 + 4].copy_from_slice(&1234u16.to_be_bytes()); // IPv4 total length
    let mut fragment = good[0].clone();
    fragment[14 + 6] = 0x20; // more fragments
    let other_length = ethernet_udp(2368, &[0u8; 100]);
    let snapped = good[1][..300].to_vec();
    // Data packets that cannot be a sensor's: a block flag, an azimuth, a return mode byte and a
    // product byte no sensor sends.
    let payload = packet([0; 12], 0).encode();
    let odd_data = [(200, 0x00), (202, 0xff), (1204, 0x41), (1205, 0x28)].map(|(at, byte)| {
        let mut p = payload.clone();
        p[at] = byte;
        if at == 202 {
            p[203] = 0xff; // azimuth 655.35 degrees
        }
        ethernet_udp(2368, &p)
    });
    let mut records = vec![
        good[0].clone(),
        position,
        good[1].clone(),
        fragment,
        snapped.clone(),
        other_length,
    ];
    records.extend(odd_data);
    records.push(good[2].clone());
    let mut bytes = pcap(1, &records);
    // The snapped record (the fifth) says 300 of its whole length kept.
    let at = 24 + records[..4].iter().map(|r| 16 + r.len()).sum::<usize>();
    bytes[at + 12..at + 16].copy_from_slice(&(good[1].len() as u32).to_le_bytes());
    // And the file cut inside a last, eleventh packet (the recorder stopped mid-write).
    bytes.extend(&bytes[24..24 + 16 + 700].to_vec());
    let c = Capture::read(&write(dir.path(), "odd.pcap", &bytes)).unwrap();
    let decoded: Vec<_> = c.data.iter().map(|(_, p)| p.clone()).collect();
    let expected: Vec<_> = clean.data.iter().map(|(_, p)| p.clone()).collect();
    assert_eq!(decoded, expected);
    assert_eq!(
        c.data.iter().map(|(i, _)| *i).collect::<Vec<_>>(),
        [0, 2, 10]
    );
    assert_eq!(c.skipped.total(), 9, "{}", c.skipped);
    let text = c.skipped.to_string();
    for why in [
        "1 with an IPv4 total length outside the packet (the first packet 1)",
        "1 IPv4 fragments (Velodyne packets are never fragmented) (the first packet 3)",
        "1 cut short by the capture's snap length (the first packet 4)",
        "1 to port 2368 of neither 1206 nor 512 bytes (the first packet 5)",
        "1 to port 2368 with a block flag other than 0xeeff (an HDL-64E's upper lasers, or not Velodyne data) (the first packet 6)",
        "1 to port 2368 with an azimuth beyond 360 degrees (the first packet 7)",
        "1 to port 2368 with a return mode byte no sensor sends (the first packet 8)",
        "1 to port 2368 of a sensor not read here (product byte not 0x21 or 0x22) (the first packet 9)",
        "1 cut short: the file ends inside it (the first packet 11)",
    ] {
        assert!(text.contains(why), "{why}: {text}");
    }
}

/// Other traffic in a capture is skipped, even when it could not be read whole (a fragment, a
/// packet snapped by the capture); 802.1Q-tagged and Linux cooked (v1, v2) captures read as
/// Ethernet ones do.
#[test]
fn other_traffic_and_other_link_layers() {
    let dir = tempfile::tempdir().unwrap();
    let good = packet([0; 12], 0).encode();
    let sensor = ethernet_udp(2368, &good);
    let mut fragment = ethernet_udp(53, b"a fragment of a DNS answer");
    fragment[14 + 6] = 0x20; // more fragments
    let snapped = ethernet_udp(53, &[7u8; 400])[..100].to_vec();
    let mut bytes = pcap(1, &[fragment, sensor.clone(), snapped.clone()]);
    // The snapped record says 100 of 442 bytes.
    let third = bytes.len() - snapped.len() - 16;
    bytes[third + 12..third + 16].copy_from_slice(&442u32.to_le_bytes());
    let path = write(dir.path(), "mixed.pcap", &bytes);
    let c = Capture::read(&path).unwrap();
    assert_eq!(c.data.len(), 1);
    assert_eq!(c.data[0].0, 1);
    // The same packet behind an 802.1Q tag, and in Linux cooked captures.
    let mut tagged = sensor[..12].to_vec();
    tagged.extend_from_slice(&[0x81, 0x00, 0x00, 0x05]);
    tagged.extend_from_slice(&sensor[12..]);
    let ip = &sensor[14..];
    let mut sll = vec![0u8; 14];
    sll.extend_from_slice(&[0x08, 0x00]);
    sll.extend_from_slice(ip);
    let mut sll2 = vec![0x08, 0x00];
    sll2.extend_from_slice(&[0u8; 18]);
    sll2.extend_from_slice(ip);
    for (link, record) in [(1, tagged), (113, sll), (276, sll2), (101, ip.to_vec())] {
        let path = write(
            dir.path(),
            &format!("link{link}.pcap"),
            &pcap(link, &[record]),
        );
        let c = Capture::read(&path).unwrap_or_else(|e| panic!("link {link}: {e}"));
        assert_eq!(c.data[0].1, packet([0; 12], 0), "link {link}");
    }
}
