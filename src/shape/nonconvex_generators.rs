//! Built-in non-convex shapes: a 3-D cross ("jack"), a flat cross, an L-shape, a ring (hollow
//! cylinder), a star (a polyhedron with a pyramid on every face) and a screw. Each comes as a
//! closed outward mesh and (but the screw) as its exact decomposition into disjoint convex parts,
//! centred on the origin of the frame they are described in (the L-shape on its bounding box).
//!
//! The box-like shapes are unions of cells of a rectilinear grid, and their surface is made of the
//! grid faces between a filled and an empty cell (two triangles each): such a surface is closed,
//! welded and free of T-junctions by construction, as long as no two filled cells touch by an
//! edge alone (none of these shapes has such a pair).

use super::mesh_check::CheckOptions;
use super::nonconvex::{NonConvexError, NonConvexPolyhedron};
use super::{MassProperties, ShapeError};
use crate::math::DVec3;
use std::f64::consts::TAU;

/// A closed outward mesh and the convex parts (corner points) whose union it bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct NonConvexMesh {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[usize; 3]>,
    pub parts: Vec<Vec<DVec3>>,
}

impl NonConvexMesh {
    /// The particle, with its convex parts attached when `with_parts`.
    pub fn build(
        &self,
        with_parts: bool,
    ) -> Result<(NonConvexPolyhedron, MassProperties), NonConvexError> {
        let (shape, mass, _) = NonConvexPolyhedron::from_mesh(
            &self.vertices,
            &self.triangles,
            CheckOptions::default(),
        )?;
        let shape = if with_parts {
            shape.with_parts(&mass, &self.parts)?
        } else {
            shape
        };
        Ok((shape, mass))
    }
}

fn positive(name: &str, value: f64) -> Result<f64, ShapeError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ShapeError::InvalidParameter(format!(
            "{name} must be a positive finite number, got {value}"
        )))
    }
}

/// A 3-D cross ("jack"): three square bars of side `width` and length `length` along x, y and z,
/// crossing at their middles.
pub fn jack(length: f64, width: f64) -> Result<NonConvexMesh, ShapeError> {
    let (l, w) = (positive("length", length)?, positive("width", width)?);
    if w >= l {
        return Err(ShapeError::InvalidParameter(format!(
            "the width ({w}) must be smaller than the length ({l})"
        )));
    }
    let g = [-l / 2.0, -w / 2.0, w / 2.0, l / 2.0];
    let (vertices, triangles) = grid_union(&g, &g, &g, |i, j, k| {
        [i, j, k].iter().filter(|&&c| c == 1).count() >= 2
    });
    let c = |x: [f64; 2], y: [f64; 2], z: [f64; 2]| box_corners(x, y, z);
    let (h, m, e) = ([-w / 2.0, w / 2.0], l / 2.0, w / 2.0);
    let parts = vec![
        c([-m, m], h, h),
        c(h, [e, m], h),
        c(h, [-m, -e], h),
        c(h, h, [e, m]),
        c(h, h, [-m, -e]),
    ];
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts,
    })
}

/// A flat cross (a plus sign): two bars of `length` × `width` crossing at their middles in the xy
/// plane, `thickness` along z.
pub fn cross(length: f64, width: f64, thickness: f64) -> Result<NonConvexMesh, ShapeError> {
    let (l, w, t) = (
        positive("length", length)?,
        positive("width", width)?,
        positive("thickness", thickness)?,
    );
    if w >= l {
        return Err(ShapeError::InvalidParameter(format!(
            "the width ({w}) must be smaller than the length ({l})"
        )));
    }
    let g = [-l / 2.0, -w / 2.0, w / 2.0, l / 2.0];
    let z = [-t / 2.0, t / 2.0];
    let (vertices, triangles) = grid_union(&g, &g, &z, |i, j, _| i == 1 || j == 1);
    let (h, m, e) = ([-w / 2.0, w / 2.0], l / 2.0, w / 2.0);
    let zz = [-t / 2.0, t / 2.0];
    let parts = vec![
        box_corners([-m, m], h, zz),
        box_corners(h, [e, m], zz),
        box_corners(h, [-m, -e], zz),
    ];
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts,
    })
}

