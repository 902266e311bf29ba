//! The `polydem` Python package's extension module (`polydem._polydem`): a [`Simulation`] that
//! loads a scene, drives the library's own run loop step by step (`polydem::run::SteppedRun`)
//! with the GIL released, reads the state as NumPy arrays and changes it between steps; and a
//! reader of the `.vtp` files runs write.

mod arrays;
mod changes;
mod errors;
mod observer;
mod scene_source;
mod simulation;
mod state;
mod vtp;

use pyo3::prelude::*;

/// Big arrays on 2 MiB pages where Linux gives them (`polydem::huge_pages`), as in the binary:
/// the large worlds' step waits less on address translation.
#[global_allocator]
static ALLOCATOR: polydem::huge_pages::HugePageAlloc = polydem::huge_pages::HugePageAlloc;

#[pymodule]
fn _polydem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<simulation::Simulation>()?;
    m.add_function(wrap_pyfunction!(vtp::read_vtp, m)?)?;
    errors::register(m)?;
    Ok(())
}
