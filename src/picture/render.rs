//! One picture of one frame: particles (spheres traced, polyhedra by their faces), walls
//! (semi-transparent, or cut away), the force network, a title and a colour bar.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::animation::Animation;
use super::camera::{Camera, View, Viewport};
use super::colormap::{category, fraction, turbo, Rgb};
use super::cut::{clip_polygon, Cut};
use super::overlay::{self, ColourBar};
use super::raster::{Raster, Shading};
use super::run_files::{FrameChoice, RunFiles, Snapshot};
use super::{png, PictureError};
use crate::io::vtk_read::PolyData;

/// Supersampling: each output pixel is the mean of 2 × 2 samples, for smooth edges.
const SAMPLES: usize = 2;
const BACKGROUND: Rgb = [1.0, 1.0, 1.0];
/// Opacity of one layer of wall: several layers (a trough seen through its far side) still
/// leave the particles readable.
const WALL_ALPHA: f32 = 0.22;
/// Muted tints telling walls apart (a screw from its trough), by wall number.
const WALL_TINTS: [Rgb; 4] = [
    [0.55, 0.58, 0.64],
    [0.66, 0.62, 0.54],
    [0.52, 0.62, 0.56],
    [0.62, 0.55, 0.64],
];

/// How to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub view: View,
    /// The point-data array of the particles that colours them (vectors by their length);
    /// `speed` is the length of `velocity` when the file has no `speed` array.
    pub colour: String,
    /// Fixed colour range; by default the range of the frame (of all frames for a series).
    pub range: Option<(f64, f64)>,
    pub cuts: Vec<Cut>,
    /// The cuts also remove the bodies whose centre lies in them (a section through a bed).
    pub cut_bodies: bool,
    pub width: usize,
    pub height: usize,
    /// Draw the contacts as lines scaled and coloured by their normal force, the particles pale.
    pub force_network: bool,
    /// Frames per second of an animated GIF (`--out *.gif`).
    pub fps: f64,
    /// Frame the camera on this box (low, high corners) instead of the frame's contents, so that
    /// every picture of a series has the same camera.
    pub fit_box: Option<(DVec3, DVec3)>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            view: View::Iso,
            colour: "speed".into(),
            range: None,
            cuts: Vec::new(),
            cut_bodies: false,
            width: 1200,
            height: 900,
            force_network: false,
            fps: 10.0,
            fit_box: None,
        }
    }
}

/// A rendered frame: 8-bit RGB rows, top to bottom, and the camera that made it (in output
/// pixels), to find where a world point lies in the picture.
#[derive(Clone, Debug)]
pub struct Picture {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
    pub camera: Camera,
}

impl Picture {
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

/// The unit of a point-data array of `particles_*.vtp`, for the colour bar.
fn unit(name: &str) -> &'static str {
    match name {
        "speed" | "velocity" => " [m/s]",
        "angular_velocity" => " [rad/s]",
        "radius" => " [m]",
        "force" | "normal_force" => " [N]",
        "torque" => " [N m]",
        _ => "",
    }
}

/// One value per particle for the field `name`, or an error listing the fields there are.
pub fn particle_values(snap: &Snapshot, name: &str) -> Result<Vec<f64>, PictureError> {
    let p = &snap.particles;
    if let Some(array) = p.point_array(name) {
        return Ok(array.magnitudes());
    }
    if name == "speed" {
        if let Some(v) = p.point_array("velocity") {
            return Ok(v.magnitudes());
        }
    }
    let mut names = p.point_array_names();
    if p.point_array("velocity").is_some() && !names.contains(&"speed") {
        names.push("speed");
    }
    Err(PictureError::file(
        &snap.particles_file,
        format!(
            "has no point data '{name}' to colour by; use --color with one of: {}",
            names.join(", ")
        ),
    ))
}

/// The values that set the colour range of a frame: the particles' field, or the contacts'
/// normal forces in a force-network picture.
pub fn frame_values(snap: &Snapshot, options: &RenderOptions) -> Result<Vec<f64>, PictureError> {
    if options.force_network {
        Ok(normal_forces(snap)?.unwrap_or_default())
    } else {
        particle_values(snap, &options.colour)
    }
}

