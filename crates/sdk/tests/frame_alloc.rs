//! Issue 46, item 3: the heap allocations of a host's frame loop once started, counted by a
//! global allocator (this test binary's only test, so that nothing else allocates while it
//! counts). The goal is none; this measures where the frame loop stands and keeps it there
//! (the multibody engine's are all rapier's own, inside its world step; the reference
//! engine's are its buffers still growing to their largest window, rayon's job queue and the
//! host's fatigue statistics).

use clutchpack_model::session::Advance;
use clutchpack_scene::{EngineChoice, Override};
use clutchpack_sdk::{SessionRequest, Simulation};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting allocations and reallocations.
struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: every call is passed to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller's contract is `System`'s.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: as above.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// `pack-8-brake` (record rate 10 kHz: ten samples a frame, ten world steps of 0.1 ms) through
/// the sdk's session as a host runs it, nothing kept but the running statistics: 20 frames of
/// 1 ms after 20 of warm-up, the allocations per frame on each engine.
///
/// Multibody engine: 207 per frame before issue 46's frame work (each sample's and interface
/// sample's vectors, the world step's gap drags, speeds, means and carriers, the shaft's
/// expansion, the stack's loads, a fatigue buffer per impact); then 60.1, every one of them
/// inside rapier3d 0.36's world step (`PhysicsPipeline::step`: its modified-body list, taken
/// at each step and grown again, 4 a step; its solver graph and island cursors, 1 each), 6
/// per world step, and 0.1 the statistics' amortised growth. Now 0.1: the open pack's world
/// steps carry the bodies without rapier's step (`Run::carry_bodies`). Asserted at most 1.0:
/// one allocation per world step again is 10 and fails. (Not yet bounded: a pack with an
/// inertial carrier, whose world rapier still steps and whose carrier's sub-steps keep their
/// nodes in fresh vectors: `pack-6-engagement` on the multibody engine, 407.4 per frame.)
///
/// Reference engine (the open-pack multirate scheme: 17 bodies, windows of 1 ms): 1437.3 per
/// frame before issue 46's frame work, when each window cloned every body's integration twice
/// (its saved start and its restart), each pass's track, the predictions and each sample's
/// gap interfaces; now 0.5 (10 in the 20 frames), each window copying into the buffers of the
/// last (`clone_reusing!`, the kept tracks of `open.rs`): the saved states' and the kept
/// tracks' vectors still growing to their largest window (none after about 100 frames),
/// rayon's job queue (about 0.05 a frame) and the host's fatigue statistics (about 0.2 a
/// frame, one per impact, `clutchpack_analysis`). Asserted at most 1.0 (twice the count): one
/// allocation more per window of the engine's own is 1.5 and fails.
///
/// `pack-6-engagement` on the reference engine (the monolithic scheme with its clamping
/// stack, before the engagement): 20.3 per frame before, the queue's owned samples and
/// interface samples (two vectors a sample, ten samples a frame); now each sent item's
/// buffers serve the next items (the reference engine's session queue): 0.25 (5 in the 20
/// frames: the queue and the host's statistics still growing). Asserted at most 1.0: one
/// allocation a sample again is 10 and fails.
#[test]
fn frame_loop_allocations_per_frame_are_bounded() {
    for (name, engine, measured, bound) in [
        ("pack-8-brake", EngineChoice::Reference, 0.5, 1.0),
        ("pack-8-brake", EngineChoice::Multibody, 0.1, 1.0),
        ("pack-6-engagement", EngineChoice::Reference, 0.25, 1.0),
    ] {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}.toml"));
        let scene = clutchpack_scene::load(&file, &Vec::<Override>::new()).unwrap();
        let sim = Simulation::new(scene.clone(), Some(engine)).unwrap();
        let mut s = sim
            .start(SessionRequest {
                stop_time_s: Some(0.05),
                ..SessionRequest::default()
            })
            .unwrap();
        let mut t = 0.0;
        let mut frame = |s: &mut clutchpack_sdk::Session, k: u32| {
            t = f64::from(k) * 1e-3;
            assert_eq!(s.advance_to(t, None).unwrap(), Advance::Reached);
        };
        for k in 1..=20 {
            frame(&mut s, k);
        }
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        for k in 21..=40 {
            frame(&mut s, k);
        }
        let per_frame = (ALLOCATIONS.load(Ordering::Relaxed) - before) as f64 / 20.0;
        println!("{name}, {engine:?}: {per_frame} allocations per 1 ms frame");
        assert!(
            per_frame <= bound,
            "{name}, {engine:?}: {per_frame} allocations per frame (measured {measured}, bound \
             {bound})"
        );
        drop(s.finish());
    }
}
