//! A square of cells in ROS `OccupancyGrid` values ([`RosOccupancy`]), as the map's merged
//! occupancy ([`crate::map::MultiHeightMap::ros_occupancy_around`]) and a distance map
//! ([`crate::odm::DistanceMap::ros_distance_around`]) are shown. A leaf: it names no other module
//! of the crate, so both `map` and `odm` can name it without naming each other.

use nalgebra::Point2;

/// A square of a level's merged occupancy in ROS `OccupancyGrid` values
/// ([`MultiHeightMap::ros_occupancy_around`](crate::map::MultiHeightMap::ros_occupancy_around)).
#[derive(Clone, Debug, PartialEq)]
pub struct RosOccupancy {
    /// The lower-left corner of its first cell, metres.
    pub corner: Point2<f64>,
    /// Cells across.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Metres per cell.
    pub resolution_m: f64,
    /// Row-major from the lowest row: probability in percent, -1 unknown.
    pub cells: Vec<i8>,
}
