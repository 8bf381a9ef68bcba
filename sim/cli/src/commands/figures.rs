//! `taxi-sim bench figures`: the README's deterministic figures of a first and a later run,
//! measured by running this binary's `run` as child processes (`.ci/check_figures` compares
//! them with the README's table).
//!
//! Three runs, one after the other, in a working directory: the aerodrome with an empty map
//! directory (the mapping drive, then one lap), the aerodrome again on the map it built (reused),
//! and the parking lot with an empty map directory. Per run: the child's peak resident memory
//! (`ru_maxrss` from `wait4`, Linux only) and its wall time (informational); per map built: its
//! size on disk (every regular file under the directory, recursively), its block files and the
//! manifest's occupied cells per level. MB is 10^6 bytes throughout.
//!
//! `--time-limit-s S` ends each child's lap at S seconds of simulated time (CI's measurement):
//! the maps are the mapping drive's, which the limit never cuts, so their figures are the same,
//! and peak memory is flat in the route's length (docs/performance.md), so it moves by a few
//! percent at most - both shown side by side in that document.

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context as _;
use indicatif::ProgressBar;
use serde_json::{Value, json};
use sim::offline_map::MapManifest;

use crate::emit;

/// The scenarios measured, from the current directory (the repository's root).
const AERODROME: &str = "scenarios/aerodrome.toml";
const PARKING_LOT: &str = "scenarios/parking_lot.toml";

/// `run`'s exit code when the run completed but an expectation did not hold (see `main.rs`):
/// the figures are measured all the same.
const EXPECTATION_FAILED: i32 = 1;

/// What `taxi-sim bench figures` was asked.
#[derive(Debug, Clone, Copy)]
pub struct FiguresOptions<'a> {
    /// The JSON object on stdout instead of the table.
    pub json: bool,
    /// The working directory (default: a new one under the system's temporary directory).
    pub out: Option<&'a Path>,
    /// Keep the offline maps built (default: deleted once measured).
    pub keep: bool,
    /// Also write the JSON object to this file, atomically.
    pub json_out: Option<&'a Path>,
    /// Each child run's `--time-limit-s` (default: none, the whole lap).
    pub time_limit_s: Option<f64>,
}

/// One child `taxi-sim run`, measured.
#[derive(Debug, Clone)]
struct RunFigures {
    /// The command line, for the record.
    command: String,
    /// Peak resident memory, MB.
    peak_memory_mb: f64,
    /// Wall time, seconds (informational: not checked).
    wall_s: f64,
    /// Whether `run` said every expectation held (exit code 0).
    expectations_met: bool,
}

/// An offline map directory, measured after its mapping drive.
#[derive(Debug, Clone)]
struct MapFigures {
    /// Sum of the sizes of every regular file under the directory, recursively.
    bytes: u64,
    /// Files under `blocks/`.
    blocks: usize,
    /// Occupied cells per level (the manifest's).
    occupied_cells: Vec<usize>,
    /// Heights of interest of the levels, metres (the manifest's).
    level_heights_m: Vec<f64>,
}

