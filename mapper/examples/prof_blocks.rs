//! Temporary: where a block read's time goes.
use std::time::Instant;
fn main() {
    let dir = std::env::args().nth(1).unwrap();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let (mut t_read, mut t_z, mut n, mut raw, mut t_p) = (0.0, 0.0, 0, 0usize, 0.0);
    for _ in 0..3 {
        for f in &files {
            let t = Instant::now();
            let b = std::fs::read(f).unwrap();
            t_read += t.elapsed().as_secs_f64();
            let hl = 48 + 16;
            let len = u32::from_le_bytes(b[hl..hl + 4].try_into().unwrap()) as usize;
            let t = Instant::now();
            let out = zstd::bulk::decompress(&b[hl + 4..hl + 4 + len], 4_000_000).unwrap();
            t_z += t.elapsed().as_secs_f64();
            raw += out.len();
            let spec = mapper::BlockSpec {
                side: 350,
                resolution_m: 0.2,
                levels: mapper::Levels::cumulative(vec![0.0, 0.7]).unwrap(),
                l_max: 37.0,
            };
            let t = Instant::now();
            let blk = mapper::blocks::decode_body(&spec, &out, mapper::BlockIndex { x: 0, y: 0 });
            t_p += t.elapsed().as_secs_f64();
            std::hint::black_box(blk.is_ok());
            n += 1;
        }
    }
    println!(
        "{n} blocks: read {:.3} ms, zstd {:.3} ms, parse+check {:.3} ms per block, {} bytes per block",
        t_read * 1e3 / n as f64,
        t_z * 1e3 / n as f64,
        t_p * 1e3 / n as f64,
        raw / n
    );
}
