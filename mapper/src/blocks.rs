//! Map blocks on disk: the documented binary format, atomic writes, and a directory store.
//!
//! A map is tiled into square blocks (70 m, 350 x 350 cells by default). Each block file holds
//! every level's log-odds and the remission statistics of its cells, the body compressed with
//! Zstandard (most cells are unknown, saturated free or never hit). Format version 3, all
//! numbers little-endian:
//!
//! | offset | size | field |
//! | --- | --- | --- |
//! | 0 | 8 | magic `TAXIBLK\0` |
//! | 8 | 4 | format version (u32, = 3) |
//! | 12 | 4 | number of levels N (u32) |
//! | 16 | 4 | level mode (u32: 0 cumulative, 1 banded) |
//! | 20 | 4 | cells per block side S (u32) |
//! | 24 | 8 | resolution, metres (f64) |
//! | 32 | 8 | block index x (i64; the block covers x in [ix*S*res, (ix+1)*S*res)) |
//! | 40 | 8 | block index y (i64) |
//! | 48 | 8N | height of interest of each level, metres (f64) |
//! | 48+8N | 4 | length C of the compressed body, bytes (u32) |
//! | 52+8N | C | the body as one Zstandard frame (below) |
//! | end-4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! The body, `4*S*S*N + 6*S*S` bytes once decompressed, each a plane of S*S cells, row 0 =
//! lowest y:
//!
//! | size | field |
//! | --- | --- |
//! | 4*S*S*N | log-odds of every cell, level after level (f32, exact; NaN = unknown) |
//! | S*S | remission mean, in steps of 1/255 over 0..1 (u8) |
//! | S*S | remission spread (standard deviation), in steps of 1/510 over 0..0.5 (u8) |
//! | 4*S*S | remission samples (u32, exact) |
//!
//! The remission is stored quantized ([`crate::remission::QuantizedRemission`]): read back, a
//! cell's mean is within 0.002 and its spread within 0.001 of what was written, its count exact;
//! the log-odds are stored as they are. Versions 1 (uncompressed) and 2 (the remission as float
//! sums, which made a textured pavement's blocks 2.4 times larger) are refused with a message
//! saying to rebuild the map.
//!
//! A file is written to a temporary file in the same directory and renamed over the target, so
//! a reader never sees half a block. Reading checks the size, magic, version, that the header
//! matches the map being loaded into, the checksum, that the body decompresses to its exact size
//! (never more: a hostile frame cannot make it allocate beyond a block), and that every value is
//! one the map can hold (a valid checksum only says the bytes are the ones written): a log-odds
//! is NaN (unknown) or within the map's clamp `+-l_max` (so never infinite); a remission cell
//! without samples has a zero mean and spread. Any mismatch is an error naming the file and the
//! field (with the level and cell of a bad value).

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{MapError, Result};
use crate::levels::{LevelMode, Levels};
use crate::remission::{QuantizedRemission, RemissionCell};

const MAGIC: &[u8; 8] = b"TAXIBLK\0";
/// Version of the block format this crate writes and reads.
pub const FORMAT_VERSION: u32 = 3;
/// Zstandard level of the body: 1, the fastest (level 3 saves 12 % more and costs a third more
/// time to write).
const ZSTD_LEVEL: i32 = 1;

/// Bytes of a cell's remission in the body: mean (u8), spread (u8), count (u32).
const REMISSION_BYTES: usize = 6;

/// Index of a block in the world's tiling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BlockIndex {
    /// Along world x.
    pub x: i64,
    /// Along world y.
    pub y: i64,
}

/// What a block must look like to belong to a map: side, resolution and levels.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockSpec {
    /// Cells per side.
    pub side: usize,
    /// Metres per cell.
    pub resolution_m: f64,
    /// Levels of the map.
    pub levels: Levels,
    /// The map's log-odds clamp (`OccupancyParams::l_max`): every known cell is within +-this.
    pub l_max: f32,
}

