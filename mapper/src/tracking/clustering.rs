//! One revolution's hits grouped into objects ([`Cluster`]).

use foldhash::HashMap;

use nalgebra::Point2;

use super::Tracker;
use crate::map::WorldCell;

/// A cluster of one revolution's hits.
pub(super) struct Cluster {
    /// Its cells.
    pub(super) cells: Vec<WorldCell>,
    /// The centre of its cells, metres.
    pub(super) center: Point2<f64>,
    /// Its bounding box (world cells, lower and upper corners).
    pub(super) bbox: (WorldCell, WorldCell),
    /// The levels it was hit in (bit `l`: level `l`).
    pub(super) levels: u32,
    /// The highest open top of its cells (`MultiHeightMap::last_scan_open_tops`): where the
    /// beam above each of its columns' top hits went (`None`: no cell told).
    pub(super) open_top_m: Option<f32>,
}

impl Tracker {
    /// Groups hits into objects: cells in buckets of the cluster gap, buckets joined to their
    /// eight neighbours.
    pub(super) fn clusters(&self, hits: &[(WorldCell, u32)]) -> Vec<Cluster> {
        let g = ((self.config.cluster_gap_m / self.resolution_m).ceil() as i64).max(1);
        let mut buckets: HashMap<(i64, i64), usize> = HashMap::default();
        let mut bucket_of = Vec::with_capacity(hits.len());
        for &((x, y), _) in hits {
            let key = (x.div_euclid(g), y.div_euclid(g));
            let n = buckets.len();
            bucket_of.push(*buckets.entry(key).or_insert(n));
        }
        let mut parent: Vec<usize> = (0..buckets.len()).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for (&(bx, by), &i) in &buckets {
            for (dx, dy) in [(1, -1), (1, 0), (1, 1), (0, 1)] {
                if let Some(&j) = buckets.get(&(bx + dx, by + dy)) {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    if a != b {
                        parent[a.max(b)] = a.min(b);
                    }
                }
            }
        }
        let mut index_of_root: HashMap<usize, usize> = HashMap::default();
        let mut clusters: Vec<Cluster> = Vec::new();
        let r = self.resolution_m;
        for (&(c, levels), &b) in hits.iter().zip(&bucket_of) {
            let root = find(&mut parent, b);
            let n = clusters.len();
            let k = *index_of_root.entry(root).or_insert(n);
            if k == n {
                clusters.push(Cluster {
                    cells: Vec::new(),
                    center: Point2::origin(),
                    bbox: (c, c),
                    levels: 0,
                    open_top_m: None,
                });
            }
            let cl = &mut clusters[k];
            cl.cells.push(c);
            cl.levels |= levels;
            cl.center.coords +=
                nalgebra::Vector2::new((c.0 as f64 + 0.5) * r, (c.1 as f64 + 0.5) * r);
            cl.bbox.0 = (cl.bbox.0.0.min(c.0), cl.bbox.0.1.min(c.1));
            cl.bbox.1 = (cl.bbox.1.0.max(c.0), cl.bbox.1.1.max(c.1));
        }
        for cl in &mut clusters {
            cl.center.coords /= cl.cells.len() as f64;
        }
        clusters
    }
}
