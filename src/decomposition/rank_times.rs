//! Where one rank of a decomposed run spends its time ([`RankTimes`]).

/// Where one rank's time goes, in seconds summed over the steps: what tells a decomposed run's
/// losses apart (`mpirun -np N polydem bench scene` prints it for every rank). The collective
/// calls hold a rank until every rank has come to them, so their time is mostly waiting for the
/// slowest.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RankTimes {
    /// The share's own step (every body it holds, ghosts included).
    pub step: f64,
    /// Whether bodies left the domain, and the largest moves: the two small collectives.
    pub agree: f64,
    /// The ghosts' states: packing, `MPI_Alltoallv`, unpacking.
    pub exchange: f64,
    /// Drawing the shares again.
    pub redraw: f64,
}

impl RankTimes {
    pub const LEN: usize = 4;

    pub fn to_array(self) -> [f64; Self::LEN] {
        [self.step, self.agree, self.exchange, self.redraw]
    }

    pub fn from_array(a: [f64; Self::LEN]) -> Self {
        RankTimes {
            step: a[0],
            agree: a[1],
            exchange: a[2],
            redraw: a[3],
        }
    }

    /// The times since `earlier`.
    pub fn since(self, earlier: RankTimes) -> RankTimes {
        let (a, b) = (self.to_array(), earlier.to_array());
        RankTimes::from_array(std::array::from_fn(|k| a[k] - b[k]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_times_of_a_window_are_the_times_at_its_end_less_those_at_its_start() {
        let start = RankTimes {
            step: 1.0,
            agree: 0.25,
            exchange: 0.5,
            redraw: 2.0,
        };
        let end = RankTimes {
            step: 4.0,
            agree: 0.75,
            exchange: 0.5,
            redraw: 3.5,
        };
        let window = end.since(start);
        assert_eq!(
            window,
            RankTimes {
                step: 3.0,
                agree: 0.5,
                exchange: 0.0,
                redraw: 1.5
            }
        );
        assert_eq!(RankTimes::from_array(window.to_array()), window);
    }
}
