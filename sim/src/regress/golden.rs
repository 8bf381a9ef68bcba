//! Golden numbers of a regression case (`[regress] golden = "FILE.json"`): a rounded summary of
//! what the vehicle did in the quick tier's laps, compared line by line with the file, so a
//! change in behaviour fails the case even while every expectation still holds; `regress
//! --bless` writes the summaries anew after a change that is meant.

use std::path::Path;

use serde_json::{Value, json};

use crate::engine::{CLOSEST_STATIC_COUNT, RunReport, StaticClearance};
use crate::error::Result;

/// Differing lines shown at most, per case.
const LINES_SHOWN: usize = 12;

/// Rounds to a multiple of `step` (a summary must not change with the last bits of a float).
fn round(x: f64, step: f64) -> Value {
    if x.is_finite() {
        json!(((x / step).round() * step * 1000.0).round() / 1000.0)
    } else {
        Value::Null
    }
}

/// Everything in the report that says what the vehicle did, rounded (times to 0.1 s, distances
/// to 0.05 m; a stop's place on the route and what a pilot is called for to 0.5 m): how the run
/// ended, laps, stops, contacts, every pass, the static objects it came nearest (an airport's
/// lights and signs, ground truth); wall time and real-time factor left out.
pub fn summary(r: &RunReport) -> Value {
    let mut v = numbers(r);
    // A run that began with a push-back: how long it was and what it came nearest (only then:
    // the other goldens stay as they were).
    if let (Some(p), Some(map)) = (&r.pushback, v.as_object_mut()) {
        map.insert(
            "pushback".into(),
            json!(format!(
                "{} m, released at {} s, {}",
                round(p.length_m, 0.1),
                round(p.released_s, 0.1),
                p.nearest_object.as_deref().map_or_else(
                    || "nothing within range".to_string(),
                    |id| format!(
                        "nearest {} at {} m",
                        id.split('/').next().unwrap_or(id),
                        round(p.min_clearance_m, 0.05)
                    )
                )
            )),
        );
    }
    v
}

/// [`summary`] but the push-back.
fn numbers(r: &RunReport) -> Value {
    json!({
        "scenario": r.scenario,
        "seed": r.seed,
        "expectations_met": r.expectations_met,
        "end": serde_json::to_value(r.end).unwrap_or(Value::Null),
        "waiting_for": r.waiting_for.as_ref().map(|w| format!(
            "({}, {}) since {} s, last seen {}",
            round(w.x_m, 0.5),
            round(w.y_m, 0.5),
            round(w.since_s, 0.1),
            w.last_seen_s.map_or("never".to_string(), |t| format!("{} s", round(t, 0.1))),
        )),
        "laps_completed": r.laps_completed,
        "lap_times_s": r.lap_times_s.iter().map(|t| round(*t, 0.1)).collect::<Vec<_>>(),
        "contacts": r.contacts.iter().map(|c| format!("{} by {} at {:.1} s", c.object, c.part, c.time_s)).collect::<Vec<_>>(),
        "stops": r.stops.iter().map(|s| json!({
            "start_s": round(s.start_s, 0.1),
            "end_s": s.end_s.map(|e| round(e, 0.1)),
            "route_s_m": round(s.route_s_m, 0.5),
        })).collect::<Vec<_>>(),
        "min_clearance_m": r.min_clearance_m.iter().map(|d| round(*d, 0.05)).collect::<Vec<_>>(),
        "obstacles": r.obstacles.iter().map(|o| json!({
            "id": o.id,
            "expected": o.expected,
            "passes": o.passes.iter().map(|p| format!(
                "lap {} {} offset {} clearance {} {}",
                p.lap,
                p.outcome.as_str(),
                round(p.max_offset_m, 0.05),
                p.min_clearance_m.iter().map(|d| round(*d, 0.05).to_string()).collect::<Vec<_>>().join("/"),
                if p.met { "met" } else { "NOT MET" },
            )).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "closest_static_m": r.closest_static.first().map(|c| round(c.min_clearance_m, 0.05)),
        "closest_static": closest_static(&r.closest_static),
        "sim_time_s": round(r.sim_time_s, 0.1),
    })
}

/// The static objects nearest, "id clearance" by rounded clearance then id: the order of those
/// as near once rounded is the ids', not the last bits of their clearances. When the report's
/// list is full, those as near as its last are left out (which of a hundred edge lights as
/// near made the cut is down to those bits too): `closest_static_m` keeps the nearest.
fn closest_static(list: &[StaticClearance]) -> Vec<String> {
    let rounded = |c: &StaticClearance| (c.min_clearance_m / 0.05).round() as i64;
    let cutoff = (list.len() >= CLOSEST_STATIC_COUNT)
        .then(|| list.last().map(rounded))
        .flatten();
    let mut kept: Vec<&StaticClearance> = list
        .iter()
        .filter(|c| cutoff.is_none_or(|k| rounded(c) < k))
        .collect();
    kept.sort_by(|a, b| rounded(a).cmp(&rounded(b)).then_with(|| a.id.cmp(&b.id)));
    kept.iter()
        .map(|c| format!("{} {}", c.id, round(c.min_clearance_m, 0.05)))
        .collect()
}

/// The summary as the golden file holds it: pretty JSON, one field a line, a final newline.
pub fn text(summary: &Value) -> String {
    serde_json::to_string_pretty(summary).unwrap_or_default() + "\n"
}

/// Compares `summary` with the golden file at `path`; with `bless`, writes it there instead
/// (atomically). Returns the lines saying how they differ (empty: the same, or blessed); a
/// missing file is a difference that says how to write it.
pub fn check(path: &Path, summary: &Value, bless: bool) -> Result<Vec<String>> {
    let now = text(summary);
    if bless {
        super::results::write(path, &now)?;
        return Ok(Vec::new());
    }
    let want = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => {
            return Ok(vec![format!(
                "golden numbers {}: {e}; write them with `taxi-sim regress FILE --bless`",
                path.display()
            )]);
        }
    };
    Ok(differences(path, &want, &now))
}

/// How `now` differs from the golden text `want`, line by line (empty: the same; line endings
/// and a missing last newline aside): each line removed or added, with its number in the file
/// or in this run's summary.
pub fn differences(path: &Path, want: &str, now: &str) -> Vec<String> {
    let normal = |t: &str| {
        let mut t = t.replace("\r\n", "\n");
        if !t.ends_with('\n') {
            t.push('\n');
        }
        t
    };
    let (want, now) = (normal(want), normal(now));
    if want == now {
        return Vec::new();
    }
    let diff = similar::TextDiff::from_lines(&want, &now);
    let changed: Vec<String> = diff
        .iter_all_changes()
        .filter_map(|c| {
            let line = c.value().trim();
            match c.tag() {
                similar::ChangeTag::Equal => None,
                similar::ChangeTag::Delete => Some(format!(
                    "golden line {}: {line}",
                    c.old_index().map_or(0, |i| i + 1)
                )),
                similar::ChangeTag::Insert => Some(format!(
                    "now line {}: {line}",
                    c.new_index().map_or(0, |i| i + 1)
                )),
            }
        })
        .collect();
    let mut out = vec![format!(
        "golden numbers differ from {} (`taxi-sim regress FILE --bless` if the change is meant):",
        path.display()
    )];
    out.extend(changed.iter().take(LINES_SHOWN).cloned());
    if changed.len() > LINES_SHOWN {
        out.push(format!(
            "... and {} more lines",
            changed.len() - LINES_SHOWN
        ));
    }
    out
}
