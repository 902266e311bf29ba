//! A small software rasteriser: a colour buffer and a z-buffer, with spheres traced per pixel,
//! flat-shaded polygons (opaque, or blended over what lies behind them) and thick lines.
//!
//! Spheres are not meshed: under an orthographic camera a sphere covers a disc, and at a pixel at
//! distance d from the disc's centre the sphere's front surface lies sqrt(r² − d²) in front of
//! its centre, with the normal known from the same numbers. So each sphere costs a few
//! operations per pixel it covers, and 65,000 spheres take well under a second.

use glam::DVec3;

use super::colormap::Rgb;

/// Lambert shading with an ambient term and a small highlight, in view coordinates (x right,
/// y up, z towards the viewer).
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    /// Unit vector towards the light.
    pub light: DVec3,
    pub ambient: f64,
    pub specular: f64,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            // From the upper left, over the viewer's shoulder.
            light: DVec3::new(-0.45, 0.6, 0.66).normalize(),
            ambient: 0.35,
            specular: 0.25,
        }
    }
}

impl Shading {
    /// The colour of a surface of `colour` whose unit normal (view coordinates) is `normal`;
    /// a normal facing away from the viewer is turned round (walls are seen from both sides).
    pub fn shade(&self, colour: Rgb, normal: DVec3) -> Rgb {
        let n = if normal.z < 0.0 { -normal } else { normal };
        let diffuse = n.dot(self.light).max(0.0);
        let half = (self.light + DVec3::Z).normalize();
        let highlight = self.specular * n.dot(half).max(0.0).powi(40);
        let k = (self.ambient + (1.0 - self.ambient) * diffuse) as f32;
        colour.map(|c| (c * k + highlight as f32).min(1.0))
    }
}

/// Colour and depth buffers of one picture.
#[derive(Clone, Debug)]
pub struct Raster {
    width: usize,
    height: usize,
    colour: Vec<Rgb>,
    depth: Vec<f32>,
}

impl Raster {
    pub fn new(width: usize, height: usize, background: Rgb) -> Self {
        Self {
            width,
            height,
            colour: vec![background; width * height],
            depth: vec![f32::INFINITY; width * height],
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn pixel(&self, x: usize, y: usize) -> Rgb {
        self.colour[y * self.width + x]
    }

    /// The pixel columns and rows whose centres may lie within `[low, high]`, clipped to the
    /// picture; None when nothing is on it.
    fn span(&self, low: f64, high: f64, size: usize) -> Option<(usize, usize)> {
        if !(low.is_finite() && high.is_finite()) || high < 0.0 || low >= size as f64 {
            return None;
        }
        let first = (low - 0.5).ceil().max(0.0) as usize;
        let last = ((high - 0.5).floor().min(size as f64 - 1.0)) as usize;
        (first <= last && high - 0.5 >= 0.0).then_some((first, last))
    }

    /// A sphere whose centre projects to pixel `(c.x, c.y)` at depth `c.z` (metres), with radius
    /// `radius_px` on screen and `radius` in metres.
    pub fn sphere(
        &mut self,
        c: DVec3,
        radius_px: f64,
        radius: f64,
        colour: Rgb,
        shading: &Shading,
    ) {
        // Below a pixel a sphere would vanish between pixel centres: keep it one pixel large.
        let r = radius_px.max(0.6);
        let Some((x0, x1)) = self.span(c.x - r, c.x + r, self.width) else {
            return;
        };
        let Some((y0, y1)) = self.span(c.y - r, c.y + r, self.height) else {
            return;
        };
        let inv = 1.0 / r;
        for y in y0..=y1 {
            let dy = (y as f64 + 0.5 - c.y) * inv;
            for x in x0..=x1 {
                let dx = (x as f64 + 0.5 - c.x) * inv;
                let d2 = dx * dx + dy * dy;
                if d2 >= 1.0 {
                    continue;
                }
                let nz = (1.0 - d2).sqrt();
                let depth = (c.z - nz * radius) as f32;
                let i = y * self.width + x;
                if depth < self.depth[i] {
                    self.depth[i] = depth;
                    self.colour[i] = shading.shade(colour, DVec3::new(dx, -dy, nz));
                }
            }
        }
    }

    /// A convex polygon (screen x, y and depth per corner) in one colour, split into a fan of
    /// triangles. With `alpha`, it is blended over what is nearer than it and the depth is left
    /// as it was, so that what lies behind shows through; without, it is opaque.
    pub fn polygon(&mut self, corners: &[DVec3], colour: Rgb, alpha: Option<f32>) {
        for k in 1..corners.len().saturating_sub(1) {
            self.triangle(corners[0], corners[k], corners[k + 1], colour, alpha);
        }
    }

    fn triangle(&mut self, a: DVec3, b: DVec3, c: DVec3, colour: Rgb, alpha: Option<f32>) {
        let edge =
            |p: DVec3, q: DVec3, x: f64, y: f64| (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x);
        let area = edge(a, b, c.x, c.y);
        if !area.is_finite() || area.abs() < 1e-12 {
            return;
        }
        let (b, c) = if area < 0.0 { (c, b) } else { (b, c) };
        let area = area.abs();
        let Some((x0, x1)) = self.span(a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x), self.width)
        else {
            return;
        };
        let Some((y0, y1)) = self.span(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), self.height)
        else {
            return;
        };
        // A pixel centre exactly on an edge shared by two triangles belongs to one of them only
        // (the one that runs along the edge one way), so a blended wall made of triangles shows
        // no seams of double blending.
        let owns = |p: DVec3, q: DVec3| {
            let (dx, dy) = (q.x - p.x, q.y - p.y);
            dy > 0.0 || (dy == 0.0 && dx < 0.0)
        };
        let inside = |w: f64, owned: bool| w > 0.0 || (w == 0.0 && owned);
        let (own_a, own_b, own_c) = (owns(b, c), owns(c, a), owns(a, b));
        for y in y0..=y1 {
            let py = y as f64 + 0.5;
            for x in x0..=x1 {
                let px = x as f64 + 0.5;
                let wa = edge(b, c, px, py);
                let wb = edge(c, a, px, py);
                let wc = edge(a, b, px, py);
                if !(inside(wa, own_a) && inside(wb, own_b) && inside(wc, own_c)) {
                    continue;
                }
                let depth = ((wa * a.z + wb * b.z + wc * c.z) / area) as f32;
                let i = y * self.width + x;
                if depth >= self.depth[i] {
                    continue;
                }
                match alpha {
                    None => {
                        self.depth[i] = depth;
                        self.colour[i] = colour;
                    }
                    Some(alpha) => {
                        let old = self.colour[i];
                        self.colour[i] =
                            [0, 1, 2].map(|k| alpha * colour[k] + (1.0 - alpha) * old[k]);
                    }
                }
            }
        }
    }

