//! What a world is built from (`World::new`).

use crate::broad_phase;
use crate::material::{Material, PairTable};
use crate::math::DVec3;
use crate::wall::Plane;

/// Everything about a world except its bodies and the parts it may lack (see `World::with_*`).
pub struct WorldConfig {
    pub time_step: f64,
    pub gravity: DVec3,
    pub materials: Vec<Material>,
    pub pair_laws: PairTable,
    pub planes: Vec<Plane>,
    pub broad_phase: broad_phase::Method,
    /// Extra distance [m] by which the broad phase's boxes are enlarged so that its pair list
    /// can be reused over several steps; `None` picks a default from the body sizes
    /// ([`World::default_skin`]).
    pub skin: Option<f64>,
    /// Worker threads for the parallel loops (0: one per core).
    pub threads: usize,
}
