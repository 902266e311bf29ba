//! The energy ledger: where the energy of the system is at a given moment.
//!
//! Kinetic + gravitational potential + elastic + dissipated is constant in an isolated system; the
//! drift of this sum measures the error of the time integration.

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyReport {
    /// Σ ½ m v² [J].
    pub kinetic_translational: f64,
    /// Σ ½ L·ω [J].
    pub kinetic_rotational: f64,
    /// Σ −m g·x [J] (zero at the origin).
    pub potential: f64,
    /// Energy stored in the contact springs [J].
    pub elastic: f64,
    /// Energy dissipated since the start [J].
    pub dissipated: f64,
    /// Energy carried out by removed bodies since the start [J].
    pub removed: f64,
    /// Energy brought in by bodies inserted during the run [J].
    pub inserted: f64,
    /// Work done on the bodies by moving walls and belt surfaces since the start [J].
    pub wall_work: f64,
    /// Potential energy the bodies gained when gravity changed (`gravity_table`) [J].
    pub gravity_work: f64,
    /// Body–body plus body–wall contacts.
    pub contacts: usize,
}

impl EnergyReport {
    /// Every figure as a number, in the order of the fields (for sums over MPI ranks).
    pub fn to_array(&self) -> [f64; 10] {
        [
            self.kinetic_translational,
            self.kinetic_rotational,
            self.potential,
            self.elastic,
            self.dissipated,
            self.removed,
            self.inserted,
            self.wall_work,
            self.gravity_work,
            self.contacts as f64,
        ]
    }

    /// The report [`EnergyReport::to_array`] gave (or a sum of such arrays).
    pub fn from_array(a: [f64; 10]) -> Self {
        EnergyReport {
            kinetic_translational: a[0],
            kinetic_rotational: a[1],
            potential: a[2],
            elastic: a[3],
            dissipated: a[4],
            removed: a[5],
            inserted: a[6],
            wall_work: a[7],
            gravity_work: a[8],
            contacts: a[9] as usize,
        }
    }

    /// Kinetic + potential + elastic + dissipated + carried out − brought in (by inserted bodies,
    /// the work of moving walls and changes of gravity): constant up to integration error.
    pub fn total(&self) -> f64 {
        self.kinetic_translational
            + self.kinetic_rotational
            + self.potential
            + self.elastic
            + self.dissipated
            + self.removed
            - self.inserted
            - self.wall_work
            - self.gravity_work
    }
}

/// The ledgers of the shares of a decomposed world, added up: the whole's (each share counts its
/// own bodies and contacts).
impl std::iter::Sum for EnergyReport {
    fn sum<I: Iterator<Item = Self>>(reports: I) -> Self {
        let mut total = [0.0; 10];
        for r in reports {
            for (t, x) in total.iter_mut().zip(r.to_array()) {
                *t += x;
            }
        }
        EnergyReport::from_array(total)
    }
}
