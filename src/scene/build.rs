//! [`Scene::build`]: the world a scene file describes, with every check that needs more than
//! the file's form (overlaps, time step, names of walls and meters).

use super::*;
use prepared::{inserted_body, orientation_stream, plane_obstacles, shape_size, sphere};

impl Scene {
    /// Builds the world: materials and their pairs, walls, particles and insertions; checks the
    /// initial overlaps and the time step.
    pub fn build(&self) -> Result<Prepared, SceneError> {
        let spec = &self.spec;
        let materials: Vec<Material> = spec
            .materials
            .iter()
            .map(|m| Material {
                name: m.name.clone(),
                density: m.density,
                youngs_modulus: m.youngs_modulus,
                poisson_ratio: m.poisson_ratio,
                restitution: m.restitution,
                friction: m.friction,
                rolling_friction: m.rolling_friction,
            })
            .collect();
        let normal = match spec.contact.normal {
            NormalModel::Hertz => NormalLaw::Hertz,
            NormalModel::Linear => NormalLaw::Linear {
                stiffness: spec.contact.stiffness.ok_or_else(|| {
                    self.error(
                        KeyPath::table("contact").key("stiffness"),
                        "normal = \"linear\" needs `stiffness` [N/m]",
                    )
                })?,
            },
        };
        let mut overrides = Vec::new();
        for (n, p) in spec.pairs.iter().enumerate() {
            let key = KeyPath::entry("pair", n).key("materials");
            let a = self.material_index(&p.materials[0], key.clone())?;
            let b = self.material_index(&p.materials[1], key)?;
            overrides.push((
                (a as usize, b as usize),
                PairOverride {
                    restitution: p.restitution,
                    friction: p.friction,
                    rolling_friction: p.rolling_friction,
                },
            ));
        }
        let pair_laws = PairTable::new(
            &materials,
            normal,
            spec.contact.tangential_stiffness_ratio,
            &overrides,
        );

        let mut planes = Vec::new();
        for (n, p) in spec.planes.iter().enumerate() {
            planes.push(Plane {
                point: DVec3::from(p.point),
                normal: DVec3::from(p.normal).normalize(),
                material: self
                    .material_index(&p.material, KeyPath::entry("plane", n).key("material"))?,
            });
        }

        let mesh_walls = walls::build(self)?;
        let shapes = shapes::build(self)?;
        let bodies = self.bodies(&shapes, &plane_obstacles(&planes), &mesh_walls)?;
        let overlapping = self.check_initial_overlaps(&bodies, &planes)?;
        // Sides first: a body behind a wall also overlaps it, and the side is the fault.
        self.check_mesh_wall_sides(&bodies, &mesh_walls, self.falling_direction())?;
        self.check_bodies_behind_closed_walls(&bodies, &mesh_walls)?;
        self.check_mesh_wall_overlaps(&bodies, &mesh_walls)?;
        let mut schedule = Vec::new();
        for (index, i) in spec.insertions.iter().enumerate() {
            if i.time > 0.0 || i.every.is_some() {
                let key = KeyPath::entry("insert", index).key("material");
                let first = i.time > 0.0;
                schedule.push(ScheduledInsertion {
                    index,
                    spec: i.clone(),
                    material: self.material_index(&i.material, key)?,
                    shape: self.shape_of(&shapes, i.shape.as_deref(), index)?,
                    next_time: if first {
                        i.time
                    } else {
                        i.every.unwrap_or(0.0)
                    },
                    done: u64::from(!first),
                });
            }
        }

        let flow_meters = self.flow_meters()?;
        let gravity_table = self.gravity_table()?;
        let gravity = DVec3::from(spec.simulation.gravity());
        // The time step allows for the fastest fall any stage of the run brings.
        let strongest = gravity_table
            .iter()
            .flat_map(|t| t.knots().iter().map(|&(_, g)| g))
            .fold(gravity, |a, g| if g.length() > a.length() { g } else { a });
        let (time_step, estimate, automatic) = self.time_step(time_step::StepInputs {
            bodies: &bodies,
            schedule: &schedule,
            materials: &materials,
            planes: &planes,
            mesh_walls: &mesh_walls,
            law: normal,
            gravity: strongest,
        })?;
        let extent = self.extent(&bodies, &planes, &mesh_walls);
        let impact_speed = self.impact_speed(strongest, &bodies, &mesh_walls);
        self.check_threads()?;
        let world = World::new(WorldConfig {
            time_step,
            gravity,
            materials,
            pair_laws,
            planes,
            broad_phase: spec.simulation.broad_phase,
            skin: spec.simulation.skin,
            threads: spec.simulation.threads,
        })
        .map_err(|e| {
            self.error(
                KeyPath::table("simulation").key("threads"),
                format!("cannot start the worker threads: {e}"),
            )
        })?
        .with_polyhedral_law(spec.contact.polyhedra)
        .with_mesh_walls(mesh_walls)
        .with_flow_meters(flow_meters);
        let world = match gravity_table {
            Some(table) => world.with_gravity_table(table),
            None => world,
        };
        let mut world = match &spec.domain {
            Some(d) => world.with_domain(crate::math::Aabb::new(
                DVec3::from(d.min),
                DVec3::from(d.max),
            )),
            None => world,
        };
        world.reserve_bodies(bodies.len());
        for (init, _) in bodies {
            world.add_body(init);
        }
        // The overlaps present at the start are contacts from the first report on. (Only when
        // there are any: the first step finds the contacts anyway, and finding them here, with
        // the scene's working memory still held, raised the peak memory by a tenth.)
        if overlapping || !world.mesh_walls().is_empty() {
            world.update_contacts();
        }
        // Their springs push bodies apart: the lightest body could take all their energy.
        let release_speed = {
            let b = world.bodies();
            let lightest = b.mass.iter().copied().fold(f64::INFINITY, f64::min);
            let elastic: f64 = world
                .contacts()
                .iter()
                .map(|c| c.report.elastic_energy)
                .sum();
            if lightest.is_finite() && lightest > 0.0 {
                (2.0 * elastic / lightest).sqrt()
            } else {
                0.0
            }
        };
        let speed_limit = (10.0 * impact_speed.max(release_speed)).max(1.0);
        let duration = spec.simulation.duration;
        Ok(Prepared {
            world,
            duration,
            output_interval: spec
                .output
                .vtk_interval
                .or(spec.simulation.output_interval)
                .unwrap_or(duration / 100.0),
            csv_interval: spec
                .output
                .csv_interval
                .or(spec.simulation.output_interval)
                .unwrap_or(duration / 100.0),
            checkpoint_interval: spec.output.checkpoint_interval,
            speed_limit,
            watchdog: spec.simulation.watchdog,
            estimate,
            automatic_time_step: automatic,
            schedule,
            output: crate::io::output::OutputOptions {
                force_network: spec.output.force_network,
                packing_region: spec
                    .output
                    .packing_region
                    .as_ref()
                    .map(|r| crate::math::Aabb::new(DVec3::from(r.min), DVec3::from(r.max))),
                extent,
                wall_names: self.wall_names()?,
            },
            notes: shapes
                .iter()
                .filter_map(|(name, b)| b.note.as_ref().map(|n| format!("[shape.{name}] {n}")))
                .collect(),
            shape_names: shapes
                .iter()
                .map(|(name, b)| (name.clone(), b.shape.clone()))
                .collect(),
        })
    }

