//! A campaign directory's `summary.md`, from its `results.jsonl`: per parameter setting the
//! runs, failures, contacts (standing; at fault / struck, of them while moving), unmet expectations, false stops and needless deviations, clearance
//! percentiles and lap times; for the falsifier, the generations; the error table of the
//! failing variants. `taxi-sim campaign show DIR` prints it.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::record::{INVALID, RunRecord};
use crate::error::Result;

/// Failing variants listed in the error table (the rest are in `results.jsonl`).
const MAX_ROWS: usize = 100;

/// The `p`-quantile (0..1) of sorted values, nearest rank.
pub(super) fn quantile(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let i = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
    Some(sorted[i])
}

fn m(x: Option<f64>) -> String {
    x.map_or("-".into(), |v| format!("{v:.2}"))
}

/// The setting's label: its parameters, or `base` when none.
pub fn setting_label(r: &RunRecord) -> String {
    if r.parameters.is_empty() {
        "base".into()
    } else {
        r.parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The summary of `records` (sorted by index) with the directory's `campaign.json`.
pub fn render(meta: &serde_json::Value, records: &[RunRecord]) -> String {
    let get = |k: &str| {
        meta.get(k)
            .map_or("?".into(), |v| v.to_string().trim_matches('"').to_string())
    };
    let mut s = format!(
        "# Campaign: {}\n\nFile `{}`, sampler `{}`, seed {}: {} runs recorded.\n\n",
        get("name"),
        get("campaign"),
        get("sampler"),
        get("seed"),
        records.len()
    );
    s += "![Smallest clearance to an obstacle per run, failures in red](clearance.svg)\n\n";
    let invalid: Vec<&RunRecord> = records.iter().filter(|r| r.end == INVALID).collect();
    if let Some(first) = invalid.first() {
        let _ = writeln!(
            s,
            "{} variants were not valid scenarios and are left out below (the first, {}: {}).\n",
            invalid.len(),
            first.index,
            first.failures.join("; ").lines().next().unwrap_or("")
        );
    }
    let valid: Vec<RunRecord> = records
        .iter()
        .filter(|r| r.end != INVALID)
        .cloned()
        .collect();
    let records = valid.as_slice();
    let failed: Vec<&RunRecord> = records.iter().filter(|r| r.failed).collect();
    let first = failed.first().map(|r| r.index + 1);
    let _ = writeln!(
        s,
        "Failures: {} of {} ({:.1} per 1000 runs); runs to the first failure: {}.\n",
        failed.len(),
        records.len(),
        1000.0 * failed.len() as f64 / records.len().max(1) as f64,
        first.map_or("none yet".into(), |n| n.to_string())
    );
    s += "## Per parameter setting\n\n| setting | runs | failed | runs with contact | contacts (standing) | at fault / struck (while moving) | unmet expectations | false stops | needless deviations | obstacle clearance p0 / p5 / p50 (m) | mover TTC / PET p0 (s) | lap time p50 / max (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let mut by_setting: BTreeMap<usize, Vec<&RunRecord>> = BTreeMap::new();
    for r in records {
        by_setting.entry(r.setting).or_default().push(r);
    }
    for rs in by_setting.values() {
        let mut clear: Vec<f64> = rs.iter().filter_map(|r| r.obstacle_clearance_m).collect();
        clear.sort_by(f64::total_cmp);
        let mut laps: Vec<f64> = rs
            .iter()
            .flat_map(|r| r.lap_times_s.iter().copied())
            .collect();
        laps.sort_by(f64::total_cmp);
        let standing: usize = rs.iter().map(|r| r.contacts_while_stopped).sum();
        let at_fault: usize = rs.iter().map(|r| r.contacts_at_fault).sum();
        let struck: usize = rs.iter().map(|r| r.contacts_struck).sum();
        let moving: usize = rs.iter().map(|r| r.contacts_struck_while_moving).sum();
        let ttc = rs.iter().filter_map(|r| r.min_ttc_s).reduce(f64::min);
        let pet = rs.iter().filter_map(|r| r.min_pet_s).reduce(f64::min);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} ({standing}) | {at_fault} / {struck} ({moving}) | {} | {} | {} | {} / {} / {} | {} / {} | {} / {} |",
            setting_label(rs[0]),
            rs.len(),
            rs.iter().filter(|r| r.failed).count(),
            rs.iter().filter(|r| r.contacts > 0).count(),
            rs.iter().map(|r| r.contacts).sum::<usize>(),
            rs.iter().filter(|r| !r.expectations_met).count(),
            rs.iter().map(|r| r.false_stops).sum::<usize>(),
            rs.iter().map(|r| r.needless_deviations).sum::<usize>(),
            m(quantile(&clear, 0.0)),
            m(quantile(&clear, 0.05)),
            m(quantile(&clear, 0.5)),
            m(ttc),
            m(pet),
            m(quantile(&laps, 0.5)),
            m(laps.last().copied()),
        );
    }
    s += &pilot_calls(records);
    if get("sampler") == "falsify" {
        s += &generations(meta, records);
    }
    let _ = writeln!(s, "\n## Failing variants\n");
    if failed.is_empty() {
        s += "None.\n";
        return s;
    }
    s += "| index | setting | end | contacts | obstacle clearance (m) | what failed | drawn | scenario |\n|---|---|---|---|---|---|---|---|\n";
    for r in failed.iter().take(MAX_ROWS) {
        let drawn: Vec<String> = r.sampled.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | `{}` |",
            r.index,
            r.setting,
            r.end,
            r.contacts,
            m(r.obstacle_clearance_m),
            r.failures.join("; ").replace('|', "/"),
            drawn.join(" ").replace('|', "/"),
            r.failure_file.as_deref().unwrap_or("-")
        );
    }
    if failed.len() > MAX_ROWS {
        let _ = writeln!(
            s,
            "\n... and {} more in `results.jsonl` (`failed: true`).",
            failed.len() - MAX_ROWS
        );
    }
    s
}