/// Runs `taxi-sim bench figures`.
pub fn run(options: &FiguresOptions<'_>) -> anyhow::Result<()> {
    anyhow::ensure!(
        cfg!(target_os = "linux"),
        "`bench figures` needs Linux: the peak memory of a child process comes from wait4's \
         ru_maxrss"
    );
    if let Some(t) = options.time_limit_s {
        anyhow::ensure!(
            t.is_finite() && t > 0.0,
            "--time-limit-s {t}: a positive number of seconds"
        );
    }
    for scenario in [AERODROME, PARKING_LOT] {
        anyhow::ensure!(
            Path::new(scenario).is_file(),
            "{scenario} not found: run `taxi-sim bench figures` from the repository's root"
        );
    }
    let (work, owned) = match options.out {
        Some(dir) => {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            (dir.to_path_buf(), false)
        }
        None => {
            let dir = std::env::temp_dir().join(format!("taxi-sim-figures-{}", std::process::id()));
            std::fs::create_dir(&dir).with_context(|| format!("creating {}", dir.display()))?;
            (dir, true)
        }
    };
    let aerodrome_map = work.join("aerodrome-map");
    let parking_lot_map = work.join("parking_lot-map");
    for dir in [&aerodrome_map, &parking_lot_map] {
        ensure_absent_or_empty(dir)?;
    }
    let exe = std::env::current_exe().context("finding this binary")?;
    let children = Children {
        exe: &exe,
        work: &work,
        time_limit_s: options.time_limit_s,
    };
    let figures = measure(&children, &aerodrome_map, &parking_lot_map).with_context(|| {
        format!(
            "measuring the figures (the working directory {} is kept)",
            work.display()
        )
    })?;
    let text = serde_json::to_string_pretty(&figures)?;
    if let Some(path) = options.json_out {
        mapper::write_atomically(path, format!("{text}\n").as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if !options.keep {
        let doomed = if owned {
            vec![work.clone()]
        } else {
            vec![aerodrome_map, parking_lot_map]
        };
        for dir in doomed {
            std::fs::remove_dir_all(&dir).with_context(|| format!("deleting {}", dir.display()))?;
        }
    }
    if options.json {
        emit(&format!("{text}\n"))
    } else {
        emit(&table(&figures)?)
    }
}

/// Refuses a map directory that holds anything: the first run must build its map from nothing.
fn ensure_absent_or_empty(dir: &Path) -> anyhow::Result<()> {
    match std::fs::read_dir(dir) {
        Ok(mut entries) => anyhow::ensure!(
            entries.next().is_none(),
            "{} is not empty: a first run needs an empty map directory; delete it or pick \
             another --out",
            dir.display()
        ),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e).with_context(|| format!("reading {}", dir.display())),
    }
    Ok(())
}

/// The three runs, with a spinner; the JSON object of their figures.
fn measure(
    children: &Children<'_>,
    aerodrome_map: &Path,
    parking_lot_map: &Path,
) -> anyhow::Result<Value> {
    let progress = ProgressBar::new_spinner();
    progress.enable_steady_tick(Duration::from_millis(200));
    let child = |what: &str, label: &str, scenario: &str, map: &Path| {
        let message = format!("{what}...");
        progress.set_message(message.clone());
        progress.suspend(|| eprintln!("{message}"));
        let figures = children.run(label, scenario, map)?;
        progress.suspend(|| {
            eprintln!(
                "  {:.1} s wall, peak memory {:.0} MB{}",
                figures.wall_s,
                figures.peak_memory_mb,
                if figures.expectations_met {
                    ""
                } else {
                    " (an expectation did not hold; measured all the same)"
                }
            );
        });
        anyhow::Ok(figures)
    };
    let aerodrome_first = child(
        "aerodrome first run (mapping drive + 1 lap)",
        "aerodrome-first-run",
        AERODROME,
        aerodrome_map,
    )?;
    let aerodrome = map_figures(aerodrome_map)?;
    let stamp = manifest_stamp(aerodrome_map)?;
    let aerodrome_later = child(
        "aerodrome later run (map reused, 1 lap)",
        "aerodrome-later-run",
        AERODROME,
        aerodrome_map,
    )?;
    anyhow::ensure!(
        manifest_stamp(aerodrome_map)? == stamp
            && map_figures(aerodrome_map)?.bytes == aerodrome.bytes,
        "the aerodrome's later run rebuilt its map in {} instead of reusing it",
        aerodrome_map.display()
    );
    let parking_lot_first = child(
        "parking lot first run (mapping drive + 1 lap)",
        "parking_lot-first-run",
        PARKING_LOT,
        parking_lot_map,
    )?;
    let parking_lot = map_figures(parking_lot_map)?;
    progress.finish_and_clear();
    Ok(json!({
        "time_limit_s": children.time_limit_s,
        "aerodrome_first_run": first_run_json(&aerodrome_first, &aerodrome),
        "aerodrome_later_run": run_json(&aerodrome_later),
        "parking_lot_first_run": first_run_json(&parking_lot_first, &parking_lot),
    }))
}

/// Rounds to `decimals` decimal places (for the JSON's readability; the bytes stay exact).
fn round(x: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (x * scale).round() / scale
}

fn run_json(run: &RunFigures) -> Value {
    json!({
        "command": run.command,
        "peak_memory_mb": round(run.peak_memory_mb, 1),
        "wall_s": round(run.wall_s, 1),
        "expectations_met": run.expectations_met,
    })
}

fn first_run_json(run: &RunFigures, map: &MapFigures) -> Value {
    let mut value = run_json(run);
    value["map_bytes"] = json!(map.bytes);
    value["map_mb"] = json!(round(map.bytes as f64 / 1e6, 3));
    value["blocks"] = json!(map.blocks);
    value["occupied_cells"] = json!(map.occupied_cells);
    value["level_heights_m"] = json!(map.level_heights_m);
    value
}

/// How the child runs are started: this binary, in the working directory, with the time limit.
struct Children<'a> {
    exe: &'a Path,
    work: &'a Path,
    time_limit_s: Option<f64>,
}

