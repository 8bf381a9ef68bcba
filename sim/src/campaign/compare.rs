//! `taxi-sim campaign compare BEFORE AFTER`: two runs of one campaign - two builds of the stack,
//! or the same build with a `--set` - side by side on the variants both hold. Safety (runs and
//! contacts at fault), availability (pilot calls, needless ones, by cause), how close it drove
//! (clearance to movers, time to collision, post-encroachment time) and what it cost (lap
//! times), then the variants whose outcome changed, to run one by one. Either side is a campaign
//! directory or a record kept in the repository (`NAME.jsonl.gz` beside `NAME.campaign.json`).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::{Path, PathBuf};

use super::record::{INVALID, RunRecord, parse_results};
use super::summary::quantile;
use crate::error::{Error, Result};

/// Changed variants listed (the rest are counted).
const MAX_CHANGED: usize = 60;

/// One side of a comparison: where it was read, its `campaign.json` and its records.
#[derive(Clone, Debug)]
pub struct Side {
    /// The directory or record file it was read from.
    pub path: PathBuf,
    /// Its `campaign.json` (`Null` when the record has none beside it).
    pub meta: serde_json::Value,
    /// Its run records, by index.
    pub records: Vec<RunRecord>,
    /// Its records say whether a pilot call ended each run (builds before the calls were
    /// recorded wrote no `pilot_call`: read as none, which would look like an improvement).
    pub calls_recorded: bool,
    /// The `campaign.json` it has not (its campaign, sampler and digest unknown, unchecked).
    pub meta_missing: Option<PathBuf>,
}

impl Side {
    /// Reads a campaign directory (`results.jsonl`, `campaign.json`) or a kept record
    /// (`NAME.jsonl` or `NAME.jsonl.gz`, with `NAME.campaign.json` beside it if there is one).
    pub fn read(path: &Path) -> Result<Side> {
        let (results, meta) = if path.is_dir() {
            (path.join("results.jsonl"), path.join("campaign.json"))
        } else {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let Some(stem) = name
                .strip_suffix(".jsonl.gz")
                .or_else(|| name.strip_suffix(".jsonl"))
            else {
                return Err(Error::BadFile {
                    path: path.to_path_buf(),
                    message: "not a campaign directory, nor a record (`.jsonl` or `.jsonl.gz`)"
                        .into(),
                });
            };
            (
                path.to_path_buf(),
                path.with_file_name(format!("{stem}.campaign.json")),
            )
        };
        let text = read_text(&results)?;
        let (records, _) = parse_results(&text, &results)?;
        if records.is_empty() {
            return Err(Error::BadFile {
                path: results,
                message: "holds no run records".into(),
            });
        }
        let calls_recorded = (text.lines().next())
            .and_then(|l| serde_json::from_str::<serde_json::Value>(l).ok())
            .is_some_and(|v| v.get("pilot_call").is_some());
        let (meta, meta_missing) = match std::fs::read_to_string(&meta) {
            Ok(t) => {
                let v = serde_json::from_str(&t).map_err(|e| Error::BadFile {
                    path: meta.clone(),
                    message: format!("not a campaign.json: {e}"),
                })?;
                (v, None)
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                (serde_json::Value::Null, Some(meta))
            }
            Err(source) => {
                return Err(Error::Io {
                    what: "reading the campaign's description",
                    path: meta,
                    source,
                });
            }
        };
        Ok(Side {
            path: path.to_path_buf(),
            meta,
            records,
            calls_recorded,
            meta_missing,
        })
    }

    /// Its digest's parts: the campaign file's (the first), then `--sampler`'s and each
    /// `--set`'s, in order (empty: no `campaign.json`).
    fn digest_parts(&self) -> Vec<String> {
        let digest = self.meta.get("digest").and_then(|d| d.as_str());
        digest.map_or_else(Vec::new, |d| d.split('-').map(str::to_string).collect())
    }

    /// A field of its `campaign.json`, as text (`?`: not known).
    fn meta_str(&self, key: &str) -> String {
        self.meta.get(key).map_or("?".into(), |v| {
            v.as_str().map_or_else(|| v.to_string(), str::to_string)
        })
    }
}