impl BlockSpec {
    /// Side of a block in metres.
    pub fn side_m(&self) -> f64 {
        self.side as f64 * self.resolution_m
    }
    fn header_len(&self) -> usize {
        48 + 8 * self.levels.count()
    }
    fn body_len(&self) -> usize {
        let cells = self.side * self.side;
        4 * cells * self.levels.count() + REMISSION_BYTES * cells
    }
}

/// The content of one block.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Where it lies.
    pub index: BlockIndex,
    /// Log-odds per level, `side * side` each, row 0 = lowest y; NaN = unknown.
    pub levels: Vec<Vec<f32>>,
    /// Remission statistics, `side * side`.
    pub remission: Vec<RemissionCell>,
}

impl Block {
    /// A block where every cell is unknown.
    pub fn unknown(spec: &BlockSpec, index: BlockIndex) -> Self {
        let cells = spec.side * spec.side;
        Block {
            index,
            levels: vec![vec![f32::NAN; cells]; spec.levels.count()],
            remission: vec![RemissionCell::default(); cells],
        }
    }
    /// True when no cell holds any information.
    pub fn is_unknown(&self) -> bool {
        self.levels.iter().all(|l| l.iter().all(|v| v.is_nan()))
            && self.remission.iter().all(|r| r.count == 0)
    }
}

/// Serialises a block (format above) into bytes. Fails when a remission cell is not the
/// statistics of intensities in 0..1 (naming the cell), or if the compressor cannot allocate.
pub fn encode_block(spec: &BlockSpec, block: &Block) -> Result<Vec<u8>> {
    frame_body(spec, block.index, &encode_body(spec, block)?)
}

/// A block file (format above) around `body`, an uncompressed body of [`encode_body`]'s layout:
/// public so that tests can write bodies no map writes.
pub fn frame_body(spec: &BlockSpec, index: BlockIndex, body: &[u8]) -> Result<Vec<u8>> {
    let packed = zstd::bulk::compress(body, ZSTD_LEVEL)
        .map_err(|e| MapError::invalid("block", format!("zstd could not compress it: {e}")))?;
    let mut out = Vec::with_capacity(spec.header_len() + 8 + packed.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(spec.levels.count() as u32).to_le_bytes());
    out.extend_from_slice(&mode_code(spec.levels.mode()).to_le_bytes());
    out.extend_from_slice(&(spec.side as u32).to_le_bytes());
    out.extend_from_slice(&spec.resolution_m.to_le_bytes());
    out.extend_from_slice(&index.x.to_le_bytes());
    out.extend_from_slice(&index.y.to_le_bytes());
    for h in spec.levels.heights_m() {
        out.extend_from_slice(&h.to_le_bytes());
    }
    out.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    out.extend_from_slice(&packed);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    Ok(out)
}

/// A block's body, uncompressed (the format's table above); an error names the first remission
/// cell that is not the statistics of intensities in 0..1. Public for benchmarks against the
/// uncompressed format 1.
pub fn encode_body(spec: &BlockSpec, block: &Block) -> Result<Vec<u8>> {
    let cells = spec.side * spec.side;
    let mut body = Vec::with_capacity(spec.body_len());
    for level in &block.levels {
        for v in level {
            body.extend_from_slice(&v.to_le_bytes());
        }
    }
    let quantized = block
        .remission
        .iter()
        .enumerate()
        .map(|(i, r)| {
            r.quantized().map_err(|why| {
                MapError::invalid(
                    "remission",
                    format!(
                        "block {:?}, {}: {why}",
                        block.index,
                        cell_name(spec.side, i)
                    ),
                )
            })
        })
        .collect::<Result<Vec<_>>>()?;
    body.extend(quantized.iter().map(|q| q.mean));
    body.extend(quantized.iter().map(|q| q.spread));
    for q in &quantized {
        body.extend_from_slice(&q.count.to_le_bytes());
    }
    debug_assert_eq!(
        body.len(),
        4 * cells * block.levels.len() + REMISSION_BYTES * cells
    );
    Ok(body)
}

fn cell_name(side: usize, i: usize) -> String {
    format!("cell {i} (row {}, column {})", i / side, i % side)
}

