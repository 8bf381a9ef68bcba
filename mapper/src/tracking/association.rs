//! Association: each cluster of a revolution matched with the track it continues.

use super::Tracker;
use super::clustering::Cluster;

impl Tracker {
    /// Each cluster's track (index into `tracks`), nearest pairs first, one to one, within what
    /// the fastest object could have covered since the track was last seen plus a metre.
    pub(super) fn associate(&self, t_s: f64, clusters: &[Cluster]) -> Vec<Option<usize>> {
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (ci, c) in clusters.iter().enumerate() {
            for (ti, t) in self.tracks.iter().enumerate() {
                let dt = (t_s - t.last_t_s).max(0.0);
                let gate = self.config.max_speed_m_s * dt + 1.0;
                // A track in steady motion is looked for where its velocity puts it.
                let expected = if t.steady >= 2 {
                    t.last + t.motion.velocity() * dt
                } else {
                    t.last
                };
                let d = (c.center - expected).norm();
                if d <= gate {
                    pairs.push((d, ci, ti));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut cluster_track = vec![None; clusters.len()];
        let mut track_taken = vec![false; self.tracks.len()];
        for (_, ci, ti) in pairs {
            if cluster_track[ci].is_none() && !track_taken[ti] {
                cluster_track[ci] = Some(ti);
                track_taken[ti] = true;
            }
        }
        cluster_track
    }
}
