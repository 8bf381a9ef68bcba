//! Remission layer: per cell sum, sum of squares and count of LiDAR intensities.
//!
//! Sums merge by addition, so an offline layer and live data combine exactly. Mean and variance
//! are what a remission-based localizer (CARMEN `localize_ackerman`) compares scans against.
//!
//! On disk a cell is stored quantized ([`QuantizedRemission`]): its mean in steps of 1/255 and
//! its spread (standard deviation) in steps of 1/510 over the intensities' range 0..1, with its
//! exact count. A cell read back has its mean within 1/510 (0.002) and its spread within 1/1020
//! (0.001) of the cell written, 25 and 50 times below the localizer's default sigma floor
//! (0.05); the float sums it replaced were noise Zstandard could not shrink (97 % of a block).

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

/// Steps of the stored mean: 1/255 of the intensities' range 0..1.
pub const MEAN_STEP: f64 = 1.0 / 255.0;
/// Steps of the stored spread: 1/510 over 0..0.5, the largest spread of values in 0..1.
pub const SPREAD_STEP: f64 = 1.0 / 510.0;

/// A cell as a block file stores it: mean and spread quantized, the count exact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QuantizedRemission {
    /// Mean intensity in steps of [`MEAN_STEP`].
    pub mean: u8,
    /// Standard deviation in steps of [`SPREAD_STEP`].
    pub spread: u8,
    /// Number of samples.
    pub count: u32,
}

impl QuantizedRemission {
    /// The statistics this stands for: the sums of `count` samples with the stored mean and
    /// spread (within half a step of the cell quantized).
    pub fn cell(&self) -> RemissionCell {
        if self.count == 0 {
            return RemissionCell::default();
        }
        let k = f64::from(self.count);
        let mean = f64::from(self.mean) * MEAN_STEP;
        let spread = f64::from(self.spread) * SPREAD_STEP;
        RemissionCell {
            sum: (mean * k) as f32,
            sum_sq: (k * (spread * spread + mean * mean)) as f32,
            count: self.count,
        }
    }
}

impl RemissionCell {
    /// The cell quantized for a block file; an error (saying what is wrong) when it is not the
    /// statistics of intensities in 0..1: a non-finite or negative sum, a mean or spread out of
    /// range, sums without samples.
    pub fn quantized(&self) -> Result<QuantizedRemission, String> {
        if self.count == 0 {
            return if self.sum == 0.0 && self.sum_sq == 0.0 {
                Ok(QuantizedRemission::default())
            } else {
                Err(format!(
                    "0 samples but sum {} and sum of squares {} (a cell without samples has \
                     zero sums)",
                    self.sum, self.sum_sq
                ))
            };
        }
        let k = f64::from(self.count);
        let mean = f64::from(self.sum) / k;
        let variance = f64::from(self.sum_sq) / k - mean * mean;
        // Float sums of values in 0..1 land a rounding error outside; more is not intensities.
        const SLACK: f64 = 1e-3;
        if !variance.is_finite() {
            return Err(format!(
                "sum {} and sum of squares {} are not finite",
                self.sum, self.sum_sq
            ));
        }
        if !(-SLACK..=1.0 + SLACK).contains(&mean) {
            return Err(format!(
                "mean intensity {mean} of {} samples is outside 0..1 (intensities are \
                 calibrated remissions 0..1)",
                self.count
            ));
        }
        if variance < -SLACK {
            return Err(format!(
                "sum of squares {} of {} samples is below their sum's square over the count \
                 (not a sum of squares)",
                self.sum_sq, self.count
            ));
        }
        let spread = variance.max(0.0).sqrt();
        if spread > 0.5 + SLACK {
            return Err(format!(
                "spread {spread} of {} samples is more than intensities in 0..1 can have (0.5)",
                self.count
            ));
        }
        Ok(QuantizedRemission {
            mean: (mean / MEAN_STEP).round().clamp(0.0, 255.0) as u8,
            spread: (spread / SPREAD_STEP).round().clamp(0.0, 255.0) as u8,
            count: self.count,
        })
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

    /// Quantized and read back, a cell keeps its count and its mean and spread within half a
    /// step; quantizing what was read back gives the same bytes.
    #[test]
    fn quantized_cells_read_back_within_half_a_step() {
        let mut worst = (0.0f64, 0.0f64);
        for seed in 0..2000u32 {
            let mut c = RemissionCell::default();
            let n = 1 + seed % 37;
            for i in 0..n {
                let h = (seed.wrapping_mul(2654435761) ^ i.wrapping_mul(40503)) % 10007;
                c.add(h as f32 / 10006.0 * (seed % 5 + 1) as f32 / 5.0);
            }
            let q = c.quantized().unwrap();
            let back = q.cell();
            assert_eq!(back.count, c.count);
            let dm = (back.mean().unwrap() - c.mean().unwrap()).abs() as f64;
            let ds = (back.variance().unwrap().sqrt() - c.variance().unwrap().sqrt()).abs() as f64;
            worst = (worst.0.max(dm), worst.1.max(ds));
            assert_eq!(back.quantized().unwrap(), q, "cell {c:?}");
        }
        assert!(worst.0 <= MEAN_STEP / 2.0 + 1e-6, "mean off by {}", worst.0);
        assert!(
            worst.1 <= SPREAD_STEP / 2.0 + 1e-4,
            "spread off by {}",
            worst.1
        );
        assert!(
            worst.0 > MEAN_STEP / 4.0,
            "the test reaches the steps: {worst:?}"
        );
    }

    #[test]
    fn cells_that_are_not_intensities_are_refused() {
        let bad = |sum: f32, sum_sq: f32, count: u32| {
            RemissionCell { sum, sum_sq, count }
                .quantized()
                .unwrap_err()
        };
        assert!(bad(3.0, 9.0, 2).contains("outside 0..1"));
        assert!(bad(-1.0, 1.0, 2).contains("outside 0..1"));
        assert!(bad(f32::NAN, 1.0, 2).contains("not finite"));
        assert!(bad(1.0, f32::INFINITY, 2).contains("not finite"));
        assert!(bad(1.0, 2.0, 2).contains("spread"));
        assert!(bad(1.0, -1.0, 2).contains("not a sum of squares"));
        assert!(bad(0.5, 0.0, 0).contains("0 samples"));
        assert_eq!(
            RemissionCell::default().quantized(),
            Ok(QuantizedRemission::default())
        );
    }
}