fn mode_code(mode: LevelMode) -> u32 {
    match mode {
        LevelMode::Cumulative => 0,
        LevelMode::Banded => 1,
    }
}

/// Parses a block file's bytes, checking them against `spec`; `path` names the file in errors.
pub fn decode_block(spec: &BlockSpec, bytes: &[u8], path: &Path) -> Result<Block> {
    let bad = |why: String| MapError::bad_file(path, why);
    if bytes.len() < 48 || &bytes[..8] != MAGIC {
        return Err(bad(format!(
            "not a taxi-sim map block (bad magic or {} bytes only)",
            bytes.len()
        )));
    }
    let u32_at =
        |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let u64_at = |o: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[o..o + 8]);
        u64::from_le_bytes(b)
    };
    let version = u32_at(8);
    let older = match version {
        1 => Some("uncompressed blocks, before taxi-sim compressed them"),
        2 => Some("the remission as float sums, before taxi-sim quantized it"),
        _ => None,
    };
    if let Some(what) = older {
        return Err(bad(format!(
            "format version {version} ({what}), this build reads version {FORMAT_VERSION}: \
             rebuild the map with `taxi-sim map`"
        )));
    }
    if version != FORMAT_VERSION {
        return Err(bad(format!(
            "format version {version}, this build reads version {FORMAT_VERSION}"
        )));
    }
    let header_len = spec.header_len();
    if bytes.len() < header_len + 8 {
        return Err(bad(format!(
            "truncated or padded: {} bytes, shorter than a block's header ({} bytes)",
            bytes.len(),
            header_len + 8
        )));
    }
    let expected_len = header_len + 8 + u32_at(header_len) as usize;
    if bytes.len() != expected_len {
        return Err(bad(format!(
            "truncated or padded: {} bytes, its header says {expected_len}",
            bytes.len()
        )));
    }
    let stored_crc = u32_at(expected_len - 4);
    let crc = crc32fast::hash(&bytes[..expected_len - 4]);
    if crc != stored_crc {
        return Err(bad(format!(
            "checksum mismatch (stored {stored_crc:#010x}, computed {crc:#010x}): the file is corrupted"
        )));
    }
    let n = u32_at(12) as usize;
    if n != spec.levels.count() {
        return Err(bad(format!(
            "field `levels` = {n}, the map has {}",
            spec.levels.count()
        )));
    }
    if u32_at(16) != mode_code(spec.levels.mode()) {
        return Err(bad(format!(
            "field `mode` = {}, the map is {:?}",
            u32_at(16),
            spec.levels.mode()
        )));
    }
    if u32_at(20) as usize != spec.side {
        return Err(bad(format!(
            "field `side` = {}, the map's blocks have {} cells a side",
            u32_at(20),
            spec.side
        )));
    }
    let res = f64::from_bits(u64_at(24));
    if res != spec.resolution_m {
        return Err(bad(format!(
            "field `resolution` = {res} m, the map has {} m",
            spec.resolution_m
        )));
    }
    let index = BlockIndex {
        x: u64_at(32) as i64,
        y: u64_at(40) as i64,
    };
    for (k, h) in spec.levels.heights_m().iter().enumerate() {
        let stored = f64::from_bits(u64_at(48 + 8 * k));
        if stored != *h {
            return Err(bad(format!(
                "field `heights[{k}]` = {stored} m, the map's level {k} is at {h} m"
            )));
        }
    }
    let block = decompress_body(spec, &bytes[header_len + 4..expected_len - 4], index)
        .map_err(|e| bad(format!("the compressed body {e}")))?;
    match bad_value(spec, &block) {
        Some(why) => Err(bad(why)),
        None => Ok(block),
    }
}