/// The text of `path`, gunzipped when its name ends in `.gz`.
fn read_text(path: &Path) -> Result<String> {
    let io = |source| Error::Io {
        what: "reading the run records",
        path: path.to_path_buf(),
        source,
    };
    let bytes = std::fs::read(path).map_err(io)?;
    if path.extension().is_some_and(|e| e == "gz") {
        let mut text = String::new();
        flate2::read::GzDecoder::new(&bytes[..])
            .read_to_string(&mut text)
            .map_err(io)?;
        Ok(text)
    } else {
        String::from_utf8(bytes).map_err(|e| Error::BadFile {
            path: path.to_path_buf(),
            message: format!("not UTF-8 text: {e}"),
        })
    }
}

/// A run's figures, summed or taken as percentiles over a set of runs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figures {
    /// Runs.
    pub runs: usize,
    /// Runs with a contact at fault, and those contacts.
    pub at_fault: (usize, usize),
    /// Runs ended by a pilot call, and the needless ones among them.
    pub calls: (usize, usize),
    /// Runs that completed their laps.
    pub completed: usize,
    /// Stops, over all runs.
    pub stops: usize,
    /// The 5th and 50th percentiles of each run's least clearance to a run-time obstacle, m.
    pub clearance_m: [Option<f64>; 2],
    /// ... of each run's least time to collision, s (runs with none left out).
    pub ttc_s: [Option<f64>; 2],
    /// ... of each run's least post-encroachment time, s (runs with none left out).
    pub pet_s: [Option<f64>; 2],
    /// The median and the longest lap, s.
    pub lap_s: [Option<f64>; 2],
}

impl Figures {
    /// The figures of `records`.
    pub fn of(records: &[&RunRecord]) -> Figures {
        let p5_p50 = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            [quantile(&v, 0.05), quantile(&v, 0.5)]
        };
        let mut laps: Vec<f64> = records.iter().flat_map(|r| r.lap_times_s.clone()).collect();
        laps.sort_by(f64::total_cmp);
        let at_fault: Vec<&&RunRecord> =
            records.iter().filter(|r| r.contacts_at_fault > 0).collect();
        let calls: Vec<&&RunRecord> = records.iter().filter(|r| r.pilot_call.is_some()).collect();
        Figures {
            runs: records.len(),
            at_fault: (
                at_fault.len(),
                at_fault.iter().map(|r| r.contacts_at_fault).sum(),
            ),
            calls: (
                calls.len(),
                calls.iter().filter(|r| r.needless_pilot_call).count(),
            ),
            completed: records.iter().filter(|r| r.end == "completed").count(),
            stops: records.iter().map(|r| r.stops).sum(),
            clearance_m: p5_p50(
                records
                    .iter()
                    .filter_map(|r| r.obstacle_clearance_m)
                    .collect(),
            ),
            ttc_s: p5_p50(records.iter().filter_map(|r| r.min_ttc_s).collect()),
            pet_s: p5_p50(records.iter().filter_map(|r| r.min_pet_s).collect()),
            lap_s: [quantile(&laps, 0.5), laps.last().copied()],
        }
    }
}

/// How a variant's run ended, as compared.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Why it ended (`completed`, `struck`, `waiting_for_hidden_obstacle`, ...).
    pub end: String,
    /// Its pilot call's cause, if one ended it (`None` too where a side did not record calls).
    pub call: Option<String>,
    /// That call was needless.
    pub needless: bool,
    /// Its contacts at fault.
    pub at_fault: usize,
    /// It failed: a contact at fault or an unmet expectation.
    pub failed: bool,
}

impl Outcome {
    fn of(r: &RunRecord, calls: bool) -> Outcome {
        Outcome {
            end: r.end.clone(),
            call: r.pilot_call.clone().filter(|_| calls),
            needless: r.needless_pilot_call && calls,
            at_fault: r.contacts_at_fault,
            failed: r.failed,
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.end)?;
        if let Some(call) = &self.call {
            write!(f, " ({call})")?;
        }
        if self.needless {
            write!(f, ", needless")?;
        }
        if self.at_fault > 0 {
            write!(f, ", {} at fault", self.at_fault)?;
        } else if self.failed {
            write!(f, ", failed")?;
        }
        Ok(())
    }
}

