//! Each laser's vertical angle: the sensors' built-in tables (HDL-32E and VLP-16 user
//! manuals), indexed by the channel's place in a block (its DSR number).

use crate::Product;

/// The HDL-32E's vertical angles by channel, degrees (manual, firing order; VeloView's
/// `HDL-32.xml` and the ROS driver's `32db.yaml` agree to 0.01 degree): the lower and the
/// upper bank interleaved.
const HDL32E_DEG: [f64; 32] = [
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00, -2.67,
    -22.67, -1.33, -21.33, 0.00, -20.00, 1.33, -18.67, 2.67, -17.33, 4.00, -16.00, 5.33, -14.67,
    6.67, -13.33, 8.00, -12.00, 9.33, -10.67, 10.67,
];

/// The VLP-16's vertical angles by channel, degrees (manual): two firing sequences of 16 per
/// block.
const VLP16_DEG: [f64; 16] = [
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0,
];

/// A sensor's lasers.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// Vertical angle of each laser, degrees, by channel number.
    pub vertical_deg: Vec<f64>,
}

impl Calibration {
    /// The built-in table of `product` (`None` for a packet that does not say).
    pub fn built_in(product: Product) -> Option<Calibration> {
        let table: &[f64] = match product {
            Product::Hdl32e => &HDL32E_DEG,
            Product::Vlp16 => &VLP16_DEG,
            Product::Unspecified => return None,
        };
        Some(Calibration {
            vertical_deg: table.to_vec(),
        })
    }

    /// The number of lasers.
    pub fn lasers(&self) -> usize {
        self.vertical_deg.len()
    }
}
