//! Counting bodies over every rank of an MPI communicator, for [`super::Decomposition::new`].

use super::bisection::{BodyCounter, LocalBodies, Region};
use crate::math::DVec3;
use mpi::collective::SystemOperation;
use mpi::traits::*;

/// This rank's bodies, counted together with every other rank's: each count is one
/// `MPI_Allreduce`, so every rank sees the same numbers and builds the same decomposition.
pub struct DistributedBodies<'a, C: Communicator> {
    pub local: LocalBodies<'a>,
    pub communicator: &'a C,
}

impl<C: Communicator> BodyCounter for DistributedBodies<'_, C> {
    fn count_below(&mut self, region: &Region, axis: usize, cut: f64) -> u64 {
        let local = self.local.count(region, axis, cut);
        let mut total = 0u64;
        self.communicator
            .all_reduce_into(&local, &mut total, SystemOperation::sum());
        total
    }

    fn bounds(&mut self) -> Option<(DVec3, DVec3)> {
        let (lower, upper) = self
            .local
            .local_bounds()
            .unwrap_or((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)));
        let (mut global_lower, mut global_upper) = ([0.0; 3], [0.0; 3]);
        let c = self.communicator;
        c.all_reduce_into(
            &lower.to_array()[..],
            &mut global_lower[..],
            SystemOperation::min(),
        );
        c.all_reduce_into(
            &upper.to_array()[..],
            &mut global_upper[..],
            SystemOperation::max(),
        );
        let (lower, upper) = (DVec3::from(global_lower), DVec3::from(global_upper));
        (lower.x <= upper.x).then_some((lower, upper))
    }
}
