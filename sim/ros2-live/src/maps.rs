//! The offline map per level as a stack's map server would serve it: the mapping drive's ROS map
//! files (`levelK.yaml` and its image, trinary) read as `map_server` reads them and sent once as
//! `nav_msgs/OccupancyGrid` (0 free, 100 occupied, -1 unknown) in `map` on `/map/level_K`,
//! transient local.

use std::path::{Path, PathBuf};

use mapper::Grid;
use mapper::export::Trinary;

/// A level's map bigger than this many cells is not sent (a message of as many bytes: 16 MiB),
/// and the simulator says so; the aerodrome's 3.5 x 0.9 km at 0.2 m would be 79 million.
pub const MAX_CELLS: usize = 16 << 20;

/// The map server files of each level in `map_dir`, level 0 first, up to the first missing.
pub fn level_files(map_dir: &Path) -> Vec<PathBuf> {
    (0..)
        .map(|k| map_dir.join(format!("level{k}.yaml")))
        .take_while(|p| p.exists())
        .collect()
}

/// The grid as `nav_msgs/OccupancyGrid` in `map`, stamped `stamp`: CDR as the bags hold it.
pub fn occupancy_message(grid: &Grid<Trinary>, stamp: ros2::msgs::Time) -> Vec<u8> {
    let g = grid.geometry();
    let data: Vec<i8> = grid
        .data()
        .iter()
        .map(|t| match t {
            Trinary::Free => 0,
            Trinary::Occupied => 100,
            Trinary::Unknown => -1,
        })
        .collect();
    let origin = ros2::msgs::Pose::planar(g.origin_m().x, g.origin_m().y, 0.0, 0.0);
    ros2::msgs::occupancy_grid(
        stamp,
        "map",
        g.resolution_m() as f32,
        (g.width() as u32, g.height() as u32),
        &origin,
        &data,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use mapper::GridGeometry;
    use nalgebra::Point2;

    #[test]
    fn a_trinary_map_is_an_occupancy_grid_from_its_origin_row() {
        let g = GridGeometry::new(Point2::new(-2.0, 4.0), 0.5, 3, 2).unwrap();
        let cells = vec![
            Trinary::Free,
            Trinary::Occupied,
            Trinary::Unknown,
            Trinary::Unknown,
            Trinary::Free,
            Trinary::Occupied,
        ];
        let grid = Grid::from_vec(g, cells).unwrap();
        let stamp = ros2::msgs::Time::from_ns(1_704_067_200_000_000_000);
        let m = occupancy_message(&grid, stamp);
        let origin = ros2::msgs::Pose::planar(-2.0, 4.0, 0.0, 0.0);
        let expected = ros2::msgs::occupancy_grid(
            stamp,
            "map",
            0.5,
            (3, 2),
            &origin,
            &[0, 100, -1, -1, 0, 100],
        );
        assert_eq!(m, expected);
    }

    #[test]
    fn the_levels_are_the_files_up_to_the_first_missing() {
        let dir = tempfile::tempdir().unwrap();
        for k in [0, 1, 3] {
            std::fs::write(dir.path().join(format!("level{k}.yaml")), "").unwrap();
        }
        let files = level_files(dir.path());
        assert_eq!(files.len(), 2);
        assert!(files[1].ends_with("level1.yaml"));
    }
}
