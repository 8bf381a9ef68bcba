//! The maps around the vehicle, `maps_hz` times a second: each level's merged occupancy (a
//! `GridMap` at the level's height, from `MultiHeightMap::ros_occupancy_around`) and its obstacle
//! distance map (a `DepthImage`).

use mapper::MultiHeightMap;
use nalgebra::Point2;
use rerun::components::Colormap;
use rerun::datatypes::{ChannelDatatype, ColorModel};

use super::{Replay, Result};

/// The cells of a grid within a square around a point.
struct Crop {
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
    /// The grid's width (row stride).
    stride: usize,
}

impl Crop {
    /// The crop of `half_m` around `center`, clamped to the grid; `None` when nothing is left.
    fn around(g: &mapper::GridGeometry, center: Point2<f64>, half_m: f64) -> Option<Crop> {
        let res = g.resolution_m();
        let half = (half_m / res).round() as i64;
        let (cx, cy) = g.cell_coords(&center);
        let x0 = (cx - half).clamp(0, g.width() as i64) as usize;
        let x1 = (cx + half).clamp(0, g.width() as i64) as usize;
        let y0 = (cy - half).clamp(0, g.height() as i64) as usize;
        let y1 = (cy + half).clamp(0, g.height() as i64) as usize;
        (x1 > x0 && y1 > y0).then(|| Crop {
            x0,
            y0,
            w: x1 - x0,
            h: y1 - y0,
            stride: g.width(),
        })
    }

    /// Row `y` of the crop in `data` (a grid of this geometry).
    fn row<'a, T>(&self, data: &'a [T], y: usize) -> &'a [T] {
        let start = y * self.stride + self.x0;
        &data[start..start + self.w]
    }
}

impl Replay {
    /// Each level's merged occupancy and distance map within `map_half_m` of `center`.
    pub(super) fn log_maps(&mut self, map: &MultiHeightMap, center: Point2<f64>) -> Result<()> {
        let half_m = self.options.map_half_m;
        for k in 0..map.levels().count() {
            // ROS OccupancyGrid values: 0..100 = probability in percent, 255 (-1) = unknown;
            // row 0 at the lowest y, like the grid.
            if let Some(crop) = map.ros_occupancy_around(k, &center, half_m) {
                let occupancy: Vec<u8> = crop.cells.iter().map(|&v| v as u8).collect();
                let z = self
                    .level_heights_m
                    .get(k)
                    .copied()
                    .unwrap_or(0.0)
                    .max(0.01);
                self.rec.log(
                    format!("world/maps/level_{k}/occupancy"),
                    &rerun::GridMap::new(
                        occupancy,
                        rerun::components::ImageFormat::from_color_model(
                            [crop.width as u32, crop.height as u32],
                            ColorModel::L,
                            ChannelDatatype::U8,
                        ),
                        crop.resolution_m as f32,
                    )
                    .with_translation([crop.corner.x as f32, crop.corner.y as f32, z as f32])
                    .with_colormap(Colormap::RvizMap)
                    .with_opacity(0.55),
                )?;
            }
            // The distance map (its own, smaller geometry) as an image, north up, 0.1 m a unit.
            if let Some(odm) = map.distance_maps().level(k)
                && let Some(crop) = Crop::around(odm.grid().geometry(), center, half_m)
            {
                let mut pixels = Vec::with_capacity(crop.w * crop.h);
                for y in (crop.y0..crop.y0 + crop.h).rev() {
                    pixels.extend(
                        crop.row(odm.grid().data(), y)
                            .iter()
                            .map(|v| (v * 10.0).round().clamp(0.0, 255.0) as u8),
                    );
                }
                self.rec.log(
                    format!("maps/level_{k}/distance"),
                    &rerun::DepthImage::new(
                        pixels,
                        rerun::components::ImageFormat::depth(
                            [crop.w as u32, crop.h as u32],
                            ChannelDatatype::U8,
                        ),
                    )
                    .with_meter(10.0)
                    .with_colormap(Colormap::Turbo)
                    // In the image's own units (0.1 m): the colours span 0-8 m, where the
                    // circles' radii plus the safety distance live; farther is all red.
                    .with_depth_range([0.0, 80.0]),
                )?;
            }
        }
        self.summary.maps_logged += 1;
        Ok(())
    }
}
