//! Merging the output directories of a campaign's shards (`taxi-sim campaign merge`) into one
//! directory equal to the single-machine run: the records by index, the failure files, the
//! summary and its chart; and which variants no shard recorded.

use std::path::{Path, PathBuf};

use super::record::{RunRecord, read_results};
use crate::error::{Error, Result};

/// What a merge found.
#[derive(Debug)]
pub struct Merged {
    /// Every record, by index.
    pub records: Vec<RunRecord>,
    /// Variants asked for (the largest `total` of the shards).
    pub total: u64,
    /// Indices below `total` no shard recorded.
    pub missing: Vec<u64>,
}

fn meta_of(dir: &Path) -> Result<serde_json::Value> {
    let path = dir.join("campaign.json");
    let text = std::fs::read_to_string(&path).map_err(|source| Error::Io {
        what: "reading a shard's campaign.json (is it a campaign directory?)",
        path: path.clone(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|e| Error::BadFile {
        path,
        message: format!("not a campaign.json: {e}"),
    })
}

/// `3, 7-9, 12`: indices as ranges.
pub fn ranges(indices: &[u64]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let mut j = i;
        while j + 1 < indices.len() && indices[j + 1] == indices[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            indices[i].to_string()
        } else {
            format!("{}-{}", indices[i], indices[j])
        });
        i = j + 1;
    }
    out.join(", ")
}

/// Merges the shard directories `dirs` into `out` (created; it must not hold another campaign's
/// results). Every shard must belong to the same campaign (its digest) and split it the same
/// number of ways. Two shards holding the same variant must agree on it (wall time aside).
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Merged> {
    let first = dirs
        .first()
        .ok_or_else(|| Error::Invalid("campaign merge: no shard directories given".into()))?;
    let meta = meta_of(first)?;
    let count_of = |m: &serde_json::Value| {
        m.get("shard")
            .and_then(|s| s.as_str())
            .and_then(|s| s.split_once('/'))
            .map(|(_, n)| n.to_string())
    };
    let mut total = 0u64;
    let mut by_index: std::collections::BTreeMap<u64, (RunRecord, &Path)> = Default::default();
    for dir in dirs {
        let m = meta_of(dir)?;
        if m.get("digest") != meta.get("digest") || count_of(&m) != count_of(&meta) {
            return Err(Error::BadFile {
                path: dir.join("campaign.json"),
                message: format!(
                    "not a shard of the same campaign as {} (digest {} split {} ways, here {} split {} ways)",
                    first.display(),
                    meta.get("digest").unwrap_or(&serde_json::Value::Null),
                    count_of(&meta).unwrap_or("1".into()),
                    m.get("digest").unwrap_or(&serde_json::Value::Null),
                    count_of(&m).unwrap_or("1".into()),
                ),
            });
        }
        total = total.max(m.get("total").and_then(|t| t.as_u64()).unwrap_or(0));
        for r in read_results(dir)? {
            match by_index.get(&r.index) {
                Some((old, from)) if !same_run(old, &r) => {
                    return Err(Error::Invalid(format!(
                        "variant {} differs between {} and {}: were they run with different versions of taxi-sim?",
                        r.index,
                        from.display(),
                        dir.display()
                    )));
                }
                Some(_) => {}
                None => {
                    by_index.insert(r.index, (r, dir.as_path()));
                }
            }
        }
    }
    std::fs::create_dir_all(out.join("failures")).map_err(|source| Error::Io {
        what: "creating the merged directory",
        path: out.to_path_buf(),
        source,
    })?;
    let mut merged_meta = meta.clone();
    if let Some(m) = merged_meta.as_object_mut() {
        m.remove("shard");
        m.insert("total".into(), total.into());
        m.insert(
            "merged_from".into(),
            dirs.iter().map(|d| d.display().to_string()).collect(),
        );
    }
    let path = out.join("campaign.json");
    if let Ok(theirs) = meta_of(out)
        && theirs.get("digest") != meta.get("digest")
    {
        return Err(Error::BadFile {
            path,
            message: "this directory holds another campaign's results; give another --out".into(),
        });
    }
    mapper::write_atomically(
        &path,
        serde_json::to_string_pretty(&merged_meta)?.as_bytes(),
    )?;
    for (r, from) in by_index.values() {
        for f in (r.failure_file.iter())
            .chain(&r.needless_file)
            .chain(&r.called_file)
        {
            let text = std::fs::read(from.join(f)).map_err(|source| Error::Io {
                what: "reading a shard's scenario file (a failure's, or a pilot call's)",
                path: from.join(f),
                source,
            })?;
            mapper::write_atomically(&out.join(f), &text)?;
        }
    }
    let records: Vec<RunRecord> = by_index.into_values().map(|(r, _)| r).collect();
    let text: String = records
        .iter()
        .map(|r| serde_json::to_string(r).map(|l| l + "\n"))
        .collect::<std::result::Result<_, _>>()?;
    mapper::write_atomically(&out.join("results.jsonl"), text.as_bytes())?;
    super::summary::write(out, &records)?;
    let have: std::collections::HashSet<u64> = records.iter().map(|r| r.index).collect();
    let missing = (0..total).filter(|i| !have.contains(i)).collect();
    Ok(Merged {
        records,
        total,
        missing,
    })
}

