//! A campaign split across machines: a [`Shard`] runs the variants `i % count == index` into its
//! own directory, which `campaign.json` claims for one campaign and one shard.

use std::path::Path;

use super::Campaign;
use crate::error::{Error, Result};

/// One shard of a campaign split across machines: the variants `i` with `i % count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: u64,
    /// Shards in all.
    pub count: u64,
}

impl Shard {
    /// Parses `I/N` (0 <= I < N), or `auto/N`, which takes `I` from `SLURM_ARRAY_TASK_ID` (a
    /// Slurm array task) or `JOB_COMPLETION_INDEX` (a Kubernetes indexed Job) through `env`.
    pub fn parse(
        text: &str,
        env: &dyn Fn(&str) -> Option<String>,
    ) -> std::result::Result<Self, String> {
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| format!("--shard {text}: expected I/N or auto/N"))?;
        let count: u64 = n
            .trim()
            .parse()
            .ok()
            .filter(|n| *n >= 1)
            .ok_or_else(|| format!("--shard {text}: N must be a whole number >= 1"))?;
        let (i, from) = if i.trim() == "auto" {
            ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"]
                .iter()
                .find_map(|k| env(k).map(|v| (v, *k)))
                .ok_or_else(|| {
                    format!("--shard {text}: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set")
                })?
        } else {
            (i.trim().to_string(), "--shard")
        };
        let index: u64 = i
            .trim()
            .parse()
            .map_err(|_| format!("--shard {text}: {from} = {i:?} is not a whole number"))?;
        if index >= count {
            return Err(format!(
                "--shard {text}: {from} = {index} is not below N = {count} (shards are numbered from 0)"
            ));
        }
        Ok(Shard { index, count })
    }

    /// Whether variant `i` belongs to this shard.
    pub fn holds(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Checks (or writes) `DIR/campaign.json`: a directory holds the results of one campaign.
pub(super) fn claim(
    campaign: &Campaign,
    dir: &Path,
    shard: Option<Shard>,
    total: u64,
) -> Result<()> {
    let path = dir.join("campaign.json");
    let mut mine = serde_json::json!({
        "campaign": campaign.path.display().to_string(),
        "name": campaign.name,
        "digest": campaign.digest,
        "settings": campaign.settings.len(),
        "sampler": campaign.sampler.as_str(),
        "batch": campaign.falsify.batch,
        "seed": campaign.seed,
        "total": total,
    });
    if let Some(s) = shard {
        mine["shard"] = serde_json::Value::String(s.to_string());
    }
    if let Ok(text) = std::fs::read_to_string(&path) {
        let theirs: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        if theirs.get("shard") != mine.get("shard") {
            let show = |v: &serde_json::Value| {
                v.get("shard")
                    .and_then(|s| s.as_str())
                    .map_or("the whole campaign".to_string(), |s| format!("shard {s}"))
            };
            return Err(Error::BadFile {
                path,
                message: format!(
                    "this directory holds {} of this campaign, not {}; give another --out",
                    show(&theirs),
                    show(&mine)
                ),
            });
        }
        if theirs.get("digest") != mine.get("digest") {
            return Err(Error::BadFile {
                path,
                message: format!(
                    "this directory holds the results of another campaign (or of an earlier version of this one: {} vs {}); give another --out or delete the directory",
                    theirs.get("digest").and_then(|d| d.as_str()).unwrap_or("?"),
                    campaign.digest
                ),
            });
        }
        return Ok(());
    }
    mapper::write_atomically(&path, serde_json::to_string_pretty(&mine)?.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::Shard;

    #[test]
    fn a_shard_is_parsed_from_the_flag_or_the_scheduler_and_checked() {
        let none = |_: &str| None;
        assert_eq!(Shard::parse("2/4", &none), Ok(Shard { index: 2, count: 4 }));
        let slurm = |k: &str| (k == "SLURM_ARRAY_TASK_ID").then(|| "3".to_string());
        assert_eq!(
            Shard::parse("auto/4", &slurm),
            Ok(Shard { index: 3, count: 4 })
        );
        let k8s = |k: &str| (k == "JOB_COMPLETION_INDEX").then(|| "0".to_string());
        assert_eq!(
            Shard::parse("auto/2", &k8s),
            Ok(Shard { index: 0, count: 2 })
        );
        for (text, env, says) in [
            (
                "4/4",
                &none as &dyn Fn(&str) -> Option<String>,
                "not below N = 4",
            ),
            ("1/0", &none, "N must be"),
            ("x/3", &none, "not a whole number"),
            ("auto/3", &none, "neither SLURM_ARRAY_TASK_ID"),
            (
                "auto/3",
                &slurm,
                "SLURM_ARRAY_TASK_ID = 3 is not below N = 3",
            ),
            ("3", &none, "expected I/N"),
        ] {
            let e = Shard::parse(text, env).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
        let s = Shard { index: 1, count: 3 };
        let held: Vec<u64> = (0..10).filter(|i| s.holds(*i)).collect();
        assert_eq!(held, vec![1, 4, 7]);
    }
}
