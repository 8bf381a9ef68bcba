//! `campaign run --variants`: which variants to run - indices and ranges, or those that failed,
//! made a pilot call (a needless one) or a contact at fault in an earlier run of the campaign -
//! to run them again on another build or with a `--set`.

use std::path::Path;

use super::Campaign;
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

/// The variants `text` names, sorted, each once, all below `total` (the variants asked for):
/// indices and ranges (`266,338,400-410`), or `WHAT@RUN` - those of an earlier run of the
/// campaign (a directory, or a kept record `NAME.jsonl.gz`) that `failed`, made a contact
/// `at-fault`, were `called` (a pilot call ended them), made a `needless` call, or `any` it
/// holds; with that run's `campaign.json`, to check it is a run of this campaign
/// ([`check_same_campaign`]).
pub fn parse_variants(text: &str, total: u64) -> Result<(Vec<u64>, Option<serde_json::Value>)> {
    let bad = |message: String| Error::Invalid(format!("--variants {text}: {message}"));
    let beyond = |i: u64| {
        bad(format!(
            "variant {i} is beyond the {total} variants of this run (more with --runs, unless a grid ends sooner)"
        ))
    };
    let mut out = Vec::new();
    let mut meta = None;
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
        meta = Some(side.meta);
    } else {
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let index = |s: &str| {
                s.trim()
                    .parse::<u64>()
                    .map_err(|_| bad(format!("`{s}` is not a variant index")))
            };
            let (a, b) = match part.split_once('-') {
                Some((a, b)) => (index(a)?, index(b)?),
                None => (index(part)?, index(part)?),
            };
            if a > b {
                return Err(bad(format!("`{part}`: a range runs upwards")));
            }
            if b >= total {
                return Err(beyond(b));
            }
            out.extend(a..=b);
        }
        if out.is_empty() {
            return Err(bad("no variant named".into()));
        }
    }
    out.sort_unstable();
    out.dedup();
    if let Some(&last) = out.last().filter(|&&i| i >= total) {
        return Err(beyond(last));
    }
    Ok((out, meta))
}

/// Whether the run described by `meta` (its `campaign.json`) is a run of `campaign` as it is
/// run now: an error when its campaign, sampler or campaign file (the first part of its digest)
/// differs - its indices would name other scenarios -; a note when only its `--set`s differ
/// (`None`: the same, or no `campaign.json` to tell).
pub fn check_same_campaign(
    meta: &serde_json::Value,
    campaign: &Campaign,
) -> Result<Option<String>> {
    if meta.is_null() {
        return Ok(Some(
            "--variants: the earlier run has no campaign.json; its indices are taken as this campaign's".into(),
        ));
    }
    let text = |k: &str| {
        meta.get(k)
            .and_then(|v| v.as_str())
            .unwrap_or("?")
            .to_string()
    };
    let digest = text("digest");
    let (theirs, ours) = (
        digest.split('-').collect::<Vec<_>>(),
        campaign.digest.split('-').collect::<Vec<_>>(),
    );
    let differs = [
        ("campaign", text("name"), campaign.name.clone()),
        (
            "sampler",
            text("sampler"),
            campaign.sampler.as_str().to_string(),
        ),
        (
            "campaign file (digest)",
            theirs[0].to_string(),
            ours[0].to_string(),
        ),
    ];
    if let Some((what, a, b)) = differs.iter().find(|(_, a, b)| a != b) {
        return Err(Error::Invalid(format!(
            "--variants: the earlier run is of another {what} (\"{a}\", not \"{b}\"): its indices name other scenarios"
        )));
    }
    Ok((theirs[1..] != ours[1..]).then(|| {
        "--variants: the earlier run had other --set values (the same variants with something changed)".to_string()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_ranges_are_read_and_bad_ones_named() {
        assert_eq!(
            parse_variants("266, 338,400-402,338", 1000).unwrap().0,
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
            (
                "5,0-99999999999",
                "variant 99999999999 is beyond the 1000 variants",
            ),
        ] {
            let e = parse_variants(text, 1000).unwrap_err().to_string();
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
        let at = |what: &str, total: u64| {
            parse_variants(&format!("{what}@{}", dir.path().display()), total).map(|p| p.0)
        };
        assert_eq!(at("called", 10).unwrap(), [5, 8]);
        assert_eq!(at("needless", 10).unwrap(), [8]);
        assert_eq!(at("failed", 10).unwrap(), [9]);
        assert_eq!(at("at-fault", 10).unwrap(), [9]);
        assert_eq!(at("any", 10).unwrap(), [3, 5, 8, 9]);
        let e = at("any", 9).unwrap_err().to_string();
        assert!(e.contains("variant 9 is beyond the 9 variants"), "{e}");
        std::fs::write(dir.path().join("results.jsonl"), line(3, None, false, 0)).unwrap();
        let e = at("needless", 10).unwrap_err().to_string();
        assert!(e.contains("is needless"), "{e}");
    }
}
