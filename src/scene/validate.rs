//! Range checks on a parsed scene: every number finite and within what the physics allows.

use super::format::{InletSpec, InsertSpec, RadiusDistribution, TimeStep, Vec3};
use super::{KeyPath, Scene, SceneError};

pub fn check(scene: &Scene) -> Result<(), SceneError> {
    let c = Checker { scene };
    let s = &scene.spec;
    let sim = KeyPath::table("simulation");
    c.positive(sim.clone().key("duration"), s.simulation.duration, "s")?;
    if let TimeStep::Seconds(dt) = s.simulation.time_step {
        c.positive(sim.clone().key("time_step"), dt, "s")?;
    }
    if let Some(interval) = s.simulation.output_interval {
        c.positive(sim.clone().key("output_interval"), interval, "s")?;
    }
    for (key, interval) in [
        ("checkpoint_interval", s.output.checkpoint_interval),
        ("vtk_interval", s.output.vtk_interval),
        ("csv_interval", s.output.csv_interval),
    ] {
        if let Some(interval) = interval {
            c.positive(KeyPath::table("output").key(key), interval, "s")?;
        }
    }
    c.vector(sim.clone().key("gravity"), s.simulation.gravity())?;
    check_counts(&c)?;
    if let Some(skin) = s.simulation.skin {
        c.non_negative(sim.clone().key("skin"), skin, "m")?;
    }
    c.non_negative(
        sim.key("initial_overlap_tolerance"),
        s.simulation.initial_overlap_tolerance,
        "(fraction of the smaller radius)",
    )?;

    let contact = KeyPath::table("contact");
    if let Some(k) = s.contact.stiffness {
        c.positive(contact.clone().key("stiffness"), k, "N/m")?;
    }
    c.positive(
        contact.key("tangential_stiffness_ratio"),
        s.contact.tangential_stiffness_ratio,
        "(k_t / k_n)",
    )?;

    if s.materials.is_empty() {
        return Err(scene.error(
            KeyPath::table("material"),
            "the scene defines no material: add at least one [[material]]",
        ));
    }
    for (n, m) in s.materials.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("material", n).key(k);
        if s.materials[..n].iter().any(|other| other.name == m.name) {
            return Err(scene.error(
                key("name"),
                format!("material '{}' is defined twice", m.name),
            ));
        }
        c.plausible(key("density"), m.density, DENSITY, "kg/m³")?;
        c.plausible(key("youngs_modulus"), m.youngs_modulus, STIFFNESS, "Pa")?;
        c.open_range(key("poisson_ratio"), m.poisson_ratio, -1.0, 0.5)?;
        c.restitution(key("restitution"), m.restitution)?;
        c.non_negative(key("friction"), m.friction, "")?;
        c.non_negative(key("rolling_friction"), m.rolling_friction, "")?;
    }
    for (n, p) in s.pairs.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("pair", n).key(k);
        let same = |other: &super::format::PairSpec| {
            let [a, b] = &other.materials;
            (a, b) == (&p.materials[0], &p.materials[1])
                || (b, a) == (&p.materials[0], &p.materials[1])
        };
        if let Some(first) = s.pairs[..n].iter().position(same) {
            return Err(scene.error(
                key("materials"),
                format!(
                    "the pair {:?} is already set by [[pair]] #{}: merge the two entries",
                    p.materials,
                    first + 1
                ),
            ));
        }
        if let Some(e) = p.restitution {
            c.restitution(key("restitution"), e)?;
        }
        if let Some(mu) = p.friction {
            c.non_negative(key("friction"), mu, "")?;
        }
        if let Some(mu) = p.rolling_friction {
            c.non_negative(key("rolling_friction"), mu, "")?;
        }
    }
    for (n, p) in s.planes.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("plane", n).key(k);
        c.vector(key("point"), p.point)?;
        c.vector(key("normal"), p.normal)?;
        // Also refuses normals too short or too long to normalise in floating point
        // (e.g. [1e-320, 0, 0], whose squared length underflows to zero).
        if crate::math::DVec3::from(p.normal).try_normalize().is_none() {
            return Err(scene.error(
                key("normal"),
                format!(
                    "{:?} cannot be used as a normal: give a non-zero vector of moderate length \
                     (it is normalised), e.g. [0.0, 0.0, 1.0]",
                    p.normal
                ),
            ));
        }
    }
    for (n, w) in s.mesh_walls.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("mesh_wall", n).key(k);
        c.positive(key("scale"), w.scale, "(factor)")?;
        c.vector(key("rotation"), w.rotation)?;
        c.vector(key("translation"), w.translation)?;
    }
    for (n, p) in s.particles.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("particle", n).key(k);
        if let Some(radius) = p.radius {
            c.plausible(key("radius"), radius, SIZE, "m")?;
        }
        c.vector(key("rotation"), p.rotation)?;
        c.vector(key("position"), p.position)?;
        c.vector(key("velocity"), p.velocity)?;
        c.vector(key("angular_velocity"), p.angular_velocity)?;
    }
    for (n, i) in s.insertions.iter().enumerate() {
        check_insertion(&c, n, i)?;
    }
    if let Some(r) = &s.output.packing_region {
        let key = |k: &str| KeyPath::table("output").key(&format!("packing_region.{k}"));
        c.vector(key("min"), r.min)?;
        c.vector(key("max"), r.max)?;
        if (0..3).any(|a| r.max[a] <= r.min[a]) {
            return Err(scene.error(key("max"), "max must be greater than min on every axis"));
        }
    }
    if let Some(d) = &s.domain {
        let key = |k: &str| KeyPath::table("domain").key(k);
        c.vector(key("min"), d.min)?;
        c.vector(key("max"), d.max)?;
        if (0..3).any(|a| d.max[a] <= d.min[a]) {
            return Err(scene.error(key("max"), "max must be greater than min on every axis"));
        }
    }
    Ok(())
}

