//! The scene file's insertions: `[[insert]]` (lattice or random fill of a box or cylinder, once
//! or repeatedly) and its inlets, a disc or rectangle from which bodies stream in.

use super::*;
use crate::math::DVec3;

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum InsertMethod {
    /// Simple cubic lattice filling the region.
    Lattice,
    /// Seeded random sequential addition without overlaps.
    Random,
}

#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct InsertSpec {
    pub method: InsertMethod,
    pub material: String,
    /// The box bodies are placed in (or give `cylinder`).
    pub region_min: Option<Vec3>,
    pub region_max: Option<Vec3>,
    /// A cylinder to place bodies in, instead of the box.
    pub cylinder: Option<CylinderRegion>,
    /// A face bodies stream in through, instead of a region (see [`InletSpec`]).
    pub inlet: Option<InletSpec>,
    pub count: Option<usize>,
    pub volume_fraction: Option<f64>,
    pub radius: Option<f64>,
    pub radius_distribution: Option<RadiusDistribution>,
    /// Insert bodies of a shape named in `[shape.NAME]` instead of spheres.
    pub shape: Option<String>,
    /// Give each inserted body a random orientation (uniform over rotations).
    #[serde(default = "yes")]
    pub random_orientation: bool,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub velocity: Vec3,
    /// Simulated time of the (first) insertion [s]; 0 = when the scene is built.
    #[serde(default)]
    pub time: f64,
    /// Repeat the insertion at this interval [s].
    pub every: Option<f64>,
    /// No repeats after this time [s]; default: the end of the run.
    pub until: Option<f64>,
}

/// A cylindrical insertion region: `length` along `axis`, centred on `centre`.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CylinderRegion {
    pub centre: Vec3,
    pub axis: Vec3,
    pub radius: f64,
    pub length: f64,
}

/// An inlet (`fix insert/stream` of LIGGGHTS): a flat face — a disc of `radius`, a rectangle of
/// `size`, or the triangles of a mesh `file` — through which bodies stream at `rate` per second,
/// leaving it along its `normal` at `speed`. Every `every` seconds the bodies of the next
/// `rate × every` are placed, without overlap, in the layer the stream sweeps in that time: the
/// face moved `speed × every` along its normal (a prism), in front of the face. The layer before
/// has moved on by then, so layers follow each other as one stream.
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InletSpec {
    /// Centre of the face [m] (a face from a file: its centroid, set when it is read).
    pub centre: Option<Vec3>,
    /// The side bodies leave the face to (need not be of unit length; a face from a file: the
    /// side its triangles face).
    pub normal: Option<Vec3>,
    /// A disc face of this radius [m].
    pub radius: Option<f64>,
    /// A rectangular face: its side lengths [m], the first along `side`.
    pub size: Option<[f64; 2]>,
    /// Direction of the rectangle's first side (its part in the face's plane); default: the
    /// coordinate axis least aligned with the normal, projected onto the face.
    pub side: Option<Vec3>,
    /// A flat face read from a mesh file (STL or OBJ, relative to the scene's folder).
    pub file: Option<String>,
    /// Turn the file's triangles over: bodies leave to the other side.
    #[serde(default)]
    pub flip: bool,
    /// Speed of the bodies along the normal [m/s].
    pub speed: f64,
    /// Bodies per second.
    pub rate: f64,
    /// The triangles of `file`, read when the scene is parsed.
    #[serde(skip)]
    pub face: Option<std::sync::Arc<InletFace>>,
}

/// A flat face read from a mesh file, in the scene's coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct InletFace {
    /// Wound counter-clockwise seen from the side bodies leave to.
    pub triangles: Vec<[DVec3; 3]>,
    /// The edges of one triangle only: the face's outline.
    pub outline: Vec<[DVec3; 2]>,
    pub area: f64,
}

