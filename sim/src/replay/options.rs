//! What the replay is asked for ([`ReplayOptions`], checked) and where it goes: the recording
//! file (written to a temporary file, renamed into place at the end) and the live viewer
//! (spawned or connected to over gRPC).

use std::path::{Path, PathBuf};

use rerun::sink::{FileSink, GrpcSink, LogSink};

use super::{Context as _, RERUN_VERSION, Result};

/// Where the replay goes and how much of the run it shows.
#[derive(Clone, Debug)]
pub struct ReplayOptions {
    /// Write a recording here (`.rrd`), atomically at the end of the run.
    pub record: Option<PathBuf>,
    /// Start a viewer (`rerun` from the PATH, or the one already listening on port 9876) and
    /// stream to it.
    pub spawn: bool,
    /// Stream to the viewer at this address (`rerun+http://host:port/proxy` or `host:port`).
    pub connect: Option<String>,
    /// LiDAR points and planner candidates every this many revolutions (the chosen path and the
    /// speed scale every revolution). Default 10 (1 Hz with the 10 Hz LiDAR).
    pub scan_every: u32,
    /// Keep every this many columns of a logged revolution (all 32 beams of each). Default 4.
    pub point_stride: usize,
    /// Occupancy and distance maps per second of simulated time (0: none). Default 1.
    pub maps_hz: f64,
    /// Half side of the square of the maps logged around the vehicle, metres. Default 30.
    pub map_half_m: f64,
    /// Vehicle pose and time series per second of simulated time (at most the physics rate).
    /// Default 20.
    pub steps_hz: f64,
}

impl Default for ReplayOptions {
    fn default() -> Self {
        ReplayOptions {
            record: None,
            spawn: false,
            connect: None,
            scan_every: 10,
            point_stride: 4,
            maps_hz: 1.0,
            map_half_m: 30.0,
            steps_hz: 20.0,
        }
    }
}

impl ReplayOptions {
    /// True when the replay has somewhere to go.
    pub fn enabled(&self) -> bool {
        self.record.is_some() || self.spawn || self.connect.is_some()
    }

    /// Checks the options; errors name the command-line flag.
    pub fn validate(&self) -> Result<()> {
        ensure!(
            self.scan_every >= 1,
            "--replay-scan-every {}: must be at least 1",
            self.scan_every
        );
        ensure!(
            self.point_stride >= 1,
            "--replay-point-stride {}: must be at least 1",
            self.point_stride
        );
        ensure!(
            self.maps_hz.is_finite() && self.maps_hz >= 0.0,
            "--replay-maps-hz {}: must be >= 0 (0: no maps)",
            self.maps_hz
        );
        ensure!(
            self.map_half_m.is_finite() && self.map_half_m > 0.0 && self.map_half_m <= 500.0,
            "--replay-map-half-m {}: must be in (0, 500] metres",
            self.map_half_m
        );
        ensure!(
            self.steps_hz.is_finite() && self.steps_hz > 0.0,
            "--replay-steps-hz {}: must be > 0",
            self.steps_hz
        );
        if let Some(path) = &self.record {
            ensure!(
                path.file_name().is_some(),
                "--record {}: not a file name",
                path.display()
            );
        }
        if let Some(addr) = &self.connect {
            proxy_url(addr)?;
        }
        Ok(())
    }
}

/// The gRPC proxy URL of a `--connect` address.
fn proxy_url(addr: &str) -> Result<String> {
    let url = if addr.contains("://") {
        addr.to_string()
    } else {
        format!("rerun+http://{addr}/proxy")
    };
    url.parse::<rerun::external::re_uri::ProxyUri>()
        .map_err(|e| invalid!("--connect {addr}: not a viewer address ({e}); expected host:port or rerun+http://host:port/proxy"))?;
    Ok(url)
}

/// The sinks of a replay's recording stream.
pub(super) struct Sinks {
    /// The recording file and/or the live viewer.
    pub(super) sinks: Vec<Box<dyn LogSink>>,
    /// The temporary recording and its destination.
    pub(super) file: Option<(tempfile::TempPath, PathBuf)>,
    /// Where it streams live.
    pub(super) streamed_to: Option<String>,
}