fn normal_forces(snap: &Snapshot) -> Result<Option<Vec<f64>>, PictureError> {
    let Some((file, contacts)) = &snap.contacts else {
        return Ok(None);
    };
    let forces = contacts.cell_array("normal_force").ok_or_else(|| {
        PictureError::file(
            file,
            "has no cell data 'normal_force' (not a force network?)",
        )
    })?;
    Ok(Some(forces.magnitudes()))
}

/// The finite range of `values`; (0, 0) when there is none.
pub fn value_range(values: &[f64]) -> (f64, f64) {
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let low = finite.clone().fold(f64::INFINITY, f64::min);
    let high = finite.fold(f64::NEG_INFINITY, f64::max);
    if low <= high {
        (low, high)
    } else {
        (0.0, 0.0)
    }
}

/// The median of the finite positive values, if there is one.
fn median(values: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = values
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return None;
    }
    let middle = v.len() / 2;
    Some(*v.select_nth_unstable_by(middle, f64::total_cmp).1)
}

/// The unit normal of a polygon by Newell's method, which is exact for planar polygons and
/// does not break on a few collinear corners.
fn polygon_normal(corners: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (k, &p) in corners.iter().enumerate() {
        let q = corners[(k + 1) % corners.len()];
        n += DVec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    n.normalize_or_zero()
}

fn corners(data: &PolyData, polygon: &[u32]) -> Vec<DVec3> {
    polygon.iter().map(|&v| data.points[v as usize]).collect()
}

/// The walls' polygons in world coordinates with their wall numbers. A plane wall is written as
/// one square (a wall number with one polygon of four corners; mesh walls are triangles): the
/// planes are cut by one another to the region the particles are in, so that a box of planes is
/// drawn as the box rather than as crossing squares.
fn wall_polygons(file: &Path, walls: &PolyData) -> Result<Vec<(usize, Vec<DVec3>)>, PictureError> {
    let numbers: Vec<usize> = match walls.cell_array("wall") {
        Some(w) if w.len() == walls.polys.len() => w.values.iter().map(|&v| v as usize).collect(),
        Some(_) => return Err(PictureError::file(file, "has not one 'wall' per polygon")),
        None => vec![0; walls.polys.len()],
    };
    let mut count: HashMap<usize, usize> = HashMap::new();
    for &n in &numbers {
        *count.entry(n).or_default() += 1;
    }
    let polygons: Vec<(usize, Vec<DVec3>)> = walls
        .polys
        .iter()
        .zip(&numbers)
        .map(|(p, &n)| (n, corners(walls, p)))
        .collect();
    let is_plane = |(n, corners): &(usize, Vec<DVec3>)| count[n] == 1 && corners.len() == 4;
    // The square's winding gives the plane's normal, which points to the particles' side.
    let planes: Vec<(DVec3, DVec3)> = polygons
        .iter()
        .filter(|p| is_plane(p))
        .map(|(_, c)| (polygon_normal(c), c[0]))
        .filter(|(n, _)| *n != DVec3::ZERO)
        .collect();
    Ok(polygons
        .iter()
        .map(|polygon| {
            let (n, corners) = polygon;
            if !is_plane(polygon) {
                return (*n, corners.clone());
            }
            let mut kept = corners.clone();
            for &(normal, point) in &planes {
                kept = clip_polygon(&kept, |x| -normal.dot(x - point));
            }
            (*n, kept)
        })
        .filter(|(_, c)| c.len() >= 3)
        .collect())
}

/// What the camera frames: every particle's bounding sphere, the polyhedra's corners and the
/// walls as drawn (plane squares already cut to the particles' side of the others).
fn fit_spheres<'a>(
    snap: &'a Snapshot,
    radii: &'a [f64],
    walls: &'a [(usize, Vec<DVec3>)],
) -> impl Iterator<Item = (DVec3, f64)> + 'a {
    let particles = snap
        .particles
        .points
        .iter()
        .copied()
        .zip(radii.iter().copied());
    let polyhedra = snap
        .polyhedra
        .iter()
        .flat_map(|(_, data)| data.points.iter().map(|&p| (p, 0.0)));
    let walls = walls.iter().flat_map(|(_, w)| w.iter().map(|&p| (p, 0.0)));
    particles.chain(polyhedra).chain(walls)
}

