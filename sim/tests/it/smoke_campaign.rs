//! The smoke campaign (`scenarios/campaigns/smoke.toml`) as the campaign tests use it: read, run
//! through the library, and run once in full per test binary. Shared by `sim`'s and `taxi-sim`'s
//! test binaries (the latter includes this file by its path).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

use sim::campaign::{Campaign, RunOptions, RunRecord, run_campaign};

/// `scenarios/campaigns/smoke.toml`, found from the testing package's directory upward.
pub fn smoke_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("scenarios/campaigns/smoke.toml"))
        .find(|path| path.is_file())
        .expect("scenarios/campaigns/smoke.toml above the package's directory")
}

/// The smoke campaign, read.
pub fn smoke() -> Campaign {
    Campaign::from_file(&smoke_path()).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `campaign` into `out` on `jobs` workers (the first `runs` variants, or all): its records.
#[allow(dead_code)] // the `taxi-sim` test binary, which includes this file, uses only `full`
pub fn run(campaign: &Campaign, out: &Path, jobs: usize, runs: Option<u64>) -> Vec<RunRecord> {
    run_recording(campaign, out, jobs, runs, false)
}

/// [`run`], each failure recorded again as a bag when `record_failures`.
pub fn run_recording(
    campaign: &Campaign,
    out: &Path,
    jobs: usize,
    runs: Option<u64>,
    record_failures: bool,
) -> Vec<RunRecord> {
    let stop = AtomicBool::new(false);
    run_campaign(
        campaign,
        &RunOptions {
            shard: None,
            maps_dir: None,
            out: out.to_path_buf(),
            jobs,
            runs,
            variants: None,
            stop: &stop,
            record_failures,
            progress: &|_| {},
            stack: None,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .records
}

/// The whole smoke campaign on two workers, its failures recorded as bags, once for every test
/// of the binary.
pub fn full() -> &'static (tempfile::TempDir, Vec<RunRecord>) {
    static FULL: OnceLock<(tempfile::TempDir, Vec<RunRecord>)> = OnceLock::new();
    FULL.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let records = run_recording(&smoke(), dir.path(), 2, None, true);
        (dir, records)
    })
}