/// An L-shaped prism: in the xy plane an arm of `length_x` along x and one of `length_y` along y,
/// both `width` wide, meeting at a square corner (at −x, −y); `height` along z. Centred on its
/// bounding box.
pub fn l_shape(
    length_x: f64,
    length_y: f64,
    width: f64,
    height: f64,
) -> Result<NonConvexMesh, ShapeError> {
    let (a, b, w, h) = (
        positive("length_x", length_x)?,
        positive("length_y", length_y)?,
        positive("width", width)?,
        positive("height", height)?,
    );
    if w >= a || w >= b {
        return Err(ShapeError::InvalidParameter(format!(
            "the width ({w}) must be smaller than both lengths ({a}, {b})"
        )));
    }
    // Centred on its bounding box, as every built-in shape.
    let (x0, y0, z0) = (-a / 2.0, -b / 2.0, -h / 2.0);
    let (vertices, triangles) = grid_union(
        &[x0, x0 + w, x0 + a],
        &[y0, y0 + w, y0 + b],
        &[z0, z0 + h],
        |i, j, _| i == 0 || j == 0,
    );
    let parts = vec![
        box_corners([x0, x0 + a], [y0, y0 + w], [z0, z0 + h]),
        box_corners([x0, x0 + w], [y0 + w, y0 + b], [z0, z0 + h]),
    ];
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts,
    })
}

/// A ring (hollow cylinder) along z: `segments` flat facets around, radii measured to the corners
/// of the facets.
pub fn ring(
    outer_radius: f64,
    inner_radius: f64,
    height: f64,
    segments: usize,
) -> Result<NonConvexMesh, ShapeError> {
    let (ro, ri, h) = (
        positive("outer_radius", outer_radius)?,
        positive("inner_radius", inner_radius)?,
        positive("height", height)?,
    );
    if ri >= ro {
        return Err(ShapeError::InvalidParameter(format!(
            "the inner radius ({ri}) must be smaller than the outer radius ({ro})"
        )));
    }
    if segments < 3 {
        return Err(ShapeError::InvalidParameter(format!(
            "a ring needs at least 3 segments, got {segments}"
        )));
    }
    let n = segments;
    // Vertex 4k + {0: outer bottom, 1: outer top, 2: inner bottom, 3: inner top}.
    let mut vertices = Vec::with_capacity(4 * n);
    for k in 0..n {
        let (s, c) = (TAU * k as f64 / n as f64).sin_cos();
        for (r, z) in [(ro, -h / 2.0), (ro, h / 2.0), (ri, -h / 2.0), (ri, h / 2.0)] {
            vertices.push(DVec3::new(r * c, r * s, z));
        }
    }
    let mut triangles = Vec::with_capacity(8 * n);
    let mut parts = Vec::with_capacity(n);
    for k in 0..n {
        let (p, q) = (4 * k, 4 * ((k + 1) % n));
        let quads = [
            [p, q, q + 1, p + 1],         // outer wall, facing out
            [p + 2, p + 3, q + 3, q + 2], // inner wall, facing the axis
            [p + 1, q + 1, q + 3, p + 3], // top, +z
            [p, p + 2, q + 2, q],         // bottom, −z
        ];
        for [a, b, c, d] in quads {
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
        parts.push(
            (0..4)
                .flat_map(|j| [vertices[p + j], vertices[q + j]])
                .collect(),
        );
    }
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts,
    })
}