impl Children<'_> {
    /// Runs `taxi-sim run SCENARIO --laps 1 --map-dir MAP --report WORK/LABEL.json` (and
    /// `--time-limit-s S` when given), its output to `WORK/LABEL.stdout.txt` and `.stderr.txt`;
    /// its peak memory and wall time.
    fn run(&self, label: &str, scenario: &str, map: &Path) -> anyhow::Result<RunFigures> {
        let (exe, work) = (self.exe, self.work);
        let report = work.join(format!("{label}.json"));
        let stdout_path = work.join(format!("{label}.stdout.txt"));
        let stderr_path = work.join(format!("{label}.stderr.txt"));
        let mut args: Vec<std::ffi::OsString> = vec![
            "run".into(),
            scenario.into(),
            "--laps".into(),
            "1".into(),
            "--map-dir".into(),
            map.into(),
            "--report".into(),
            report.into(),
        ];
        if let Some(t) = self.time_limit_s {
            args.extend(["--time-limit-s".into(), t.to_string().into()]);
        }
        run_measured(exe, &args, &stdout_path, &stderr_path)
    }
}

/// Runs `exe ARGS`, its output to the two files; its peak memory and wall time.
fn run_measured(
    exe: &Path,
    args: &[std::ffi::OsString],
    stdout_path: &Path,
    stderr_path: &Path,
) -> anyhow::Result<RunFigures> {
    let command = std::iter::once(exe.as_os_str())
        .chain(args.iter().map(|a| a.as_os_str()))
        .map(|a| a.to_string_lossy())
        .collect::<Vec<_>>()
        .join(" ");
    let create = |path: &Path| {
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))
    };
    let start = Instant::now();
    let child = Command::new(exe)
        .args(args)
        .stdin(Stdio::null())
        .stdout(create(stdout_path)?)
        .stderr(create(stderr_path)?)
        .spawn()
        .with_context(|| format!("starting `{command}`"))?;
    let (status, peak_kib) =
        wait_with_peak_memory(child).with_context(|| format!("waiting for `{command}`"))?;
    let wall_s = start.elapsed().as_secs_f64();
    let expectations_met = match status.code() {
        Some(0) => true,
        Some(EXPECTATION_FAILED) => false,
        _ => anyhow::bail!(
            "`{command}` failed ({status}); the end of its error output ({}):\n{}",
            stderr_path.display(),
            tail(stderr_path, 10)
        ),
    };
    Ok(RunFigures {
        command,
        peak_memory_mb: peak_kib as f64 * 1024.0 / 1e6,
        wall_s,
        expectations_met,
    })
}

/// The last `lines` lines of a text file (empty when unreadable).
fn tail(path: &Path, lines: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

/// Waits for `child` with `wait4`: its exit status and peak resident memory, KiB (`ru_maxrss`
/// of the child alone; Linux counts it in KiB). std's `Child::wait` does not give the usage.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)] // the workspace's second unsafe code: one libc call, no alternative in std
fn wait_with_peak_memory(child: std::process::Child) -> io::Result<(ExitStatus, u64)> {
    use std::os::unix::process::ExitStatusExt as _;
    let pid = libc::pid_t::try_from(child.id()).map_err(io::Error::other)?;
    let mut status: libc::c_int = 0;
    // SAFETY: `rusage` is plain old data (integers and `timeval`s): all-zero bytes are a value.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: `status` and `usage` are live, writable locals of the types wait4 writes;
        // `pid` is our own child, which nothing else waits for (`child` is owned here and std
        // never reaps it on its own), so the id cannot have been reused.
        let reaped = unsafe { libc::wait4(pid, &raw mut status, 0, &raw mut usage) };
        if reaped == pid {
            break;
        }
        let error = io::Error::last_os_error();
        if error.kind() != io::ErrorKind::Interrupted {
            return Err(error);
        }
    }
    // Reaped: dropping the handle only closes its pipes (none here), it does not wait.
    drop(child);
    let peak_kib = u64::try_from(usage.ru_maxrss).unwrap_or(0);
    Ok((ExitStatus::from_raw(status), peak_kib))
}

/// Elsewhere: the figure needs Linux's `ru_maxrss` (the child is stopped).
#[cfg(not(target_os = "linux"))]
fn wait_with_peak_memory(mut child: std::process::Child) -> io::Result<(ExitStatus, u64)> {
    let _ = child.kill();
    let _ = child.wait();
    Err(io::Error::other(
        "the peak memory of a child process needs Linux (wait4's ru_maxrss)",
    ))
}

/// The manifest's modification time and length: changed if a run rebuilt the map.
fn manifest_stamp(map: &Path) -> anyhow::Result<(std::time::SystemTime, u64)> {
    let path = map.join("manifest.json");
    let meta = std::fs::metadata(&path).with_context(|| format!("reading {}", path.display()))?;
    Ok((meta.modified()?, meta.len()))
}

