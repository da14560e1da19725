//! An automatic's gear as a co-simulation output (`transmission.gear`, the FMU's and Python's
//! `Simulation`'s): the index of the gear engaged in `[[transmission.gears]]`, -1 while none
//! is, followed through `scenes/eight-speed.toml`'s 1 -> 2 -> 3 upshifts and
//! `scenes/eight-speed-packs.toml`'s 1 -> 2 with resolved packs, on both engines.

use clutchpack_scene::{EngineChoice, Override, Scene};
use clutchpack_sdk::NetworkSimulation;
use std::path::Path;

fn scene_file(name: &str) -> Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}.toml"));
    clutchpack_scene::load(&file, &Vec::<Override>::new()).unwrap()
}

/// The gear output at each of `times` (s).
fn gears(scene: &Scene, engine: EngineChoice, times: &[f64]) -> Vec<f64> {
    let end = *times.last().unwrap();
    let mut sim = NetworkSimulation::start(scene, Some(engine), &[], None, Some(end)).unwrap();
    assert!(
        sim.variables()
            .iter()
            .any(|v| v.name == "transmission.gear"),
        "an output"
    );
    times
        .iter()
        .map(|&t| {
            sim.advance_to(t, None).unwrap();
            let out = sim.outputs();
            out.iter()
                .find(|(n, _)| n == "transmission.gear")
                .unwrap()
                .1
        })
        .collect()
}

/// The 8-speed (its table R, 1, 2, ..., so an index is the gear's number): 1st before the
/// 1 -> 2 shift (at 1.0 s), none in its inertia phase (C released at 1.149 s, E locked at
/// 1.194 s), 2nd after it, 3rd after the 2 -> 3 shift (C locks at 2.218 s).
#[test]
fn the_gear_output_follows_the_eight_speeds_shifts_on_both_engines() {
    let scene = scene_file("eight-speed");
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let g = gears(&scene, engine, &[0.5, 1.17, 1.5, 2.5]);
        assert_eq!(g, vec![1.0, -1.0, 2.0, 3.0], "{engine:?}");
    }
}

/// With C and E resolved packs a pack holds a gear when its faces are all locked: 1st at 0.03 s
/// (C clamped and locked from the start, though its carriers' speeds differ by 3 rad/s as its
/// discs rattle in their play), 2nd at 0.4 s (E's faces locked at 0.252 s).
#[test]
fn the_gear_output_reads_resolved_packs_on_both_engines() {
    let scene = scene_file("eight-speed-packs");
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let g = gears(&scene, engine, &[0.03, 0.4]);
        assert_eq!(g, vec![1.0, 2.0], "{engine:?}");
    }
}