/// A star: a regular octahedron (`spikes` = 8) or icosahedron (20) of circumradius `radius` with
/// a pyramid of height `spike_length` on every face. The octahedron with spikes of height
/// radius/√3 · 2 is the stella octangula.
pub fn star(spikes: usize, radius: f64, spike_length: f64) -> Result<NonConvexMesh, ShapeError> {
    let (r, h) = (
        positive("radius", radius)?,
        positive("spike_length", spike_length)?,
    );
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let (base, faces): (Vec<DVec3>, Vec<[usize; 3]>) = match spikes {
        8 => (
            vec![
                DVec3::X,
                -DVec3::X,
                DVec3::Y,
                -DVec3::Y,
                DVec3::Z,
                -DVec3::Z,
            ],
            vec![
                [0, 2, 4],
                [2, 1, 4],
                [1, 3, 4],
                [3, 0, 4],
                [2, 0, 5],
                [1, 2, 5],
                [3, 1, 5],
                [0, 3, 5],
            ],
        ),
        20 => {
            let mut v = Vec::new();
            for (a, b) in [(1.0, phi), (-1.0, phi), (1.0, -phi), (-1.0, -phi)] {
                v.push(DVec3::new(0.0, a, b));
                v.push(DVec3::new(a, b, 0.0));
                v.push(DVec3::new(b, 0.0, a));
            }
            let v: Vec<DVec3> = v.into_iter().map(|p| p.normalize()).collect();
            let hull = crate::geometry::convex_hull::convex_hull(&v)
                .map_err(|_| ShapeError::InvalidParameter("icosahedron".into()))?;
            (v, hull)
        }
        _ => {
            return Err(ShapeError::InvalidParameter(format!(
                "a star has 8 spikes (on an octahedron) or 20 (on an icosahedron), not {spikes}"
            )))
        }
    };
    let mut vertices: Vec<DVec3> = base.iter().map(|&p| p * r).collect();
    let mut triangles = Vec::with_capacity(3 * faces.len());
    let mut parts = vec![vertices.clone()];
    for &[a, b, c] in &faces {
        let (pa, pb, pc) = (vertices[a], vertices[b], vertices[c]);
        let normal = (pb - pa).cross(pc - pa).normalize();
        let apex = (pa + pb + pc) / 3.0 + normal * h;
        let i = vertices.len();
        vertices.push(apex);
        triangles.extend([[a, b, i], [b, c, i], [c, a, i]]);
        parts.push(vec![pa, pb, pc, apex]);
    }
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts,
    })
}

