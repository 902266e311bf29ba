//! A built scene ready to run ([`Prepared`]), and the insertions it does during the run.

use super::*;

/// A world ready to run, with the facts the run needs and the user should be told.
pub struct Prepared {
    pub world: World,
    pub duration: f64,
    /// Simulated seconds between VTK frames.
    pub output_interval: f64,
    /// Simulated seconds between rows of the CSV series (`energy.csv`, `wall_forces.csv`,
    /// `flow.csv`).
    pub csv_interval: f64,
    /// Simulated seconds between checkpoints (`[output] checkpoint_interval`); `None`: only at
    /// the end and when interrupted.
    pub checkpoint_interval: Option<f64>,
    /// No body goes faster in a sound run [m/s]: ten times the fastest impact the scene can
    /// bring (initial and insertion speeds, a fall across the whole scene, walls' surfaces).
    pub speed_limit: f64,
    /// Whether the watchdog stops the run or warns (`[simulation] watchdog`).
    pub watchdog: format::WatchdogMode,
    /// The stable-step estimate, and whether the step was chosen automatically.
    pub estimate: timestep::Estimate,
    pub automatic_time_step: bool,
    /// Insertions still to come during the run, in file order.
    pub schedule: Vec<ScheduledInsertion>,
    /// What the run writes beyond the defaults.
    pub output: crate::io::output::OutputOptions,
    /// What building the scene repaired or decided that the user should know (welded mesh
    /// vertices, turned triangles).
    pub notes: Vec<String>,
    /// The scene's `[shape.NAME]`s, by name (for the outputs' `shape` numbers).
    pub shape_names: Vec<(String, Shape)>,
}

/// An `[[insert]]` that happens during the run, once or repeatedly.
#[derive(Clone, Debug)]
pub struct ScheduledInsertion {
    /// Which `[[insert]]` of the file (from 0).
    pub index: usize,
    pub spec: format::InsertSpec,
    pub material: u32,
    /// The shape inserted, or `None` for spheres of the spec's radius or distribution.
    pub shape: Option<shapes::BuiltShape>,
    /// Simulated time of the next insertion [s].
    pub next_time: f64,
    /// Insertions done so far (varies the random stream of repeats).
    pub done: u64,
}

/// What one insertion during the run did.
#[derive(Clone, Debug, PartialEq)]
pub struct InsertionReport {
    pub index: usize,
    pub time: f64,
    pub inserted: usize,
    /// Set when fewer spheres than asked for fitted: why.
    pub shortfall: Option<String>,
}

impl Prepared {
    /// Simulated time of the next scheduled insertion, if any.
    pub fn next_insertion_time(&self) -> Option<f64> {
        self.schedule.iter().map(|s| s.next_time).reduce(f64::min)
    }

    /// Does every insertion due at the world's current time (to within half a step), placing the
    /// spheres that fit among the bodies present now.
    pub fn insert_due(&mut self) -> Vec<InsertionReport> {
        let world = &mut self.world;
        let now = world.time() + 0.5 * world.time_step();
        let mut reports = Vec::new();
        for s in self.schedule.iter_mut().filter(|s| s.next_time <= now) {
            let existing: Vec<Placed> = (0..world.bodies().len())
                .map(|i| Placed {
                    centre: world.bodies().position[i],
                    radius: world.bodies().bounding_radius[i],
                })
                .collect();
            let planes = plane_obstacles(world.planes());
            let size = s.shape.as_ref().map(shape_size);
            let (placed, shortfall) = match insert::insert(
                &s.spec,
                size,
                &existing,
                &planes,
                world.mesh_walls(),
                s.done,
            ) {
                Ok(placed) => (placed, None),
                Err(e) => (e.placed, Some(e.message)),
            };
            let mut orientations = orientation_stream(&s.spec, s.done);
            for p in &placed {
                world.insert_body(inserted_body(
                    &s.spec,
                    s.shape.as_ref(),
                    s.material,
                    p,
                    &mut orientations,
                ));
            }
            reports.push(InsertionReport {
                index: s.index,
                time: world.time(),
                inserted: placed.len(),
                shortfall,
            });
            s.done += 1;
            let until = s.spec.until.unwrap_or(f64::INFINITY);
            s.next_time = match s.spec.every {
                Some(every) if s.next_time + every <= until + 0.5 * world.time_step() => {
                    s.next_time + every
                }
                _ => f64::INFINITY,
            };
        }
        self.schedule.retain(|s| s.next_time.is_finite());
        reports
    }
}

pub(super) fn shape_size(shape: &shapes::BuiltShape) -> insert::ShapeSize {
    insert::ShapeSize {
        bounding_radius: shape.shape.bounding_radius(),
        volume: shape.shape.unit_mass_properties().volume,
    }
}

/// The random orientations of one insertion: its own stream, so that turning random orientation
/// on or off does not move the bodies.
pub(super) fn orientation_stream(
    spec: &format::InsertSpec,
    repetition: u64,
) -> crate::rng::SplitMix64 {
    crate::rng::SplitMix64::new(
        spec.seed ^ 0x0123_4567_89AB_CDEF ^ repetition.wrapping_mul(0x9E37_79B9_7F4A_7C15),
    )
}

/// The body an insertion puts at a placed bounding sphere.
pub(super) fn inserted_body(
    spec: &format::InsertSpec,
    shape: Option<&shapes::BuiltShape>,
    material: u32,
    placed: &Placed,
    orientations: &mut crate::rng::SplitMix64,
) -> BodyInit {
    let velocity = DVec3::from(spec.initial_velocity());
    match shape {
        None => sphere(placed.radius, material, placed.centre, velocity),
        Some(built) => {
            let rotation = if spec.random_orientation {
                shapes::random_rotation(orientations)
            } else {
                DQuat::IDENTITY
            };
            BodyInit {
                shape: built.shape.clone(),
                material,
                // The bounding sphere is centred on the centre of mass.
                position: placed.centre,
                orientation: (rotation * built.principal).normalize(),
                velocity,
                angular_velocity: DVec3::ZERO,
            }
        }
    }
}

pub(super) fn plane_obstacles(planes: &[Plane]) -> Vec<insert::PlaneObstacle> {
    planes
        .iter()
        .map(|p| insert::PlaneObstacle {
            point: p.point,
            normal: p.normal,
        })
        .collect()
}

pub(super) fn sphere(radius: f64, material: u32, position: DVec3, velocity: DVec3) -> BodyInit {
    BodyInit {
        shape: Shape::Sphere(Sphere::new(radius)),
        material,
        position,
        orientation: DQuat::IDENTITY,
        velocity,
        angular_velocity: DVec3::ZERO,
    }
}
