//! The camera: an orthographic view along one of a few fixed directions, fitted to the scene.
//!
//! Orthographic, because engineering pictures are read for sizes and positions (a particle at the
//! back is as large as one at the front), and because a sphere then projects to an exact circle,
//! which the rasteriser traces per pixel. The world's up is +z, as gravity points along −z in the
//! examples.

use std::str::FromStr;

use glam::{DVec2, DVec3};

/// Where the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum View {
    /// From the front, right and above (x to the right, y away from the viewer, z up).
    #[default]
    Iso,
    /// From −y: x to the right, z up.
    Front,
    /// From +z: x to the right, y up.
    Top,
    /// From +x: y to the right, z up.
    Side,
    /// From the direction `x,y,z` (a vector from the scene towards the viewer), z up.
    From(DVec3),
}

impl FromStr for View {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "iso" => Ok(View::Iso),
            "front" => Ok(View::Front),
            "top" => Ok(View::Top),
            "side" => Ok(View::Side),
            other => {
                let bad = || {
                    format!(
                        "unknown view '{other}': use iso, front, top, side, or a direction \
                         x,y,z towards the viewer (e.g. 1,-2,1)"
                    )
                };
                let parts: Vec<f64> = other
                    .split(',')
                    .map(|p| p.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad())?;
                match parts[..] {
                    [x, y, z] if DVec3::new(x, y, z).length() > 0.0 => {
                        Ok(View::From(DVec3::new(x, y, z).normalize()))
                    }
                    _ => Err(bad()),
                }
            }
        }
    }
}

impl View {
    /// The unit vector from the scene towards the viewer.
    fn towards_viewer(self) -> DVec3 {
        match self {
            // More from the front than from the side, so that long machines along x (conveyors,
            // drums) show their length.
            View::Iso => DVec3::new(0.55, -1.0, 0.65).normalize(),
            View::Front => DVec3::NEG_Y,
            View::Top => DVec3::Z,
            View::Side => DVec3::X,
            View::From(d) => d,
        }
    }
}

/// A rectangle of the picture, in pixels: where the scene is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub x: f64,
    pub y: f64,
    pub width: f64,
    pub height: f64,
}

/// Maps world points to pixels: x to the right, y down, and a depth in metres that grows away
/// from the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    right: DVec3,
    up: DVec3,
    towards_viewer: DVec3,
    /// The scene point (in right/up coordinates) at the viewport's centre.
    centre: DVec2,
    /// Pixels per metre.
    scale: f64,
    viewport: Viewport,
}

impl Camera {
    /// The camera of `view` that shows every sphere `(centre, radius)` inside `viewport`, with a
    /// small margin. Polygons are fitted by their vertices with radius 0.
    pub fn fit(
        view: View,
        spheres: impl Iterator<Item = (DVec3, f64)>,
        viewport: Viewport,
    ) -> Self {
        let towards_viewer = view.towards_viewer();
        let right = DVec3::Z.cross(towards_viewer);
        let right = if right.length_squared() > 1e-12 {
            right.normalize()
        } else {
            DVec3::X
        };
        let up = towards_viewer.cross(right);
        let mut low = DVec2::splat(f64::INFINITY);
        let mut high = DVec2::splat(f64::NEG_INFINITY);
        for (p, r) in spheres {
            if !p.is_finite() || !r.is_finite() {
                continue;
            }
            let q = DVec2::new(p.dot(right), p.dot(up));
            low = low.min(q - r);
            high = high.max(q + r);
        }
        if !low.is_finite() || !high.is_finite() {
            // Nothing to show: a unit square around the origin.
            low = DVec2::splat(-0.5);
            high = DVec2::splat(0.5);
        }
        let extent = (high - low).max(DVec2::splat(1e-12));
        let scale = 0.94 * (viewport.width / extent.x).min(viewport.height / extent.y);
        Self {
            right,
            up,
            towards_viewer,
            centre: 0.5 * (low + high),
            scale,
            viewport,
        }
    }

    /// Pixel x, pixel y (down) and depth in metres (larger is farther) of a world point.
    pub fn project(&self, p: DVec3) -> DVec3 {
        let v = &self.viewport;
        DVec3::new(
            v.x + 0.5 * v.width + (p.dot(self.right) - self.centre.x) * self.scale,
            v.y + 0.5 * v.height - (p.dot(self.up) - self.centre.y) * self.scale,
            -p.dot(self.towards_viewer),
        )
    }

    /// A world direction in view coordinates (right, up, towards the viewer).
    pub fn to_view(&self, d: DVec3) -> DVec3 {
        DVec3::new(
            d.dot(self.right),
            d.dot(self.up),
            d.dot(self.towards_viewer),
        )
    }

    /// Pixels per metre.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The same view with every pixel length multiplied by `factor` (for supersampling).
    pub fn scaled(&self, factor: f64) -> Self {
        let v = self.viewport;
        Self {
            scale: self.scale * factor,
            viewport: Viewport {
                x: v.x * factor,
                y: v.y * factor,
                width: v.width * factor,
                height: v.height * factor,
            },
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PORT: Viewport = Viewport {
        x: 0.0,
        y: 0.0,
        width: 200.0,
        height: 100.0,
    };

    #[test]
    fn front_view_puts_x_right_and_z_up_and_fits() {
        let points = [
            (DVec3::new(-1.0, 0.0, 0.0), 0.0),
            (DVec3::new(1.0, 0.0, 0.5), 0.0),
        ];
        let c = Camera::fit(View::Front, points.into_iter(), PORT);
        let a = c.project(points[0].0);
        let b = c.project(points[1].0);
        assert!(b.x > a.x && b.y < a.y, "{a} {b}");
        // Width 2 m fills 94 % of 200 px.
        assert!((b.x - a.x - 188.0).abs() < 1e-9);
        assert!(((a.x + b.x) / 2.0 - 100.0).abs() < 1e-9);
        // Farther along +y is deeper.
        assert!(c.project(DVec3::Y).z > c.project(DVec3::ZERO).z);
    }

    #[test]
    fn every_view_is_a_right_handed_orthonormal_frame() {
        let views = [
            View::Iso,
            View::Front,
            View::Top,
            View::Side,
            View::From(DVec3::NEG_Z),
        ];
        for view in views {
            let c = Camera::fit(view, std::iter::empty(), PORT);
            assert!((c.right.cross(c.up) - c.towards_viewer).length() < 1e-12);
            assert!((c.right.length() - 1.0).abs() < 1e-12);
        }
        let top = Camera::fit(View::Top, std::iter::empty(), PORT);
        assert_eq!(top.to_view(DVec3::X), DVec3::X);
        assert_eq!(top.to_view(DVec3::Y), DVec3::Y);
    }

    #[test]
    fn views_parse_and_unknown_ones_are_named() {
        assert_eq!("side".parse::<View>(), Ok(View::Side));
        assert!("diagonal".parse::<View>().unwrap_err().contains("diagonal"));
        assert_eq!("0, -2, 0".parse::<View>(), Ok(View::From(DVec3::NEG_Y)));
        assert!("0,0,0".parse::<View>().is_err());
        assert!("1,2".parse::<View>().is_err());
    }
}
