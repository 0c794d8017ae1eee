//! The one font figures use, embedded in the binary: plotters' `ab_glyph` text needs a registered
//! font, and a fresh machine (a cluster node, CI) may have no system fonts at all.
//! DejaVu Sans, Bitstream Vera license: `assets/fonts/LICENSE`.

use super::error::PlotError;
use plotters::style::FontStyle;
use std::sync::OnceLock;

static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The family name figures ask for; DejaVu Sans is registered under it.
pub const FAMILY: &str = "sans-serif";

/// Register DejaVu Sans as `sans-serif` (once per process; later calls are free).
pub fn register() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}
