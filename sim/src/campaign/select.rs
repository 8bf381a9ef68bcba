//! `campaign run --variants`: which variants to run - indices and ranges, or those that failed,
//! made a pilot call (a needless one) or a contact at fault in an earlier run of the campaign -
//! to run them again on another build or with a `--set`.

use std::path::Path;

use super::compare::Side;
use super::record::RunRecord;
use crate::error::{Error, Result};

/// Whether an earlier run's record is picked.
type Pick = fn(&RunRecord) -> bool;

/// What an earlier run's variants are picked by, by name.
const PICKS: [(&str, Pick); 5] = [
    ("failed", |r| r.failed),
    ("at-fault", |r| r.contacts_at_fault > 0),
    ("called", |r| r.pilot_call.is_some()),
    ("needless", |r| r.needless_pilot_call),
    ("any", |_| true),
];

/// The variants `text` names, sorted, each once: indices and ranges (`266,338,400-410`), or
/// `WHAT@RUN` - those of an earlier run of the campaign (a directory, or a kept record
/// `NAME.jsonl.gz`) that `failed`, made a contact `at-fault`, were `called` (a pilot call ended
/// them), made a `needless` call, or `any` it holds.
pub fn parse_variants(text: &str) -> Result<Vec<u64>> {
    let bad = |message: String| Error::Invalid(format!("--variants {text}: {message}"));
    let mut out = Vec::new();
    if let Some((what, run)) = text.split_once('@') {
        let Some((_, pick)) = PICKS.iter().find(|(name, _)| *name == what) else {
            let names: Vec<&str> = PICKS.iter().map(|(n, _)| *n).collect();
            return Err(bad(format!(
                "`{what}`: expected one of {}",
                names.join(", ")
            )));
        };
        let side = Side::read(Path::new(run))?;
        out.extend(side.records.iter().filter(|r| pick(r)).map(|r| r.index));
        if out.is_empty() {
            return Err(bad(format!("no variant of {run} is {what}")));
        }
    } else {
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let index = |s: &str| {
                s.trim()
                    .parse::<u64>()
                    .map_err(|_| bad(format!("`{s}` is not a variant index")))
            };
            match part.split_once('-') {
                Some((a, b)) => {
                    let (a, b) = (index(a)?, index(b)?);
                    if a > b {
                        return Err(bad(format!("`{part}`: a range runs upwards")));
                    }
                    out.extend(a..=b);
                }
                None => out.push(index(part)?),
            }
        }
        if out.is_empty() {
            return Err(bad("no variant named".into()));
        }
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_ranges_are_read_and_bad_ones_named() {
        assert_eq!(
            parse_variants("266, 338,400-402,338").unwrap(),
            [266, 338, 400, 401, 402]
        );
        for (text, says) in [
            ("12,x", "`x` is not a variant index"),
            ("9-3", "`9-3`: a range runs upwards"),
            (",", "no variant named"),
            (
                "slow@dir",
                "`slow`: expected one of failed, at-fault, called, needless, any",
            ),
        ] {
            let e = parse_variants(text).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
    }

    #[test]
    fn an_earlier_runs_variants_are_picked_by_what_they_did() {
        let dir = tempfile::tempdir().unwrap();
        let line = |index: u64, call: Option<&str>, needless: bool, at_fault: usize| {
            let r = serde_json::json!({
                "index": index, "sample": index, "setting": 0, "seed": 1, "sampled": {},
                "parameters": {}, "u": [], "end": "completed", "expectations_met": true,
                "failed": at_fault > 0, "failures": [], "contacts": at_fault, "contacts_with": [],
                "contacts_at_fault": at_fault, "obstacles": [], "min_clearance_m": [],
                "obstacle_clearance_m": null, "stops": 0, "deviations": 0, "false_stops": 0,
                "needless_deviations": 0, "lap_times_s": [], "sim_time_s": 1.0,
                "wall_time_s": 1.0, "score": 1.0, "failure_file": null, "pilot_call": call,
                "needless_pilot_call": needless,
            });
            r.to_string() + "\n"
        };
        let text = line(3, None, false, 0)
            + &line(5, Some("blocked/mover"), false, 0)
            + &line(8, Some("hidden_obstacle/lost_obstacle"), true, 0)
            + &line(9, None, false, 2);
        std::fs::write(dir.path().join("results.jsonl"), text).unwrap();
        let at = |what: &str| parse_variants(&format!("{what}@{}", dir.path().display()));
        assert_eq!(at("called").unwrap(), [5, 8]);
        assert_eq!(at("needless").unwrap(), [8]);
        assert_eq!(at("failed").unwrap(), [9]);
        assert_eq!(at("at-fault").unwrap(), [9]);
        assert_eq!(at("any").unwrap(), [3, 5, 8, 9]);
        std::fs::write(dir.path().join("results.jsonl"), line(3, None, false, 0)).unwrap();
        let e = at("needless").unwrap_err().to_string();
        assert!(e.contains("is needless"), "{e}");
    }
}