impl InletFace {
    /// Whether a disc of `radius` about `q` (in the face's plane, normal `n`) lies on the face:
    /// `q` in a triangle and at least `radius` from the outline.
    fn holds(&self, q: DVec3, radius: f64, n: DVec3) -> bool {
        let inside = self.triangles.iter().any(|&[a, b, c]| {
            [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(p, r)| (r - p).cross(q - p).dot(n) >= 0.0)
        });
        inside
            && self.outline.iter().all(|&[a, b]| {
                let ab = b - a;
                let t =
                    ((q - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                (a + ab * t - q).length() >= radius
            })
    }
}

/// The frame of a face: its unit normal and two unit directions in its plane.
fn face_frame(normal: Vec3, side: Option<Vec3>) -> (DVec3, DVec3, DVec3) {
    let n = DVec3::from(normal).normalize_or(DVec3::Z);
    let project = |d: DVec3| (d - n * n.dot(d)).try_normalize();
    let axis = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .min_by(|a, b| n.dot(*a).abs().total_cmp(&n.dot(*b).abs()))
        .unwrap_or(DVec3::X);
    let u = side
        .and_then(|s| project(DVec3::from(s)))
        .or_else(|| project(axis))
        .unwrap_or(DVec3::X);
    (n, u, n.cross(u))
}

impl InletSpec {
    /// The face's unit normal and in-plane directions (first along `side`).
    pub fn frame(&self) -> (DVec3, DVec3, DVec3) {
        face_frame(self.normal.unwrap_or([0.0, 0.0, 1.0]), self.side)
    }

    fn centre_point(&self) -> DVec3 {
        DVec3::from(self.centre.unwrap_or([0.0; 3]))
    }

    /// Area of the face [m²].
    pub fn area(&self) -> f64 {
        match (self.radius, self.size, &self.face) {
            (Some(r), _, _) => std::f64::consts::PI * r * r,
            (None, Some([a, b]), _) => a * b,
            (None, None, Some(face)) => face.area,
            (None, None, None) => 0.0,
        }
    }

    /// Half extents of a disc or rectangle along its two in-plane directions.
    fn half_extents(&self) -> (f64, f64) {
        match (self.radius, self.size) {
            (Some(r), _) => (r, r),
            (None, Some([a, b])) => (0.5 * a, 0.5 * b),
            (None, None) => (0.0, 0.0),
        }
    }

    /// Whether a sphere at `centre` lies wholly in the layer of thickness `depth` in front of
    /// the face.
    pub fn holds(&self, centre: DVec3, radius: f64, depth: f64) -> bool {
        let (n, u, v) = self.frame();
        let d = centre - self.centre_point();
        let along = d.dot(n);
        // A body may touch the layer's bounds to within rounding (lattice sites lie on them).
        let radius = radius * (1.0 - 1e-9);
        if along < radius || along > depth - radius {
            return false;
        }
        match (self.radius, self.size, &self.face) {
            (Some(r), _, _) => (d - n * along).length() <= r - radius,
            (None, Some([a, b]), _) => {
                d.dot(u).abs() <= 0.5 * a - radius && d.dot(v).abs() <= 0.5 * b - radius
            }
            (None, None, Some(face)) => face.holds(centre - n * along, radius, n),
            (None, None, None) => false,
        }
    }

    /// Points inside the layer of thickness `depth`: its middle and points half-way out on the
    /// face (a face from a file: the middles of its first triangles).
    pub fn probe_points(&self, depth: f64) -> Vec<Vec3> {
        let (n, u, v) = self.frame();
        let lift = n * (0.5 * depth);
        if let Some(face) = &self.face {
            return std::iter::once(self.centre_point())
                .chain(
                    face.triangles
                        .iter()
                        .take(8)
                        .map(|&[a, b, c]| (a + b + c) / 3.0),
                )
                .map(|p| (p + lift).to_array())
                .collect();
        }
        let (a, b) = self.half_extents();
        let middle = self.centre_point() + lift;
        [
            (0.0, 0.0),
            (0.5, 0.5),
            (-0.5, 0.5),
            (0.5, -0.5),
            (-0.5, -0.5),
        ]
        .into_iter()
        .map(|(x, y)| (middle + u * (x * a * 0.7) + v * (y * b * 0.7)).to_array())
        .collect()
    }

    /// The box around the layer of thickness `depth`.
    fn bounds(&self, depth: f64) -> (Vec3, Vec3) {
        let (n, u, v) = self.frame();
        let corners: Vec<DVec3> = match &self.face {
            Some(face) => face.triangles.iter().flatten().copied().collect(),
            None => {
                // A disc's box: the square around it, a safe superset.
                let (a, b) = self.half_extents();
                let c = self.centre_point();
                [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
                    .into_iter()
                    .map(|(x, y)| c + u * (x * a) + v * (y * b))
                    .collect()
            }
        };
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in corners {
            for q in [p, p + n * depth] {
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo.to_array(), hi.to_array())
    }
}

impl InsertSpec {
    /// Thickness [m] of the layer an inlet fills at each insertion: `speed × every`.
    pub fn inlet_depth(&self) -> f64 {
        match &self.inlet {
            Some(i) => i.speed * self.every.unwrap_or(0.0),
            None => 0.0,
        }
    }

    /// The velocity bodies are inserted with: `velocity`, or an inlet's speed along its normal.
    pub fn initial_velocity(&self) -> Vec3 {
        match &self.inlet {
            Some(i) => (i.frame().0 * i.speed).to_array(),
            None => self.velocity,
        }
    }

    /// How many bodies the insertion's `repetition`-th time places when it gives a count (an
    /// inlet: those of its rate due in that interval, so that the mean rate is exact); `None`
    /// for a volume fraction.
    pub fn count_at(&self, repetition: u64) -> Option<usize> {
        match &self.inlet {
            Some(i) => {
                let per = i.rate * self.every.unwrap_or(0.0);
                let due = |k: u64| (per * k as f64 + 1e-9).floor();
                Some((due(repetition + 1) - due(repetition)).max(0.0) as usize)
            }
            None => self.count,
        }
    }

    /// The box bodies are placed in: the one given, or the cylinder's bounding box. (Checked
    /// before use: one of the two is given, and the cylinder's axis is not zero.)
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if let Some(inlet) = &self.inlet {
            return inlet.bounds(self.inlet_depth());
        }
        match (self.region_min, self.region_max, self.cylinder) {
            (Some(lo), Some(hi), _) => (lo, hi),
            (_, _, Some(c)) => {
                let a = unit(c.axis);
                let (mut lo, mut hi) = (c.centre, c.centre);
                for k in 0..3 {
                    let half = 0.5 * c.length * a[k].abs()
                        + c.radius * (1.0 - a[k] * a[k]).max(0.0).sqrt();
                    lo[k] -= half;
                    hi[k] += half;
                }
                (lo, hi)
            }
            _ => ([0.0; 3], [0.0; 3]),
        }
    }

    /// Volume of the region [m³].
    pub fn volume(&self) -> f64 {
        if let Some(inlet) = &self.inlet {
            return inlet.area() * self.inlet_depth();
        }
        match self.cylinder {
            Some(c) => std::f64::consts::PI * c.radius * c.radius * c.length,
            None => {
                let (lo, hi) = self.bounds();
                (0..3).map(|k| hi[k] - lo[k]).product()
            }
        }
    }

    /// Whether a sphere of `radius` at `centre` lies wholly inside the region (a box region is
    /// handled by where centres are drawn).
    pub fn holds(&self, centre: Vec3, radius: f64) -> bool {
        if let Some(inlet) = &self.inlet {
            return inlet.holds(DVec3::from(centre), radius, self.inlet_depth());
        }
        let Some(c) = self.cylinder else {
            return true;
        };
        let a = unit(c.axis);
        let d: Vec<f64> = (0..3).map(|k| centre[k] - c.centre[k]).collect();
        let along: f64 = (0..3).map(|k| d[k] * a[k]).sum();
        let across2: f64 = (0..3).map(|k| d[k] * d[k]).sum::<f64>() - along * along;
        along.abs() <= 0.5 * c.length - radius && across2.max(0.0).sqrt() <= c.radius - radius
    }
}

fn unit(v: Vec3) -> Vec3 {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [0.0, 0.0, 1.0]
    }
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum RadiusDistribution {
    /// Radii uniform in [min, max].
    Uniform { min: f64, max: f64 },
    /// Normal with the given mean and standard deviation, truncated to [min, max].
    Normal {
        mean: f64,
        std_dev: f64,
        min: f64,
        max: f64,
    },
}