/// A screw-shaped grain: a core of radius `core_radius` with `blades` helical blades out to
/// `radius`, `length` long along z, turning `turns` times over its length. Built as a twisted
/// extrusion of its cross-section (the core with the blades' sections, each blade
/// `blade_width` wide at the rim) in `segments` layers per turn; the caps are fans from the axis.
/// Not given as convex parts (its layers are twisted).
#[allow(clippy::too_many_arguments)]
pub fn screw(
    radius: f64,
    core_radius: f64,
    blade_width: f64,
    length: f64,
    turns: f64,
    blades: usize,
    segments: usize,
) -> Result<NonConvexMesh, ShapeError> {
    let (r, c, w, l) = (
        positive("radius", radius)?,
        positive("core_radius", core_radius)?,
        positive("blade_width", blade_width)?,
        positive("length", length)?,
    );
    if c >= r {
        return Err(ShapeError::InvalidParameter(format!(
            "the core radius ({c}) must be smaller than the radius ({r})"
        )));
    }
    if !(turns.is_finite() && turns >= 0.0) {
        return Err(ShapeError::InvalidParameter(format!(
            "turns must be a finite number ≥ 0, got {turns}"
        )));
    }
    if !(2..=12).contains(&blades) || segments < 4 {
        return Err(ShapeError::InvalidParameter(format!(
            "a screw needs 2 to 12 blades and at least 4 segments per turn, got {blades} and \
             {segments}"
        )));
    }
    // Half the angle a blade spans at the rim and at the core (same width at both).
    let (half_rim, half_core) = ((0.5 * w / r).asin(), (0.5 * w / c).min(1.0).asin());
    let pitch = TAU / blades as f64;
    if 2.0 * half_core >= pitch || w >= 2.0 * c {
        return Err(ShapeError::InvalidParameter(format!(
            "blades {w} wide do not fit {blades} times around a core of radius {c}"
        )));
    }
    // The cross-section, counter-clockwise: per blade, core → rim → rim → core, then the core
    // between blades in a few steps.
    let between = 3;
    let mut section: Vec<(f64, f64)> = Vec::new();
    for b in 0..blades {
        let a = pitch * b as f64;
        section.extend([
            (c, a - half_core),
            (r, a - half_rim),
            (r, a + half_rim),
            (c, a + half_core),
        ]);
        let (from, to) = (a + half_core, a + pitch - half_core);
        for k in 1..between {
            section.push((c, from + (to - from) * k as f64 / between as f64));
        }
    }
    let m = section.len();
    let layers = ((turns * segments as f64).ceil() as usize).max(1);
    let mut vertices = Vec::with_capacity((layers + 1) * m + 2);
    for k in 0..=layers {
        let t = k as f64 / layers as f64;
        let (z, twist) = (-0.5 * l + l * t, TAU * turns * t);
        vertices.extend(section.iter().map(|&(rho, phi)| {
            let (sin, cos) = (phi + twist).sin_cos();
            DVec3::new(rho * cos, rho * sin, z)
        }));
    }
    let (bottom, top) = (vertices.len(), vertices.len() + 1);
    vertices.push(DVec3::new(0.0, 0.0, -0.5 * l));
    vertices.push(DVec3::new(0.0, 0.0, 0.5 * l));
    let at = |k: usize, i: usize| k * m + i % m;
    let mut triangles = Vec::with_capacity(2 * layers * m + 2 * m);
    for k in 0..layers {
        for i in 0..m {
            let (a, b, cc, d) = (at(k, i), at(k, i + 1), at(k + 1, i + 1), at(k + 1, i));
            triangles.push([a, b, cc]);
            triangles.push([a, cc, d]);
        }
    }
    for i in 0..m {
        triangles.push([bottom, at(0, i + 1), at(0, i)]);
        triangles.push([top, at(layers, i), at(layers, i + 1)]);
    }
    Ok(NonConvexMesh {
        vertices,
        triangles,
        parts: Vec::new(),
    })
}

/// The eight corners of the box x × y × z.
fn box_corners(x: [f64; 2], y: [f64; 2], z: [f64; 2]) -> Vec<DVec3> {
    (0..8)
        .map(|k| DVec3::new(x[k & 1], y[(k >> 1) & 1], z[(k >> 2) & 1]))
        .collect()
}

