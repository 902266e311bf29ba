//! Checkpoints are written and read without holding the file in memory: a run's peak memory is
//! the world's, not the world's and two or three copies of its checkpoint (at 65,000 spheres the
//! file is 120 MB, and writing it had tripled the run's peak). Measured with an allocator that
//! counts the bytes allocated (this test binary's own), against the size of the file.

use polydem::checkpoint::{self, Checkpoint};
use polydem::run::{self, Control};
use polydem::scene::overrides::Override;
use polydem::scene::Scene;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting the bytes allocated now and the most since the last reset.
struct Counting;

static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(by: usize) {
    let now = NOW.fetch_add(by, Ordering::SeqCst) + by;
    PEAK.fetch_max(now, Ordering::SeqCst);
}

// SAFETY: every call is passed on to the system allocator unchanged; only counters are added.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) };
        NOW.fetch_sub(layout.size(), Ordering::SeqCst);
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, layout, new_size) };
        if !q.is_null() {
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                NOW.fetch_sub(layout.size() - new_size, Ordering::SeqCst);
            }
        }
        q
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// `f`'s result, the bytes it left allocated, and the most it had allocated at once beyond
/// what it left (its transient memory).
fn measured<T>(f: impl FnOnce() -> T) -> (T, isize, usize) {
    let before = NOW.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    let value = f();
    let after = NOW.load(Ordering::SeqCst);
    let peak = PEAK.load(Ordering::SeqCst);
    (
        value,
        after as isize - before as isize,
        peak - after.max(before),
    )
}

#[test]
fn checkpoints_are_written_and_read_without_a_copy_of_the_file_in_memory() {
    // The settling box example (2,000 spheres with friction and rolling friction), shortened to
    // when the first have landed: bodies, contacts and rolling histories, a 2 MB checkpoint.
    let dir = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/settling_box.toml");
    let shorter: Vec<Override> = [
        "simulation.duration=0.12",
        "simulation.output_interval=0.12",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    let scene = Scene::load_with(&file, &shorter).unwrap();
    let record = checkpoint::SceneRecord::new(scene.file.clone(), scene.source.clone());
    let mut prepared = scene.build().unwrap();
    let out = dir.path().join("out");
    let control = Control {
        scene: Some(record),
        stop: None,
    };
    run::run_with(&mut prepared, &out, control, |_| {}).unwrap();
    assert!(
        prepared.world.contacts().iter().count() > 500,
        "the bodies should touch: {} bodies, {} contacts",
        prepared.world.bodies().len(),
        prepared.world.contacts().iter().count()
    );

    // The checkpoint the run wrote at its end.
    let (_, written) = checkpoint::checkpoints_in(&out).pop().unwrap();
    let size = std::fs::metadata(&written).unwrap().len() as usize;
    assert!(size > 1_000_000, "{size} bytes: too small a file to tell");

    let (read, kept, transient) = measured(|| checkpoint::read(&written).unwrap());
    // The decoded checkpoint stays (about as large as the file); what reading took besides it is
    // its buffers. Reading the file whole first took the file's size more.
    assert!(kept > 0);
    assert!(
        transient < size / 8,
        "reading a {size}-byte checkpoint took {transient} bytes besides the {kept} it kept"
    );

    // The same checkpoint written again from the world, borrowed: the same bytes, and no more
    // memory than the writer's buffer (encoding into memory first took twice the file's size,
    // and a copy of the world's state a third of it).
    let templates = run::templates(&prepared);
    let again = Checkpoint {
        polydem_version: read.polydem_version.clone(),
        scene: read.scene.clone(),
        fingerprint: read.fingerprint,
        world: prepared.world.state_ref(&templates).unwrap(),
        progress: read.progress,
    };
    let copy = dir.path().join("again.ckpt");
    let (result, _, transient) = measured(|| checkpoint::write(&copy, &again));
    result.unwrap();
    assert!(
        transient < size / 8,
        "writing a {size}-byte checkpoint took {transient} bytes"
    );
    assert!(
        std::fs::read(&copy).unwrap() == std::fs::read(&written).unwrap(),
        "the world's borrowed state should write the very checkpoint the run wrote"
    );
}
