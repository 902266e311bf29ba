//! Small hand-built closed meshes for tests: an axis-aligned box and a non-convex L-shaped prism,
//! both outward-oriented (counter-clockwise seen from outside).

use crate::math::DVec3;

/// The box [lo, hi] as 8 vertices and 12 outward triangles.
pub fn box_mesh(lo: DVec3, hi: DVec3) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    // Vertex k has x from bit 0, y from bit 1, z from bit 2.
    let vertices = (0..8)
        .map(|k| {
            DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    // Quads counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    (vertices, quads_to_triangles(&quads))
}

/// The L-shaped prism [0,2]×[0,1]×[0,1] ∪ [0,1]×[1,2]×[0,1].
pub fn l_shape_mesh() -> (Vec<DVec3>, Vec<[usize; 3]>) {
    // The L in the xy-plane, counter-clockwise seen from +z; vertex k at z = 0, k + 6 at z = 1.
    let outline = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut vertices: Vec<DVec3> = outline
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
    vertices.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, 1.0)));
    // The L split into four triangles (counter-clockwise seen from +z).
    let cap = [[0, 1, 2], [0, 2, 3], [0, 3, 5], [3, 4, 5]];
    let mut triangles = Vec::new();
    for [a, b, c] in cap {
        triangles.push([a + 6, b + 6, c + 6]); // top, normal +z
        triangles.push([a, c, b]); // bottom, normal −z
    }
    let sides: Vec<[usize; 4]> = (0..6)
        .map(|k| [k, (k + 1) % 6, (k + 1) % 6 + 6, k + 6])
        .collect();
    triangles.extend(quads_to_triangles(&sides));
    (vertices, triangles)
}

/// The same surface with every triangle turned over (normals pointing inward).
pub fn flipped(triangles: &[[usize; 3]]) -> Vec<[usize; 3]> {
    triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
}

fn quads_to_triangles(quads: &[[usize; 4]]) -> Vec<[usize; 3]> {
    quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect()
}