/// Measures the offline map in `map`: bytes on disk, block files, the manifest's cells.
fn map_figures(map: &Path) -> anyhow::Result<MapFigures> {
    let path = map.join("manifest.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let manifest: MapManifest =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    let blocks_dir = map.join("blocks");
    let mut blocks = 0;
    for entry in std::fs::read_dir(&blocks_dir)
        .with_context(|| format!("reading {}", blocks_dir.display()))?
    {
        if entry?.file_type()?.is_file() {
            blocks += 1;
        }
    }
    if blocks != manifest.blocks {
        eprintln!(
            "warning: {} holds {blocks} files, its manifest says {} blocks",
            blocks_dir.display(),
            manifest.blocks
        );
    }
    Ok(MapFigures {
        bytes: bytes_under(map)?,
        blocks,
        occupied_cells: manifest.occupied_cells,
        level_heights_m: manifest.level_heights_m,
    })
}

/// Sum of the sizes of every regular file under `dir`, recursively (symbolic links not
/// followed).
fn bytes_under(dir: &Path) -> anyhow::Result<u64> {
    let mut total = 0;
    let mut pending: Vec<PathBuf> = vec![dir.to_path_buf()];
    while let Some(dir) = pending.pop() {
        for entry in
            std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?
        {
            let entry = entry?;
            let kind = entry.file_type()?;
            if kind.is_dir() {
                pending.push(entry.path());
            } else if kind.is_file() {
                total += entry.metadata()?.len();
            }
        }
    }
    Ok(total)
}

/// The human table: one row per figure, named as in the README's table.
fn table(figures: &Value) -> anyhow::Result<String> {
    let mut t = String::new();
    writeln!(t, "{:<42} value", "figure")?;
    for (key, name) in [
        ("aerodrome_first_run", "aerodrome"),
        ("parking_lot_first_run", "parking lot"),
    ] {
        let f = &figures[key];
        let cells: Vec<String> = f["occupied_cells"]
            .as_array()
            .map(|a| a.iter().map(Value::to_string).collect())
            .unwrap_or_default();
        let rows = [
            (
                format!("{name} offline map on disk"),
                format!(
                    "{:.1} MB ({} bytes)",
                    f["map_mb"].as_f64().unwrap_or(f64::NAN),
                    f["map_bytes"]
                ),
            ),
            (format!("{name} map blocks"), f["blocks"].to_string()),
            (
                format!("{name} occupied cells per level"),
                cells.join(" / "),
            ),
        ];
        for (figure, value) in rows {
            writeln!(t, "{figure:<42} {value}")?;
        }
    }
    for (key, name) in [
        ("aerodrome_first_run", "aerodrome first run"),
        ("aerodrome_later_run", "aerodrome later run"),
        ("parking_lot_first_run", "parking lot first run"),
    ] {
        let f = &figures[key];
        let peak = f["peak_memory_mb"].as_f64().unwrap_or(f64::NAN);
        let wall = f["wall_s"].as_f64().unwrap_or(f64::NAN);
        writeln!(t, "{:<42} {peak:.0} MB", format!("{name} peak memory"))?;
        writeln!(
            t,
            "{:<42} {wall:.1} s (not checked)",
            format!("{name} wall time")
        )?;
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_names_every_figure_as_the_readme_does() {
        let run = RunFigures {
            command: "taxi-sim run".into(),
            peak_memory_mb: 279.94,
            wall_s: 142.63,
            expectations_met: true,
        };
        let map = MapFigures {
            bytes: 30_499_732,
            blocks: 243,
            occupied_cells: vec![958, 108],
            level_heights_m: vec![0.0, 1.1],
        };
        let figures = json!({
            "aerodrome_first_run": first_run_json(&run, &map),
            "aerodrome_later_run": run_json(&run),
            "parking_lot_first_run": first_run_json(&run, &map),
        });
        assert_eq!(figures["aerodrome_first_run"]["map_mb"], json!(30.5));
        assert_eq!(
            figures["aerodrome_later_run"]["peak_memory_mb"],
            json!(279.9)
        );
        let t = table(&figures).unwrap();
        for row in [
            "aerodrome offline map on disk              30.5 MB (30499732 bytes)",
            "aerodrome map blocks                       243",
            "parking lot occupied cells per level       958 / 108",
            "aerodrome later run peak memory            280 MB",
            "parking lot first run wall time            142.6 s (not checked)",
        ] {
            assert!(t.contains(row), "{row:?} not in\n{t}");
        }
    }

    #[test]
    fn bytes_under_counts_every_regular_file_recursively() {
        let dir = std::env::temp_dir().join(format!("taxi-sim-bytes-under-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("blocks/deeper")).unwrap();
        std::fs::write(dir.join("manifest.json"), [0u8; 10]).unwrap();
        std::fs::write(dir.join("blocks/a"), [0u8; 100]).unwrap();
        std::fs::write(dir.join("blocks/deeper/b"), [0u8; 1000]).unwrap();
        let bytes = bytes_under(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(bytes, 1110);
    }
}