/// Two sides compared on the variants both hold.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The variants both hold, valid on both sides.
    pub common: usize,
    /// Variants only one side holds: before, after.
    pub only: (usize, usize),
    /// Common variants left out as not valid scenarios (`invalid`): on both sides, before
    /// only, after only (valid before: worse).
    pub invalid: (usize, usize, usize),
    /// The figures over the common variants: before, after (laps: over the variants both
    /// completed).
    pub figures: (Figures, Figures),
    /// Both sides recorded their pilot calls (else calls are left out of the comparison).
    pub calls_known: bool,
    /// Pilot calls by cause over the common variants: (calls, needless) before, after.
    pub causes: BTreeMap<String, [(usize, usize); 2]>,
    /// The common variants whose outcome changed: index, before, after (empty for the falsify
    /// sampler, whose variants after its first generation depend on the runs before them).
    pub changed: Vec<(u64, Outcome, Outcome)>,
    /// Sampled by the falsifier: its variants after the first generation differ by build, so
    /// only the figures of the two searches are compared.
    pub falsify: bool,
    /// The two sides' campaign files differ (the first part of their digests): a variant's index
    /// may not name the same scenario on both.
    pub file_changed: bool,
    /// They were run with different `--set`s (the rest of their digests): the same variants
    /// with something changed.
    pub sets_differ: bool,
}

/// Compares `before` and `after` on the variants both hold. An error when they are runs of
/// different campaigns (their names), of different samplers, or hold no variant in common.
pub fn compare(before: &Side, after: &Side) -> Result<Comparison> {
    let refuse = |message: String| Error::BadFile {
        path: after.path.clone(),
        message,
    };
    for key in ["name", "sampler"] {
        let (a, b) = (before.meta_str(key), after.meta_str(key));
        if a != "?" && b != "?" && a != b {
            let what = if key == "name" { "campaign" } else { "sampler" };
            return Err(refuse(format!(
                "a run of {what} \"{b}\", not of \"{a}\" as {} (its variants are other scenarios)",
                before.path.display()
            )));
        }
    }
    let after_by: BTreeMap<u64, &RunRecord> = after.records.iter().map(|r| (r.index, r)).collect();
    let all: Vec<(&RunRecord, &RunRecord)> = (before.records.iter())
        .filter_map(|r| after_by.get(&r.index).map(|s| (r, *s)))
        .collect();
    if all.is_empty() {
        return Err(refuse(format!(
            "no variant in common with {}",
            before.path.display()
        )));
    }
    let bad = |r: &RunRecord| r.end == INVALID;
    let invalid = (
        all.iter().filter(|(o, n)| bad(o) && bad(n)).count(),
        all.iter().filter(|(o, n)| bad(o) && !bad(n)).count(),
        all.iter().filter(|(o, n)| !bad(o) && bad(n)).count(),
    );
    let pairs: Vec<(&RunRecord, &RunRecord)> = all
        .iter()
        .copied()
        .filter(|(o, n)| !bad(o) && !bad(n))
        .collect();
    let calls_known = before.calls_recorded && after.calls_recorded;
    let olds: Vec<&RunRecord> = pairs.iter().map(|p| p.0).collect();
    let news: Vec<&RunRecord> = pairs.iter().map(|p| p.1).collect();
    let mut figures = (Figures::of(&olds), Figures::of(&news));
    let both_done = |r: &(&RunRecord, &RunRecord)| r.0.end == "completed" && r.1.end == "completed";
    let done: Vec<&(&RunRecord, &RunRecord)> = pairs.iter().filter(|p| both_done(p)).collect();
    figures.0.lap_s = lap_figures(done.iter().map(|p| p.0));
    figures.1.lap_s = lap_figures(done.iter().map(|p| p.1));
    let falsify = before.meta_str("sampler") == "falsify" || after.meta_str("sampler") == "falsify";
    let changed = (pairs.iter())
        .filter(|_| !falsify)
        .map(|(o, n)| {
            (
                o.index,
                Outcome::of(o, calls_known),
                Outcome::of(n, calls_known),
            )
        })
        .filter(|(_, o, n)| o != n)
        .collect();
    let (a, b) = (before.digest_parts(), after.digest_parts());
    Ok(Comparison {
        common: pairs.len(),
        only: (
            before.records.len() - all.len(),
            after.records.len() - all.len(),
        ),
        invalid,
        figures,
        calls_known,
        causes: if calls_known {
            causes(&olds, &news)
        } else {
            BTreeMap::new()
        },
        changed,
        falsify,
        file_changed: !a.is_empty() && !b.is_empty() && a[0] != b[0],
        sets_differ: !a.is_empty() && !b.is_empty() && a[1..] != b[1..],
    })
}

