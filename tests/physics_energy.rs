//! The energy ledger: kinetic + potential + elastic + dissipated stays constant.
//!
//! (a) Elastic collisions (e = 1, μ = 0, no rolling resistance) of spheres in a closed box under
//!     gravity conserve kinetic + potential + elastic energy.
//! (b) With damping (e = 0.5), friction (μ = 0.5) and rolling resistance (μ_r = 0.1), spheres
//!     falling into a box come to rest; the ledger's total, which adds the dissipated energy, must
//!     still be constant.

use polydem::body::BodyInit;
use polydem::contact::Partner;
use polydem::contact_law::NormalLaw;
use polydem::material::{Material, PairTable};
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::wall::Plane;
use polydem::{World, WorldConfig};
use std::collections::BTreeSet;

const G: f64 = 9.81;

/// xorshift64*: a fixed, dependency-free pseudo-random sequence in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// The six inward-facing walls of the box [0, size.x] × [0, size.y] × [0, size.z].
fn box_planes(size: DVec3) -> Vec<Plane> {
    let wall = |point: DVec3, normal: DVec3| Plane {
        point,
        normal,
        material: 0,
    };
    vec![
        wall(DVec3::ZERO, DVec3::Z),
        wall(DVec3::new(0.0, 0.0, size.z), -DVec3::Z),
        wall(DVec3::ZERO, DVec3::X),
        wall(DVec3::new(size.x, 0.0, 0.0), -DVec3::X),
        wall(DVec3::ZERO, DVec3::Y),
        wall(DVec3::new(0.0, size.y, 0.0), -DVec3::Y),
    ]
}

fn world(material: Material, size: DVec3, dt: f64) -> World {
    let laws = PairTable::new(
        std::slice::from_ref(&material),
        NormalLaw::Hertz,
        2.0 / 7.0,
        &[],
    );
    World::new(WorldConfig {
        time_step: dt,
        gravity: DVec3::new(0.0, 0.0, -G),
        materials: vec![material],
        pair_laws: laws,
        planes: box_planes(size),
        broad_phase: Default::default(),
        skin: None,
        threads: 1,
    })
    .unwrap()
}

/// Spheres on a jittered lattice filling `size` with random velocities up to `speed` per component
/// and random spins.
fn fill(
    w: &mut World,
    rng: &mut Rng,
    count: (usize, usize, usize),
    size: DVec3,
    r: (f64, f64),
    speed: f64,
) {
    let cell = size / DVec3::new(count.0 as f64, count.1 as f64, count.2 as f64);
    for k in 0..count.2 {
        for j in 0..count.1 {
            for i in 0..count.0 {
                let radius = rng.range(r.0, r.1);
                let slack = 0.5 * cell.min_element() - radius;
                assert!(slack > 0.0);
                let centre = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * cell;
                let jitter = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let velocity = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                let spin = DVec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                w.add_body(BodyInit {
                    shape: Shape::Sphere(Sphere::new(radius)),
                    material: 0,
                    position: centre + jitter * (0.9 * slack),
                    orientation: DQuat::IDENTITY,
                    velocity: velocity * speed,
                    angular_velocity: spin * (speed / radius),
                });
            }
        }
    }
}

/// Every contact pair present now (plane contacts as (body, u32::MAX − plane)).
fn contact_pairs(w: &World) -> BTreeSet<(u32, u32)> {
    w.contacts()
        .iter()
        .map(|c| match c.key.partner {
            Partner::Body(b) => (c.key.a, b),
            Partner::Plane(p) => (c.key.a, u32::MAX - p),
            Partner::Mesh(_) => unreachable!("no mesh walls here"),
        })
        .collect()
}

/// Energy history of a run: (max |E_total − E_total(0)|, number of collisions, final report).
struct Run {
    initial: polydem::energy::EnergyReport,
    final_: polydem::energy::EnergyReport,
    max_drift: f64,
    collisions: usize,
    steps: u64,
}

/// Runs `duration` in chunks of `chunk` steps, recording the largest deviation of the ledger's
/// total and counting collisions (contacts that appear between two samples; a chunk is shorter
/// than any contact, so none is missed).
fn run(w: &mut World, duration: f64, chunk: u64) -> Run {
    let initial = w.energy();
    let e0 = initial.total();
    let mut max_drift: f64 = 0.0;
    let mut collisions = 0;
    let mut before = contact_pairs(w);
    let steps = (duration / w.time_step()).round() as u64;
    let mut done = 0;
    while done < steps {
        let n = chunk.min(steps - done);
        w.run_steps(n);
        done += n;
        max_drift = max_drift.max((w.energy().total() - e0).abs());
        let now = contact_pairs(w);
        collisions += now.difference(&before).count();
        before = now;
    }
    Run {
        initial,
        final_: w.energy(),
        max_drift,
        collisions,
        steps,
    }
}

/// Lowest gravitational potential the spheres can have: every centre one radius above the floor.
fn potential_floor(w: &World) -> f64 {
    (0..w.bodies().len())
        .map(|i| w.bodies().mass[i] * G * w.bodies().bounding_radius[i])
        .sum()
}

