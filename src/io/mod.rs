//! Mesh input (`mesh`: STL and OBJ files read into welded triangle lists) and
//! simulation output: particle and wall snapshots for ParaView (`.vtp` plus a
//! `.pvd` time series) and scalar time series as CSV; `vtk_read` and `csv_read`
//! read that output back for `polydem render` and `polydem plot`.
//!
//! Every file is written through [`atomic::write_atomic`], so a crash or a
//! full disk in the middle of a long run never leaves a truncated file behind:
//! a reader sees either the previous complete version or the new one. A `.pvd`
//! series is rewritten whole on every frame for the same reason (it is small);
//! CSV series grow by whole lines appended and synced (see `csv`).

pub mod atomic;
pub mod body_values;
pub mod csv;
pub mod csv_read;
pub mod mesh;
pub mod output;
pub mod vtk;
pub mod vtk_read;

pub use atomic::{write_atomic, write_atomic_bytes};
pub use csv::CsvSeries;
pub use vtk::{
    write_body_surfaces, write_particles, write_polygons, BodyFields, ParticleFrame, PolygonMesh,
    PvdSeries,
};

/// Formats `x` so that `str::parse::<f64>` gives back exactly `x`.
///
/// Rust's `{}` is the shortest round-trip form but never uses an exponent, so
/// `1e-300` would become a 300-digit string; outside a comfortable range the
/// equally exact `{:e}` form is used instead. Integral values print without a
/// fractional part (`3`, not `3.0`).
pub(crate) fn format_f64(x: f64) -> String {
    let magnitude = x.abs();
    if !x.is_finite() || x == 0.0 || (1e-5..1e16).contains(&magnitude) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// The error every writer returns for caller mistakes (mismatched lengths,
/// out-of-range indices), so they are reported rather than panicking.
pub(crate) fn invalid_input(message: impl Into<String>) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message.into())
}

#[cfg(test)]
mod tests {
    use super::format_f64;

    #[test]
    fn format_f64_round_trips_and_stays_short() {
        let values = [
            0.0,
            -0.0,
            3.0,
            -2.5,
            0.1,
            1e-5,
            1.234_567_890_123_456_7e-7,
            1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            1e16,
            -1.7976931348623157e308,
            123_456_789.125,
        ];
        for x in values {
            let s = format_f64(x);
            assert!(s.len() < 30, "{x} formatted as {s}");
            let back: f64 = s.parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x} -> {s} -> {back}");
        }
        assert_eq!(format_f64(3.0), "3");
        assert_eq!(format_f64(0.001), "0.001");
        assert_eq!(
            format_f64(f64::INFINITY).parse::<f64>().unwrap(),
            f64::INFINITY
        );
        assert!(format_f64(f64::NAN).parse::<f64>().unwrap().is_nan());
    }
}
