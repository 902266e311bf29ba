//! What the contacts do to the walls: the impulse and angular impulse each wall takes, and the work
//! moving walls do on the bodies (the energy they bring in).

use crate::contact::{ContactStore, Partner, Placement};
use crate::math::DVec3;
use crate::narrow_phase::ContactPoint;
use crate::step::prefetch::prefetch;
use crate::wall::{MeshWall, Plane, WallState};
use rayon::prelude::*;

/// The walls as they are: planes, mesh walls, each mesh wall's motion over the step and at its
/// end (`None` for a fixed wall), and the time the mesh walls' poses are at.
#[derive(Clone, Copy)]
pub struct WallsNow<'a> {
    pub planes: &'a [Plane],
    pub meshes: &'a [MeshWall],
    pub states: &'a [Option<[WallState; 2]>],
    pub time: f64,
}

/// How many wall entries ahead [`WallLoads::book`] asks for an entry's data.
const PREFETCH_AHEAD: usize = 16;

/// Running totals per wall (planes first, then mesh walls: the numbering of the output's `wall`).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct WallLoads {
    /// Time integral of the contact force on each wall since the start [N s].
    pub impulse: Vec<DVec3>,
    /// Time integral of the torque on each wall about its reference point (the rotation axis point
    /// of a mesh wall, the point of a plane) [N m s].
    pub angular_impulse: Vec<DVec3>,
    /// Work done on the bodies by moving walls (and belt surfaces) since the start [J].
    pub work: f64,
    /// Power of the wall forces at the last evaluation (for the trapezoidal work integral).
    power: f64,
    /// The wall entries that touch, and each one's share of this step (working memory of
    /// [`WallLoads::book`]).
    #[serde(skip)]
    touching: Vec<u32>,
    #[serde(skip)]
    shares: Vec<Share>,
}

/// What one wall entry adds to its wall's totals over a step.
#[derive(Clone, Copy, Debug, Default)]
struct Share {
    /// The wall's number; `u32::MAX` for an entry that adds nothing (apart, or a ghost's).
    wall: u32,
    impulse: DVec3,
    angular_impulse: DVec3,
    power: f64,
}

/// Wall entries per parallel work item of [`WallLoads::book`].
const SHARES_PER_ITEM: usize = 512;

impl WallLoads {
    /// Books the contacts' reactions on the walls over the step `dt` (0 for a fresh evaluation,
    /// which only sets the power the next step's work starts from). `wall_time` is when the mesh
    /// walls are where they are. A ghost's contacts are left to its owner (`Bodies::ghost`).
    /// `at`: where the bodies are, which the contact points the store does not keep are found
    /// again from.
    ///
    /// Each entry's share (its contact point found again, its force and moment read) is worked
    /// out in parallel; the shares are then added up one by one in entry order, the same sums
    /// as a single loop's, so the totals have the same bits for any thread count.
    pub fn book(&mut self, store: &ContactStore, at: Placement, walls: WallsNow, dt: f64) {
        let count = at.planes.len() + walls.meshes.len();
        self.impulse.resize(count, DVec3::ZERO);
        self.angular_impulse.resize(count, DVec3::ZERO);
        // Most wall entries do not touch (a sphere near a mesh wall has four slots, one of
        // which touches as a rule): their flags are read once, in order, and only the entries
        // that touch are worked out (the same shares in the same order).
        let flags = store.touching();
        self.touching.clear();
        self.touching
            .extend(store.wall_entries().iter().filter(|&&e| flags[e as usize]));
        let entries = &self.touching;
        entries
            .par_iter()
            .enumerate()
            .with_min_len(SHARES_PER_ITEM)
            .map(|(n, &e)| {
                // The wall entries are scattered over the store, which the contact loop has
                // passed over since: ask for an entry's lines some entries ahead (2.5 % of the
                // 65,000-sphere step went to waiting for them).
                if let Some(&ahead) = entries.get(n + PREFETCH_AHEAD) {
                    let ahead = ahead as usize;
                    prefetch(&store.keys()[ahead]);
                    prefetch(&store.loads()[ahead]);
                }
                // Half as far ahead, the entry's key is at hand: ask for its body's place and
                // shape, which a contact point the store does not keep is found again from (in
                // a world of spheres and planes, 1.4 % of the 65,000-sphere step waited for
                // them).
                if let Some(&ahead) = entries.get(n + PREFETCH_AHEAD / 2) {
                    let a = store.keys()[ahead as usize].a as usize;
                    prefetch(&at.bodies.position[a]);
                    prefetch(&at.bodies.shape[a]);
                }
                share(store, e as usize, at, walls, dt)
            })
            .collect_into_vec(&mut self.shares);
        let mut power = 0.0;
        for s in self.shares.iter().filter(|s| s.wall != u32::MAX) {
            let w = s.wall as usize;
            self.impulse[w] -= s.impulse;
            self.angular_impulse[w] -= s.angular_impulse;
            power += s.power;
        }
        // Trapezoidal rule over the step.
        self.work += 0.5 * dt * (self.power + power);
        self.power = power;
    }
}

/// What wall entry `e` adds to its wall's totals over the step `dt` (see [`WallLoads::book`]).
#[inline]
fn share(store: &ContactStore, e: usize, at: Placement, walls: WallsNow, dt: f64) -> Share {
    let (key, load) = (store.keys()[e], store.loads()[e]);
    if !store.touching()[e] || !at.bodies.counts(key.a as usize) {
        return Share {
            wall: u32::MAX,
            ..Share::default()
        };
    }
    // For a wall partner the load's second moment is the law's couple on the body.
    let (f, torque) = (load.force, load.torque_b);
    let ContactPoint {
        point: p,
        normal: n,
        ..
    } = store.contact_point(e, at);
    let mut power = 0.0;
    let (w, centre) = match key.partner {
        Partner::Plane(k) => (k as usize, walls.planes[k as usize].point),
        Partner::Mesh(m) => {
            let m = m as usize;
            let centre = match &walls.states[m] {
                // Fixed walls report torques about the origin of their reference placement.
                None => walls.meshes[m].motion.reference_point(walls.time),
                Some([_, at_end]) => {
                    power =
                        f.dot(at_end.surface_velocity(p, n)) + torque.dot(at_end.angular_velocity);
                    at_end.centre
                }
            };
            (walls.planes.len() + m, centre)
        }
        Partner::Body(_) => unreachable!("wall entries have wall partners"),
    };
    Share {
        wall: w as u32,
        impulse: f * dt,
        angular_impulse: ((p - centre).cross(f) + torque) * dt,
        power,
    }
}
