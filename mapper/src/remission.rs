//! Remission layer: per cell sum, sum of squares and count of LiDAR intensities.
//!
//! Sums merge by addition, so an offline layer and live data combine exactly. Mean and variance
//! are what a remission-based localizer (CARMEN `localize_ackerman`) compares scans against.

/// Intensity statistics of one cell. `repr(C)` and plain data: a block file's remission section
/// (little-endian) is read straight into an array of these.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct RemissionCell {
    /// Sum of intensities.
    pub sum: f32,
    /// Sum of squared intensities.
    pub sum_sq: f32,
    /// Number of samples.
    pub count: u32,
}

impl RemissionCell {
    /// Adds one intensity sample.
    #[inline]
    pub fn add(&mut self, intensity: f32) {
        self.sum += intensity;
        self.sum_sq += intensity * intensity;
        self.count += 1;
    }
    /// Mean intensity, `None` without samples.
    pub fn mean(&self) -> Option<f32> {
        (self.count > 0).then(|| self.sum / self.count as f32)
    }
    /// Population variance of the intensity, `None` without samples.
    pub fn variance(&self) -> Option<f32> {
        let mean = self.mean()?;
        Some((self.sum_sq / self.count as f32 - mean * mean).max(0.0))
    }
    /// The statistics of both cells' samples together.
    pub fn merged(&self, other: &RemissionCell) -> RemissionCell {
        RemissionCell {
            sum: self.sum + other.sum,
            sum_sq: self.sum_sq + other.sum_sq,
            count: self.count + other.count,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_variance() {
        let mut c = RemissionCell::default();
        assert_eq!(c.mean(), None);
        for v in [0.2, 0.4, 0.6] {
            c.add(v);
        }
        assert!((c.mean().unwrap() - 0.4).abs() < 1e-6);
        assert!((c.variance().unwrap() - 0.08 / 3.0).abs() < 1e-6);
        let mut d = RemissionCell::default();
        d.add(1.0);
        assert_eq!(c.merged(&d).count, 4);
    }
}