    /// Where the scene happens: its bodies at the start, insertion regions, plane walls' points,
    /// mesh walls and the domain (for drawing plane walls as far as that). `None` for a scene of
    /// nothing.
    fn extent(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        planes: &[Plane],
        mesh_walls: &[crate::wall::MeshWall],
    ) -> Option<crate::math::Aabb> {
        use crate::math::Aabb;
        let spec = &self.spec;
        let boxes = bodies
            .iter()
            .map(|(b, _)| Aabb::around_sphere(b.position, b.shape.bounding_radius()))
            .chain(spec.insertions.iter().map(|i| {
                let (lo, hi) = i.bounds();
                Aabb::new(DVec3::from(lo), DVec3::from(hi))
            }))
            .chain(planes.iter().map(|p| Aabb::new(p.point, p.point)))
            .chain(mesh_walls.iter().map(|w| w.bounds()))
            .chain(
                spec.domain
                    .iter()
                    .map(|d| Aabb::new(DVec3::from(d.min), DVec3::from(d.max))),
            );
        boxes.reduce(|a, b| a.union(&b))
    }

    /// Refuses more worker threads than any use of this machine could want (`--threads 100000`
    /// tried to start them all): 16 per core, and at least 64.
    fn check_threads(&self) -> Result<(), SceneError> {
        let threads = self.spec.simulation.threads;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let most = (16 * cores).max(64);
        if threads > most {
            return Err(self.error(
                KeyPath::table("simulation").key("threads"),
                format!(
                    "{threads} threads on a machine with {cores} cores: at most {most} are \
                     allowed, and more than one per core gains nothing; 0 takes one per core"
                ),
            ));
        }
        Ok(())
    }

