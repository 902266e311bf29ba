//! Range checks on a parsed scene: every number finite and within what the physics allows.

use super::format::{InsertSpec, RadiusDistribution, TimeStep, Vec3};
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
    c.vector(sim.clone().key("gravity"), s.simulation.gravity)?;
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
        c.positive(key("density"), m.density, "kg/m³")?;
        c.positive(key("youngs_modulus"), m.youngs_modulus, "Pa")?;
        c.open_range(key("poisson_ratio"), m.poisson_ratio, -1.0, 0.5)?;
        c.restitution(key("restitution"), m.restitution)?;
        c.non_negative(key("friction"), m.friction, "")?;
        c.non_negative(key("rolling_friction"), m.rolling_friction, "")?;
    }
    for (n, p) in s.pairs.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("pair", n).key(k);
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
        if p.normal.iter().all(|&v| v == 0.0) {
            return Err(scene.error(key("normal"), "the normal must not be the zero vector"));
        }
    }
    for (n, p) in s.particles.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("particle", n).key(k);
        c.positive(key("radius"), p.radius, "m")?;
        c.vector(key("position"), p.position)?;
        c.vector(key("velocity"), p.velocity)?;
        c.vector(key("angular_velocity"), p.angular_velocity)?;
    }
    for (n, i) in s.insertions.iter().enumerate() {
        check_insertion(&c, n, i)?;
    }
    Ok(())
}

fn check_insertion(c: &Checker, n: usize, i: &InsertSpec) -> Result<(), SceneError> {
    let key = |k: &str| KeyPath::entry("insert", n).key(k);
    c.vector(key("region_min"), i.region_min)?;
    c.vector(key("region_max"), i.region_max)?;
    c.vector(key("velocity"), i.velocity)?;
    if (0..3).any(|a| i.region_max[a] <= i.region_min[a]) {
        return Err(c.scene.error(
            key("region_max"),
            "region_max must be greater than region_min on every axis",
        ));
    }
    match (i.count, i.volume_fraction) {
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
    match (i.radius, i.radius_distribution) {
        (Some(r), None) => c.positive(key("radius"), r, "m")?,
        (None, Some(d)) => {
            let key = key("radius_distribution");
            let (min, max) = match d {
                RadiusDistribution::Uniform { min, max } => (min, max),
                RadiusDistribution::Normal {
                    mean,
                    std_dev,
                    min,
                    max,
                } => {
                    c.positive(key.clone(), mean, "m (mean)")?;
                    c.positive(key.clone(), std_dev, "m (std_dev)")?;
                    if !(min..=max).contains(&mean) {
                        return Err(c.scene.error(key, "mean must lie between min and max"));
                    }
                    (min, max)
                }
            };
            c.positive(key.clone(), min, "m (min)")?;
            c.positive(key.clone(), max, "m (max)")?;
            if max < min {
                return Err(c.scene.error(key, "max must not be below min"));
            }
        }
        _ => {
            return Err(c.scene.error(
                key("radius"),
                "give exactly one of `radius` and `radius_distribution`",
            ))
        }
    }
    Ok(())
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
        if e > 0.0 && e <= 1.0 {
            Ok(())
        } else {
            Err(self
                .scene
                .error(key, format!("{e} is not allowed: must lie in (0, 1]")))
        }
    }

    fn vector(&self, key: KeyPath, v: Vec3) -> Result<(), SceneError> {
        for x in v {
            self.finite(key.clone(), x)?;
        }
        Ok(())
    }
}
