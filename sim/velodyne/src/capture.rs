//! The UDP datagrams of a capture: a pcap or pcapng file read with `pcap-parser`, each packet's
//! link layer (Ethernet with or without an 802.1Q tag, Linux cooked capture v1 or v2, raw IPv4),
//! IPv4 header (its own length, not assumed 20 bytes) and UDP header parsed. Packets that are
//! not IPv4 UDP (ARP, IPv6, TCP) are skipped; so is, as VeloView and Wireshark read on past it,
//! one that cannot be read whole - a fragment, cut short by the capture's snap length, a length
//! field past its end - counted by why when it was for the sensor's ports (2368, 8308)
//! ([`Skipped`]). A file that ends inside a packet, or a record whose header cannot be read, is
//! read up to there, the rest counted as skipped. An unsupported link type is an error.

use std::fs::File;
use std::path::{Path, PathBuf};

use pcap_parser::{Linktype, PcapBlockOwned, PcapError, create_reader, pcapng::Block};

use crate::VelodyneError;

/// One UDP datagram of a capture.
#[derive(Clone, Debug, PartialEq)]
pub struct Datagram {
    /// The packet's record index in the capture, from 0 (every record counts, UDP or not).
    pub index: usize,
    /// The capture's timestamp (the host's clock), seconds since the Unix epoch.
    pub time_s: f64,
    /// UDP source port.
    pub src_port: u16,
    /// UDP destination port.
    pub dst_port: u16,
    /// The UDP payload.
    pub payload: Vec<u8>,
}

/// Packets for the sensor's ports skipped because they could not be read whole: how many, the
/// first's record index, by why.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skipped(pub std::collections::BTreeMap<String, (u64, usize)>);

impl Skipped {
    /// Counts packet `index`, skipped for `why`.
    pub fn add(&mut self, why: String, index: usize) {
        self.0.entry(why).or_insert((0, index)).0 += 1;
    }

    /// Packets skipped in all.
    pub fn total(&self) -> u64 {
        self.0.values().map(|(n, _)| n).sum()
    }
}

impl std::fmt::Display for Skipped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let parts: Vec<String> = self
            .0
            .iter()
            .map(|(why, (n, first))| format!("{n} {why} (the first packet {first})"))
            .collect();
        write!(f, "{}", parts.join("; "))
    }
}