fn check_insertion(c: &Checker, n: usize, i: &InsertSpec) -> Result<(), SceneError> {
    let key = |k: &str| KeyPath::entry("insert", n).key(k);
    c.non_negative(key("time"), i.time, "s")?;
    if let Some(every) = i.every {
        c.positive(key("every"), every, "s")?;
    }
    if let Some(until) = i.until {
        c.finite(key("until"), until)?;
        if until < i.time {
            return Err(c.scene.error(key("until"), "until must not be before time"));
        }
    }
    c.vector(key("velocity"), i.velocity)?;
    match (i.region_min, i.region_max, i.cylinder, &i.inlet) {
        (Some(lo), Some(hi), None, None) => {
            c.vector(key("region_min"), lo)?;
            c.vector(key("region_max"), hi)?;
            if (0..3).any(|a| hi[a] <= lo[a]) {
                return Err(c.scene.error(
                    key("region_max"),
                    "region_max must be greater than region_min on every axis",
                ));
            }
        }
        (None, None, None, Some(inlet)) => check_inlet(c, n, i, inlet)?,
        (None, None, Some(cyl), None) => {
            c.vector(key("cylinder.centre"), cyl.centre)?;
            c.vector(key("cylinder.axis"), cyl.axis)?;
            if cyl.axis.iter().all(|&x| x == 0.0) {
                return Err(c
                    .scene
                    .error(key("cylinder.axis"), "the axis must not be zero"));
            }
            c.positive(key("cylinder.radius"), cyl.radius, "m")?;
            c.positive(key("cylinder.length"), cyl.length, "m")?;
        }
        _ => {
            return Err(c.scene.error(
                key("region_min"),
                "give the region as `region_min` and `region_max` (a box), as `cylinder = \
                 { centre, axis, radius, length }`, or as `inlet = { centre, normal, radius or \
                 size, speed, rate }` (bodies streaming in through a face), one of the three",
            ))
        }
    }
    match (i.count, i.volume_fraction) {
        (None, None) if i.inlet.is_some() => {}
        (count, _) if i.inlet.is_some() => {
            let k = if count.is_some() {
                "count"
            } else {
                "volume_fraction"
            };
            return Err(c.scene.error(
                key(k),
                "an inlet inserts `inlet.rate` bodies per second, `rate × every` at a time: \
                 leave out `count` and `volume_fraction`",
            ));
        }
        (Some(_), Some(_)) | (None, None) => {
            return Err(c.scene.error(
                key("count"),
                "give exactly one of `count` and `volume_fraction`",
            ))
        }
        (Some(0), None) => return Err(c.scene.error(key("count"), "count must be at least 1")),
        (None, Some(f)) => c.open_range(key("volume_fraction"), f, 0.0, 0.74)?,
        _ => {}
    }
    let (r_min, r_max) = match (i.radius, i.radius_distribution) {
        (None, None) if i.shape.is_some() => {
            // Sized by the shape: the sphere of equal volume for how many fit, the bounding
            // sphere for the narrowest region. A shape that is unknown or fails to build is
            // reported where shapes are built, with the list of names.
            let spec = i
                .shape
                .as_ref()
                .and_then(|name| c.scene.spec.shapes.get(name));
            let folder = super::shapes::scene_folder(c.scene);
            match spec.map(|spec| super::shapes::build_one(spec, folder)) {
                Some(Ok(built)) => (
                    built.shape.equivalent_radius(),
                    built.shape.bounding_radius(),
                ),
                _ => return Ok(()),
            }
        }
        (Some(r), None) if i.shape.is_none() => {
            c.plausible(key("radius"), r, SIZE, "m")?;
            (r, r)
        }
        (None, Some(d)) if i.shape.is_none() => check_distribution(c, n, d)?,
        _ => {
            return Err(c.scene.error(
                key("radius"),
                "give exactly one of `radius`, `radius_distribution` and `shape`",
            ))
        }
    };
    check_insertion_size(c, n, i, r_min, r_max)
}

