//! Text for pictures and plots, drawn from the glyph outlines of the embedded font.
//!
//! plotters 0.3.7 draws ab_glyph text placing each glyph at the pen position without its left
//! bearing and on a per-glyph baseline, so "0.95" prints as "0. 95" and letters jump. This
//! wrapper around any plotters backend draws text itself (pen advance, kerning, bearings, one
//! baseline, the rotations plotters asks for) and forwards everything else.

use ab_glyph::{point, Font, FontRef, OutlinedGlyph, PxScale, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

use super::font::DEJAVU_SANS;

/// A plotters backend whose text is drawn by [`layout`].
pub struct TextBackend<B> {
    inner: B,
    font: FontRef<'static>,
}

impl<B> TextBackend<B> {
    pub fn new(inner: B) -> Self {
        Self {
            inner,
            font: embedded_font(),
        }
    }
}

fn embedded_font() -> FontRef<'static> {
    match FontRef::try_from_slice(DEJAVU_SANS) {
        Ok(font) => font,
        // The bytes are compiled in and parsed by a test.
        Err(_) => unreachable!("the embedded font is a valid TrueType file"),
    }
}

/// The glyphs of `text` at `size` pixels (the font's ascent minus descent), placed from the
/// top-left corner of its box, and the box's width and height.
pub fn layout(font: &FontRef<'static>, text: &str, size: f64) -> (Vec<OutlinedGlyph>, f32, f32) {
    let scale = PxScale::from(size as f32);
    let scaled = font.as_scaled(scale);
    let ascent = scaled.ascent();
    let mut pen = 0.0f32;
    let mut previous = None;
    let mut glyphs = Vec::new();
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            pen += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, point(pen, ascent));
        if let Some(outline) = font.outline_glyph(glyph) {
            glyphs.push(outline);
        }
        pen += scaled.h_advance(id);
        previous = Some(id);
    }
    (glyphs, pen, ascent - scaled.descent())
}

impl<B: DrawingBackend> DrawingBackend for TextBackend<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let colour = style.color();
        if colour.alpha == 0.0 {
            return Ok(());
        }
        let (glyphs, width, height) = layout(&self.font, text, style.size());
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0.0,
            HPos::Center => -0.5 * width,
            HPos::Right => -width,
        };
        let dy = match anchor.v_pos {
            VPos::Top => 0.0,
            VPos::Center => -0.5 * height,
            VPos::Bottom => -height,
        };
        let transform = style.transform();
        let (w, h) = self.get_size();
        let mut result = Ok(());
        for glyph in &glyphs {
            let bounds = glyph.px_bounds();
            glyph.draw(|x, y, coverage| {
                if result.is_err() || coverage <= 0.0 {
                    return;
                }
                let gx = (bounds.min.x + dx).round() as i32 + x as i32;
                let gy = (bounds.min.y + dy).round() as i32 + y as i32;
                let (rx, ry) = transform.transform(gx, gy);
                let (px, py) = (pos.0 + rx, pos.1 + ry);
                if px >= 0 && py >= 0 && (px as u32) < w && (py as u32) < h {
                    let c = BackendColor {
                        alpha: colour.alpha * f64::from(coverage.min(1.0)),
                        rgb: colour.rgb,
                    };
                    result = self.inner.draw_pixel((px, py), c);
                }
            });
        }
        result
    }

    fn estimate_text_size<TStyle: BackendTextStyle>(
        &self,
        text: &str,
        style: &TStyle,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        let (_, width, height) = layout(&self.font, text, style.size());
        Ok((width.ceil() as u32, height.ceil() as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_follow_one_another_without_gaps_or_overlaps() {
        let font = embedded_font();
        let (glyphs, width, height) = layout(&font, "0.95", 20.0);
        assert_eq!(glyphs.len(), 4);
        let bounds: Vec<_> = glyphs.iter().map(|g| g.px_bounds()).collect();
        for pair in bounds.windows(2) {
            let gap = pair[1].min.x - pair[0].max.x;
            assert!((-1.0..4.0).contains(&gap), "gap {gap}");
        }
        // One baseline: the digits' bottoms agree, the point sits on it.
        assert!((bounds[0].max.y - bounds[2].max.y).abs() <= 1.0);
        assert!((bounds[1].max.y - bounds[0].max.y).abs() <= 1.0);
        assert!(
            width > 30.0 && width < 50.0 && (height - 20.0).abs() < 4.0,
            "{width} {height}"
        );
    }
}