/// The falsifier's generations: runs, failures and the lowest score of each.
fn generations(meta: &serde_json::Value, records: &[RunRecord]) -> String {
    let batch = meta
        .get("batch")
        .and_then(|b| b.as_u64())
        .unwrap_or(1)
        .max(1);
    let mut by_gen: BTreeMap<u64, (usize, usize, f64)> = BTreeMap::new();
    for r in records {
        let e = by_gen
            .entry(r.sample / batch)
            .or_insert((0, 0, f64::INFINITY));
        e.0 += 1;
        e.1 += usize::from(r.failed);
        e.2 = e.2.min(r.score);
    }
    let mut s = format!(
        "\n## Search ({batch} samples a generation)\n\n| generation | runs | failures | lowest score |\n|---|---|---|---|\n"
    );
    for (g, (n, f, low)) in by_gen {
        let _ = writeln!(s, "| {g} | {n} | {f} | {low:.2} |");
    }
    s
}

/// Writes `dir/summary.md` from `records`.
pub fn write(dir: &Path, records: &[RunRecord]) -> Result<()> {
    let meta: serde_json::Value = std::fs::read_to_string(dir.join("campaign.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or_default();
    let name = meta
        .get("name")
        .and_then(|n| n.as_str())
        .unwrap_or("campaign");
    chart(dir, name, records)?;
    mapper::write_atomically(&dir.join("summary.md"), render(&meta, records).as_bytes())?;
    Ok(())
}

/// Writes `dir/clearance.svg`: each run's smallest clearance to a run-time obstacle against its
/// index, failures in red - where a search converges, and how far the passing runs keep off.
pub fn chart(dir: &Path, title: &str, records: &[RunRecord]) -> Result<()> {
    use plotters::prelude::*;
    crate::chart::register_font();
    let path = dir.join("clearance.svg");
    let tmp = dir.join(".clearance.svg.partial");
    let top = records
        .iter()
        .filter_map(|r| r.obstacle_clearance_m)
        .fold(0.5_f64, f64::max)
        .min(5.0);
    let draw = || -> std::result::Result<(), Box<dyn std::error::Error>> {
        let root = SVGBackend::new(&tmp, (900, 420)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..records.len().max(1) as f64, 0.0..top * 1.05)?;
        chart
            .configure_mesh()
            .x_desc("run (index)")
            .y_desc("smallest clearance to an obstacle, m")
            .draw()?;
        for (failed, colour, label) in [(false, BLUE, "passed"), (true, RED, "failed")] {
            chart
                .draw_series(records.iter().filter(|r| r.failed == failed).map(|r| {
                    let y = r.obstacle_clearance_m.unwrap_or(top).clamp(0.0, top);
                    Circle::new((r.index as f64, y), 2, colour.filled())
                }))?
                .label(label)
                .legend(move |(x, y)| Circle::new((x, y), 3, colour.filled()));
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE)
            .draw()?;
        root.present()?;
        Ok(())
    };
    draw().map_err(|e| crate::Error::Invalid(format!("{}: drawing: {e}", path.display())))?;
    std::fs::rename(&tmp, &path).map_err(|source| crate::Error::Io {
        what: "moving the chart into place",
        path,
        source,
    })
}

/// The pilot calls by cause (the rule that called / what held the vehicle), with the needless
/// ones: those where ground truth had no object near what held it.
fn pilot_calls(records: &[RunRecord]) -> String {
    // Per cause: calls, needless ones, and the objects nearest what held the vehicle (their
    // ids without a trailing variant number: `careful_van`, `person`).
    let mut by_cause: BTreeMap<&str, (usize, usize, BTreeMap<String, usize>)> = BTreeMap::new();
    for r in records {
        if let Some(cause) = &r.pilot_call {
            let e = by_cause.entry(cause.as_str()).or_default();
            e.0 += 1;
            e.1 += usize::from(r.needless_pilot_call);
            if let Some((id, _)) = &r.pilot_call_object
                && !r.needless_pilot_call
            {
                let kind = id.trim_end_matches(|c: char| c.is_ascii_digit() || c == '_');
                *e.2.entry(kind.to_string()).or_default() += 1;
            }
        }
    }
    let calls: usize = by_cause.values().map(|c| c.0).sum();
    let needless: usize = by_cause.values().map(|c| c.1).sum();
    let mut s = format!(
        "\n## Pilot calls\n\n{calls} of {} runs ended with a pilot call, {needless} of them needless (no object within {} m of what held the vehicle in the last {} s, nor - waiting for a mover believed at its body - one that struck it standing against it, or - one lost at its body - any mover within {} m of its parts).\n",
        records.len(),
        crate::engine::REAL_WITHIN_M,
        crate::engine::NEEDLESS_WINDOW_S,
        crate::engine::AT_BODY_WITHIN_M
    );
    if calls > 0 {
        s += "\n| call / what held it | calls | needless | what was there (ground truth) |\n|---|---|---|---|\n";
        for (cause, (n, k, there)) in by_cause {
            let there: Vec<String> = there.iter().map(|(id, c)| format!("{id} {c}")).collect();
            let _ = writeln!(s, "| {cause} | {n} | {k} | {} |", there.join(", "));
        }
    }
    s + &needless_calls(records)
}

/// The runs whose pilot call was needless: what held the vehicle, the object nearest it, and
/// the scenario file to run alone (the first [`MAX_ROWS`]).
fn needless_calls(records: &[RunRecord]) -> String {
    let needless: Vec<&RunRecord> = records.iter().filter(|r| r.needless_pilot_call).collect();
    if needless.is_empty() {
        return String::new();
    }
    let mut s = "\nThe needless calls, to read one by one:\n\n| index | call / what held it | nearest object (ground truth) | scenario |\n|---|---|---|---|\n".to_string();
    for r in needless.iter().take(MAX_ROWS) {
        let nearest = r
            .pilot_call_object
            .as_ref()
            .map_or("-".to_string(), |(id, d)| format!("{id} {d:.2} m"));
        let _ = writeln!(
            s,
            "| {} | {} | {nearest} | `{}` |",
            r.index,
            r.pilot_call.as_deref().unwrap_or("-"),
            r.needless_file.as_deref().unwrap_or("-")
        );
    }
    if needless.len() > MAX_ROWS {
        let _ = writeln!(
            s,
            "\n... and {} more in `results.jsonl` (`needless_pilot_call: true`).",
            needless.len() - MAX_ROWS
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The per-setting row counts contacts at fault, struck, and of those struck while moving.
    #[test]
    fn the_setting_row_counts_contacts_struck_while_moving() {
        let record = |at_fault: usize, struck: usize, moving: usize| -> RunRecord {
            serde_json::from_value(serde_json::json!({
                "index": 0, "sample": 0, "setting": 0, "seed": 3, "sampled": {},
                "parameters": {}, "u": [], "end": "struck", "expectations_met": at_fault == 0,
                "failed": at_fault > 0, "failures": [], "contacts": at_fault + struck,
                "contacts_with": ["van"], "contacts_at_fault": at_fault,
                "contacts_struck": struck, "contacts_struck_while_moving": moving,
                "min_ttc_s": null, "min_pet_s": null, "obstacles": [], "min_clearance_m": [0.0],
                "obstacle_clearance_m": 0.0, "static_clearance_m": 1.0, "stops": 1,
                "deviations": 0, "false_stops": 0, "needless_deviations": 0, "lap_times_s": [],
                "sim_time_s": 40.0, "wall_time_s": 4.0, "score": 0.0, "failure_file": null,
            }))
            .expect("a record")
        };
        let meta = serde_json::json!({"name": "t", "sampler": "random", "total": 2});
        let text = render(&meta, &[record(1, 0, 0), record(0, 2, 1)]);
        assert!(text.contains("| 1 / 2 (1) |"), "{text}");
    }
}