/// Checks a radius distribution; returns the smallest and largest radius it can draw.
fn check_distribution(
    c: &Checker,
    n: usize,
    d: RadiusDistribution,
) -> Result<(f64, f64), SceneError> {
    let key = |k: &str| KeyPath::entry("insert", n).key(&format!("radius_distribution.{k}"));
    let (min, max) = match d {
        RadiusDistribution::Uniform { min, max } | RadiusDistribution::Normal { min, max, .. } => {
            (min, max)
        }
    };
    c.positive(key("min"), min, "m")?;
    c.positive(key("max"), max, "m")?;
    if max < min {
        return Err(c.scene.error(
            key("max"),
            format!("{max} is below min = {min}: max must be ≥ min"),
        ));
    }
    if let RadiusDistribution::Normal { mean, std_dev, .. } = d {
        c.positive(key("mean"), mean, "m")?;
        c.positive(key("std_dev"), std_dev, "m")?;
        if !(min..=max).contains(&mean) {
            return Err(c.scene.error(
                key("mean"),
                format!("{mean} is not allowed: must lie in [min, max] = [{min}, {max}]"),
            ));
        }
        // Radii are drawn by rejection: a window holding almost none of the distribution would
        // make drawing them take forever.
        let inside = normal_cdf((max - mean) / std_dev) - normal_cdf((min - mean) / std_dev);
        if inside < MIN_NORMAL_ACCEPTANCE {
            return Err(c.scene.error(
                key("std_dev"),
                format!(
                    "only {:.2e} % of a normal distribution with std_dev = {std_dev} lies in \
                     [min, max] = [{min}, {max}] (at least {} % is needed): widen [min, max], \
                     lower std_dev, or give a fixed `radius`",
                    100.0 * inside,
                    100.0 * MIN_NORMAL_ACCEPTANCE
                ),
            ));
        }
    }
    Ok((min, max))
}

/// Most facets or vertices a generated particle shape may have: beyond, every contact of the
/// body costs milliseconds, and a mistyped count would allocate gigabytes before any step.
const SHAPE_COUNT_MAX: i64 = 10_000;
/// Most segments (and rings, divisions) along one direction of a generated wall.
const WALL_COUNT_MAX: i64 = 100_000;

