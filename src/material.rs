//! Materials and the contact parameters of each pair of materials.

use crate::contact_law::{restitution, NormalLaw, PairLaw};

/// Index of a material in the world's material table (bodies and walls name their material so).
pub type MaterialId = u32;

/// Bulk properties of a material, as a user gives them in the scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Density [kg/m³].
    pub density: f64,
    /// Young's modulus [Pa].
    pub youngs_modulus: f64,
    /// Poisson ratio [-], in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Normal coefficient of restitution [-], in [0, 1] (0: perfectly plastic).
    pub restitution: f64,
    /// Coulomb friction coefficient [-].
    pub friction: f64,
    /// Rolling friction coefficient [-] (rolling resistance torque limit / (R* F_n)).
    pub rolling_friction: f64,
}

impl Material {
    /// Shear modulus G = E / (2(1+ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

/// Values a user sets for one pair of materials instead of mixing the two materials' values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairOverride {
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
}

/// Contact parameters for every ordered pair of materials, resolved once before the run.
#[derive(Clone, Debug)]
pub struct PairTable {
    count: usize,
    laws: Vec<PairLaw>,
}

impl PairTable {
    /// Mixes material properties pair by pair. Elastic constants follow Hertz theory
    /// (Johnson 1985, §4.2 and §7.2): 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂ and
    /// 1/G* = 2(2−ν₁)(1+ν₁)/E₁ + 2(2−ν₂)(1+ν₂)/E₂. Restitution, friction and rolling friction of
    /// unlike materials are the mean of the two unless `overrides` sets them.
    pub fn new(
        materials: &[Material],
        normal: NormalLaw,
        tangential_stiffness_ratio: f64,
        overrides: &[((usize, usize), PairOverride)],
    ) -> Self {
        let count = materials.len();
        let mut laws = Vec::with_capacity(count * count);
        for a in materials {
            for b in materials {
                laws.push(mix(a, b, normal, tangential_stiffness_ratio));
            }
        }
        let mut table = Self { count, laws };
        for ((i, j), o) in overrides {
            for (p, q) in [(*i, *j), (*j, *i)] {
                let law = &mut table.laws[p * count + q];
                if let Some(e) = o.restitution {
                    law.restitution = e;
                }
                if let Some(mu) = o.friction {
                    law.friction = mu;
                }
                if let Some(mu_r) = o.rolling_friction {
                    law.rolling_friction = mu_r;
                }
            }
        }
        for law in &mut table.laws {
            law.damping = restitution::damping_for_restitution(law.normal, law.restitution);
            law.damping_volume = restitution::damping_for_restitution(
                NormalLaw::Linear { stiffness: 1.0 },
                law.restitution,
            );
        }
        table
    }

    pub fn get(&self, a: u32, b: u32) -> &PairLaw {
        &self.laws[a as usize * self.count + b as usize]
    }

    pub fn iter(&self) -> impl Iterator<Item = &PairLaw> {
        self.laws.iter()
    }
}

fn mix(a: &Material, b: &Material, normal: NormalLaw, tangential_stiffness_ratio: f64) -> PairLaw {
    let inv_e = (1.0 - a.poisson_ratio.powi(2)) / a.youngs_modulus
        + (1.0 - b.poisson_ratio.powi(2)) / b.youngs_modulus;
    let inv_g = 2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus
        + 2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus;
    PairLaw {
        normal,
        effective_youngs_modulus: 1.0 / inv_e,
        effective_shear_modulus: 1.0 / inv_g,
        restitution: 0.5 * (a.restitution + b.restitution),
        friction: 0.5 * (a.friction + b.friction),
        rolling_friction: 0.5 * (a.rolling_friction + b.rolling_friction),
        tangential_stiffness_ratio,
        damping: 0.0,
        damping_volume: 0.0,
        // Mindlin's k_t = 8 G* a over Hertz's S_n = 2 E* a; the other laws set k_t/S_n.
        tangential_damping_ratio: match normal {
            NormalLaw::Hertz => (4.0 * inv_e / inv_g).sqrt(),
            NormalLaw::Linear { .. } => tangential_stiffness_ratio.sqrt(),
        },
        tangential_damping_ratio_volume: tangential_stiffness_ratio.sqrt(),
    }
}
