//! The charts' font: the bundled DejaVu Sans (`sim/assets/fonts`) registered as plotters'
//! `sans-serif`, so a machine without fonts draws the same pictures (tuning, campaign summaries).

use std::sync::Once;

use plotters::style::FontStyle;

static FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Registers the bundled font as plotters' `sans-serif` (once): every chart of the crate calls
/// this before drawing text.
pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        // The bundled file is a valid font (a test draws with it): nothing to report here.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}