/// Refuses counts of generated shapes and walls that would take more memory or time than any
/// scene needs (`sides = 1000000000` used to abort with an allocation failure). Read from the
/// file's own tree, so every count key of every generator is covered.
fn check_counts(c: &Checker) -> Result<(), SceneError> {
    const COUNTS: [&str; 9] = [
        "sides",
        "vertices",
        "segments",
        "spikes",
        "blades",
        "rings",
        "segments_per_turn",
        "radial_segments",
        "divisions",
    ];
    let Ok(tree) = c.scene.source.parse::<toml::Table>() else {
        return Ok(()); // the typed reading has reported it already
    };
    let too_many = |table: &toml::Table, limit: i64| -> Option<(String, i64)> {
        COUNTS.iter().find_map(|&k| {
            let values: Vec<i64> = match table.get(k)? {
                toml::Value::Integer(n) => vec![*n],
                toml::Value::Array(a) => a.iter().filter_map(toml::Value::as_integer).collect(),
                _ => return None,
            };
            values
                .into_iter()
                .find(|&n| n > limit)
                .map(|n| (k.to_string(), n))
        })
    };
    let refuse = |key: KeyPath, (k, n): (String, i64), limit: i64| {
        c.scene.error(
            key,
            format!(
                "{k} = {n} is more than the {limit} a generated {} may have: each would cost \
                 memory and time in every contact; use fewer (or a mesh file)",
                if limit == SHAPE_COUNT_MAX {
                    "shape"
                } else {
                    "wall"
                }
            ),
        )
    };
    if let Some(shapes) = tree.get("shape").and_then(toml::Value::as_table) {
        for (name, shape) in shapes {
            if let Some(found) = shape.as_table().and_then(|t| too_many(t, SHAPE_COUNT_MAX)) {
                let key = KeyPath::table(&format!("shape.{name}")).key(&found.0);
                return Err(refuse(key, found, SHAPE_COUNT_MAX));
            }
        }
    }
    if let Some(walls) = tree.get("mesh_wall").and_then(toml::Value::as_array) {
        for (n, wall) in walls.iter().enumerate() {
            let generator = wall.get("generator").and_then(toml::Value::as_table);
            if let Some(found) = generator.and_then(|g| too_many(g, WALL_COUNT_MAX)) {
                let key = KeyPath::entry("mesh_wall", n).key(&format!("generator.{}", found.0));
                return Err(refuse(key, found, WALL_COUNT_MAX));
            }
        }
    }
    Ok(())
}

/// A range no physical value of a DEM scene leaves.
#[derive(Clone, Copy)]
struct Plausible {
    what: &'static str,
    min: f64,
    max: f64,
}

/// From aerogel's few kg/m³ (with room) to beyond osmium's 22,600.
const DENSITY: Plausible = Plausible {
    what: "a density",
    min: 1e-2,
    max: 1e6,
};
/// From the softest gels (about 1 kPa; DEM's softened materials are 1e5 and up) to beyond
/// diamond's 1.2e12 Pa.
const STIFFNESS: Plausible = Plausible {
    what: "a Young's modulus",
    min: 1.0,
    max: 1e13,
};
/// From a nanometre (colloids) to a kilometre (boulders would be metres).
const SIZE: Plausible = Plausible {
    what: "a particle radius",
    min: 1e-9,
    max: 1e3,
};

/// Smallest share of a normal radius distribution that [min, max] must hold.
const MIN_NORMAL_ACCEPTANCE: f64 = 1e-3;

/// The keys of an inlet (`[[insert]] inlet = { … }`): a disc or a rectangle, a normal that is not
/// zero, a speed and a rate; `every` given (the interval between layers), `velocity` not (the
/// inlet sets it).
fn check_inlet(c: &Checker, n: usize, i: &InsertSpec, inlet: &InletSpec) -> Result<(), SceneError> {
    let key = |k: &str| KeyPath::entry("insert", n).key(k);
    // A face from a file was read (and its centre and normal set) when the scene was parsed.
    let (Some(centre), Some(normal)) = (inlet.centre, inlet.normal) else {
        let k = if inlet.centre.is_none() {
            "inlet.centre"
        } else {
            "inlet.normal"
        };
        return Err(c.scene.error(
            key(k),
            "an inlet's face needs its `centre` and `normal` (or a mesh `file`, which gives them)",
        ));
    };
    c.vector(key("inlet.centre"), centre)?;
    c.vector(key("inlet.normal"), normal)?;
    if normal.iter().all(|&x| x == 0.0) {
        return Err(c.scene.error(
            key("inlet.normal"),
            "the normal must not be zero: it is the direction bodies leave the face in",
        ));
    }
    match (inlet.radius, inlet.size, &inlet.file) {
        (Some(r), None, None) => c.positive(key("inlet.radius"), r, "m")?,
        (None, Some([a, b]), None) => {
            c.positive(key("inlet.size"), a, "m")?;
            c.positive(key("inlet.size"), b, "m")?;
        }
        (None, None, Some(_)) => {}
        _ => {
            return Err(c.scene.error(
                key("inlet.radius"),
                "give the face as `radius` (a disc), `size = [a, b]` (a rectangle, side a \
                 along `side`) or `file` (a flat mesh), one of the three",
            ))
        }
    }
    if inlet.flip && inlet.file.is_none() {
        return Err(c.scene.error(
            key("inlet.flip"),
            "`flip` turns the triangles of a face from a `file`; a disc or rectangle leaves to \
             its `normal`",
        ));
    }
    if let Some(side) = inlet.side {
        c.vector(key("inlet.side"), side)?;
        if inlet.size.is_none() {
            return Err(c.scene.error(
                key("inlet.side"),
                "`side` turns a rectangular face (`size`); a disc has none",
            ));
        }
        let (nn, s) = (
            crate::math::DVec3::from(normal).normalize(),
            crate::math::DVec3::from(side),
        );
        if (s - nn * nn.dot(s)).length() <= 1e-9 * s.length() {
            return Err(c.scene.error(
                key("inlet.side"),
                "`side` must not be parallel to the normal: it is a direction in the face",
            ));
        }
    }
    c.positive(key("inlet.speed"), inlet.speed, "m/s")?;
    c.positive(key("inlet.rate"), inlet.rate, "bodies/s")?;
    if i.every.is_none() {
        return Err(c.scene.error(
            key("inlet"),
            "an inlet inserts a layer of bodies every `every` seconds: give `every` (the \
             layer is `inlet.speed × every` thick, at least one body across)",
        ));
    }
    if i.velocity != [0.0; 3] {
        return Err(c.scene.error(
            key("velocity"),
            "an inlet gives its bodies `inlet.speed` along `inlet.normal`: leave out `velocity`",
        ));
    }
    Ok(())
}

