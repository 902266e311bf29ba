//! Broad-phase benchmark: time per update for moving bodies in a dilute gas, a dense packing and a
//! dense 1:20 bidisperse packing.

use crate::broad_phase::{BroadPhase, Method, Pair};
use crate::math::{Aabb, DVec3};
use crate::rng::SplitMix64;
use std::time::Instant;

/// The kinds of scene the broad phase is timed on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scene {
    /// Unit spheres at 5 % volume fraction placed at random (overlaps allowed, as in an ideal
    /// gas), each moving 2 % of its radius per step in a random direction, reflected at the walls
    /// of a cube.
    Gas,
    /// Unit spheres at 50 % volume fraction on a jittered cubic lattice (each touching about six
    /// neighbours, as in a settled bed), vibrating by 0.2 % of the radius per step.
    Packing,
    /// Spheres of radius 20 on a coarse cubic lattice with spheres of radius 1 filling the space
    /// between them on a fine lattice: sizes differing 1:20 in one dense scene, vibrating as
    /// `Packing`. The count is the total; small spheres are ~99.98 % of it.
    Bidisperse,
}

impl Scene {
    pub fn name(self) -> &'static str {
        match self {
            Scene::Gas => "gas",
            Scene::Packing => "packing",
            Scene::Bidisperse => "bidisperse 1:20",
        }
    }
}

/// Moving spheres: centres, radii and the motion applied each step.
pub struct Bodies {
    pub centre: Vec<DVec3>,
    pub radius: Vec<f64>,
    velocity: Vec<DVec3>,
    domain: Aabb,
    rng: SplitMix64,
    scene: Scene,
}

impl Bodies {
    /// About `n` bodies of the given scene (lattices are filled up to the nearest complete layer
    /// count not above `n`).
    pub fn new(scene: Scene, n: usize, seed: u64) -> Self {
        let mut rng = SplitMix64::new(seed);
        let (centre, radius, domain) = match scene {
            Scene::Gas => {
                let side = (n as f64 * 4.0 / 3.0 * std::f64::consts::PI / 0.05).cbrt();
                let centre = (0..n)
                    .map(|_| {
                        DVec3::new(
                            rng.uniform(1.0, side - 1.0),
                            rng.uniform(1.0, side - 1.0),
                            rng.uniform(1.0, side - 1.0),
                        )
                    })
                    .collect();
                (
                    centre,
                    vec![1.0; n],
                    Aabb::new(DVec3::ZERO, DVec3::splat(side)),
                )
            }
            Scene::Packing => {
                let per_side = (n as f64).cbrt().floor().max(1.0) as usize;
                let spacing = 2.0 * 0.99; // neighbours overlap slightly, as when settled
                let mut centre = Vec::with_capacity(n);
                for k in 0..per_side {
                    for j in 0..per_side {
                        for i in 0..per_side {
                            let jitter = DVec3::new(
                                rng.uniform(-0.01, 0.01),
                                rng.uniform(-0.01, 0.01),
                                rng.uniform(-0.01, 0.01),
                            );
                            centre
                                .push(DVec3::new(i as f64, j as f64, k as f64) * spacing + jitter);
                        }
                    }
                }
                while centre.len() < n {
                    // Top up with a partial layer so the count is exactly n.
                    let m = centre.len() - per_side.pow(3);
                    let (i, j) = (m % per_side, m / per_side);
                    centre.push(DVec3::new(i as f64, j as f64, per_side as f64) * spacing);
                }
                let side = (per_side + 1) as f64 * spacing;
                let count = centre.len();
                (
                    centre,
                    vec![1.0; count],
                    Aabb::new(DVec3::splat(-1.0), DVec3::splat(side)),
                )
            }
            Scene::Bidisperse => bidisperse(n, &mut rng),
        };
        let step = match scene {
            Scene::Gas => 0.02,
            _ => 0.002,
        };
        let velocity = centre
            .iter()
            .map(|_| random_direction(&mut rng) * step)
            .collect();
        Self {
            centre,
            radius,
            velocity,
            domain,
            rng,
            scene,
        }
    }

    pub fn len(&self) -> usize {
        self.centre.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centre.is_empty()
    }

    /// One step of motion: the gas moves ballistically (reflected at the walls), packings vibrate
    /// about their places with a fresh random direction every step.
    pub fn advance(&mut self) {
        for i in 0..self.centre.len() {
            if self.scene != Scene::Gas {
                let size = self.velocity[i].length();
                let dir = random_direction(&mut self.rng);
                // Alternate directions so vibrating bodies stay near their sites.
                self.velocity[i] = if self.velocity[i].dot(dir) > 0.0 {
                    -dir
                } else {
                    dir
                } * size;
            }
            let next = self.centre[i] + self.velocity[i];
            let r = self.radius[i];
            for axis in 0..3 {
                if next[axis] - r < self.domain.min[axis] || next[axis] + r > self.domain.max[axis]
                {
                    self.velocity[i][axis] = -self.velocity[i][axis];
                }
            }
            self.centre[i] += self.velocity[i];
        }
    }