/// Decompresses a body straight into the log-odds arrays of block `index` (no intermediate
/// copy) and its remission planes into one buffer: exactly the body's size, never more (a
/// hostile frame cannot make it allocate beyond a block).
fn decompress_body(
    spec: &BlockSpec,
    packed: &[u8],
    index: BlockIndex,
) -> std::result::Result<Block, String> {
    use std::io::Read as _;
    let cells = spec.side * spec.side;
    // Zeroed (calloc'd) arrays: every byte is overwritten below.
    let mut levels: Vec<Vec<f32>> = (0..spec.levels.count())
        .map(|_| bytemuck::zeroed_vec(cells))
        .collect();
    let mut remission = vec![0u8; REMISSION_BYTES * cells];
    let mut decoder = zstd::stream::read::Decoder::with_buffer(packed)
        .map_err(|e| format!("cannot be read: {e}"))?;
    let short = |e: std::io::Error| format!("does not decompress to a block: {e}");
    for level in &mut levels {
        decoder
            .read_exact(bytemuck::cast_slice_mut(&mut level[..]))
            .map_err(short)?;
    }
    decoder.read_exact(&mut remission).map_err(short)?;
    let mut more = [0u8; 1];
    if decoder.read(&mut more).map_err(short)? != 0 {
        return Err(format!(
            "decompresses to more than a block's {} bytes",
            spec.body_len()
        ));
    }
    // The file is little-endian; the arrays were filled with its bytes as they are.
    if cfg!(target_endian = "big") {
        for v in levels.iter_mut().flatten() {
            *v = f32::from_bits(u32::from_le(v.to_bits()));
        }
    }
    let remission = remission_cells(spec.side, &remission)?;
    Ok(Block {
        index,
        levels,
        remission,
    })
}

/// The remission cells of a body's three remission planes (`REMISSION_BYTES * side^2` bytes);
/// an error names the first cell without samples whose mean or spread is not zero.
fn remission_cells(side: usize, planes: &[u8]) -> std::result::Result<Vec<RemissionCell>, String> {
    let cells = side * side;
    let (means, rest) = planes.split_at(cells);
    let (spreads, counts) = rest.split_at(cells);
    means
        .iter()
        .zip(spreads)
        .zip(counts.chunks_exact(4))
        .enumerate()
        .map(|(i, ((&mean, &spread), count))| {
            let count = u32::from_le_bytes([count[0], count[1], count[2], count[3]]);
            if count == 0 && (mean != 0 || spread != 0) {
                return Err(format!(
                    "field `remission.count`, {}: 0 samples but mean {mean} and spread {spread} \
                     (steps; a cell without samples stores zeros)",
                    cell_name(side, i)
                ));
            }
            Ok(QuantizedRemission {
                mean,
                spread,
                count,
            }
            .cell())
        })
        .collect()
}

/// Block `index` from its uncompressed body, checked value by value (the error says which);
/// `body` has [`encode_body`]'s length.
pub fn decode_body(
    spec: &BlockSpec,
    body: &[u8],
    index: BlockIndex,
) -> std::result::Result<Block, String> {
    if body.len() != spec.body_len() {
        return Err(format!(
            "the body holds {} bytes, a block of this map has {}",
            body.len(),
            spec.body_len()
        ));
    }
    let cells = spec.side * spec.side;
    let (level_bytes, remission) = body.split_at(4 * cells * spec.levels.count());
    let levels = level_bytes
        .chunks_exact(4 * cells)
        .map(|level| {
            level
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect()
        })
        .collect();
    let block = Block {
        index,
        levels,
        remission: remission_cells(spec.side, remission)?,
    };
    match bad_value(spec, &block) {
        Some(why) => Err(why),
        None => Ok(block),
    }
}

/// The first log-odds of a block no map of `spec` can hold, described with its field, level and
/// cell; `None` when every value is possible.
///
/// A log-odds is NaN (unknown, by design) or within `+-spec.l_max`: insertion clamps every update
/// to it, free-space walks stop at `-l_max`, forgetting moves a cell toward its prior, and only
/// live cells are saved, so an infinite or larger value was never written by a map. (Remission
/// cells are checked as they are read: every quantized value is possible but a mean or spread
/// without samples.)
fn bad_value(spec: &BlockSpec, block: &Block) -> Option<String> {
    for (k, level) in block.levels.iter().enumerate() {
        // NaN fails the comparison but is legitimate; test the fast common case first.
        let bad = level
            .iter()
            .position(|v| !(v.abs() <= spec.l_max || v.is_nan()));
        if let Some(i) = bad {
            let v = level[i];
            let what = if v.is_infinite() {
                "infinite"
            } else {
                "beyond the map's log-odds clamp"
            };
            return Some(format!(
                "field `log_odds` of level {k}, {}: {v} is {what} (a cell is NaN = unknown or \
                 within +-{} = occupancy.l_max): no map with this clamp writes it",
                cell_name(spec.side, i),
                spec.l_max
            ));
        }
    }
    None
}

