//! Filling a box region with spheres: on a lattice, or at seeded random non-overlapping places.

use super::format::{InletFace, InsertMethod, InsertSpec, RadiusDistribution};
use crate::math::{Aabb, DVec3};
use crate::narrow_phase::{is_behind_mesh, sphere_mesh};
use crate::rng::SplitMix64;
use crate::wall::MeshWall;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A sphere to be placed: centre and radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub centre: DVec3,
    pub radius: f64,
}

/// Why an insertion could not be done in full (the caller adds file and key), with the spheres
/// that could be placed: a scene refuses to start with fewer, a run in progress inserts those.
#[derive(Clone, Debug, PartialEq)]
pub struct InsertError {
    pub message: String,
    pub placed: Vec<Placed>,
}

/// A plane wall spheres must stay in front of: a point on it and its unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneObstacle {
    pub point: DVec3,
    pub normal: DVec3,
}

/// Random sequential addition tries this many places per sphere before giving up.
const ATTEMPTS_PER_SPHERE: usize = 2000;

/// For an insertion of a named shape: the radius of its bounding sphere (what must not overlap)
/// and its volume (what counts towards a volume fraction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSize {
    pub bounding_radius: f64,
    pub volume: f64,
}

/// Places the spheres one insertion asks for, avoiding the spheres in `existing`, the planes and
/// the mesh walls (where they are now).
/// For a shape, the spheres are its bounding spheres, so bodies never overlap whatever their
/// orientation. `repetition` varies the random stream for repeated insertions of the same spec.
pub fn insert(
    spec: &InsertSpec,
    shape: Option<ShapeSize>,
    existing: &[Placed],
    planes: &[PlaneObstacle],
    meshes: &[MeshWall],
    repetition: u64,
) -> Result<Vec<Placed>, InsertError> {
    let (min, max) = spec.bounds();
    let (min, max) = (DVec3::from(min), DVec3::from(max));
    let mut rng = SplitMix64::new(spec.seed.wrapping_add(repetition.wrapping_mul(0x9E37_79B9)));
    let count = spec.count_at(repetition);
    if count == Some(0) {
        return Ok(Vec::new()); // an inlet whose rate brings no body in this interval
    }
    let radii = draw_radii(spec, count, shape, spec.volume(), &mut rng);
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let mut obstacles = Obstacles::new(existing, planes, meshes, r_max);
    obstacles.region = Some(spec);
    let what = Noun::of(spec);
    match spec.method {
        InsertMethod::Lattice => lattice(min, max, &radii, &mut obstacles, &what),
        InsertMethod::Random => random(min, max, radii, &mut obstacles, &mut rng, &what),
    }
}

/// What an insertion places, as its messages name it: spheres, or bodies of a named shape (whose
/// bounding spheres are what is placed).
struct Noun {
    one: String,
    many: String,
    radius: &'static str,
}

impl Noun {
    fn of(spec: &InsertSpec) -> Self {
        match &spec.shape {
            Some(name) => Self {
                one: format!("'{name}' body"),
                many: format!("'{name}' bodies"),
                radius: "bounding radius",
            },
            None => Self {
                one: "sphere".into(),
                many: "spheres".into(),
                radius: "radius",
            },
        }
    }
}

/// What a new sphere must not overlap: spheres (hashed on a grid), planes and mesh walls.
struct Obstacles<'a> {
    cell: f64,
    grid: HashMap<(i64, i64, i64), Vec<Placed>>,
    planes: &'a [PlaneObstacle],
    meshes: &'a [MeshWall],
    /// The insertion, whose region (a cylinder) a body must lie in, beyond the box its centres
    /// are drawn from.
    region: Option<&'a InsertSpec>,
}

impl<'a> Obstacles<'a> {
    fn new(
        existing: &[Placed],
        planes: &'a [PlaneObstacle],
        meshes: &'a [MeshWall],
        r_max: f64,
    ) -> Self {
        let largest = existing.iter().map(|p| p.radius).fold(r_max, f64::max);
        let mut obstacles = Self {
            cell: 2.0 * largest.max(f64::MIN_POSITIVE),
            grid: HashMap::new(),
            planes,
            meshes,
            region: None,
        };
        for p in existing {
            obstacles.add(*p);
        }
        obstacles
    }