/// The pilot calls of `olds` and `news` by cause: (calls, needless) on each side.
fn causes(olds: &[&RunRecord], news: &[&RunRecord]) -> BTreeMap<String, [(usize, usize); 2]> {
    let mut causes: BTreeMap<String, [(usize, usize); 2]> = BTreeMap::new();
    for (side, records) in [olds, news].into_iter().enumerate() {
        for r in records {
            if let Some(call) = &r.pilot_call {
                let e = &mut causes.entry(call.clone()).or_default()[side];
                e.0 += 1;
                e.1 += usize::from(r.needless_pilot_call);
            }
        }
    }
    causes
}

/// The median and the longest of the laps of `records`, s.
fn lap_figures<'a>(records: impl Iterator<Item = &'a RunRecord>) -> [Option<f64>; 2] {
    let mut laps: Vec<f64> = records
        .flat_map(|r| r.lap_times_s.iter().copied())
        .collect();
    laps.sort_by(f64::total_cmp);
    [quantile(&laps, 0.5), laps.last().copied()]
}

impl Comparison {
    /// Where after does worse than before on the common variants: more runs at fault, more
    /// pilot calls or more needless ones (when both recorded them), variants no longer valid
    /// (empty: no worse).
    pub fn worse(&self) -> Vec<String> {
        let (o, n) = &self.figures;
        let mut why = Vec::new();
        let mut check = |what: &str, before: usize, after: usize| {
            if after > before {
                why.push(format!("{what} {before} -> {after}"));
            }
        };
        check("runs at fault", o.at_fault.0, n.at_fault.0);
        if self.calls_known {
            check("pilot calls", o.calls.0, n.calls.0);
            check("needless pilot calls", o.calls.1, n.calls.1);
        }
        check("variants no longer valid", 0, self.invalid.2);
        why
    }
}

fn m2(x: [Option<f64>; 2], digits: usize) -> String {
    let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.digits$}"));
    format!("{} / {}", f(x[0]), f(x[1]))
}

fn pct(n: usize, of: usize) -> String {
    format!("{n} ({:.1} %)", 100.0 * n as f64 / of.max(1) as f64)
}

/// The comparison as Markdown: what was compared and what was left out, the figures side by
/// side, the pilot calls by cause, the changed variants (the first [`MAX_CHANGED`], then all of
/// them as a `--variants` list).
pub fn render(c: &Comparison, before: &Side, after: &Side) -> String {
    let label = |s: &Side| s.path.display().to_string();
    let mut s = format!(
        "# Campaign compared: {}\n\nBefore `{}`, after `{}`: the {} variants both hold (sampler `{}`, seed {}).\n",
        before.meta_str("name"),
        label(before),
        label(after),
        c.common,
        before.meta_str("sampler"),
        before.meta_str("seed"),
    );
    s += &notes(c, before, after);
    s += &figures_table(&c.figures, c.calls_known);
    let worse = c.worse();
    s += &if worse.is_empty() {
        "\nAfter is no worse: no more runs at fault, pilot calls or needless ones.\n".to_string()
    } else {
        format!("\n**After is worse**: {}.\n", worse.join(", "))
    };
    if c.calls_known {
        s += "\n## Pilot calls by cause\n\n| call / what held it | before (needless) | after (needless) |\n| --- | --- | --- |\n";
        for (cause, [o, n]) in &c.causes {
            let _ = writeln!(s, "| {cause} | {} ({}) | {} ({}) |", o.0, o.1, n.0, n.1);
        }
    }
    if c.falsify {
        return s;
    }
    let _ = write!(
        s,
        "\n## Variants whose outcome changed: {} of {}\n\n",
        c.changed.len(),
        c.common
    );
    if !c.changed.is_empty() {
        s += "| variant | before | after |\n| --- | --- | --- |\n";
        for (i, o, n) in c.changed.iter().take(MAX_CHANGED) {
            let _ = writeln!(s, "| {i} | {o} | {n} |");
        }
        if c.changed.len() > MAX_CHANGED {
            let _ = writeln!(s, "\n... and {} more.", c.changed.len() - MAX_CHANGED);
        }
        let all: Vec<u64> = c.changed.iter().map(|(i, _, _)| *i).collect();
        let _ = writeln!(
            s,
            "\nAll of them, to run again: `--variants {}`",
            super::merge::ranges(&all).replace(", ", ",")
        );
    }
    s
}