    /// A line `width_px` wide from `a` to `b` (screen coordinates), drawn over everything: the
    /// force network is read through the particles.
    pub fn line(&mut self, a: DVec3, b: DVec3, width_px: f64, colour: Rgb) {
        let half = 0.5 * width_px.max(1.0);
        let Some((x0, x1)) = self.span(a.x.min(b.x) - half, a.x.max(b.x) + half, self.width) else {
            return;
        };
        let Some((y0, y1)) = self.span(a.y.min(b.y) - half, a.y.max(b.y) + half, self.height)
        else {
            return;
        };
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let length2 = (dx * dx + dy * dy).max(1e-12);
        for y in y0..=y1 {
            let py = y as f64 + 0.5;
            for x in x0..=x1 {
                let px = x as f64 + 0.5;
                let t = (((px - a.x) * dx + (py - a.y) * dy) / length2).clamp(0.0, 1.0);
                let (ex, ey) = (px - a.x - t * dx, py - a.y - t * dy);
                if ex * ex + ey * ey <= half * half {
                    self.colour[y * self.width + x] = colour;
                }
            }
        }
    }

    /// Darkens by `amount` every pixel that lies more than `step` metres in front of a neighbour
    /// (or in front of the background): an outline round each body, so that touching bodies of
    /// one colour stay apart. Faces of one body meet without a step and get no line.
    pub fn outline(&mut self, step: f32, amount: f32) {
        let (w, h) = (self.width, self.height);
        let mut edge = vec![false; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let d = self.depth[i];
                if !d.is_finite() {
                    continue;
                }
                let farther = |j: usize| self.depth[j] - d > step;
                edge[i] = (x > 0 && farther(i - 1))
                    || (x + 1 < w && farther(i + 1))
                    || (y > 0 && farther(i - w))
                    || (y + 1 < h && farther(i + w));
            }
        }
        for (c, _) in self.colour.iter_mut().zip(&edge).filter(|(_, &e)| e) {
            *c = c.map(|v| v * (1.0 - amount));
        }
    }

    /// Fades every pixel towards `colour` by `amount` (0: unchanged, 1: all `colour`).
    pub fn fade(&mut self, colour: Rgb, amount: f32) {
        for c in &mut self.colour {
            *c = [0, 1, 2].map(|k| amount * colour[k] + (1.0 - amount) * c[k]);
        }
    }

    /// 8-bit RGB bytes of the picture shrunk by `factor` in each direction, each output pixel the
    /// mean of a `factor` × `factor` block (supersampling smooths the edges).
    pub fn to_rgb8(&self, factor: usize) -> (usize, usize, Vec<u8>) {
        let factor = factor.max(1);
        let (w, h) = (self.width / factor, self.height / factor);
        let mut bytes = Vec::with_capacity(3 * w * h);
        let norm = 1.0 / (factor * factor) as f32;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 3];
                for sy in 0..factor {
                    for sx in 0..factor {
                        let c = self.pixel(x * factor + sx, y * factor + sy);
                        for k in 0..3 {
                            sum[k] += c[k];
                        }
                    }
                }
                bytes.extend(sum.map(|s| (s * norm * 255.0).round().clamp(0.0, 255.0) as u8));
            }
        }
        (w, h, bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: Rgb = [1.0, 1.0, 1.0];
    const RED: Rgb = [1.0, 0.0, 0.0];
    const BLUE: Rgb = [0.0, 0.0, 1.0];

    fn count(r: &Raster, colour: Rgb) -> usize {
        (0..r.height())
            .flat_map(|y| (0..r.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| r.pixel(x, y) == colour)
            .count()
    }

    #[test]
    fn a_sphere_covers_its_disc_and_is_lit_from_the_upper_left() {
        let mut r = Raster::new(40, 40, WHITE);
        r.sphere(
            DVec3::new(20.0, 20.0, 0.0),
            10.0,
            1.0,
            RED,
            &Shading::default(),
        );
        let covered = 40 * 40 - count(&r, WHITE);
        let disc = std::f64::consts::PI * 100.0;
        assert!((covered as f64 - disc).abs() < 0.05 * disc, "{covered}");
        let upper_left = r.pixel(15, 15)[0];
        let lower_right = r.pixel(25, 25)[0];
        assert!(upper_left > lower_right, "{upper_left} {lower_right}");
        assert_eq!(
            r.pixel(20, 20)[2],
            r.pixel(20, 20)[1],
            "only the highlight adds blue and green"
        );
    }

    #[test]
    fn the_nearer_sphere_hides_the_farther() {
        let mut r = Raster::new(40, 40, WHITE);
        let flat = Shading {
            ambient: 1.0,
            specular: 0.0,
            ..Shading::default()
        };
        r.sphere(DVec3::new(15.0, 20.0, 5.0), 10.0, 1.0, RED, &flat);
        r.sphere(DVec3::new(25.0, 20.0, 0.0), 10.0, 1.0, BLUE, &flat);
        assert_eq!(r.pixel(20, 20), BLUE);
        // Drawn in the other order, the same.
        let mut s = Raster::new(40, 40, WHITE);
        s.sphere(DVec3::new(25.0, 20.0, 0.0), 10.0, 1.0, BLUE, &flat);
        s.sphere(DVec3::new(15.0, 20.0, 5.0), 10.0, 1.0, RED, &flat);
        assert_eq!(s.pixel(20, 20), BLUE);
        assert_eq!(s.pixel(8, 20), RED);
    }

    #[test]
    fn a_square_of_two_triangles_is_covered_once() {
        let mut r = Raster::new(20, 20, [0.0; 3]);
        let square = [
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(18.0, 2.0, 0.0),
            DVec3::new(18.0, 18.0, 0.0),
            DVec3::new(2.0, 18.0, 0.0),
        ];
        r.polygon(&square, WHITE, Some(0.5));
        // Every covered pixel blended exactly once, the diagonal included.
        assert_eq!(count(&r, [0.5; 3]), 16 * 16);
        assert_eq!(count(&r, [0.0; 3]), 400 - 256);
    }

    #[test]
    fn a_blended_wall_in_front_tints_and_one_behind_does_not() {
        let mut r = Raster::new(20, 20, WHITE);
        r.polygon(
            &[
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(20.0, 0.0, 1.0),
                DVec3::new(0.0, 20.0, 1.0),
            ],
            RED,
            None,
        );
        let wall = |z| {
            [
                DVec3::new(0.0, 0.0, z),
                DVec3::new(10.0, 0.0, z),
                DVec3::new(0.0, 10.0, z),
            ]
        };
        r.polygon(&wall(2.0), BLUE, Some(0.5));
        assert_eq!(r.pixel(2, 2), RED);
        r.polygon(&wall(0.0), BLUE, Some(0.5));
        assert_eq!(r.pixel(2, 2), [0.5, 0.0, 0.5]);
    }

    #[test]
    fn outlines_follow_depth_steps_only() {
        let flat = Shading {
            ambient: 1.0,
            specular: 0.0,
            ..Shading::default()
        };
        let mut r = Raster::new(40, 20, WHITE);
        // Two touching spheres of one colour, the right one farther back.
        r.sphere(DVec3::new(10.0, 10.0, 0.0), 8.0, 8.0, RED, &flat);
        r.sphere(DVec3::new(26.0, 10.0, 20.0), 8.0, 8.0, RED, &flat);
        r.outline(2.0, 0.5);
        // The rim against the background and the left sphere's edge over the right one are
        // darkened; the middle of each sphere is not.
        assert_eq!(r.pixel(2, 10), [0.5, 0.0, 0.0]);
        assert_eq!(r.pixel(17, 10), [0.5, 0.0, 0.0]);
        assert_eq!(r.pixel(10, 10), RED);
        assert_eq!(r.pixel(26, 10), RED);
        assert_eq!(r.pixel(0, 0), WHITE);
    }

    #[test]
    fn supersampled_edges_are_averaged() {
        let mut r = Raster::new(4, 2, [0.0; 3]);
        r.line(
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(4.0, 0.5, 0.0),
            1.0,
            WHITE,
        );
        let (w, h, bytes) = r.to_rgb8(2);
        assert_eq!((w, h), (2, 1));
        assert_eq!(bytes, [128; 6]);
    }
}
