//! The cell clearing: what a moving track seen on a smooth step has left is handed back.

use nalgebra::Point2;

use super::Tracker;
use crate::map::WorldCell;

impl Tracker {
    /// The cells moving tracks seen on a smooth step this revolution have left, taken from
    /// them and from the cell records; sorted.
    pub(super) fn clear_left_cells(&mut self, t_s: f64) -> Vec<WorldCell> {
        let r = self.resolution_m;
        let mut clear = Vec::new();
        for track in &mut self.tracks {
            if !(track.moving && track.smooth && track.bbox.is_some()) {
                continue;
            }
            // Every cell of the object lies within its extent of any point of it, the centre of
            // the hits seen now included, however much of it is hidden now.
            let reach = track.max_extent_m + self.config.clear_margin_m;
            let center = track.last;
            let cells = &mut self.cells;
            track.painted.retain(|c| {
                let Some(rec) = cells.get(c) else {
                    return false;
                };
                if rec.owner != track.id {
                    return false;
                }
                let at = Point2::new((c.0 as f64 + 0.5) * r, (c.1 as f64 + 0.5) * r);
                if (at - center).norm() <= reach || rec.last_hit_s == t_s {
                    return true;
                }
                clear.push(*c);
                cells.remove(c);
                false
            });
        }
        clear.sort_unstable();
        clear
    }
}