    /// The direction bodies fall at the start: gravity, or under a gravity table its first
    /// non-zero row (zero if there is none).
    fn falling_direction(&self) -> DVec3 {
        let sim = &self.spec.simulation;
        let first = DVec3::from(sim.gravity());
        if first != DVec3::ZERO {
            return first;
        }
        sim.gravity_table
            .iter()
            .flatten()
            .map(|r| DVec3::new(r[1], r[2], r[3]))
            .find(|g| *g != DVec3::ZERO)
            .unwrap_or(DVec3::ZERO)
    }

    /// `[simulation] gravity_table`, checked.
    fn gravity_table(&self) -> Result<Option<TimeTable<DVec3>>, SceneError> {
        let sim = &self.spec.simulation;
        let Some(rows) = &sim.gravity_table else {
            return Ok(None);
        };
        let key = KeyPath::table("simulation").key("gravity_table");
        if sim.gravity.is_some() {
            return Err(self.error(
                key,
                "give either `gravity` (constant) or `gravity_table`, not both",
            ));
        }
        let knots = rows
            .iter()
            .map(|r| (r[0], DVec3::new(r[1], r[2], r[3])))
            .collect();
        TimeTable::new(knots)
            .map(Some)
            .map_err(|e| self.error(key, format!("{e} (rows are [time, gx, gy, gz])")))
    }

    /// The names of the walls in `wall_forces.csv`: planes first, then mesh walls, each its
    /// `name` or `wallN`; checked to be usable as column heads and distinct.
    fn wall_names(&self) -> Result<Vec<String>, SceneError> {
        let spec = &self.spec;
        let given =
            spec.planes
                .iter()
                .enumerate()
                .map(|(n, p)| (KeyPath::entry("plane", n).key("name"), p.name.as_ref()))
                .chain(
                    spec.mesh_walls.iter().enumerate().map(|(n, w)| {
                        (KeyPath::entry("mesh_wall", n).key("name"), w.name.as_ref())
                    }),
                );
        let mut names: Vec<String> = Vec::new();
        for (w, (key, name)) in given.enumerate() {
            let name = match name {
                None => format!("wall{w}"),
                Some(name) => {
                    if !usable_as_column(name) {
                        return Err(self.error(
                            key,
                            format!(
                                "{name:?}: a wall's name heads its columns in wall_forces.csv; \
                                 use letters, digits, `_` and `-`"
                            ),
                        ));
                    }
                    name.clone()
                }
            };
            if names.contains(&name) {
                return Err(self.error(
                    key,
                    format!("two walls are called {name:?}: give each its own name"),
                ));
            }
            names.push(name);
        }
        Ok(names)
    }

    /// The `[[output.flow_meter]]`s.
    fn flow_meters(&self) -> Result<Vec<FlowMeter>, SceneError> {
        let mut meters: Vec<FlowMeter> = Vec::new();
        for (n, m) in self.spec.output.flow_meters.iter().enumerate() {
            let key = |k: &str| KeyPath::table("output").key(&format!("flow_meter[{n}].{k}"));
            if !usable_as_column(&m.name) {
                return Err(self.error(
                    key("name"),
                    format!(
                        "{:?}: a meter's name heads its columns in flow.csv; use letters, digits, \
                         `_` and `-`",
                        m.name
                    ),
                ));
            }
            if meters.iter().any(|other| other.name == m.name) {
                return Err(self.error(
                    key("name"),
                    format!(
                        "two flow meters are called {:?}: give each its own name",
                        m.name
                    ),
                ));
            }
            let finite = |v: [f64; 3]| crate::math::is_finite_vec(DVec3::from(v));
            let surface = match (m.point, m.normal, m.min, m.max) {
                (Some(point), Some(normal), None, None) => {
                    let normal = DVec3::from(normal)
                        .try_normalize()
                        .filter(|_| finite(point))
                        .ok_or_else(|| {
                            self.error(
                                key("normal"),
                                "point and normal must be finite, the normal non-zero",
                            )
                        })?;
                    FlowSurface::Plane {
                        point: DVec3::from(point),
                        normal,
                    }
                }
                (None, None, Some(min), Some(max)) => {
                    let (lo, hi) = (DVec3::from(min), DVec3::from(max));
                    if !(finite(min) && finite(max)) || lo.cmpge(hi).any() {
                        return Err(self.error(
                            key("max"),
                            "min and max must be finite, max greater than min on every axis",
                        ));
                    }
                    FlowSurface::RegionOutflow(crate::math::Aabb::new(lo, hi))
                }
                _ => {
                    return Err(self.error(
                        key("point"),
                        "give `point` and `normal` (flow through a plane) or `min` and `max` \
                         (flow out of a box), not a mix",
                    ))
                }
            };
            meters.push(FlowMeter::new(m.name.clone(), surface));
        }
        Ok(meters)
    }

