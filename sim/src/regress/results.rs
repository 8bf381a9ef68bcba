//! A regression run's results as CI systems read them: JUnit XML (one `testsuite` per folder,
//! one `testcase` per file, `failure` with the message, `skipped` for a known problem or a case
//! of the other tier, properties for seed, laps, sim time and the rerun command), JSON lines
//! (one [`CaseResult`] a line) and a Markdown summary; each written atomically. Shards' JSON
//! lines merge back into one run ([`read_json`]).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Duration;

use quick_junit::{NonSuccessKind, Property, Report, TestCase, TestCaseStatus, TestSuite};

use super::{CaseResult, Status};
use crate::error::{Error, Result};

/// The counts of a run, by status.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Passed.
    pub passed: usize,
    /// Failed (an expectation; a known problem fixed or changed).
    pub failed: usize,
    /// Known problems that still fail as stated.
    pub known_problems: usize,
    /// Not run in this tier.
    pub not_run: usize,
    /// Files that are not valid scenarios, or runs that could not be made.
    pub errors: usize,
}

impl Counts {
    /// The counts of `results`.
    pub fn of(results: &[CaseResult]) -> Counts {
        let mut c = Counts::default();
        for r in results {
            match r.status {
                Status::Passed => c.passed += 1,
                Status::Failed => c.failed += 1,
                Status::KnownProblem => c.known_problems += 1,
                Status::NotRun => c.not_run += 1,
                Status::Error => c.errors += 1,
            }
        }
        c
    }

    /// "N cases: P passed, F failed, K known problems, R not run, E errors".
    pub fn sentence(&self) -> String {
        format!(
            "{} cases: {} passed, {} failed, {} known problems, {} not run, {} errors",
            self.passed + self.failed + self.known_problems + self.not_run + self.errors,
            self.passed,
            self.failed,
            self.known_problems,
            self.not_run,
            self.errors
        )
    }

    /// The exit code: 2 when a file was bad, 1 when a case failed, 0 otherwise.
    pub fn exit_code(&self) -> u8 {
        if self.errors > 0 {
            2
        } else if self.failed > 0 {
            1
        } else {
            0
        }
    }
}

/// The JUnit report of `results` (named `name`), suites in the order of their first case.
pub fn junit(name: &str, results: &[CaseResult]) -> Report {
    let mut report = Report::new(name);
    let mut suites: Vec<(String, TestSuite)> = Vec::new();
    for r in results {
        let k = match suites.iter().position(|(s, _)| *s == r.suite) {
            Some(k) => k,
            None => {
                suites.push((r.suite.clone(), TestSuite::new(r.suite.as_str())));
                suites.len() - 1
            }
        };
        suites[k].1.add_test_case(test_case(r));
    }
    for (_, mut s) in suites {
        let t: f64 = s
            .test_cases
            .iter()
            .filter_map(|c| c.time)
            .map(|d| d.as_secs_f64())
            .sum();
        s.set_time(Duration::from_secs_f64(t));
        report.add_test_suite(s);
    }
    report
}

/// One case as a JUnit test case.
fn test_case(r: &CaseResult) -> TestCase {
    let message = r.messages.join("; ");
    let status = match r.status {
        Status::Passed => TestCaseStatus::success(),
        Status::Failed | Status::Error => {
            let kind = if r.status == Status::Error {
                NonSuccessKind::Error
            } else {
                NonSuccessKind::Failure
            };
            let mut s = TestCaseStatus::non_success(kind);
            s.set_message(message.as_str());
            s.set_type(if r.status == Status::Error {
                "bad input"
            } else {
                "expectation"
            });
            s.set_description(format!("{}\nrerun: {}", r.messages.join("\n"), r.rerun));
            s
        }
        Status::KnownProblem => {
            let mut s = TestCaseStatus::skipped();
            s.set_message(format!(
                "known problem: {}",
                r.known_problem.as_deref().unwrap_or("")
            ));
            s.set_type("known problem");
            s.set_description(message.as_str());
            s
        }
        Status::NotRun => {
            let mut s = TestCaseStatus::skipped();
            s.set_message(message.as_str());
            s.set_type("not run");
            s
        }
    };
    let mut case = TestCase::new(r.name.as_str(), status);
    case.set_classname(r.suite.as_str());
    case.set_time(Duration::from_secs_f64(r.wall_time_s.max(0.0)));
    for (k, v) in [
        ("file", r.file.clone()),
        ("seed", r.seed.to_string()),
        ("laps", r.laps.to_string()),
        ("end", r.end.clone().unwrap_or_default()),
        ("sim_time_s", format!("{:.1}", r.sim_time_s)),
        ("real_time_factor", format!("{:.1}", r.real_time_factor)),
        ("rerun", r.rerun.clone()),
    ] {
        case.add_property(Property::new(k, v));
    }
    case
}

