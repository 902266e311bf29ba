//! What is written over a rendered scene: the title (run, time, body count) and the colour bar
//! with its scale, drawn with plotters on the finished 8-bit picture so the text is sharp.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::colormap::{category, turbo, Rgb};
use super::font::{register, FAMILY};
use super::text::TextBackend;
use super::PictureError;

/// The colour bar: which field, over which range.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourBar {
    /// Name and unit, e.g. `speed [m/s]`.
    pub label: String,
    pub low: f64,
    pub high: f64,
    /// For a field of categories (material, shape): the values present with their labels, each
    /// shown as a swatch of its colour instead of the continuous scale.
    pub categories: Vec<(u32, String)>,
}

/// Pixels kept free for the title at the top and the colour bar at the right of a picture
/// `width` × `height`.
pub fn margins(width: usize, height: usize) -> (usize, usize) {
    let title = (height / 14).clamp(24, 60);
    let bar = (width / 9).clamp(90, 160);
    (title, bar)
}

fn font_size(height: usize) -> f64 {
    (height as f64 / 36.0).clamp(11.0, 28.0)
}

/// Draws `title` and `bar` over the RGB bytes of a `width` × `height` picture.
pub fn draw(
    rgb: &mut [u8],
    width: usize,
    height: usize,
    title: &str,
    bar: Option<&ColourBar>,
) -> Result<(), PictureError> {
    register();
    let draw_error = |e: &dyn std::fmt::Display| PictureError::Draw(e.to_string());
    let (title_height, bar_width) = margins(width, height);
    let size = font_size(height);
    let root = TextBackend::new(BitMapBackend::with_buffer(
        rgb,
        (width as u32, height as u32),
    ))
    .into_drawing_area();
    let text = |px: f64, pos: Pos| {
        TextStyle::from((FAMILY, px).into_font())
            .color(&BLACK)
            .pos(pos)
    };
    root.draw_text(
        title,
        &text(size * 1.1, Pos::new(HPos::Left, VPos::Center)),
        ((size * 0.6) as i32, (title_height / 2) as i32),
    )
    .map_err(|e| draw_error(&e))?;

    if let Some(bar) = bar {
        let x0 = (width - bar_width + (bar_width / 8)) as i32;
        let x1 = x0 + (bar_width / 6).max(12) as i32;
        let y0 = (title_height as f64 + 2.2 * size) as i32;
        let y1 = (height as f64 - 1.5 * size) as i32;
        root.draw_text(
            &bar.label,
            &text(size * 0.9, Pos::new(HPos::Right, VPos::Center)),
            (
                (width as f64 - 0.4 * size) as i32,
                (title_height as f64 + 0.9 * size) as i32,
            ),
        )
        .map_err(|e| draw_error(&e))?;
        if !bar.categories.is_empty() {
            let n = bar.categories.len() as f64;
            let step = (f64::from(y1 - y0) / n).min(2.0 * size);
            for (k, (c, label)) in bar.categories.iter().enumerate() {
                let top = y0 + (k as f64 * step) as i32;
                let bottom = top + (0.8 * step) as i32;
                let [r, g, b] = to_u8(category(*c as usize));
                root.draw(&Rectangle::new(
                    [(x0, top), (x1, bottom)],
                    RGBColor(r, g, b).filled(),
                ))
                .map_err(|e| draw_error(&e))?;
                root.draw_text(
                    label,
                    &text(size * 0.8, Pos::new(HPos::Left, VPos::Center)),
                    (x1 + 7, (top + bottom) / 2),
                )
                .map_err(|e| draw_error(&e))?;
            }
            return root.present().map_err(|e| draw_error(&e));
        }
        for y in y0..=y1 {
            let t = f64::from(y1 - y) / f64::from((y1 - y0).max(1));
            let [r, g, b] = to_u8(turbo(t));
            root.draw(&Rectangle::new(
                [(x0, y), (x1, y + 1)],
                RGBColor(r, g, b).filled(),
            ))
            .map_err(|e| draw_error(&e))?;
        }
        root.draw(&Rectangle::new(
            [(x0, y0), (x1, y1 + 1)],
            BLACK.stroke_width(1),
        ))
        .map_err(|e| draw_error(&e))?;
        // One value only (all particles alike): one tick, in the middle, where its colour is.
        let ticks: Vec<f64> = if bar.high > bar.low {
            (0..5).map(|k| f64::from(k) / 4.0).collect()
        } else {
            vec![0.5]
        };
        for t in ticks {
            let y = y1 - ((y1 - y0) as f64 * t).round() as i32;
            let value = bar.low + t * (bar.high - bar.low);
            root.draw(&PathElement::new([(x1, y), (x1 + 4, y)], BLACK))
                .map_err(|e| draw_error(&e))?;
            root.draw_text(
                &format_value(value),
                &text(size * 0.8, Pos::new(HPos::Left, VPos::Center)),
                (x1 + 7, y),
            )
            .map_err(|e| draw_error(&e))?;
        }
    }
    root.present().map_err(|e| draw_error(&e))
}

fn to_u8(c: Rgb) -> [u8; 3] {
    c.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8)
}

/// A number for a label: short, with an exponent only where plain digits would be long.
pub fn format_value(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_format_short() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(1.0), "1");
        assert_eq!(format_value(0.125), "0.125");
        assert_eq!(format_value(-12.3456), "-12.35");
        assert_eq!(format_value(2.5e-6), "2.50e-6");
        assert_eq!(format_value(123456.0), "1.23e5");
    }

    #[test]
    fn title_and_bar_leave_ink() {
        let (w, h) = (400, 300);
        let mut rgb = vec![255u8; 3 * w * h];
        let bar = ColourBar {
            label: "speed [m/s]".into(),
            low: 0.0,
            high: 2.0,
            categories: Vec::new(),
        };
        draw(&mut rgb, w, h, "test t = 1 s", Some(&bar)).unwrap();
        let (title, bar_width) = margins(w, h);
        let ink = |x0: usize, x1: usize, y0: usize, y1: usize| {
            (y0..y1)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .filter(|&(x, y)| rgb[3 * (y * w + x)] < 128)
                .count()
        };
        assert!(ink(0, w / 2, 0, title) > 50, "title text");
        assert!(ink(w - bar_width, w, title, h) > 100, "colour bar");
        assert_eq!(
            ink(0, w - bar_width, title + 5, h),
            0,
            "the scene area is left alone"
        );
    }
}