    /// Every body the scene places, in file order: single particles, then each insertion. Each
    /// comes with the key that placed it, for messages.
    fn bodies(
        &self,
        shapes: &BTreeMap<String, shapes::BuiltShape>,
        planes: &[insert::PlaneObstacle],
        meshes: &[crate::wall::MeshWall],
    ) -> Result<Vec<(BodyInit, KeyPath)>, SceneError> {
        let mut bodies = Vec::new();
        let mut placed: Vec<Placed> = Vec::new();
        for (n, p) in self.spec.particles.iter().enumerate() {
            let key = KeyPath::entry("particle", n);
            let material = self.material_index(&p.material, key.clone().key("material"))?;
            let position = DVec3::from(p.position);
            let velocity = DVec3::from(p.velocity);
            let mut body = match (p.radius, &p.shape) {
                (Some(radius), None) => sphere(radius, material, position, velocity),
                (None, Some(name)) => {
                    let built = self.named_shape(shapes, name, key.clone().key("shape"))?;
                    let rotation = DQuat::from_scaled_axis(DVec3::from(p.rotation));
                    let (position, orientation) = built.pose(position, rotation);
                    BodyInit {
                        shape: built.shape.clone(),
                        material,
                        position,
                        orientation,
                        velocity,
                        angular_velocity: DVec3::ZERO,
                    }
                }
                _ => {
                    return Err(self.error(
                        key.key("radius"),
                        "give exactly one of `radius` (a sphere) and `shape` (a [shape.NAME])",
                    ))
                }
            };
            body.angular_velocity = DVec3::from(p.angular_velocity);
            placed.push(Placed {
                centre: body.position,
                radius: body.shape.bounding_radius(),
            });
            bodies.push((body, key));
        }
        for (n, spec) in self.spec.insertions.iter().enumerate() {
            if spec.time > 0.0 {
                continue; // happens during the run
            }
            let key = KeyPath::entry("insert", n);
            let material = self.material_index(&spec.material, key.clone().key("material"))?;
            let shape = self.shape_of(shapes, spec.shape.as_deref(), n)?;
            let size = shape.as_ref().map(shape_size);
            let new = insert::insert(spec, size, &placed, planes, meshes, 0)
                .map_err(|e| self.error(key.clone(), e.message))?;
            let mut orientations = orientation_stream(spec, 0);
            for p in &new {
                let body = inserted_body(spec, shape.as_ref(), material, p, &mut orientations);
                bodies.push((body, key.clone()));
            }
            placed.extend(new);
        }
        Ok(bodies)
    }