/// Every IPv4 UDP datagram of the capture at `path`, in capture order, and the sensor's packets
/// skipped.
pub fn read_datagrams(path: &Path) -> Result<(Vec<Datagram>, Skipped), VelodyneError> {
    let file = File::open(path).map_err(|source| VelodyneError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let whole = |what: String| VelodyneError::File {
        file: path.to_path_buf(),
        what,
    };
    let mut reader = create_reader(1 << 20, file)
        .map_err(|e| whole(format!("not a pcap or pcapng capture ({e:?})")))?;
    let mut out = Vec::new();
    let mut skipped = Skipped::default();
    // The legacy header's link type and time unit; pcapng's per interface.
    let mut legacy: Option<(Linktype, f64)> = None;
    let mut interfaces: Vec<(Linktype, f64)> = Vec::new();
    let mut index = 0usize;
    loop {
        match reader.next() {
            Ok((offset, block)) => {
                let packet = match block {
                    PcapBlockOwned::LegacyHeader(h) => {
                        let unit = if h.is_nanosecond_precision() {
                            1e-9
                        } else {
                            1e-6
                        };
                        legacy = Some((h.network, unit));
                        None
                    }
                    PcapBlockOwned::Legacy(b) => {
                        let (link, unit) = legacy.ok_or_else(|| whole("no header".into()))?;
                        let time_s = b.ts_sec as f64 + b.ts_usec as f64 * unit;
                        Some((link, time_s, b.caplen, b.origlen, b.data.to_vec()))
                    }
                    PcapBlockOwned::NG(Block::SectionHeader(_)) => {
                        interfaces.clear();
                        None
                    }
                    PcapBlockOwned::NG(Block::InterfaceDescription(i)) => {
                        let per_s = i.ts_resolution().unwrap_or(1_000_000).max(1) as f64;
                        interfaces.push((i.linktype, 1.0 / per_s));
                        None
                    }
                    PcapBlockOwned::NG(Block::EnhancedPacket(p)) => {
                        let &(link, unit) = interfaces.get(p.if_id as usize).ok_or_else(|| {
                            packet_error(path, index, format!("interface {} undeclared", p.if_id))
                        })?;
                        let ticks = (u64::from(p.ts_high) << 32) | u64::from(p.ts_low);
                        let data = p.data.get(..p.caplen as usize).unwrap_or(p.data);
                        Some((
                            link,
                            ticks as f64 * unit,
                            p.caplen,
                            p.origlen,
                            data.to_vec(),
                        ))
                    }
                    PcapBlockOwned::NG(Block::SimplePacket(p)) => {
                        let &(link, _) = interfaces
                            .first()
                            .ok_or_else(|| packet_error(path, index, "no interface".into()))?;
                        let len = p.data.len() as u32;
                        Some((link, 0.0, len, p.origlen.max(len), p.data.to_vec()))
                    }
                    PcapBlockOwned::NG(_) => None,
                };
                if let Some((link, time_s, caplen, origlen, data)) = packet {
                    let record = Record {
                        index,
                        link,
                        time_s,
                        caplen,
                        origlen,
                    };
                    if let Some(d) = datagram_of(path, &record, &data, &mut skipped)? {
                        out.push(d);
                    }
                    index += 1;
                }
                reader.consume(offset);
            }
            Err(PcapError::Eof) => break,
            Err(PcapError::Incomplete(_)) => {
                reader
                    .refill()
                    .map_err(|e| whole(format!("read failed ({e:?})")))?;
                if reader.reader_exhausted() && reader.data().is_empty() {
                    break;
                }
            }
            // A capture cut short (the recorder stopped mid-write) or a record whose header is
            // damaged: what came before is read, the rest skipped and counted (the framing is
            // lost past it), as Wireshark and VeloView read up to it.
            Err(PcapError::UnexpectedEof) => {
                skipped.add("cut short: the file ends inside it".into(), index);
                break;
            }
            Err(e) => {
                if index == 0 {
                    return Err(packet_error(path, index, format!("unreadable ({e:?})")));
                }
                skipped.add(
                    format!("unreadable ({e:?}), and every record after it"),
                    index,
                );
                break;
            }
        }
    }
    if index == 0 && skipped.total() == 0 {
        return Err(whole("no packets".into()));
    }
    Ok((out, skipped))
}

/// A packet record's fields beside its data.
struct Record {
    index: usize,
    link: Linktype,
    time_s: f64,
    caplen: u32,
    origlen: u32,
}

/// The UDP datagram of one packet record; `None` for what is skipped (not IPv4 UDP, or a packet
/// that cannot be read whole: counted in `skipped` when it was for the sensor's ports).
fn datagram_of(
    path: &Path,
    r: &Record,
    data: &[u8],
    skipped: &mut Skipped,
) -> Result<Option<Datagram>, VelodyneError> {
    if !supported(r.link) {
        return Err(packet_error(
            path,
            r.index,
            format!(
                "link type {} not supported (Ethernet 1, Linux cooked 113 and 276, raw IPv4 101 \
                 and 228 are)",
                r.link.0
            ),
        ));
    }
    // A packet that cannot be read whole is skipped; counted if it was for the sensor's ports.
    let velodyne = |port: Option<u16>| {
        port.is_some_and(|p| p == crate::packet::DATA_PORT || p == crate::packet::POSITION_PORT)
    };
    let parsed = udp(r.link, data);
    if r.caplen < r.origlen {
        let port = match &parsed {
            Ok(Some(d)) => Some(d.1),
            Ok(None) => None,
            Err((port, _)) => *port,
        };
        if velodyne(port) {
            skipped.add("cut short by the capture's snap length".into(), r.index);
        }
        return Ok(None);
    }
    match parsed {
        Ok(Some(d)) => Ok(Some(Datagram {
            index: r.index,
            time_s: r.time_s,
            src_port: d.0,
            dst_port: d.1,
            payload: d.2.to_vec(),
        })),
        Err((port, what)) => {
            if velodyne(port) {
                skipped.add(what, r.index);
            }
            Ok(None)
        }
        Ok(None) => Ok(None),
    }
}

fn packet_error(path: &Path, index: usize, what: String) -> VelodyneError {
    VelodyneError::Packet {
        file: PathBuf::from(path),
        index,
        what,
    }
}

/// A UDP datagram's ports and payload.
type Udp<'a> = (u16, u16, &'a [u8]);

/// Whether packets of link type `link` can be read.
fn supported(link: Linktype) -> bool {
    matches!(
        link,
        Linktype::ETHERNET
            | Linktype::LINUX_SLL
            | Linktype::LINUX_SLL2
            | Linktype::RAW
            | Linktype::IPV4
    )
}

