//! The stack's process when the simulator starts it (`run --stack ros2 --stack-command CMD`):
//! `sh -c CMD` in a process group of its own with `ROS_DOMAIN_ID` set to the run's domain, its
//! output into a log file or the simulator's stderr; watched while the run waits on it (a stack
//! that exits ends the run with its status and the last lines it wrote) and stopped when the run
//! ends: SIGINT to its group, as Ctrl-C would, then SIGKILL after a grace period.

use std::fs::File;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use sim::{Error, Result};

/// How long a stopped stack gets to end on SIGINT before it is killed.
const GRACE: Duration = Duration::from_secs(5);

/// Lines of the stack's log quoted when it exits on its own.
const TAIL_LINES: usize = 5;

/// Gives the stack's process SIGINT's and SIGQUIT's default actions, whatever the simulator's
/// own are: a simulator started in the background by a non-interactive shell has them ignored,
/// an ignored disposition survives `exec`, and a shell started with SIGINT ignored can neither
/// trap nor reset it - the stack would then be killed after the grace, not stopped as Ctrl-C
/// stops it.
#[allow(unsafe_code)] // the workspace's fourth unsafe code: std has no way to reset a signal
fn interruptible(command: &mut Command) {
    // SAFETY: runs in the forked child before exec; `signal` is async-signal-safe (POSIX) and
    // touches no memory of the parent's.
    unsafe {
        command.pre_exec(|| {
            for sig in [libc::SIGINT, libc::SIGQUIT] {
                if libc::signal(sig, libc::SIG_DFL) == libc::SIG_ERR {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        });
    }
}

/// A stack process the simulator started and will stop.
pub struct StackProcess {
    command: String,
    child: Child,
    log: Option<PathBuf>,
}

impl StackProcess {
    /// Starts `sh -c command` on ROS domain `domain_id`, its stdout and stderr appended to `log`
    /// (or the simulator's stderr).
    pub fn spawn(command: &str, domain_id: u16, log: Option<&Path>) -> Result<Self> {
        let (out, err) = match log {
            Some(path) => {
                let file = File::create(path).map_err(|source| Error::Io {
                    what: "creating the stack's log",
                    path: path.to_path_buf(),
                    source,
                })?;
                let second = file.try_clone().map_err(|source| Error::Io {
                    what: "opening the stack's log twice",
                    path: path.to_path_buf(),
                    source,
                })?;
                (Stdio::from(file), Stdio::from(second))
            }
            None => (Stdio::from(std::io::stderr()), Stdio::inherit()),
        };
        let mut shell = Command::new("sh");
        shell
            .arg("-c")
            .arg(command)
            .env("ROS_DOMAIN_ID", domain_id.to_string())
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(err)
            .process_group(0);
        interruptible(&mut shell);
        let child = shell
            .spawn()
            .map_err(|e| Error::Stack(format!("starting the stack `{command}`: {e}")))?;
        Ok(StackProcess {
            command: command.to_string(),
            child,
            log: log.map(Path::to_path_buf),
        })
    }

    /// The process's id (its group's too).
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// `Err` naming the stack, its status and its last lines when it has exited; `when` says
    /// at what point of the run ("before it was discovered", "at t = 3.100 s").
    pub fn check(&mut self, when: &str) -> Result<()> {
        match self.child.try_wait() {
            Ok(None) => Ok(()),
            Ok(Some(status)) => Err(Error::Stack(format!(
                "the stack `{}` exited {} {when}{}",
                self.command,
                describe(status),
                self.tail()
            ))),
            Err(e) => Err(Error::Stack(format!(
                "watching the stack `{}`: {e}",
                self.command
            ))),
        }
    }

    /// The last lines of its log, as a suffix of an error message.
    fn tail(&self) -> String {
        let Some(path) = &self.log else {
            return String::new();
        };
        let text = std::fs::read_to_string(path).unwrap_or_default();
        let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
        let last = &lines[lines.len().saturating_sub(TAIL_LINES)..];
        if last.is_empty() {
            format!(" (its log {} is empty)", path.display())
        } else {
            format!(
                "; the end of its log {}:\n  {}",
                path.display(),
                last.join("\n  ")
            )
        }
    }

    /// Stops it: SIGINT to its process group, SIGKILL after the grace period. Returns how it
    /// ended (`None`: it could not be waited for).
    pub fn stop(&mut self) -> Option<ExitStatus> {
        if let Ok(Some(status)) = self.child.try_wait() {
            return Some(status);
        }
        // The group the child leads (spawned with process_group(0)): its children too.
        let group = rustix::process::Pid::from_raw(self.child.id() as i32);
        let signal = |s| group.map(|g| rustix::process::kill_process_group(g, s));
        let _ = signal(rustix::process::Signal::INT);
        let deadline = Instant::now() + GRACE;
        while Instant::now() < deadline {
            match self.child.try_wait() {
                Ok(Some(status)) => return Some(status),
                Ok(None) => std::thread::sleep(Duration::from_millis(20)),
                Err(_) => return None,
            }
        }
        let _ = signal(rustix::process::Signal::KILL);
        self.child.wait().ok()
    }
}

impl Drop for StackProcess {
    fn drop(&mut self) {
        self.stop();
    }
}

/// "with status 3", "on signal 9".
fn describe(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("with status {code}"),
        (None, Some(signal)) => format!("on signal {signal}"),
        _ => format!("({status})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stack_that_exits_is_named_with_its_status_and_last_lines() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("stack.log");
        let mut p = StackProcess::spawn(
            "echo domain $ROS_DOMAIN_ID; echo 'Traceback: boom' >&2; exit 3",
            42,
            Some(&log),
        )
        .unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        let e = loop {
            match p.check("at t = 1.500 s") {
                Ok(()) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(10))
                }
                Ok(()) => panic!("the stack did not exit"),
                Err(e) => break e.to_string(),
            }
        };
        assert!(e.contains("exited with status 3 at t = 1.500 s"), "{e}");
        assert!(
            e.contains("domain 42") && e.contains("Traceback: boom"),
            "{e}"
        );
    }

    #[test]
    fn a_stack_is_stopped_with_sigint_and_killed_if_it_ignores_it() {
        // Answers SIGINT by exiting 7: stopped by the signal, not killed.
        let mut polite =
            StackProcess::spawn("trap 'exit 7' INT; while :; do sleep 0.05; done", 0, None)
                .unwrap();
        std::thread::sleep(Duration::from_millis(200));
        assert!(polite.check("now").is_ok());
        assert_eq!(polite.stop().and_then(|s| s.code()), Some(7));
        // Ignores SIGINT: killed after the grace period, its whole group with it.
        let started = Instant::now();
        let mut stubborn =
            StackProcess::spawn("trap '' INT; while :; do sleep 0.05; done", 0, None).unwrap();
        std::thread::sleep(Duration::from_millis(200));
        let status = stubborn.stop().unwrap();
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(libc::SIGKILL));
        assert!(started.elapsed() >= GRACE);
    }
}