/// Two records of one variant agree on everything but the wall time.
fn same_run(a: &RunRecord, b: &RunRecord) -> bool {
    a.timeless() == b.timeless()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_print_as_ranges() {
        assert_eq!(ranges(&[]), "");
        assert_eq!(ranges(&[3]), "3");
        assert_eq!(ranges(&[3, 7, 8, 9, 12]), "3, 7-9, 12");
    }

    /// A run's record as a campaign writes it: a pilot called for a hidden obstacle, needless
    /// (nothing there by ground truth) or needed.
    fn record(index: u64, needless: bool) -> RunRecord {
        let mut r: RunRecord = serde_json::from_value(serde_json::json!({
            "index": index, "sample": index, "setting": 0, "seed": 3, "sampled": {},
            "parameters": {}, "u": [], "end": "waiting_for_hidden_obstacle",
            "expectations_met": true, "failed": false, "failures": [], "contacts": 0,
            "contacts_with": [], "min_ttc_s": null, "min_pet_s": null, "obstacles": [],
            "min_clearance_m": [0.5], "obstacle_clearance_m": 0.5, "static_clearance_m": 1.0,
            "stops": 1, "deviations": 0, "false_stops": 0, "needless_deviations": 0,
            "lap_times_s": [], "sim_time_s": 73.1, "wall_time_s": 5.8, "score": 0.5,
            "failure_file": null,
            "pilot_call": "hidden_obstacle/mover_lost_at_body",
            "pilot_call_object": ["fuel_truck_2", 12.16],
        }))
        .expect("a record");
        r.needless_pilot_call = needless;
        r.needless_file = needless.then(|| format!("needless/{index}.toml"));
        r
    }

    /// Two shards, one with a needless pilot call: the merged directory holds its scenario
    /// file as written and the summary lists it, and only it, among the needless calls.
    #[test]
    fn a_merge_keeps_each_needless_calls_scenario_and_lists_it() {
        let root = std::env::temp_dir().join(format!("taxi-sim-merge-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let shard = |i: u64, needless: bool| {
            let dir = root.join(format!("shard{i}"));
            std::fs::create_dir_all(dir.join("needless")).unwrap();
            let meta = format!(r#"{{"digest": "d1", "total": 2, "shard": "{i}/2"}}"#);
            std::fs::write(dir.join("campaign.json"), meta).unwrap();
            let line = serde_json::to_string(&record(i, needless)).unwrap() + "\n";
            std::fs::write(dir.join("results.jsonl"), line).unwrap();
            if needless {
                std::fs::write(dir.join(format!("needless/{i}.toml")), "# variant 1\n").unwrap();
            }
            dir
        };
        let (a, b) = (shard(0, false), shard(1, true));
        let out = root.join("merged");
        let merged = merge(&[a, b], &out).expect("merged");
        assert_eq!(merged.records.len(), 2);
        let kept = std::fs::read_to_string(out.join("needless/1.toml")).expect("copied");
        assert_eq!(kept, "# variant 1\n");
        assert!(!out.join("needless/0.toml").exists());
        let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
        let rows: Vec<&str> = summary
            .lines()
            .filter(|l| l.contains("needless/"))
            .collect();
        assert_eq!(
            rows,
            [
                "| 1 | hidden_obstacle/mover_lost_at_body | fuel_truck_2 12.16 m | `needless/1.toml` |"
            ]
        );
        let _ = std::fs::remove_dir_all(&root);
    }
}
