//! What the contacts do to the walls: the impulse and angular impulse each wall takes, and the work
//! moving walls do on the bodies (the energy they bring in).

use crate::contact::{ContactStore, Partner, Placement};
use crate::math::DVec3;
use crate::narrow_phase::ContactPoint;
use crate::step::prefetch::prefetch;
use crate::wall::{MeshWall, Plane, WallState};

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
}

impl WallLoads {
    /// Books the contacts' reactions on the walls over the step `dt` (0 for a fresh evaluation,
    /// which only sets the power the next step's work starts from). `wall_time` is when the mesh
    /// walls are where they are. A ghost's contacts are left to its owner (`Bodies::ghost`).
    /// `at`: where the bodies are, which the contact points the store does not keep are found
    /// again from.
    pub fn book(&mut self, store: &ContactStore, at: Placement, walls: WallsNow, dt: f64) {
        let bodies = at.bodies;
        let WallsNow {
            planes,
            meshes: walls,
            states: wall_states,
            time: wall_time,
        } = walls;
        let count = planes.len() + walls.len();
        self.impulse.resize(count, DVec3::ZERO);
        self.angular_impulse.resize(count, DVec3::ZERO);
        let (keys, touching) = (store.keys(), store.touching());
        let load = store.loads();
        let mut power = 0.0;
        let entries = store.wall_entries();
        for (n, &e) in entries.iter().enumerate() {
            // The wall entries are scattered over the store, which the contact loop has passed
            // over since: ask for an entry's lines some entries ahead (2.5 % of the 65,000-sphere
            // step went to waiting for them).
            if let Some(&ahead) = entries.get(n + PREFETCH_AHEAD) {
                let ahead = ahead as usize;
                prefetch(&touching[ahead]);
                prefetch(&keys[ahead]);
                prefetch(&load[ahead]);
            }
            let e = e as usize;
            if !touching[e] || !bodies.counts(keys[e].a as usize) {
                continue;
            }
            // For a wall partner the load's second moment is the law's couple on the body.
            let (f, torque) = (load[e].force, load[e].torque_b);
            let ContactPoint {
                point: p,
                normal: n,
                ..
            } = store.contact_point(e, at);
            let (w, centre) = match keys[e].partner {
                Partner::Plane(k) => (k as usize, planes[k as usize].point),
                Partner::Mesh(m) => {
                    let m = m as usize;
                    let centre = match &wall_states[m] {
                        // Fixed walls report torques about the origin of their reference placement.
                        None => walls[m].motion.reference_point(wall_time),
                        Some([_, at_end]) => {
                            power += f.dot(at_end.surface_velocity(p, n))
                                + torque.dot(at_end.angular_velocity);
                            at_end.centre
                        }
                    };
                    (planes.len() + m, centre)
                }
                Partner::Body(_) => unreachable!("wall entries have wall partners"),
            };
            self.impulse[w] -= f * dt;
            self.angular_impulse[w] -= ((p - centre).cross(f) + torque) * dt;
        }
        // Trapezoidal rule over the step.
        self.work += 0.5 * dt * (self.power + power);
        self.power = power;
    }
}