/// (a): relative drift of the total energy at `steps_per_contact` steps per (fastest) collision.
fn elastic_run(steps_per_contact: f64) -> (f64, usize) {
    let material = Material {
        name: "elastic".into(),
        density: 2500.0,
        youngs_modulus: 1e8,
        poisson_ratio: 0.25,
        restitution: 1.0,
        friction: 0.0,
        rolling_friction: 0.0,
    };
    // Hertz contact duration of a sphere–sphere collision at the largest relative speed (~4 m/s:
    // the spheres start at up to 1.7 m/s and fall through 0.1 m), the shortest contact of the run.
    let (r, v) = (0.008, 4.0);
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let e_star = 1e8 / (2.0 * (1.0 - 0.25 * 0.25));
    let (m_star, r_star) = (0.5 * m, 0.5 * r);
    let delta_max = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let t_c = 2.943 * delta_max / v;
    let size = DVec3::new(0.1, 0.1, 0.1);
    let mut w = world(material, size, t_c / steps_per_contact);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    fill(&mut w, &mut rng, (3, 3, 3), size, (0.008, 0.012), 1.0);
    let result = run(&mut w, 1.0, 10);
    // Scale: the mechanical energy above the lowest possible state (potential measured from the
    // floor, not from the arbitrary origin).
    let scale = result.initial.total() - potential_floor(&w);
    let drift = result.max_drift / scale;
    println!(
        "elastic, {steps_per_contact} steps/contact ({} steps): E(0) = {:.6e} J above rest, \
         {} collisions, max |E − E(0)|/E(0) = {drift:.3e}, final {:?}",
        result.steps, scale, result.collisions, result.final_
    );
    (drift, result.collisions)
}

#[test]
fn elastic_collisions_conserve_energy() {
    let (coarse, collisions) = elastic_run(40.0);
    let (fine, _) = elastic_run(80.0);
    assert!(collisions > 200, "only {collisions} collisions");
    // The brief's 0.1 %. Velocity Verlet conserves a shadow energy: the measured energy oscillates
    // by O((ω dt)²) of the energy inside the contacts during each contact and returns after it; the
    // kink of the Hertz force at δ = 0 (F ∝ δ^{3/2}) leaves a small lasting error per collision.
    assert!(fine < 1e-3 && coarse < 1e-3);
    // Second order: halving dt should reduce the drift about four-fold; require a halving.
    assert!(
        fine < 0.5 * coarse,
        "drift does not shrink with dt: {coarse:e} → {fine:e}"
    );
}

fn dissipative_run(steps_per_contact: f64) -> f64 {
    let material = Material {
        name: "lossy".into(),
        density: 2500.0,
        youngs_modulus: 1e8,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction: 0.1,
    };
    let (r, v) = (0.008, 3.0);
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let e_star = 1e8 / (2.0 * (1.0 - 0.25 * 0.25));
    let (m_star, r_star) = (0.5 * m, 0.5 * r);
    let delta_max = (15.0 * m_star * v * v / (16.0 * e_star * r_star.sqrt())).powf(0.4);
    let t_c = 2.943 * delta_max / v;
    let size = DVec3::new(0.08, 0.08, 0.3);
    let mut w = world(material, size, t_c / steps_per_contact);
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    fill(
        &mut w,
        &mut rng,
        (3, 3, 4),
        DVec3::new(0.08, 0.08, 0.12),
        (0.008, 0.012),
        0.5,
    );
    // Lift the spheres 0.1 m so that they fall into the box.
    for x in &mut w.bodies_mut().position {
        x.z += 0.1;
    }
    let result = run(&mut w, 1.5, 20);
    let f = result.final_;
    // Scale: the energy that the run converts into heat, E_total(0) minus the potential energy of
    // the final (resting) state. E_total(0) alone would not do: it contains the potential energy
    // relative to the arbitrary origin of coordinates, which no process touches.
    let scale = result.initial.total() - f.potential;
    let drift = result.max_drift / scale;
    println!(
        "dissipative, {steps_per_contact} steps/contact ({} steps): E(0) − E_pot(final) = {:.6e} J, \
         {} collisions, max |E_total − E_total(0)| / scale = {drift:.3e}, final kinetic {:.3e} J \
         (rotational {:.3e}), elastic {:.3e} J, dissipated {:.6e} J, contacts {}",
        result.steps,
        scale,
        result.collisions,
        f.kinetic_translational + f.kinetic_rotational,
        f.kinetic_rotational,
        f.elastic,
        f.dissipated,
        f.contacts
    );
    assert!(
        f.kinetic_translational + f.kinetic_rotational < 1e-3 * scale,
        "not at rest at the end"
    );
    drift
}

#[test]
fn dissipation_is_accounted_for() {
    let coarse = dissipative_run(40.0);
    let fine = dissipative_run(80.0);
    // The brief's 1 %. Two errors are expected, both O(dt): the ledger books the damping and
    // friction work of a step as F_{n+1}·(x_{n+1} − x_n), where the work velocity Verlet actually
    // does is ½(F_n + F_{n+1})·(x_{n+1} − x_n); and the damping uses a predicted velocity. With
    // the ledger fixed (see below) the error was measured at 2.5e-3 (40 steps/contact) and
    // 1.15e-3 (80), i.e. first order, hence the 0.75 ratio.
    //
    // Without that fix the error is ≈ 4.4e-2 at both steps: when a contact ends, the energy left
    // in its tangential (and rolling) spring disappears from `elastic` without being added to
    // `dissipated`. While sliding, the spring is set to ξ = −(F + γ v_t)/k_t (LAMMPS), so even as
    // N → 0 it keeps ½ k_t ξ² → ½ c² m* v_t², a dt-independent leak at every contact that
    // separates while sliding. Fix: `ContactList::update` returns the history-spring energy
    // (½ k_t |ξ|² + ½ |M_r|²/k_r) of the contacts it drops and `World::detect_contacts` adds it to
    // `dissipated` (the normal spring needs nothing: its energy → 0 with the overlap).
    assert!(
        fine < 0.01 && coarse < 0.01,
        "energy ledger off by {coarse:.2e} / {fine:.2e} of the dissipated energy: is the spring \
         energy of ended contacts booked as dissipated?"
    );
    assert!(
        fine < 0.75 * coarse,
        "ledger error does not shrink with dt: {coarse:e} → {fine:e}"
    );
}