/// Writes `text` to `path` atomically, its folder made if missing.
pub(super) fn write(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            what: "creating the folder",
            path: dir.to_path_buf(),
            source,
        })?;
    }
    mapper::write_atomically(path, text.as_bytes())?;
    Ok(())
}

/// Writes the JUnit XML of `results` to `path`.
pub fn write_junit(path: &Path, results: &[CaseResult]) -> Result<()> {
    let xml = junit("taxi-sim regress", results)
        .to_string()
        .map_err(|e| Error::Invalid(format!("{}: JUnit XML: {e}", path.display())))?;
    write(path, &xml)
}

/// Writes `results` as JSON lines to `path`.
pub fn write_json(path: &Path, results: &[CaseResult]) -> Result<()> {
    let mut text = String::new();
    for r in results {
        text += &serde_json::to_string(r)?;
        text.push('\n');
    }
    write(path, &text)
}

/// Reads JSON lines written by [`write_json`] (a shard's); a bad line is an error naming it.
pub fn read_json(path: &Path) -> Result<Vec<CaseResult>> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        what: "reading regression results",
        path: path.to_path_buf(),
        source,
    })?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l).map_err(|e| Error::BadFile {
                path: path.to_path_buf(),
                message: format!("line {}: not a regression result: {e}", i + 1),
            })
        })
        .collect()
}

/// Writes the Markdown summary of `results` to `path`.
pub fn write_summary(path: &Path, results: &[CaseResult], wall_s: f64) -> Result<()> {
    write(path, &summary(results, wall_s))
}

/// The status as the table shows it.
pub fn status_word(s: Status) -> &'static str {
    match s {
        Status::Passed => "passed",
        Status::Failed => "FAILED",
        Status::KnownProblem => "known problem",
        Status::NotRun => "not run",
        Status::Error => "ERROR",
    }
}

/// The Markdown summary: the counts, a table of every case, what failed with its rerun command.
pub fn summary(results: &[CaseResult], wall_s: f64) -> String {
    let sim_s: f64 = results.iter().map(|r| r.sim_time_s).sum();
    let mut s = format!(
        "# Scenario regressions\n\n{}. {sim_s:.0} s of simulated time in {wall_s:.0} s of wall time.\n\n",
        Counts::of(results).sentence()
    );
    s += "| case | status | end | contacts (at fault / struck) | obstacle clearance (m) | sim time (s) | wall time (s) | x real time |\n|---|---|---|---|---|---|---|---|\n";
    let mut by_suite: BTreeMap<&str, Vec<&CaseResult>> = BTreeMap::new();
    for r in results {
        by_suite.entry(&r.suite).or_default().push(r);
    }
    for (suite, rs) in &by_suite {
        for r in rs {
            s += &format!(
                "| {suite}/{} | {} | {} | {} ({} / {}) | {} | {:.1} | {:.1} | {:.1} |\n",
                r.name,
                status_word(r.status),
                r.end.as_deref().unwrap_or("-"),
                r.contacts,
                r.contacts_at_fault,
                r.contacts_struck,
                r.obstacle_clearance_m
                    .map_or("-".into(), |c| format!("{c:.2}")),
                r.sim_time_s,
                r.wall_time_s,
                r.real_time_factor
            );
        }
    }
    let notes: Vec<&CaseResult> = results
        .iter()
        .filter(|r| {
            matches!(
                r.status,
                Status::Failed | Status::Error | Status::KnownProblem
            )
        })
        .collect();
    if !notes.is_empty() {
        s += "\n## Failures and known problems\n\n";
        for r in notes {
            s += &format!(
                "- **{}/{}** ({}): {}",
                r.suite,
                r.name,
                status_word(r.status),
                r.messages.join("; ")
            );
            if let Some(k) = &r.known_problem {
                s += &format!(" - known problem: {k}");
            }
            s += &format!(" - rerun: `{}`\n", r.rerun);
        }
    }
    s
}