/// What the comparison left out or could not check, a line each.
fn notes(c: &Comparison, before: &Side, after: &Side) -> String {
    let mut s = String::new();
    for side in [before, after] {
        if let Some(m) = &side.meta_missing {
            let _ = writeln!(
                s,
                "\nNo `{}`: its campaign, sampler and digest are not known, nor checked against the other side's.",
                m.display()
            );
        }
        if !side.calls_recorded {
            let _ = writeln!(
                s,
                "\n`{}` records no pilot calls (an older build): calls are left out of the comparison.",
                side.path.display()
            );
        }
    }
    if c.only != (0, 0) {
        let _ = writeln!(
            s,
            "\nLeft out: {} variants only before holds, {} only after.",
            c.only.0, c.only.1
        );
    }
    let (both, before_only, after_only) = c.invalid;
    if both + before_only + after_only > 0 {
        let _ = writeln!(
            s,
            "\nLeft out as no valid scenario: {both} variants on both sides, {before_only} before only, {after_only} after only."
        );
    }
    if c.file_changed {
        s += "\n**The campaign file changed between them** (the first part of its digest): a variant's index may name another scenario on each side.\n";
    } else if c.sets_differ {
        s += "\nRun with different `--set`s (the rest of the digest): the same variants with something changed.\n";
    }
    if c.falsify {
        s += "\nThe falsify sampler: its variants after the first generation depend on the runs before them, so the two searches are compared by their figures, not variant for variant.\n";
    }
    s
}

/// The figures before and after as a table.
fn figures_table((o, n): &(Figures, Figures), calls: bool) -> String {
    let calls_of = |f: &Figures| {
        if calls {
            (pct(f.calls.0, f.runs), f.calls.1.to_string())
        } else {
            ("not recorded".to_string(), "not recorded".to_string())
        }
    };
    let ((oc, on), (nc, nn)) = (calls_of(o), calls_of(n));
    let rows: [(&str, String, String); 9] = [
        (
            "at fault (runs / contacts)",
            format!("{} / {}", o.at_fault.0, o.at_fault.1),
            format!("{} / {}", n.at_fault.0, n.at_fault.1),
        ),
        ("pilot calls", oc, nc),
        ("needless pilot calls", on, nn),
        (
            "completed",
            pct(o.completed, o.runs),
            pct(n.completed, n.runs),
        ),
        ("stops", o.stops.to_string(), n.stops.to_string()),
        (
            "clearance to obstacles p5 / p50, m",
            m2(o.clearance_m, 2),
            m2(n.clearance_m, 2),
        ),
        (
            "time to collision p5 / p50, s",
            m2(o.ttc_s, 2),
            m2(n.ttc_s, 2),
        ),
        (
            "post-encroachment time p5 / p50, s",
            m2(o.pet_s, 1),
            m2(n.pet_s, 1),
        ),
        (
            "lap p50 / max, s (variants both completed)",
            m2(o.lap_s, 1),
            m2(n.lap_s, 1),
        ),
    ];
    let mut s = "\n| | before | after |\n| --- | --- | --- |\n".to_string();
    for (name, a, b) in rows {
        let _ = writeln!(s, "| {name} | {a} | {b} |");
    }
    s
}

#[cfg(test)]
#[path = "compare_tests.rs"]
mod tests;