impl ReplayOptions {
    /// Opens the recording file and/or the live viewer. Errors name the flag at fault.
    pub(super) fn open_sinks(&self) -> Result<Sinks> {
        let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
        let mut file = None;
        if let Some(path) = &self.record {
            let (sink, tmp) = record_sink(path)?;
            sinks.push(Box::new(sink));
            file = Some((tmp, path.clone()));
        }
        let mut streamed_to = None;
        if self.spawn {
            let spawn = rerun::SpawnOptions::default();
            let info = rerun::spawn(&spawn).map_err(|e| {
                invalid!(
                    "--spawn: could not start the Rerun viewer ({e}); install it with `pip install rerun-sdk=={}.*` (the viewer must match Rerun {RERUN_VERSION}) or use --record",
                    RERUN_VERSION
                )
            })?;
            let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
            sinks.push(Box::new(grpc_sink(&url)?));
            streamed_to = Some(url);
        }
        if let Some(addr) = &self.connect {
            let url = proxy_url(addr)?;
            sinks.push(Box::new(grpc_sink(&url)?));
            streamed_to = Some(url);
        }
        ensure!(
            !sinks.is_empty(),
            "the replay needs --record, --spawn or --connect"
        );
        Ok(Sinks {
            sinks,
            file,
            streamed_to,
        })
    }

    /// How the recording stream batches what is logged. A recording only: large chunks (fewer,
    /// smaller on disk). Live: the default 200 ms.
    pub(super) fn batcher_config(&self) -> rerun::log::ChunkBatcherConfig {
        let live = self.spawn || self.connect.is_some();
        if live {
            rerun::log::ChunkBatcherConfig::DEFAULT
        } else {
            rerun::log::ChunkBatcherConfig {
                flush_tick: std::time::Duration::from_secs(2),
                flush_num_bytes: 8 * 1024 * 1024,
                ..rerun::log::ChunkBatcherConfig::DEFAULT
            }
        }
    }
}

/// The sink writing `--record path`: a temporary file next to `path` (the directory created
/// if need be), renamed over it by [`persist`].
fn record_sink(path: &Path) -> Result<(FileSink, tempfile::TempPath)> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir)
        .ctx(|| format!("--record {}: creating {}", path.display(), dir.display()))?;
    let tmp = tempfile::Builder::new()
        .prefix(".taxi-sim-replay-")
        .suffix(".rrd.part")
        .tempfile_in(&dir)
        .ctx(|| {
            format!(
                "--record {}: creating a file in {}",
                path.display(),
                dir.display()
            )
        })?
        .into_temp_path();
    let sink = FileSink::new(tmp.to_path_buf())
        .ctx(|| format!("--record {}: opening the recording", path.display()))?;
    Ok((sink, tmp))
}

/// Moves the finished recording `tmp` into place at `dest`, readable by others; returns `dest`
/// and the recording's size in bytes.
pub(super) fn persist(tmp: tempfile::TempPath, dest: PathBuf) -> Result<(PathBuf, u64)> {
    let size = std::fs::metadata(&tmp)
        .ctx(|| format!("--record {}: the recording vanished", dest.display()))?
        .len();
    ensure!(
        size > 0,
        "--record {}: Rerun wrote nothing (see its messages above)",
        dest.display()
    );
    set_readable(&tmp);
    tmp.persist(&dest).ctx(|| {
        format!(
            "--record {}: moving the recording into place",
            dest.display()
        )
    })?;
    Ok((dest, size))
}

/// tempfile creates 0600 files; a recording is for others to read too.
fn set_readable(path: &Path) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        let _ = std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o644));
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// The sink streaming to the viewer at `url` (a gRPC proxy URL).
fn grpc_sink(url: &str) -> Result<GrpcSink> {
    let uri = url
        .parse::<rerun::external::re_uri::ProxyUri>()
        .map_err(|e| invalid!("viewer address {url}: {e}"))?;
    Ok(GrpcSink::new(uri))
}
