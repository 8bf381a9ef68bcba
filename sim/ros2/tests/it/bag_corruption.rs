//! Bags cut short or with a byte changed, as a recorder killed or a disk gone bad leaves them:
//! each refused with an error naming the file (and the last message read), never a panic,
//! never a message that was not written.

use std::ops::Range;

use ros2::BagError;

use crate::common::{Message, read_all, run_bag};

/// Clouds this large make a bag of about 2.4 MB: several MCAP chunks (1 MiB each).
const POINTS: usize = 12_000;

fn le_u64(b: &[u8]) -> usize {
    usize::try_from(u64::from_le_bytes(b[..8].try_into().unwrap())).unwrap()
}

/// Where each chunk's records lie in an MCAP file, compressed: the file's records walked from
/// its magic (opcode, u64 length, body) to the data section's end (opcode 0x0f); a chunk
/// (opcode 0x06) holds two stamps, its uncompressed size and CRC, its compression's name, then
/// its records' length and the records.
fn chunk_records(bytes: &[u8]) -> Vec<Range<usize>> {
    let mut at = 8;
    let mut out = Vec::new();
    while at + 9 <= bytes.len() && bytes[at] != 0x0f {
        let body = at + 9;
        if bytes[at] == 0x06 {
            let name = u32::from_le_bytes(bytes[body + 28..body + 32].try_into().unwrap());
            let records = body + 32 + name as usize;
            let start = records + 8;
            out.push(start..start + le_u64(&bytes[records..]));
        }
        at = body + le_u64(&bytes[at + 1..]);
    }
    out
}

/// The read's error, checked: it names `file`, and says after which message it stopped (the
/// last one read, or none).
fn checked_error(read: &[Message], result: Result<(), BagError>, file: &str, case: &str) -> String {
    let e = result.expect_err(case);
    assert!(matches!(e, BagError::Read { .. }), "{case}: {e:?}");
    let text = e.to_string();
    assert!(text.contains(file), "{case}: {text}");
    let at = match read.last() {
        Some(m) => format!("after message {} of {}: ", m.index, m.topic),
        None => "before its first message: ".to_string(),
    };
    assert!(text.contains(&at), "{case}: {text} (not {at:?})");
    text
}

/// A bag cut anywhere - inside its magic, a chunk, the index records, the summary, the closing
/// magic - is refused as truncated, naming the file and the last message read; what was read
/// before is what was written, in order.
#[test]
fn a_bag_cut_anywhere_is_refused_after_the_messages_before_the_cut() {
    let dir = tempfile::tempdir().unwrap();
    let (_, written) = run_bag(&dir.path().join("run.mcap"), POINTS);
    let bytes = std::fs::read(dir.path().join("run.mcap")).unwrap();
    let chunks = chunk_records(&bytes);
    assert!(chunks.len() >= 2, "{chunks:?}");
    let mut cuts: Vec<usize> = (0..bytes.len()).step_by(bytes.len() / 150).collect();
    cuts.extend([1, 8, 9, 17, bytes.len() - 8, bytes.len() - 1]);
    // Just after each chunk's records: the chunk is whole, its message index is not.
    cuts.extend(chunks.iter().map(|c| c.end + 1));
    let cut = dir.path().join("cut.mcap");
    let mut after_some = 0;
    for n in cuts {
        std::fs::write(&cut, &bytes[..n]).unwrap();
        let (read, result) = read_all(&cut);
        let case = format!("cut at {n} of {}", bytes.len());
        let e = checked_error(&read, result, "cut.mcap", &case);
        assert!(e.contains("truncated"), "{case}: {e}");
        assert!(
            read[..] == written[..read.len()],
            "{case}: other messages read"
        );
        after_some += usize::from(!read.is_empty());
    }
    assert!(after_some > 10, "{after_some} cuts after the first chunk");
}

/// A byte changed in a chunk's compressed records is refused (by the decompressor or the
/// chunk's CRC), naming the file and the last message of the chunks before it, all of which
/// read as written - or, where the change leaves the chunk's content whole and its CRC right
/// (the LZ4 frame's end mark), the bag reads as written.
#[test]
fn a_changed_byte_in_a_chunk_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (_, written) = run_bag(&dir.path().join("run.mcap"), POINTS);
    let bytes = std::fs::read(dir.path().join("run.mcap")).unwrap();
    let bad = dir.path().join("bad.mcap");
    let (mut tried, mut refused) = (0, 0);
    for chunk in chunk_records(&bytes) {
        for at in chunk.clone().step_by((chunk.len() / 40).max(1)) {
            let mut b = bytes.clone();
            b[at] ^= 0x55;
            std::fs::write(&bad, &b).unwrap();
            let (read, result) = read_all(&bad);
            let case = format!("byte {at} of chunk {chunk:?}");
            tried += 1;
            if result.is_ok() {
                assert!(read == written, "{case}: read otherwise");
                continue;
            }
            refused += 1;
            checked_error(&read, result, "bad.mcap", &case);
            assert!(
                read[..] == written[..read.len()],
                "{case}: other messages read"
            );
        }
    }
    assert!(refused * 10 >= tried * 9, "{refused} of {tried} refused");
}

/// A byte changed anywhere in the file - magic, headers, lengths, chunks, indices, summary -
/// never panics the reader nor makes it invent a message: it reads some of what was written,
/// in order, and either ends or is refused naming the file.
#[test]
fn a_changed_byte_anywhere_reads_only_written_messages() {
    let dir = tempfile::tempdir().unwrap();
    let (_, written) = run_bag(&dir.path().join("run.mcap"), 300);
    let bytes = std::fs::read(dir.path().join("run.mcap")).unwrap();
    let bad = dir.path().join("bad.mcap");
    let mut refused = 0;
    let positions = (0..bytes.len()).step_by(bytes.len() / 400).chain(0..64);
    for at in positions.chain(bytes.len() - 64..bytes.len()) {
        let mut b = bytes.clone();
        b[at] ^= 0xff;
        std::fs::write(&bad, &b).unwrap();
        let (read, result) = read_all(&bad);
        if let Err(e) = result {
            let text = e.to_string();
            assert!(text.contains("bad.mcap"), "byte {at}: {text}");
            refused += 1;
        }
        // What was read is written messages, in order (a skipped chunk shifts the indices).
        let key = |m: &Message| (m.topic.clone(), m.log_time_ns, m.data.clone());
        let mut rest = written.iter().map(key);
        for m in &read {
            assert!(
                rest.any(|w| w == key(m)),
                "byte {at}: {} {} invented",
                m.topic,
                m.index
            );
        }
    }
    assert!(refused > 100, "{refused} refused");
}