/// Most spheres one insertion may ask for (directly, or through `volume_fraction`).
const MAX_INSERTED: f64 = 1e8;

/// Densest packing of equal spheres (Kepler): no request for more sphere volume can be met.
const DENSEST_PACKING: f64 = 0.74;

/// Refuses, before any sphere is drawn, requests that cannot fit in the region or would exhaust
/// memory.
fn check_insertion_size(
    c: &Checker,
    n: usize,
    i: &InsertSpec,
    r_min: f64,
    r_max: f64,
) -> Result<(), SceneError> {
    let key = |k: &str| KeyPath::entry("insert", n).key(k);
    // Shapes are placed by their bounding spheres.
    let (one, many) = match &i.shape {
        Some(name) => (
            format!("'{name}' body of bounding radius"),
            format!("'{name}' bodies of bounding radius"),
        ),
        None => ("sphere of radius".into(), "spheres of radius".into()),
    };
    let (lo, hi) = i.bounds();
    if let Some(inlet) = &i.inlet {
        let depth = i.inlet_depth();
        if depth < 2.0 * r_max {
            return Err(c.scene.error(
                key("every"),
                format!(
                    "the inlet's layer, speed × every = {depth:.4e} m, is thinner than one {one} \
                     {r_max} m: give every ≥ {:.4e} s (or a higher speed)",
                    2.0 * r_max / inlet.speed
                ),
            ));
        }
    }
    let extent: Vec<f64> = match (i.cylinder, &i.inlet) {
        (Some(cyl), _) => vec![2.0 * cyl.radius, cyl.length],
        (_, Some(inlet)) => match (inlet.radius, inlet.size) {
            (Some(r), _) => vec![2.0 * r],
            (None, Some([a, b])) => vec![a, b],
            // A face from a file: narrow or not, bodies that do not fit are reported.
            (None, None) => Vec::new(),
        },
        _ => (0..3).map(|a| hi[a] - lo[a]).collect(),
    };
    if extent.iter().any(|&e| e < 2.0 * r_max) {
        let narrow = match &i.inlet {
            Some(inlet) if inlet.radius.is_some() => "inlet.radius",
            Some(_) => "inlet.size",
            None => "region_max",
        };
        return Err(c.scene.error(
            key(narrow),
            format!(
                "the region {extent:?} m is narrower than one {one} {r_max} m on some axis: \
                 enlarge the region or use smaller bodies"
            ),
        ));
    }
    let region = i.volume();
    let smallest = 4.0 / 3.0 * std::f64::consts::PI * r_min.powi(3);
    let inlet_count = i
        .inlet
        .as_ref()
        .map(|inlet| (inlet.rate * i.every.unwrap_or(0.0)).ceil() as usize);
    let (count_key, most) = match (inlet_count.or(i.count), i.volume_fraction) {
        (Some(count), _) => {
            let count_key = if i.inlet.is_some() {
                "inlet.rate"
            } else {
                "count"
            };
            let needed = count as f64 * smallest;
            if needed > DENSEST_PACKING * region {
                return Err(c.scene.error(
                    key(count_key),
                    format!(
                        "{count} {many} ≥ {r_min} m take at least {needed:.3e} m³, more than \
                         fits in the region's {region:.3e} m³ (at most 74 % can be filled): \
                         enlarge the region or ask for fewer"
                    ),
                ));
            }
            (count_key, count as f64)
        }
        (None, Some(f)) => ("volume_fraction", (f * region / smallest).ceil()),
        (None, None) => unreachable!("checked above: count or volume_fraction is given"),
    };
    if most > MAX_INSERTED {
        return Err(c.scene.error(
            key(count_key),
            format!(
                "this would insert up to {most:.3e} spheres, more than the {MAX_INSERTED:.0e} one \
                 insertion may place: use larger spheres or a smaller region"
            ),
        ));
    }
    Ok(())
}

