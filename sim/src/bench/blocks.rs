//! `taxi-sim bench blocks`: writing and reading the offline map's blocks, the compressed format
//! (3) against the same body uncompressed, as format 1 stored it, on the blocks of a real map.
//!
//! Both ways do the same work but the compression: the body encoded and written atomically
//! (temporary file, fsync, rename), then read, checksummed and decoded with every value checked:
//! once from the page cache (just written) and once from the disk (the file dropped from the
//! cache first, as a map is read when a run starts).
//! Each block is written and read both ways in alternation, so the machine's drift falls on both.

use std::time::Instant;

use mapper::blocks::{decode_body, encode_body};
use mapper::{Block, BlockStore, write_atomically};

use super::timing::{Figure, median};
use crate::error::{Error, Result};

/// Drops `path` from the page cache (its pages are clean: written with fsync), so the next read
/// comes from the disk. Best effort: an error leaves it cached, and the figure says "cached".
fn evict(path: &std::path::Path) -> bool {
    std::fs::File::open(path)
        .is_ok_and(|f| rustix::fs::fadvise(&f, 0, None, rustix::fs::Advice::DontNeed).is_ok())
}

/// Format 1: the header's 8-byte magic and version, the uncompressed body, its CRC-32 (the rest
/// of format 1's header is the same as the current format's and left out of both timings'
/// difference); the body is the current format's.
fn write_v1(
    store_spec: &mapper::BlockSpec,
    block: &Block,
    path: &std::path::Path,
) -> Result<usize> {
    let mut bytes = b"TAXIBLK\0".to_vec();
    bytes.extend_from_slice(&1u32.to_le_bytes());
    bytes.extend_from_slice(&encode_body(store_spec, block)?);
    let crc = crc32fast::hash(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    write_atomically(path, &bytes)?;
    Ok(bytes.len())
}

fn read_v1(spec: &mapper::BlockSpec, block: &Block, path: &std::path::Path) -> Result<Block> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        what: "reading a block",
        path: path.to_path_buf(),
        source,
    })?;
    let n = bytes.len();
    let stored = u32::from_le_bytes([bytes[n - 4], bytes[n - 3], bytes[n - 2], bytes[n - 1]]);
    if crc32fast::hash(&bytes[..n - 4]) != stored {
        return Err(Error::Invalid(format!("{}: checksum", path.display())));
    }
    decode_body(spec, &bytes[12..n - 4], block.index).map_err(Error::Invalid)
}

/// The figures over the blocks in `blocks_dir` (a map's `blocks/`), up to `max_blocks` of them.
pub fn block_figures(
    blocks_dir: &std::path::Path,
    spec: mapper::BlockSpec,
    max_blocks: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let source = BlockStore::open(blocks_dir, spec.clone())?;
    let indices = source.list()?;
    let step = (indices.len() / max_blocks.max(1)).max(1);
    let blocks: Vec<Block> = indices
        .iter()
        .step_by(step)
        .filter_map(|i| source.load(*i).transpose())
        .collect::<std::result::Result<_, _>>()?;
    if blocks.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no blocks",
            blocks_dir.display()
        )));
    }
    let scratch = tempfile::tempdir().map_err(|source| Error::Io {
        what: "creating a scratch directory",
        path: std::env::temp_dir(),
        source,
    })?;
    let store = BlockStore::open(scratch.path().join("v2"), spec.clone())?;
    let v1_dir = scratch.path().join("v1");
    let (mut w1, mut w2, mut r1, mut r2) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut c1, mut c2, mut evicted) = (Vec::new(), Vec::new(), true);
    let (mut bytes1, mut bytes2) = (0usize, 0usize);
    for (k, block) in blocks.iter().enumerate() {
        progress(&format!("block {} of {}", k + 1, blocks.len()));
        let p1 = v1_dir.join(format!("{k}.tsmb"));
        let t = Instant::now();
        bytes1 += write_v1(&spec, block, &p1)?;
        w1.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        store.save(block)?;
        w2.push(t.elapsed().as_secs_f64());
        bytes2 += std::fs::metadata(store.path(block.index))
            .map(|m| m.len() as usize)
            .unwrap_or(0);
        let t = Instant::now();
        let a = read_v1(&spec, block, &p1)?;
        r1.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let b = store.load(block.index)?;
        r2.push(t.elapsed().as_secs_f64());
        if b.as_ref() != Some(&a) && !same_bits(&a, b.as_ref()) {
            return Err(Error::Invalid(format!(
                "block {:?} did not read back",
                block.index
            )));
        }
        // From the disk: each file dropped from the page cache first.
        evicted &= evict(&p1);
        let t = Instant::now();
        read_v1(&spec, block, &p1)?;
        c1.push(t.elapsed().as_secs_f64());
        evicted &= evict(&store.path(block.index));
        let t = Instant::now();
        store.load(block.index)?;
        c2.push(t.elapsed().as_secs_f64());
    }
    let n = blocks.len();
    let fig = |name: &str, mut v: Vec<f64>| Figure {
        name: format!("blocks/{name}"),
        median: median(&mut v) * 1e3,
        unit: "ms",
        baseline: None,
        ratio: None,
        target: None,
    };
    let (w1, w2, r1, r2) = (
        fig("write/format_1_raw", w1),
        fig("write", w2),
        fig("read/format_1_raw", r1),
        fig("read", r2),
    );
    let disk = if evicted {
        "from_disk"
    } else {
        "cached_could_not_evict"
    };
    let (c1, c2) = (
        fig(&format!("read/{disk}/format_1_raw"), c1),
        fig(&format!("read/{disk}"), c2),
    );
    let with = |mut f: Figure, base: &Figure, target: &'static str| {
        f.baseline = Some(base.name.clone());
        f.ratio = Some(base.median / f.median);
        f.target = Some(target);
        f
    };
    let size = |name: &str, bytes: usize| Figure {
        name: format!("blocks/{name}_per_block"),
        median: bytes as f64 / n as f64 / 1e6,
        unit: "MB",
        baseline: None,
        ratio: None,
        target: None,
    };
    let (s1, s2) = (size("bytes/format_1_raw", bytes1), size("bytes", bytes2));
    Ok(vec![
        with(w2, &w1, ">= 1x format 1"),
        w1,
        with(r2, &r1, ">= 1x format 1"),
        r1,
        with(c2, &c1, ">= 1x format 1"),
        c1,
        with(s2, &s1, "map <= 60 MB"),
        s1,
    ])
}

