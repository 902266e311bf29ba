//! The font of every label: DejaVu Sans, cut down to Latin, Greek and a few signs (see
//! assets/fonts), compiled in, so that pictures are made the same on a cluster node without fonts
//! as on a desktop (plotters' own `ttf` feature would need the system's font libraries). plotters
//! measures text with it (registered here); `text` draws it.

use std::sync::Once;

use plotters::style::FontStyle;

/// The font family name the pictures ask plotters for.
pub const FAMILY: &str = "sans-serif";

pub(crate) const DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

/// Registers the font with plotters, once per process; every drawing function calls it first.
pub fn register() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are compiled in and checked by a test: they cannot fail to parse.
        if plotters::style::register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_err() {
            unreachable!("the embedded font is a valid TrueType file");
        }
    });
}

#[cfg(test)]
mod tests {
    use plotters::style::{register_font, FontStyle};

    #[test]
    fn the_embedded_font_parses() {
        assert!(register_font("font-test", FontStyle::Normal, super::DEJAVU_SANS).is_ok());
        super::register();
    }
}