/// Standard normal cumulative distribution, Φ(x) = (1 + erf(x/√2))/2, with erf after Abramowitz
/// & Stegun 7.1.26 (absolute error below 1.5e-7, ample for a feasibility check).
fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    0.5 * (1.0 + erf.copysign(x))
}

struct Checker<'a> {
    scene: &'a Scene,
}

impl Checker<'_> {
    fn finite(&self, key: KeyPath, v: f64) -> Result<(), SceneError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.scene.error(key, format!("{v} is not a finite number")))
        }
    }

    /// A value > 0 within `range` (inclusive), which no physical input of a DEM run leaves:
    /// outside, the time step and forces leave the range of floating point.
    fn plausible(
        &self,
        key: KeyPath,
        v: f64,
        range: Plausible,
        unit: &str,
    ) -> Result<(), SceneError> {
        self.positive(key.clone(), v, unit)?;
        if (range.min..=range.max).contains(&v) {
            Ok(())
        } else {
            Err(self.scene.error(
                key,
                format!(
                    "{v:e} {unit} is outside any physical range for {} ({:e} to {:e} {unit}); a \
                     mistyped exponent?",
                    range.what, range.min, range.max
                ),
            ))
        }
    }

    fn positive(&self, key: KeyPath, v: f64, unit: &str) -> Result<(), SceneError> {
        self.finite(key.clone(), v)?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self
                .scene
                .error(key, format!("{v} is not allowed: must be > 0 {unit}")))
        }
    }

    fn non_negative(&self, key: KeyPath, v: f64, unit: &str) -> Result<(), SceneError> {
        self.finite(key.clone(), v)?;
        if v >= 0.0 {
            Ok(())
        } else {
            Err(self
                .scene
                .error(key, format!("{v} is not allowed: must be ≥ 0 {unit}")))
        }
    }

    fn open_range(&self, key: KeyPath, v: f64, lo: f64, hi: f64) -> Result<(), SceneError> {
        self.finite(key.clone(), v)?;
        if v > lo && v < hi {
            Ok(())
        } else {
            Err(self
                .scene
                .error(key, format!("{v} is not allowed: must lie in ({lo}, {hi})")))
        }
    }

    fn restitution(&self, key: KeyPath, e: f64) -> Result<(), SceneError> {
        self.finite(key.clone(), e)?;
        if (0.0..=1.0).contains(&e) {
            Ok(())
        } else {
            Err(self
                .scene
                .error(key, format!("{e} is not allowed: must lie in [0, 1]")))
        }
    }

    fn vector(&self, key: KeyPath, v: Vec3) -> Result<(), SceneError> {
        for x in v {
            self.finite(key.clone(), x)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    const BASE: &str = "[simulation]\nduration = 0.01\n\n[[material]]\nname = \"glass\"\n\
        density = 2500.0\nyoungs_modulus = 5e9\npoisson_ratio = 0.25\nrestitution = 0.8\n\
        friction = 0.3\n";

    /// The message of the error `extra` (appended to a valid scene) causes, or "ok".
    fn message(extra: &str) -> String {
        match Scene::parse(Path::new("s.toml"), format!("{BASE}{extra}")) {
            Ok(_) => "ok".into(),
            Err(e) => e.to_string(),
        }
    }

    fn insert(size: &str) -> String {
        message(&format!(
            "\n[[insert]]\nmethod = \"random\"\nmaterial = \"glass\"\n\
             region_min = [0.0, 0.0, 0.0]\nregion_max = [0.1, 0.1, 0.1]\n{size}\n"
        ))
    }

    #[test]
    fn the_base_scene_and_a_modest_insertion_are_valid() {
        assert_eq!(message(""), "ok");
        assert_eq!(insert("count = 10\nradius = 0.005"), "ok");
    }

    #[test]
    fn plane_normals_that_cannot_be_normalised_are_refused() {
        for normal in [
            "[0.0, 0.0, 0.0]",
            "[1e-320, 0.0, 0.0]",
            "[1e200, 1e200, 0.0]",
        ] {
            let m = message(&format!(
                "\n[[plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = {normal}\nmaterial = \"glass\"\n"
            ));
            assert!(
                m.starts_with("s.toml:14: [[plane]] #1 normal:") && m.contains("non-zero"),
                "{m}"
            );
        }
        let m = message("\n[[plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [nan, 0.0, 1.0]\nmaterial = \"glass\"\n");
        assert!(m.contains("normal: NaN is not a finite number"), "{m}");
    }

    #[test]
    fn a_pair_set_twice_is_refused_in_either_order() {
        let pair = |a: &str, b: &str| {
            format!("\n[[pair]]\nmaterials = [\"{a}\", \"{b}\"]\nfriction = 0.1\n")
        };
        assert_eq!(message(&pair("glass", "glass")), "ok");
        let m = message(&(pair("glass", "steel") + &pair("steel", "glass")));
        assert!(
            m.contains("[[pair]] #2 materials") && m.contains("[[pair]] #1"),
            "{m}"
        );
    }

    #[test]
    fn radius_distributions_are_checked_field_by_field() {
        let dist = |d: &str| insert(&format!("count = 10\nradius_distribution = {{ {d} }}"));
        let m = dist("kind = \"uniform\", min = 0.006, max = 0.004");
        assert!(
            m.contains("radius_distribution.max: 0.004 is below min"),
            "{m}"
        );
        let m = dist("kind = \"normal\", mean = 0.005, std_dev = nan, min = 0.004, max = 0.006");
        assert!(m.contains("radius_distribution.std_dev: NaN"), "{m}");
        let m = dist("kind = \"normal\", mean = 0.007, std_dev = 0.001, min = 0.004, max = 0.006");
        assert!(
            m.contains("radius_distribution.mean: 0.007 is not allowed"),
            "{m}"
        );
        // A window holding (almost) nothing of the distribution would hang the rejection sampler.
        for (lo, hi) in [(0.005, 0.005), (0.005, 0.005000001)] {
            let m = dist(&format!(
                "kind = \"normal\", mean = 0.005, std_dev = 0.001, min = {lo}, max = {hi}"
            ));
            assert!(m.contains("radius_distribution.std_dev: only"), "{m}");
        }
        let ok = "kind = \"normal\", mean = 0.005, std_dev = 0.001, min = 0.005, max = 0.0051";
        assert_eq!(dist(ok), "ok");
    }

    #[test]
    fn impossible_or_gigantic_insertions_are_refused_before_drawing() {
        let m = insert("count = 1000000000000\nradius = 0.005");
        assert!(m.contains("count:") && m.contains("ask for fewer"), "{m}");
        let m = insert("count = 1000000000000\nradius = 1e-9");
        assert!(
            m.contains("count:") && m.contains("more than the 1e8"),
            "{m}"
        );
        let m = insert("volume_fraction = 0.5\nradius = 1e-6");
        assert!(
            m.contains("volume_fraction:") && m.contains("more than the 1e8"),
            "{m}"
        );
        let m = insert("count = 1\nradius = 0.06");
        assert!(m.contains("region_max:") && m.contains("narrower"), "{m}");
    }

    #[test]
    fn normal_cdf_matches_known_values() {
        for (x, p) in [
            (0.0, 0.5),
            (1.0, 0.841_344_7),
            (-1.96, 0.024_997_9),
            (3.0, 0.998_650_1),
        ] {
            assert!(
                (normal_cdf(x) - p).abs() < 2e-7,
                "Φ({x}) = {}",
                normal_cdf(x)
            );
        }
    }
}
