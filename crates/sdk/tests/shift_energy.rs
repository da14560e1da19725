//! Each shift's energy balance in an automatic's shift summary (`ShiftSummary::work_in_j`,
//! `energy_residual_j`): the run takes its balance at every shift's start from a copy of
//! itself finished there, which must leave the run as the engine's one call to its end gives
//! it, bit for bit (the reference engine's calls never end its steps; the multibody engine's
//! do, and the shifts' starts are already breakpoints of the schedule's signals).

use clutchpack_scene::{EngineChoice, Override, Scene};
use clutchpack_sdk::{multibody_step_s, NetworkRequest, Simulation};
use std::path::Path;

fn scene_file(name: &str, duration_s: f64) -> Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}.toml"));
    let mut scene = clutchpack_scene::load(&file, &Vec::<Override>::new()).unwrap();
    scene.simulation.duration_s = duration_s;
    scene
}

/// `scenes/eight-speed.toml` (lumped, shifts at 1.0 and 2.0 s) over 2.5 s and
/// `scenes/eight-speed-packs.toml` (C and E resolved, the shift at 0.05 s) over 0.1 s, on both
/// engines: the summary's energy terms and final speeds are those of the engine's own
/// `run_network` to the bit, and every shift carries its balance.
#[test]
fn taking_each_shifts_energy_balance_leaves_the_run_bit_for_bit() {
    for (name, duration_s) in [("eight-speed", 2.5), ("eight-speed-packs", 0.1)] {
        let scene = scene_file(name, duration_s);
        let net = scene.network.as_ref().unwrap();
        let sim = &scene.simulation;
        for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
            let out = Simulation::new(scene.clone(), Some(engine))
                .unwrap()
                .run(NetworkRequest::default())
                .unwrap()
                .into_network()
                .unwrap();
            let run = match engine {
                EngineChoice::Reference => {
                    let options = clutchpack_sdk::reference::network::NetworkOptions {
                        tolerance: sim.tolerance,
                        max_step_s: sim.max_step_s,
                        record_rate_hz: sim.record_rate_hz,
                    };
                    clutchpack_sdk::reference::network::run_network(
                        net,
                        duration_s,
                        &options,
                        &mut clutchpack_model::NullObserver,
                    )
                }
                EngineChoice::Multibody => {
                    let options = clutchpack_sdk::multibody::network::NetworkStepOptions {
                        step_s: multibody_step_s(&scene),
                        record_rate_hz: sim.record_rate_hz,
                    };
                    clutchpack_sdk::multibody::network::run_network(
                        net,
                        duration_s,
                        &options,
                        &mut clutchpack_model::NullObserver,
                    )
                }
            }
            .unwrap();
            let s = &out.summary;
            assert_eq!(s.energy.terms, run.energy, "{name} on {engine:?}");
            assert_eq!(s.steps, run.steps, "{name} on {engine:?}");
            let speeds: Vec<f64> = s.bodies.iter().map(|b| b.final_speed_rad_s).collect();
            assert_eq!(speeds, run.last.speed_rad_s, "{name} on {engine:?}");
            assert!(!s.shifts.is_empty(), "{name}");
            for sh in &s.shifts {
                let (work, residual) = (sh.work_in_j.unwrap(), sh.energy_residual_j.unwrap());
                assert!(
                    work > 0.0 && residual.abs() < 1e-6 * work,
                    "{name} on {engine:?}: {sh:?}"
                );
            }
        }
    }
}