    fn key(&self, p: DVec3) -> (i64, i64, i64) {
        let c = (p / self.cell).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    }

    fn add(&mut self, p: Placed) {
        self.grid.entry(self.key(p.centre)).or_default().push(p);
    }

    fn is_free(&self, centre: DVec3, radius: f64) -> bool {
        if !self
            .region
            .is_none_or(|r| r.holds(centre.to_array(), radius))
        {
            return false;
        }
        let in_front = |w: &PlaneObstacle| (centre - w.point).dot(w.normal) >= radius;
        if !self.planes.iter().all(in_front) {
            return false;
        }
        let clear_of = |wall: &MeshWall| {
            let x = wall.pose().to_reference(centre);
            if !wall.bounds().overlaps(&Aabb::around_sphere(x, radius)) {
                return true;
            }
            sphere_mesh(x, radius, wall).is_empty() && !is_behind_mesh(x, wall)
        };
        if !self.meshes.iter().all(clear_of) {
            return false;
        }
        let (kx, ky, kz) = self.key(centre);
        (-1..=1).all(|dx| {
            (-1..=1).all(|dy| {
                (-1..=1).all(|dz| {
                    self.grid
                        .get(&(kx + dx, ky + dy, kz + dz))
                        .is_none_or(|cell| {
                            // Touching is allowed, to within the rounding of lattice coordinates.
                            cell.iter().all(|p| {
                                (p.centre - centre).length_squared()
                                    >= ((p.radius + radius) * (1.0 - 1e-9)).powi(2)
                            })
                        })
                })
            })
        })
    }
}

/// The face of an inlet read from a mesh file: its triangles (turned over with `flip`), outline,
/// area, centroid and unit normal (the side its triangles face). Refused, saying why, unless the
/// triangles lie in one plane and all face one way.
pub fn flat_face(
    mesh: &crate::io::mesh::ImportedMesh,
    flip: bool,
) -> Result<(InletFace, DVec3, DVec3), String> {
    let triangles: Vec<[DVec3; 3]> = mesh
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            let t = if flip { [a, c, b] } else { [a, b, c] };
            t.map(|i| mesh.vertices[i])
        })
        .collect();
    let cross = |[a, b, c]: [DVec3; 3]| (b - a).cross(c - a);
    let total: DVec3 = triangles.iter().map(|&t| cross(t)).sum();
    let area2: f64 = triangles.iter().map(|&t| cross(t).length()).sum();
    let Some(normal) = total
        .try_normalize()
        .filter(|_| total.length() > 0.5 * area2)
    else {
        return Err(
            "its triangles do not face one way (an inlet face is flat, all its \
                    triangles wound alike)"
                .into(),
        );
    };
    if let Some(k) = triangles.iter().position(|&t| cross(t).dot(normal) <= 0.0) {
        return Err(format!(
            "triangle {k} faces the other way from the rest: an inlet face is flat, all its \
             triangles wound alike"
        ));
    }
    let area = 0.5 * area2;
    let centre: DVec3 = triangles
        .iter()
        .map(|&t| (t[0] + t[1] + t[2]) / 3.0 * (0.5 * cross(t).length()))
        .sum::<DVec3>()
        / area;
    let size = mesh
        .vertices
        .iter()
        .fold(Aabb::new(centre, centre), |b, &v| b.union(&Aabb::new(v, v)))
        .extent()
        .length();
    if let Some((k, off)) = triangles
        .iter()
        .flatten()
        .map(|&v| (v - centre).dot(normal).abs())
        .enumerate()
        .find(|&(_, off)| off > 1e-6 * size)
    {
        return Err(format!(
            "it is not flat: corner {} of triangle {} lies {off:.3e} m off the plane of the \
             face; an inlet face is one flat patch",
            k % 3,
            k / 3
        ));
    }
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *edges.entry((p.min(q), p.max(q))).or_default() += 1;
        }
    }
    // In the hash map's order: only whether every edge is far enough counts.
    let outline: Vec<[DVec3; 2]> = edges
        .into_iter()
        .filter(|&(_, count)| count == 1)
        .map(|((p, q), _)| [mesh.vertices[p], mesh.vertices[q]])
        .collect();
    Ok((
        InletFace {
            triangles,
            outline,
            area,
        },
        centre,
        normal,
    ))
}