/// Whether two blocks hold the same bits (NaN payloads compared as bits).
fn same_bits(a: &Block, b: Option<&Block>) -> bool {
    let Some(b) = b else { return false };
    let bits = |x: &Block| -> Vec<u32> { x.levels.iter().flatten().map(|v| v.to_bits()).collect() };
    a.index == b.index && bits(a) == bits(b) && a.remission == b.remission
}

/// The figures over the offline map of `scenario` under the default configuration (the mapping
/// drive first if the map is missing or stale), up to 100 of its blocks.
pub fn figures_for(
    scenario: &std::path::Path,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let scenario = crate::scenario::Scenario::from_file(scenario)?;
    let config = crate::scenario::RunConfig::default();
    let dir = crate::offline_map::default_map_dir(&scenario, &config);
    crate::offline_map::ensure(
        &scenario,
        &config,
        &dir,
        &mut || progress("mapping drive"),
        &mut |_, _| {},
    )?;
    let map = config.mapping.map;
    let spec = mapper::BlockSpec {
        side: map.block_cells,
        resolution_m: map.resolution_m,
        levels: crate::offline_map::levels_of(&scenario, &config)?,
        l_max: map.occupancy.l_max,
    };
    block_figures(&dir.join("blocks"), spec, 100, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The benchmark reads back what it wrote both ways (it fails otherwise) and reports the
    /// compressed blocks smaller than the raw ones.
    #[test]
    fn blocks_written_both_ways_read_back_and_compressed_are_smaller() {
        let mut map = mapper::workloads::two_level_map();
        let car = mapper::workloads::fake_wing_car();
        map.insert_scan(&mapper::workloads::parking_lot_scan(), Some(&car))
            .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let spec = map.block_spec().clone();
        let store = BlockStore::open(dir.path(), spec.clone()).unwrap();
        map.save_live(&store).unwrap();
        let figures = block_figures(dir.path(), spec, 100, &mut |_| {}).unwrap();
        let get = |name: &str| {
            figures
                .iter()
                .find(|f| f.name == name)
                .unwrap_or_else(|| panic!("{name} in {figures:?}"))
        };
        let (raw, packed) = (
            get("blocks/bytes/format_1_raw_per_block"),
            get("blocks/bytes_per_block"),
        );
        // The raw body: 2 levels of f32 log-odds and 6 bytes of remission per cell.
        let side = map.block_spec().side;
        let body_mb = ((4 * 2 + 6) * side * side + 16) as f64 / 1e6;
        assert!(
            (raw.median - body_mb).abs() < 1e-6 && packed.median * 4.0 < raw.median,
            "{body_mb} MB raw: {figures:?}"
        );
        assert!(get("blocks/read").median > 0.0 && get("blocks/write").median > 0.0);
    }
}