/// The surface of the union of the cells (i, j, k) of the grid with planes `xs`, `ys`, `zs` for
/// which `filled` holds: two outward triangles for every cell face between a filled cell and an
/// empty one (or the outside).
pub fn grid_union(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    filled: impl Fn(usize, usize, usize) -> bool,
) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let size = [xs.len() - 1, ys.len() - 1, zs.len() - 1];
    let is_filled = |c: [i64; 3]| {
        (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < size[a])
            && filled(c[0] as usize, c[1] as usize, c[2] as usize)
    };
    let mut index = std::collections::BTreeMap::new();
    let mut vertices = Vec::new();
    let mut vertex = |g: [usize; 3]| -> usize {
        *index.entry(g).or_insert_with(|| {
            vertices.push(DVec3::new(xs[g[0]], ys[g[1]], zs[g[2]]));
            vertices.len() - 1
        })
    };
    let mut triangles = Vec::new();
    for i in 0..size[0] {
        for j in 0..size[1] {
            for k in 0..size[2] {
                let cell = [i as i64, j as i64, k as i64];
                if !is_filled(cell) {
                    continue;
                }
                for axis in 0..3 {
                    for side in [0usize, 1] {
                        let mut neighbour = cell;
                        neighbour[axis] += if side == 1 { 1 } else { -1 };
                        if is_filled(neighbour) {
                            continue;
                        }
                        // The face's corners, counter-clockwise seen from outside: walk the other
                        // two axes (u, v) with u × v along +axis, reversed on the low side.
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let corner = |du: usize, dv: usize| {
                            let mut g = [i, j, k];
                            g[axis] += side;
                            g[u] += du;
                            g[v] += dv;
                            g
                        };
                        let mut quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if side == 0 {
                            quad.reverse();
                        }
                        let [a, b, c, d] = quad.map(&mut vertex);
                        triangles.push([a, b, c]);
                        triangles.push([a, c, d]);
                    }
                }
            }
        }
    }
    (vertices, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::mesh_check::{check_mesh, CheckReport};

    fn volume(m: &NonConvexMesh) -> f64 {
        MassProperties::from_mesh(&m.vertices, &m.triangles)
            .unwrap()
            .volume
    }

    #[test]
    fn generated_meshes_are_valid_and_match_their_parts() {
        let cases: Vec<(&str, NonConvexMesh, f64)> = vec![
            ("jack", jack(3.0, 1.0).unwrap(), 3.0 + 4.0),
            ("cross", cross(3.0, 1.0, 0.5).unwrap(), 5.0 * 0.5),
            ("l", l_shape(2.0, 3.0, 1.0, 0.5).unwrap(), (2.0 + 2.0) * 0.5),
            ("ring", ring(2.0, 1.0, 1.0, 12).unwrap(), {
                let a = 0.5 * 12.0 * (TAU / 12.0).sin();
                a * (4.0 - 1.0)
            }),
            ("star8", star(8, 1.0, 1.0).unwrap(), {
                // Octahedron 4/3 r³, and 8 pyramids of base area √3/2 (edge √2), height 1.
                4.0 / 3.0 + 8.0 * (3f64.sqrt() / 2.0) / 3.0
            }),
            ("star20", star(20, 1.0, 0.5).unwrap(), 0.0),
            ("screw", screw(1.0, 0.4, 0.3, 3.0, 1.5, 2, 24).unwrap(), 0.0),
            (
                "screw3",
                screw(1.0, 0.5, 0.2, 2.0, 0.7, 3, 16).unwrap(),
                0.0,
            ),
        ];
        for (name, m, expected) in cases {
            let checked = check_mesh(&m.vertices, &m.triangles, CheckOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(checked.report, CheckReport::default(), "{name}");
            let v = volume(&m);
            if expected > 0.0 {
                assert!(
                    (v - expected).abs() < 1e-12 * expected,
                    "{name}: {v} vs {expected}"
                );
            }
            let with_parts = !m.parts.is_empty();
            let (p, _) = m
                .build(with_parts)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(p.parts().len(), m.parts.len());
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(jack(1.0, 1.0).is_err());
        assert!(jack(-1.0, 0.1).is_err());
        assert!(cross(1.0, 0.1, 0.0).is_err());
        assert!(l_shape(1.0, 2.0, 1.5, 1.0).is_err());
        assert!(ring(1.0, 2.0, 1.0, 12).is_err());
        assert!(ring(2.0, 1.0, 1.0, 2).is_err());
        assert!(star(12, 1.0, 1.0).is_err());
        assert!(screw(1.0, 1.2, 0.2, 1.0, 1.0, 2, 24).is_err());
        assert!(screw(1.0, 0.3, 0.5, 1.0, 1.0, 6, 24).is_err());
        assert!(screw(1.0, 0.3, 0.1, 1.0, 1.0, 1, 24).is_err());
    }

    #[test]
    fn a_screw_keeps_its_cross_section_area() {
        // Twisting moves each layer rigidly: the volume is about section area × length (the
        // side triangles between twisted layers bulge a little).
        let m = screw(1.0, 0.4, 0.3, 3.0, 1.0, 2, 48).unwrap();
        let straight = screw(1.0, 0.4, 0.3, 3.0, 0.0, 2, 48).unwrap();
        let (v, v0) = (volume(&m), volume(&straight));
        assert!((v / v0 - 1.0).abs() < 0.05, "{v} vs {v0}");
        assert_eq!(straight.triangles.len(), 2 * 12 + 2 * 12);
    }
}
