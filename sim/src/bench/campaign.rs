//! `taxi-sim bench campaign`: runs per hour of a campaign on this machine, against the same
//! variants run the straightforward way - each written to a scenario file and run by its own
//! `taxi-sim run` process, `jobs` at a time, each building its own offline map (its file is new,
//! so its map is stale). Both in every round, in alternating order (this machine drifts); each
//! round in fresh directories.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

use super::timing::{Figure, median};
use crate::campaign::Campaign;
use crate::campaign::{RunOptions, run_campaign, variant};
use crate::error::{Error, Result};

/// What to measure.
pub struct CampaignBench<'a> {
    /// The campaign file.
    pub campaign: &'a Path,
    /// Variants a round (indices `round * variants ..`).
    pub variants: u64,
    /// Rounds.
    pub rounds: usize,
    /// Runs at a time, both ways.
    pub jobs: usize,
    /// The `taxi-sim` binary of the separate processes.
    pub exe: PathBuf,
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.to_path_buf();
    move |source| Error::Io { what, path, source }
}

/// Seconds to run variants `0..n` in this process, into a fresh directory (its map included).
fn in_process(campaign: &Campaign, n: u64, jobs: usize, dir: &Path) -> Result<f64> {
    let stop = AtomicBool::new(false);
    let t = Instant::now();
    run_campaign(
        campaign,
        &RunOptions {
            shard: None,
            maps_dir: None,
            out: dir.to_path_buf(),
            jobs,
            runs: Some(n),
            variants: None,
            stop: &stop,
            record_failures: false,
            progress: &|_| {},
            stack: None,
        },
    )?;
    Ok(t.elapsed().as_secs_f64())
}

/// Seconds to run the same variants as separate `taxi-sim run` processes.
fn processes(campaign: &Campaign, n: u64, jobs: usize, exe: &Path, dir: &Path) -> Result<f64> {
    std::fs::create_dir_all(dir).map_err(io("creating a bench directory", dir))?;
    let files: Vec<PathBuf> = (0..n)
        .map(|i| {
            let path = dir.join(format!("variant-{i}.toml"));
            mapper::write_atomically(&path, variant(campaign, i, &[]).text.as_bytes())?;
            Ok(path)
        })
        .collect::<Result<_>>()?;
    let next = AtomicUsize::new(0);
    let t = Instant::now();
    let failed: Vec<String> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..jobs.max(1))
            .map(|_| {
                s.spawn(|| {
                    let mut bad = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(file) = files.get(i) else { return bad };
                        let out = std::process::Command::new(exe)
                            .arg("run")
                            .arg(file)
                            .arg("--map-dir")
                            .arg(dir.join(format!("map-{i}")))
                            .output();
                        match out {
                            Ok(o) if matches!(o.status.code(), Some(0 | 1)) => {}
                            Ok(o) => bad.push(String::from_utf8_lossy(&o.stderr).into_owned()),
                            Err(e) => bad.push(e.to_string()),
                        }
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_default())
            .collect()
    });
    if let Some(e) = failed.first() {
        return Err(Error::Invalid(format!("{}: {e}", exe.display())));
    }
    Ok(t.elapsed().as_secs_f64())
}

/// Runs per hour both ways; `progress` is told each step.
pub fn campaign_figures(
    b: &CampaignBench<'_>,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<Figure>> {
    let campaign = Campaign::from_file(b.campaign)?;
    let scratch =
        tempfile::tempdir().map_err(io("creating a scratch directory", Path::new(".")))?;
    let (mut mine, mut theirs) = (Vec::new(), Vec::new());
    for round in 0..b.rounds.max(1) {
        let here = scratch.path().join(format!("round-{round}"));
        let (mut ta, mut tz) = (0.0, 0.0);
        // Alternate which goes first.
        for campaign_first in [round % 2 == 0, round % 2 == 1] {
            if campaign_first {
                progress(&format!("round {}: campaign", round + 1));
                ta = in_process(&campaign, b.variants, b.jobs, &here.join("campaign"))?;
            } else {
                progress(&format!("round {}: separate processes", round + 1));
                tz = processes(
                    &campaign,
                    b.variants,
                    b.jobs,
                    &b.exe,
                    &here.join("processes"),
                )?;
            }
        }
        mine.push(b.variants as f64 * 3600.0 / ta);
        theirs.push(b.variants as f64 * 3600.0 / tz);
        let _ = std::fs::remove_dir_all(&here);
    }
    let stem = b
        .campaign
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = |what: &str| format!("campaign/{stem}/{what}");
    let (a, z) = (median(&mut mine), median(&mut theirs));
    Ok(vec![
        Figure {
            name: name(&format!("runs_per_hour_{}_jobs", b.jobs)),
            median: a,
            unit: "/h",
            baseline: Some(name("runs_per_hour_separate_processes")),
            ratio: Some(a / z),
            target: None,
        },
        Figure {
            name: name("runs_per_hour_separate_processes"),
            median: z,
            unit: "/h",
            baseline: None,
            ratio: None,
            target: None,
        },
    ])
}