    pub fn boxes(&self, out: &mut Vec<Aabb>) {
        out.clear();
        out.extend(
            self.centre
                .iter()
                .zip(&self.radius)
                .map(|(&c, &r)| Aabb::around_sphere(c, r)),
        );
    }
}

fn random_direction(rng: &mut SplitMix64) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-6 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

/// Big spheres (radius 20) on a coarse lattice, small ones (radius 1) on a fine lattice wherever
/// they do not overlap a big one, until `n` bodies.
fn bidisperse(n: usize, rng: &mut SplitMix64) -> (Vec<DVec3>, Vec<f64>, Aabb) {
    let (big, small): (f64, f64) = (20.0, 1.0);
    let coarse = 2.0 * big * 1.02;
    let fine = 2.0 * small * 0.99;
    // Each coarse cell holds one big sphere and the small ones around it.
    let per_cell = {
        let sites = (coarse / fine).floor() as usize;
        let mut count = 1;
        for k in 0..sites {
            for j in 0..sites {
                for i in 0..sites {
                    let p = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * fine;
                    if (p - DVec3::splat(coarse / 2.0)).length() > big + small {
                        count += 1;
                    }
                }
            }
        }
        count
    };
    let cells = ((n as f64 / per_cell as f64).cbrt().ceil() as usize).max(1);
    let sites = (coarse / fine).floor() as usize;
    let (mut centre, mut radius) = (Vec::with_capacity(n), Vec::with_capacity(n));
    'fill: for ck in 0..cells {
        for cj in 0..cells {
            for ci in 0..cells {
                let origin = DVec3::new(ci as f64, cj as f64, ck as f64) * coarse;
                let middle = origin + DVec3::splat(coarse / 2.0);
                centre.push(middle);
                radius.push(big);
                if centre.len() == n {
                    break 'fill;
                }
                for k in 0..sites {
                    for j in 0..sites {
                        for i in 0..sites {
                            let p =
                                origin + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * fine;
                            if (p - middle).length() > big + small {
                                let jitter = DVec3::new(
                                    rng.uniform(-0.01, 0.01),
                                    rng.uniform(-0.01, 0.01),
                                    rng.uniform(-0.01, 0.01),
                                );
                                centre.push(p + jitter);
                                radius.push(small);
                                if centre.len() == n {
                                    break 'fill;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    let side = cells as f64 * coarse;
    (
        centre,
        radius,
        Aabb::new(DVec3::splat(-big), DVec3::splat(side + big)),
    )
}

/// Timing of one broad phase on one scene.
#[derive(Clone, Debug)]
pub struct Timing {
    pub scene: Scene,
    pub bodies: usize,
    pub method: &'static str,
    /// Median over the timed steps [s].
    pub seconds_per_step: f64,
    /// Mean number of candidate pairs per step.
    pub pairs: f64,
}

/// Times `steps` updates of `method` on a scene of about `n` bodies after `warmup` untimed ones
/// (the first call of an incremental method does its full sort then).
pub fn time(scene: Scene, n: usize, method: Method, warmup: usize, steps: usize) -> Timing {
    let mut bodies = Bodies::new(scene, n, 1);
    let mut phase: Box<dyn BroadPhase> = method.build();
    let (mut boxes, mut pairs): (Vec<Aabb>, Vec<Pair>) = (Vec::new(), Vec::new());
    let mut samples = Vec::with_capacity(steps);
    let mut pair_total = 0usize;
    for step in 0..warmup + steps {
        bodies.advance();
        bodies.boxes(&mut boxes);
        let start = Instant::now();
        phase.find_pairs(&boxes, &mut pairs);
        let elapsed = start.elapsed().as_secs_f64();
        if step >= warmup {
            samples.push(elapsed);
            pair_total += pairs.len();
        }
    }
    samples.sort_by(f64::total_cmp);
    Timing {
        scene,
        bodies: bodies.len(),
        method: phase.name(),
        seconds_per_step: samples[samples.len() / 2],
        pairs: pair_total as f64 / steps as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad_phase::BruteForce;

    #[test]
    fn scenes_have_the_requested_size_and_packings_no_gross_overlaps() {
        for scene in [Scene::Gas, Scene::Packing, Scene::Bidisperse] {
            let b = Bodies::new(scene, 3000, 1);
            assert_eq!(b.len(), 3000, "{scene:?}");
            if scene == Scene::Gas {
                // An ideal gas: its bodies may overlap, only the density matters here.
                continue;
            }
            let mut boxes = Vec::new();
            b.boxes(&mut boxes);
            let mut pairs = Vec::new();
            BruteForce.find_pairs(&boxes, &mut pairs);
            for (i, j) in pairs {
                let (i, j) = (i as usize, j as usize);
                let gap = (b.centre[i] - b.centre[j]).length() - b.radius[i] - b.radius[j];
                // Packings overlap by about 1 % of the small radius, never more than 5 %.
                assert!(gap > -0.05, "{scene:?}: overlap {gap}");
            }
        }
        assert_eq!(
            Bodies::new(Scene::Bidisperse, 3000, 1)
                .radius
                .iter()
                .filter(|&&r| r == 20.0)
                .count(),
            1
        );
    }
}