fn box_corners(low: DVec3, high: DVec3) -> impl Iterator<Item = (DVec3, f64)> {
    (0..8).map(move |k| {
        let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
        let corner = DVec3::new(
            pick(1, low.x, high.x),
            pick(2, low.y, high.y),
            pick(4, low.z, high.z),
        );
        (corner, 0.0)
    })
}

/// The box around all that the camera would frame in `snap`; None for an empty scene.
pub fn scene_box(snap: &Snapshot) -> Result<Option<(DVec3, DVec3)>, PictureError> {
    let radii = match snap.particles.point_array("radius") {
        Some(r) => r.values.clone(),
        None => vec![0.0; snap.particles.points.len()],
    };
    let walls = match &snap.walls {
        Some((file, data)) => wall_polygons(file, data)?,
        None => Vec::new(),
    };
    let mut low = DVec3::INFINITY;
    let mut high = DVec3::NEG_INFINITY;
    for (p, r) in fit_spheres(snap, &radii, &walls) {
        if p.is_finite() && r.is_finite() {
            low = low.min(p - r);
            high = high.max(p + r);
        }
    }
    Ok(low.cmple(high).all().then_some((low, high)))
}

/// Renders one frame. `name` goes into the title.
pub fn render_snapshot(
    name: &str,
    snap: &Snapshot,
    options: &RenderOptions,
) -> Result<Picture, PictureError> {
    let (width, height) = (options.width, options.height);
    if !(64..=16384).contains(&width) || !(64..=16384).contains(&height) {
        return Err(PictureError::Option(format!(
            "picture size {width}x{height}: each side must be 64 to 16384 pixels"
        )));
    }
    let particles = &snap.particles;
    let radii = particles
        .point_array("radius")
        .ok_or_else(|| PictureError::file(&snap.particles_file, "has no point data 'radius'"))?;
    let radii = &radii.values;
    let ids: Vec<f64> = match particles.point_array("id") {
        Some(a) => a.values.clone(),
        None => (0..particles.points.len()).map(|i| i as f64).collect(),
    };
    let index_of_id: HashMap<u64, usize> = ids
        .iter()
        .enumerate()
        .map(|(i, &id)| (id as u64, i))
        .collect();

    // Polyhedral bodies are drawn by their faces, which carry the body's id.
    let polyhedra = match &snap.polyhedra {
        Some((file, data)) => {
            let face_ids = data.cell_array("id").ok_or_else(|| {
                PictureError::file(file, "has no cell data 'id' naming each face's body")
            })?;
            if face_ids.len() != data.polys.len() {
                return Err(PictureError::file(file, "has not one 'id' per polygon"));
            }
            Some((data, face_ids.values.clone()))
        }
        None => None,
    };
    let polyhedral: HashSet<u64> = polyhedra
        .iter()
        .flat_map(|(_, ids)| ids.iter().map(|&id| id as u64))
        .collect();

    let (values, bar_label, forces) = if options.force_network {
        let forces = normal_forces(snap)?.ok_or_else(|| {
            PictureError::Option(
                "--force-network: the run wrote no contacts.pvd; set force_network = true in \
                 the scene's [output] and run it again"
                    .into(),
            )
        })?;
        (Vec::new(), format!("normal force{}", unit("force")), forces)
    } else {
        let values = particle_values(snap, &options.colour)?;
        let label = format!("{}{}", options.colour, unit(&options.colour));
        (values, label, Vec::new())
    };
    let (low, high) = options.range.unwrap_or_else(|| {
        value_range(if options.force_network {
            &forces
        } else {
            &values
        })
    });

    // The camera frames everything, walls included (before any cut, so that a cut does not
    // move the picture).
    let (title_height, bar_width) = overlay::margins(width, height);
    let viewport = Viewport {
        x: 0.0,
        y: title_height as f64,
        width: (width - bar_width) as f64,
        height: (height - title_height) as f64,
    };
    let walls = match &snap.walls {
        Some((file, data)) => wall_polygons(file, data)?,
        None => Vec::new(),
    };
    let camera = match options.fit_box {
        Some((low, high)) => Camera::fit(options.view, box_corners(low, high), viewport),
        None => Camera::fit(options.view, fit_spheres(snap, radii, &walls), viewport),
    };
    let fine = camera.scaled(SAMPLES as f64);
    let shading = Shading::default();
    // Walls are large and often face away from the light: more ambient light and no highlight
    // keep their far sides from turning black.
    let wall_shading = Shading {
        ambient: 0.6,
        specular: 0.0,
        ..shading
    };
    let mut raster = Raster::new(width * SAMPLES, height * SAMPLES, BACKGROUND);

    // Materials and shapes are categories: a colour each, not a scale.
    let categorical =
        !options.force_network && matches!(options.colour.as_str(), "material" | "shape");
    let mut categories: Vec<u32> = if categorical {
        values
            .iter()
            .filter(|v| v.is_finite() && **v >= 0.0)
            .map(|&v| v as u32)
            .collect()
    } else {
        Vec::new()
    };
    categories.sort_unstable();
    categories.dedup();
    let categories: Vec<(u32, String)> = categories
        .into_iter()
        .map(|c| {
            let label = match snap.legend.get(&(options.colour.clone(), c)) {
                Some(name) => format!("{c} {name}"),
                None => c.to_string(),
            };
            (c, label)
        })
        .collect();
    let colour_of = |i: usize| -> Rgb {
        if options.force_network {
            [0.8, 0.8, 0.8]
        } else if categorical {
            category(values[i].max(0.0) as usize)
        } else {
            turbo(fraction(values[i], low, high))
        }
    };
    let cut_away = |i: usize| {
        options.cut_bodies && options.cuts.iter().any(|c| c.removes(particles.points[i]))
    };
    for (i, (&p, &r)) in particles.points.iter().zip(radii).enumerate() {
        if polyhedral.contains(&(ids[i] as u64)) || cut_away(i) {
            continue;
        }
        let c = fine.project(p);
        raster.sphere(c, r * fine.scale(), r, colour_of(i), &shading);
    }
    if let Some((data, face_ids)) = &polyhedra {
        for (polygon, &id) in data.polys.iter().zip(face_ids) {
            let Some(&i) = index_of_id.get(&(id as u64)).filter(|&&i| !cut_away(i)) else {
                continue;
            };
            let world = corners(data, polygon);
            let colour = shading.shade(colour_of(i), fine.to_view(polygon_normal(&world)));
            let screen: Vec<DVec3> = world.iter().map(|&p| fine.project(p)).collect();
            raster.polygon(&screen, colour, None);
        }
    }

    // Outlines where the depth jumps by more than a fraction of a typical body: round every
    // body against the background and against the bodies behind it.
    if let Some(radius) = median(radii) {
        raster.outline((0.3 * radius) as f32, 0.45);
    }

    // Cut walls are opaque: what is left of them is behind the particles anyway.
    let alpha = options.cuts.is_empty().then_some(WALL_ALPHA);
    for (wall, polygon) in &walls {
        let mut world = polygon.clone();
        for cut in &options.cuts {
            world = cut.clip(&world);
        }
        if world.len() < 3 {
            continue;
        }
        let colour = wall_shading.shade(
            WALL_TINTS[wall % WALL_TINTS.len()],
            fine.to_view(polygon_normal(&world)),
        );
        let screen: Vec<DVec3> = world.iter().map(|&p| fine.project(p)).collect();
        raster.polygon(&screen, colour, alpha);
    }

    if options.force_network {
        if let Some((_, contacts)) = &snap.contacts {
            raster.fade(BACKGROUND, 0.35);
            // Strongest last, so they lie on top.
            // Cell data runs over vertex cells first, then lines.
            let line_forces = forces.get(contacts.num_verts..).unwrap_or_default();
            let lines: Vec<&[u32]> = contacts.lines.iter().collect();
            let mut order: Vec<usize> = (0..lines.len().min(line_forces.len())).collect();
            order.sort_by(|&a, &b| line_forces[a].total_cmp(&line_forces[b]));
            for k in order {
                let t = fraction(line_forces[k], low, high);
                let width_px = (1.0 + 5.0 * t) * SAMPLES as f64;
                let line = lines[k];
                for pair in line.windows(2) {
                    let a = fine.project(contacts.points[pair[0] as usize]);
                    let b = fine.project(contacts.points[pair[1] as usize]);
                    raster.line(a, b, width_px, turbo(t));
                }
            }
        }
    }

    let (w, h, mut rgb) = raster.to_rgb8(SAMPLES);
    let title = format!(
        "{name}   t = {} s   {} bodies",
        overlay::format_value(snap.time),
        particles.points.len()
    );
    let bar = ColourBar {
        label: bar_label,
        low,
        high,
        categories,
    };
    overlay::draw(&mut rgb, w, h, &title, Some(&bar))?;
    Ok(Picture {
        width: w,
        height: h,
        rgb,
        camera,
    })
}