/// Writes `bytes` to `path` atomically: a temporary file in the same directory, synced, then renamed.
/// The directory is created if it does not exist.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = temp_beside(path)?;
    tmp.write_all(bytes)
        .map_err(|e| MapError::io(tmp.path(), e))?;
    persist_synced(tmp, path)
}

/// A temporary file in `path`'s directory (created if missing), readable by others (0644), for
/// [`persist_synced`] to rename over `path`.
pub(crate) fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // Every command writes through here: a missing folder is created, the same for all.
    std::fs::create_dir_all(dir).map_err(|e| MapError::io(dir, e))?;
    // tempfile creates 0600 files; a map or a picture is for others to read too.
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    builder.tempfile_in(dir).map_err(|e| MapError::io(dir, e))
}

/// Syncs a finished temporary file and renames it over `path`.
pub(crate) fn persist_synced(tmp: tempfile::NamedTempFile, path: &Path) -> Result<()> {
    tmp.as_file()
        .sync_all()
        .map_err(|e| MapError::io(tmp.path(), e))?;
    tmp.persist(path).map_err(|e| MapError::io(path, e.error))?;
    Ok(())
}

/// A directory of block files, `block_<x>_<y>.tsmb`.
#[derive(Clone, Debug)]
pub struct BlockStore {
    dir: PathBuf,
    spec: BlockSpec,
}

impl BlockStore {
    /// A store in `dir` (created if missing) for blocks of `spec`.
    pub fn open(dir: impl Into<PathBuf>, spec: BlockSpec) -> Result<Self> {
        let dir = dir.into();
        std::fs::create_dir_all(&dir).map_err(|e| MapError::io(&dir, e))?;
        Ok(BlockStore { dir, spec })
    }
    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
    /// What the store's blocks look like.
    pub fn spec(&self) -> &BlockSpec {
        &self.spec
    }
    /// The file of a block.
    pub fn path(&self, index: BlockIndex) -> PathBuf {
        self.dir.join(format!("block_{}_{}.tsmb", index.x, index.y))
    }
    /// Loads a block; `Ok(None)` when it was never saved (no file), an error when the file is bad.
    pub fn load(&self, index: BlockIndex) -> Result<Option<Block>> {
        let path = self.path(index);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(MapError::io(path, e)),
        };
        let block = decode_block(&self.spec, &bytes, &path)?;
        if block.index != index {
            return Err(MapError::bad_file(
                &path,
                format!("holds block {:?}, expected {index:?}", block.index),
            ));
        }
        Ok(Some(block))
    }
    /// Saves a block atomically.
    pub fn save(&self, block: &Block) -> Result<()> {
        write_atomically(&self.path(block.index), &encode_block(&self.spec, block)?)
    }
    /// Indices of every block file in the store, sorted.
    pub fn list(&self) -> Result<Vec<BlockIndex>> {
        let mut out = Vec::new();
        let entries = std::fs::read_dir(&self.dir).map_err(|e| MapError::io(&self.dir, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| MapError::io(&self.dir, e))?;
            let name = entry.file_name();
            let Some(rest) = name
                .to_str()
                .and_then(|n| n.strip_prefix("block_"))
                .and_then(|n| n.strip_suffix(".tsmb"))
            else {
                continue;
            };
            let mut parts = rest.split('_');
            if let (Some(Ok(x)), Some(Ok(y)), None) = (
                parts.next().map(str::parse),
                parts.next().map(str::parse),
                parts.next(),
            ) {
                out.push(BlockIndex { x, y });
            }
        }
        out.sort();
        Ok(out)
    }
}