/// The UDP datagram in a packet of link type `link` (one [`supported`]): `None` for what is not
/// IPv4 UDP; an error says what is wrong, with the destination port when it could be read.
pub fn udp(link: Linktype, data: &[u8]) -> Result<Option<Udp<'_>>, (Option<u16>, String)> {
    let be16 = |b: &[u8], at: usize| b.get(at..at + 2).map(|s| u16::from_be_bytes([s[0], s[1]]));
    let short = |what: &str| (None, format!("{what} cut short ({} bytes)", data.len()));
    let (ethertype, ip) = match link {
        Linktype::ETHERNET => {
            let mut at = 12;
            let mut t = be16(data, at).ok_or_else(|| short("Ethernet header"))?;
            if t == 0x8100 {
                at += 4;
                t = be16(data, at).ok_or_else(|| short("802.1Q tag"))?;
            }
            (t, &data[(at + 2).min(data.len())..])
        }
        Linktype::LINUX_SLL => (
            be16(data, 14).ok_or_else(|| short("Linux cooked header"))?,
            data.get(16..).ok_or_else(|| short("Linux cooked header"))?,
        ),
        Linktype::LINUX_SLL2 => (
            be16(data, 0).ok_or_else(|| short("Linux cooked v2 header"))?,
            data.get(20..)
                .ok_or_else(|| short("Linux cooked v2 header"))?,
        ),
        _ => (0x0800, data),
    };
    if ethertype != 0x0800 || ip.first().is_none_or(|b| b >> 4 != 4) {
        return Ok(None);
    }
    let ihl = usize::from(ip[0] & 0x0f) * 4;
    if ihl < 20 || ip.len() < ihl {
        return Err(short("IPv4 header"));
    }
    if ip[9] != 17 {
        return Ok(None);
    }
    let flags_offset = be16(ip, 6).unwrap_or(0);
    // Only a first fragment (offset 0) carries the UDP header.
    let port = (flags_offset & 0x1fff == 0)
        .then(|| be16(ip, ihl + 2))
        .flatten();
    let total = usize::from(be16(ip, 2).unwrap_or(0));
    if flags_offset & 0x2000 != 0 || flags_offset & 0x1fff != 0 {
        return Err((
            port,
            "IPv4 fragments (Velodyne packets are never fragmented)".into(),
        ));
    }
    if total < ihl + 8 || total > ip.len() {
        return Err((
            port,
            "with an IPv4 total length outside the packet".to_string(),
        ));
    }
    let u = &ip[ihl..total];
    let (src, dst, len) = (
        be16(u, 0).unwrap_or(0),
        be16(u, 2).unwrap_or(0),
        usize::from(be16(u, 4).unwrap_or(0)),
    );
    if len < 8 || len > u.len() {
        return Err((
            Some(dst),
            "with a UDP length outside the datagram".to_string(),
        ));
    }
    Ok(Some((src, dst, &u[8..len])))
}

/// A classic pcap (little-endian, microsecond stamps, Ethernet) of `datagrams`: `(time_s,
/// port, payload)`, each sent from 192.168.1.201 to the broadcast address on that UDP port, as
/// a Velodyne sensor sends them. What the tests build captures with; VeloView, Wireshark and
/// the ROS driver read it.
pub fn pcap_bytes(datagrams: &[(f64, u16, Vec<u8>)]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&0xa1b2_c3d4u32.to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&4u16.to_le_bytes());
    for w in [0u32, 0, 65535, 1] {
        out.extend_from_slice(&w.to_le_bytes());
    }
    for (time_s, port, payload) in datagrams {
        let mut f = vec![0xff; 6];
        f.extend_from_slice(&[0x60, 0x76, 0x88, 0x20, 0x12, 0x6e, 0x08, 0x00]);
        let total = (20 + 8 + payload.len()) as u16;
        f.extend_from_slice(&[0x45, 0]);
        f.extend_from_slice(&total.to_be_bytes());
        f.extend_from_slice(&[
            0, 0, 0x40, 0, 64, 17, 0, 0, 192, 168, 1, 201, 255, 255, 255, 255,
        ]);
        f.extend_from_slice(&port.to_be_bytes());
        f.extend_from_slice(&port.to_be_bytes());
        f.extend_from_slice(&((8 + payload.len()) as u16).to_be_bytes());
        f.extend_from_slice(&[0, 0]);
        f.extend_from_slice(payload);
        let (secs, micros) = (time_s.floor(), ((time_s - time_s.floor()) * 1e6).round());
        for w in [
            secs as u32,
            (micros as u32).min(999_999),
            f.len() as u32,
            f.len() as u32,
        ] {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&f);
    }
    out
}