/// The smallest radius an insertion can produce.
pub fn smallest_radius(spec: &InsertSpec, shape: Option<ShapeSize>) -> f64 {
    if let Some(shape) = shape {
        return shape.bounding_radius;
    }
    match (spec.radius, spec.radius_distribution) {
        (Some(r), _) => r,
        (None, Some(RadiusDistribution::Uniform { min, .. }))
        | (None, Some(RadiusDistribution::Normal { min, .. })) => min,
        (None, None) => unreachable!("validated: a radius, distribution or shape is given"),
    }
}

/// Radii for the insertion: `count` of them, or as many as make up `volume_fraction` of the region.
fn draw_radii(
    spec: &InsertSpec,
    count: Option<usize>,
    shape: Option<ShapeSize>,
    region_volume: f64,
    rng: &mut SplitMix64,
) -> Vec<f64> {
    let mut draw = || -> f64 {
        if let Some(shape) = shape {
            return shape.bounding_radius;
        }
        match (spec.radius, spec.radius_distribution) {
            (Some(r), _) => r,
            (None, Some(RadiusDistribution::Uniform { min, max })) => rng.uniform(min, max),
            (
                None,
                Some(RadiusDistribution::Normal {
                    mean,
                    std_dev,
                    min,
                    max,
                }),
            ) => loop {
                let r = mean + std_dev * rng.normal();
                if (min..=max).contains(&r) {
                    break r;
                }
            },
            (None, None) => unreachable!("validated: a radius, distribution or shape is given"),
        }
    };
    let volume_of = |r: f64| match shape {
        Some(shape) => shape.volume,
        None => 4.0 / 3.0 * PI * r.powi(3),
    };
    match (count, spec.volume_fraction) {
        (Some(n), _) => (0..n).map(|_| draw()).collect(),
        (None, Some(fraction)) => {
            let target = fraction * region_volume;
            let mut radii = Vec::new();
            let mut volume = 0.0;
            while volume < target {
                let r = draw();
                volume += volume_of(r);
                radii.push(r);
            }
            radii
        }
        (None, None) => unreachable!("validated: count or volume_fraction is given"),
    }
}

/// Simple cubic lattice with spacing 2 r_max, filled x first, then y, then z (bottom up);
/// sites where a sphere would overlap an obstacle are skipped.
fn lattice(
    min: DVec3,
    max: DVec3,
    radii: &[f64],
    obstacles: &mut Obstacles,
    what: &Noun,
) -> Result<Vec<Placed>, InsertError> {
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let spacing = 2.0 * r_max;
    let fits = |lo: f64, hi: f64| -> usize {
        if hi - lo < spacing {
            0
        } else {
            ((hi - lo - spacing) / spacing + 1e-9).floor() as usize + 1
        }
    };
    let (nx, ny, nz) = (fits(min.x, max.x), fits(min.y, max.y), fits(min.z, max.z));
    let sites = nx * ny * nz;
    let mut placed = Vec::with_capacity(radii.len());
    for n in 0..sites {
        let Some(&r) = radii.get(placed.len()) else {
            break;
        };
        let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
        let centre = min + DVec3::splat(r_max) + DVec3::new(i as f64, j as f64, k as f64) * spacing;
        if obstacles.is_free(centre, r) {
            let p = Placed { centre, radius: r };
            obstacles.add(p);
            placed.push(p);
        }
    }
    if placed.len() < radii.len() {
        return Err(InsertError {
            message: format!(
                "the region holds {sites} lattice sites of spacing {spacing:.4e} m \
                 ({nx}×{ny}×{nz}), {} of them free of other bodies and walls, but {} {} \
                 were asked for: enlarge the region or ask for fewer",
                placed.len(),
                radii.len(),
                what.many
            ),
            placed,
        });
    }
    Ok(placed)
}

