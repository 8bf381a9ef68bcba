//! The charts' font: the bundled DejaVu Sans (`sim/assets/fonts`) registered as plotters'
//! `sans-serif`, so a machine without fonts draws the same pictures (tuning, campaign summaries,
//! the representation comparison), and a picture drawn as SVG and PNG both.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::error::{Error, Result};

/// The charts' series colours, in order (matplotlib's first seven, told apart in print).
pub(crate) const PALETTE: [RGBColor; 7] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
];

/// What a drawing closure returns: plotters' error as text.
pub(crate) type DrawResult = std::result::Result<(), String>;

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

/// Draws `f` into `<dir>/<stem>.svg` and `<dir>/<stem>.png`, each written atomically.
pub(crate) fn both(
    dir: &Path,
    stem: &str,
    size: (u32, u32),
    svg: impl Fn(DrawingArea<SVGBackend<'_>, Shift>) -> DrawResult,
    png: impl Fn(DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> Result<()> {
    register_font();
    let located = |e: String, ext: &str| {
        Error::Invalid(format!(
            "{}: drawing: {e}",
            dir.join(format!("{stem}.{ext}")).display()
        ))
    };
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        svg(root).map_err(|e| located(e, "svg"))?;
    }
    mapper::write_atomically(&dir.join(format!("{stem}.svg")), text.as_bytes())?;
    let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        png(root).map_err(|e| located(e, "png"))?;
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &buf,
        size.0,
        size.1,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| located(e.to_string(), "png"))?;
    mapper::write_atomically(&dir.join(format!("{stem}.png")), &bytes)?;
    Ok(())
}