/// Where frame `index` goes: `out` itself for a single picture named `*.png`, else a numbered
/// file in `out` (a folder, by default the run's own).
fn output_path(dir: &Path, out: Option<&Path>, index: usize, series: bool) -> PathBuf {
    let numbered = format!("render_{index:06}.png");
    match out {
        Some(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) => {
            if series {
                let stem = p.file_stem().unwrap_or_default().to_string_lossy();
                p.with_file_name(format!("{stem}_{index:06}.png"))
            } else {
                p.to_path_buf()
            }
        }
        Some(folder) => folder.join(numbered),
        None => dir.join(numbered),
    }
}

/// Renders the chosen frames of the run in `dir` to PNG files, or into one animated GIF when
/// `out` names a `.gif` file; returns the files written. A series shares one colour range (that
/// of all its frames) so that colours compare, and one camera, so that the picture stays still
/// while bodies come and go.
pub fn render_run(
    dir: &Path,
    frames: FrameChoice,
    options: &RenderOptions,
    out: Option<&Path>,
) -> Result<Vec<PathBuf>, PictureError> {
    let run = RunFiles::open(dir)?;
    if options.force_network && !run.has_contacts() {
        return Err(PictureError::Option(format!(
            "--force-network: {} has no contacts.pvd; set force_network = true in the scene's \
             [output] and run it again",
            dir.display()
        )));
    }
    let indices = run.select(frames)?;
    let series = frames == FrameChoice::All;
    let mut options = options.clone();
    // A series shares one colour range and one camera: a first pass over its frames finds them.
    if series {
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut fit: Option<(DVec3, DVec3)> = None;
        for &i in &indices {
            let snap = run.load(i, options.force_network)?;
            let (l, h) = value_range(&frame_values(&snap, &options)?);
            low = low.min(l);
            high = high.max(h);
            if let Some((a, b)) = scene_box(&snap)? {
                fit = Some(fit.map_or((a, b), |(c, d)| (a.min(c), b.max(d))));
            }
        }
        if options.range.is_none() {
            options.range = (low <= high).then_some((low, high));
        }
        options.fit_box = options.fit_box.or(fit);
    }
    let name = run.name();
    let gif = out.filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("gif")));
    if let Some(path) = gif {
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent)
                .map_err(|e| PictureError::file(parent, e.to_string()))?;
        }
        let mut animation = None;
        for &i in &indices {
            let picture = render_snapshot(&name, &run.load(i, options.force_network)?, &options)?;
            let animation = match &mut animation {
                Some(a) => a,
                None => animation.insert(Animation::new(
                    path,
                    picture.width,
                    picture.height,
                    options.fps,
                )?),
            };
            animation.push(&picture.rgb)?;
        }
        return match animation {
            Some(a) => Ok(vec![a.finish()?]),
            None => Ok(Vec::new()),
        };
    }
    let mut written = Vec::new();
    for &i in &indices {
        let snap = run.load(i, options.force_network)?;
        let picture = render_snapshot(&name, &snap, &options)?;
        let path = output_path(dir, out, i, series);
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent)
                .map_err(|e| PictureError::file(parent, e.to_string()))?;
        }
        png::write_rgb(&path, picture.width, picture.height, &picture.rgb)?;
        written.push(path);
    }
    Ok(written)
}