/// Random sequential addition: largest spheres first, each at the first random place that overlaps
/// nothing placed so far. Jams near 30–38 % volume fraction; beyond that use a lattice and let the
/// spheres settle.
fn random(
    min: DVec3,
    max: DVec3,
    mut radii: Vec<f64>,
    obstacles: &mut Obstacles,
    rng: &mut SplitMix64,
    what: &Noun,
) -> Result<Vec<Placed>, InsertError> {
    radii.sort_by(|a, b| b.total_cmp(a));
    let mut placed = Vec::with_capacity(radii.len());
    for &radius in &radii {
        let lo = min + DVec3::splat(radius);
        let hi = max - DVec3::splat(radius);
        if lo.cmpgt(hi).any() {
            return Err(InsertError {
                message: format!(
                    "a {} of {} {radius:.4e} m does not fit in the region",
                    what.one, what.radius
                ),
                placed,
            });
        }
        let found = (0..ATTEMPTS_PER_SPHERE)
            .map(|_| {
                DVec3::new(
                    rng.uniform(lo.x, hi.x),
                    rng.uniform(lo.y, hi.y),
                    rng.uniform(lo.z, hi.z),
                )
            })
            .find(|&c| obstacles.is_free(c, radius));
        let Some(centre) = found else {
            return Err(InsertError {
                message: format!(
                    "placed only {} of {} {} without overlap after {ATTEMPTS_PER_SPHERE} \
                     tries for the next one: random filling jams near 30% volume fraction (of \
                     the bounding spheres, for shapes); enlarge the region, ask for fewer, or \
                     use method = \"lattice\"",
                    placed.len(),
                    radii.len(),
                    what.many
                ),
                placed,
            });
        };
        let p = Placed { centre, radius };
        obstacles.add(p);
        placed.push(p);
    }
    // Neighbours in space become neighbours in memory (the bodies are numbered in this order):
    // placed at random, a large fill would have every contact reach two far-apart places in
    // the body arrays, and the run would wait on memory.
    let cell = obstacles.cell;
    let key = |p: &Placed| {
        let c = ((p.centre - min) / cell).floor();
        (c.z as i64, c.y as i64, c.x as i64)
    };
    placed.sort_by_key(key);
    Ok(placed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(method: InsertMethod) -> InsertSpec {
        InsertSpec {
            method,
            material: "m".into(),
            region_min: Some([0.0; 3]),
            region_max: Some([1.0; 3]),
            cylinder: None,
            inlet: None,
            count: Some(100),
            volume_fraction: None,
            radius: Some(0.05),
            radius_distribution: None,
            seed: 3,
            velocity: [0.0; 3],
            time: 0.0,
            every: None,
            until: None,
            shape: None,
            random_orientation: true,
        }
    }

    fn no_overlaps(p: &[Placed]) -> bool {
        p.iter().enumerate().all(|(i, a)| {
            p[i + 1..]
                .iter()
                .all(|b| (a.centre - b.centre).length() >= a.radius + b.radius - 1e-12)
        })
    }

    fn inside(p: &[Placed]) -> bool {
        p.iter().all(|s| {
            s.centre.cmpge(DVec3::splat(s.radius - 1e-12)).all()
                && s.centre.cmple(DVec3::splat(1.0 - s.radius + 1e-12)).all()
        })
    }

    #[test]
    fn lattice_and_random_fills_are_inside_and_do_not_overlap() {
        for method in [InsertMethod::Lattice, InsertMethod::Random] {
            let p = insert(&spec(method), None, &[], &[], &[], 0).unwrap();
            assert_eq!(p.len(), 100);
            assert!(no_overlaps(&p) && inside(&p), "{method:?}");
        }
    }

    #[test]
    fn random_fill_is_reproducible_and_seed_dependent() {
        let a = insert(&spec(InsertMethod::Random), None, &[], &[], &[], 0).unwrap();
        assert_eq!(
            a,
            insert(&spec(InsertMethod::Random), None, &[], &[], &[], 0).unwrap()
        );
        let mut other = spec(InsertMethod::Random);
        other.seed = 4;
        assert_ne!(a, insert(&other, None, &[], &[], &[], 0).unwrap());
    }

    #[test]
    fn volume_fraction_with_size_distribution() {
        let mut s = spec(InsertMethod::Random);
        s.count = None;
        s.volume_fraction = Some(0.2);
        s.radius = None;
        s.radius_distribution = Some(RadiusDistribution::Uniform {
            min: 0.03,
            max: 0.06,
        });
        let p = insert(&s, None, &[], &[], &[], 0).unwrap();
        let volume: f64 = p.iter().map(|s| 4.0 / 3.0 * PI * s.radius.powi(3)).sum();
        assert!((0.2..0.2 + 4.0 / 3.0 * PI * 0.06f64.powi(3) + 1e-12).contains(&volume));
        assert!(p.iter().all(|s| (0.03..=0.06).contains(&s.radius)));
        assert!(no_overlaps(&p) && inside(&p));
    }

    #[test]
    fn random_fill_avoids_existing_spheres() {
        let wall = Placed {
            centre: DVec3::splat(0.5),
            radius: 0.3,
        };
        let p = insert(&spec(InsertMethod::Random), None, &[wall], &[], &[], 0).unwrap();
        let mut all = p.clone();
        all.push(wall);
        assert!(no_overlaps(&all));
    }

    #[test]
    fn fills_stay_in_front_of_planes() {
        // A tilted plane cuts the region: no sphere may reach behind it.
        let plane = PlaneObstacle {
            point: DVec3::new(0.5, 0.5, 0.5),
            normal: DVec3::new(1.0, 1.0, 1.0).normalize(),
        };
        for method in [InsertMethod::Lattice, InsertMethod::Random] {
            let mut s = spec(method);
            s.count = Some(40);
            let p = insert(&s, None, &[], &[plane], &[], 0).unwrap();
            assert_eq!(p.len(), 40);
            assert!(p
                .iter()
                .all(|s| (s.centre - plane.point).dot(plane.normal) >= s.radius));
        }
    }

    #[test]
    fn fills_keep_clear_of_mesh_walls_where_they_are_now() {
        // A screw-like obstacle: a slab of the unit region's middle, moved by its pose.
        let slab = crate::wall::generators::box_mesh(
            DVec3::new(-0.1, -0.1, 0.4),
            DVec3::new(1.1, 1.1, 0.6),
            2,
            crate::wall::Facing::Outward,
        )
        .unwrap()
        .into_wall(0)
        .unwrap();
        let mut moved = slab.clone();
        moved.motion = crate::wall::WallMotion::fixed()
            .with_velocity(DVec3::new(0.0, 0.0, 0.2))
            .unwrap();
        moved.set_time(1.0);
        for (wall, (lo, hi)) in [(slab, (0.4, 0.6)), (moved, (0.6, 0.8))] {
            for method in [InsertMethod::Lattice, InsertMethod::Random] {
                let mut s = spec(method);
                s.count = Some(40);
                let walls = [wall.clone()];
                let p = insert(&s, None, &[], &[], &walls, 0).unwrap();
                assert_eq!(p.len(), 40);
                let clear = |s: &Placed| s.centre.z + s.radius <= lo || s.centre.z - s.radius >= hi;
                assert!(p.iter().all(clear), "{method:?} in slab [{lo}, {hi}]");
            }
        }
    }

    #[test]
    fn a_partial_fill_reports_what_fitted() {
        let mut s = spec(InsertMethod::Lattice);
        s.count = Some(1001);
        let e = insert(&s, None, &[], &[], &[], 0).unwrap_err();
        assert_eq!(e.placed.len(), 1000);
    }

    #[test]
    fn overfull_requests_are_refused_with_advice() {
        let mut s = spec(InsertMethod::Lattice);
        s.count = Some(1001);
        assert!(insert(&s, None, &[], &[], &[], 0)
            .unwrap_err()
            .message
            .contains("1000 lattice sites"));
        let mut s = spec(InsertMethod::Random);
        s.count = Some(2000);
        assert!(insert(&s, None, &[], &[], &[], 0)
            .unwrap_err()
            .message
            .contains("lattice"));
    }
}