    fn named_shape<'s>(
        &self,
        shapes: &'s BTreeMap<String, shapes::BuiltShape>,
        name: &str,
        key: KeyPath,
    ) -> Result<&'s shapes::BuiltShape, SceneError> {
        shapes.get(name).ok_or_else(|| {
            let known: Vec<&String> = shapes.keys().collect();
            self.error(
                key,
                format!("no shape named '{name}'; the scene defines {known:?} ([shape.NAME])"),
            )
        })
    }

    /// The shape an insertion places, if it names one.
    fn shape_of(
        &self,
        shapes: &BTreeMap<String, shapes::BuiltShape>,
        name: Option<&str>,
        index: usize,
    ) -> Result<Option<shapes::BuiltShape>, SceneError> {
        name.map(|name| {
            self.named_shape(shapes, name, KeyPath::entry("insert", index).key("shape"))
                .cloned()
        })
        .transpose()
    }

    /// Refuses bodies that start overlapping a mesh wall by more than the tolerance (times the
    /// sphere's radius, or the polyhedron's volume-equivalent radius; for a polyhedron the
    /// overlap is the mean depth of the run's volume-law contact, as between bodies).
    fn check_mesh_wall_overlaps(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        walls: &[crate::wall::MeshWall],
    ) -> Result<(), SceneError> {
        let tolerance = self.spec.simulation.initial_overlap_tolerance;
        for (b, key) in bodies {
            for (n, wall) in walls.iter().enumerate() {
                let contacts = match &b.shape {
                    Shape::Sphere(s) => {
                        crate::narrow_phase::sphere_mesh(b.position, s.radius, wall)
                    }
                    Shape::Convex(p) => crate::narrow_phase::convex_mesh(
                        p,
                        b.position,
                        b.orientation,
                        wall,
                        crate::contact_law::PolyhedralLaw::Volume,
                    ),
                    Shape::NonConvex(p) => {
                        let mut found = Vec::new();
                        crate::narrow_phase::nonconvex_mesh_contacts(
                            p,
                            b.position,
                            b.orientation,
                            wall,
                            &mut Default::default(),
                            &mut found,
                        );
                        found
                    }
                };
                let deepest = contacts.iter().map(|g| g.overlap).fold(0.0, f64::max);
                if deepest > tolerance * b.shape.equivalent_radius() {
                    return Err(self.error(
                        key.clone(),
                        format!(
                            "the particle at {:?} overlaps [[mesh_wall]] #{} by {deepest:.3e} m; \
                             move it to the side the wall faces",
                            b.position.to_array(),
                            n + 1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Refuses a start in which bodies overlap each other or a wall by more than the tolerance:
    /// such a start would fire bodies apart with energy the user never put in. Returns whether
    /// any body overlaps at all (within the tolerance).
    fn check_initial_overlaps(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        planes: &[Plane],
    ) -> Result<bool, SceneError> {
        use crate::broad_phase::{BroadPhase, CellGrid};
        use crate::math::Aabb;
        let tolerance = self.spec.simulation.initial_overlap_tolerance;
        let radius = |b: &BodyInit| b.shape.bounding_radius();
        let boxes: Vec<Aabb> = bodies
            .iter()
            .map(|(b, _)| Aabb::around_sphere(b.position, radius(b)))
            .collect();
        let mut pairs = Vec::new();
        CellGrid::default().find_pairs(&boxes, &mut pairs);
        let mut scratch = crate::narrow_phase::ClipScratch::default();
        let mut overlapping = false;
        for (i, j) in pairs {
            let ((a, key_a), (b, key_b)) = (&bodies[i as usize], &bodies[j as usize]);
            // The contact detection of the run itself: mean depth for polyhedra.
            let overlap = crate::narrow_phase::body_body(
                posed(a),
                posed(b),
                crate::contact_law::PolyhedralLaw::Volume,
                &mut scratch,
            )
            .map_or(0.0, |g| g.overlap);
            let size = |b: &BodyInit| b.shape.equivalent_radius();
            let allowed = tolerance * size(a).min(size(b));
            overlapping |= overlap > 0.0;
            if overlap > allowed {
                return Err(self.error(
                    key_b.clone(),
                    format!(
                        "this particle at {:?} overlaps {key_a} at {:?} by {overlap:.3e} m, more \
                         than initial_overlap_tolerance allows ({allowed:.3e} m); move them apart",
                        b.position.to_array(),
                        a.position.to_array()
                    ),
                ));
            }
        }
        for (b, key) in bodies {
            for (n, plane) in planes.iter().enumerate() {
                let overlap = depth_behind_plane(b, plane);
                overlapping |= overlap > 0.0;
                if overlap > tolerance * b.shape.equivalent_radius() {
                    return Err(self.error(
                        key.clone(),
                        format!(
                            "the particle at {:?} overlaps [[plane]] #{} by {overlap:.3e} m (or \
                             lies behind it); move it to the side the plane's normal points to",
                            b.position.to_array(),
                            n + 1
                        ),
                    ));
                }
            }
        }
        Ok(overlapping)
    }
}

/// Whether `name` can head CSV columns as it is: letters, digits, `_` and `-`.
fn usable_as_column(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}
fn posed(b: &BodyInit) -> crate::narrow_phase::Posed<'_> {
    crate::narrow_phase::Posed {
        shape: &b.shape,
        position: b.position,
        orientation: b.orientation,
    }
}

/// How far a body reaches behind a plane (negative: the gap in front of it).
fn depth_behind_plane(b: &BodyInit, plane: &Plane) -> f64 {
    let height = |x: DVec3| (x - plane.point).dot(plane.normal);
    match &b.shape {
        Shape::Sphere(s) => s.radius - height(b.position),
        Shape::Convex(p) => -p
            .vertices()
            .iter()
            .map(|&v| height(b.position + b.orientation * v))
            .fold(f64::INFINITY, f64::min),
        Shape::NonConvex(p) => -p
            .vertices()
            .iter()
            .map(|&v| height(b.position + b.orientation * v))
            .fold(f64::INFINITY, f64::min),
    }
}