/// Reads `--size WxH`.
pub fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let bad =
        || format!("cannot read size '{text}': write width x height in pixels, e.g. 1200x900");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: usize = w.trim().parse().map_err(|_| bad())?;
    let h: usize = h.trim().parse().map_err(|_| bad())?;
    Ok((w, h))
}

/// Reads `--range LOW:HIGH`.
pub fn parse_range(text: &str) -> Result<(f64, f64), String> {
    let bad = || format!("cannot read range '{text}': write low:high, e.g. 0:1.5");
    let (l, h) = text.split_once(':').ok_or_else(bad)?;
    let l: f64 = l.trim().parse().map_err(|_| bad())?;
    let h: f64 = h.trim().parse().map_err(|_| bad())?;
    if !(l.is_finite() && h.is_finite() && l < h) {
        return Err(bad());
    }
    Ok((l, h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_ranges_parse() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert!(parse_size("800").unwrap_err().contains("e.g. 1200x900"));
        assert_eq!(parse_range("0:1.5"), Ok((0.0, 1.5)));
        assert!(parse_range("2:1").is_err());
    }

    #[test]
    fn output_paths() {
        let dir = Path::new("run");
        assert_eq!(
            output_path(dir, None, 3, false),
            Path::new("run/render_000003.png")
        );
        let file = Path::new("pics/a.png");
        assert_eq!(output_path(dir, Some(file), 3, false), file);
        assert_eq!(
            output_path(dir, Some(file), 3, true),
            Path::new("pics/a_000003.png")
        );
        assert_eq!(
            output_path(dir, Some(Path::new("pics")), 3, true),
            Path::new("pics/render_000003.png")
        );
    }

    #[test]
    fn plane_squares_cut_each_other_to_the_particles_side() {
        use crate::io::vtk_read::CellList;
        // A floor (normal +z) and a side wall at x = 0 (normal +x), both 2 m squares around the
        // origin, as the run writes them; a mesh-wall triangle stays whole.
        let floor = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| DVec3::new(x, y, 0.0));
        let side = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(y, z)| DVec3::new(0.0, y, z));
        let triangle = [
            DVec3::new(-5.0, 0.0, -5.0),
            DVec3::new(-4.0, 0.0, -5.0),
            DVec3::Z,
        ];
        let points: Vec<DVec3> = floor
            .iter()
            .chain(&side)
            .chain(&triangle)
            .copied()
            .collect();
        let walls = PolyData {
            points,
            polys: CellList {
                connectivity: (0..11).collect(),
                offsets: vec![4, 8, 11],
            },
            cell_data: vec![crate::io::vtk_read::DataArray {
                name: "wall".into(),
                components: 1,
                values: vec![0.0, 1.0, 2.0],
            }],
            ..PolyData::default()
        };
        let polygons = wall_polygons(Path::new("walls.vtp"), &walls).unwrap();
        assert_eq!(polygons.len(), 3);
        assert!(
            polygons[0].1.iter().all(|p| p.x >= 0.0),
            "floor kept on the +x side"
        );
        assert!(
            polygons[1].1.iter().all(|p| p.z >= 0.0),
            "side kept above the floor"
        );
        assert_eq!(polygons[2].1, triangle);
    }

    #[test]
    fn newell_normal_of_a_square() {
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        assert_eq!(polygon_normal(&square), DVec3::Z);
    }
}
