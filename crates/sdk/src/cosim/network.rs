//! The network half of [`CoSimulation`]: a network scene's run ([`crate::NetworkSimulation`])
//! started with every input driven, its inputs handed over when they change, its outputs
//! read after each advance (docs/DECISIONS.md, "Network recordings and inputs").

use super::{next_run, CoSimulation, Quantity};
use crate::{RecordingRequest, Result};
use clutchpack_scene::EngineChoice;
use std::sync::atomic::AtomicBool;

impl CoSimulation {
    /// [`CoSimulation::start`] of a network scene: its run driving every input, each at its
    /// value as set.
    pub(super) fn start_network(
        &mut self,
        engine: EngineChoice,
        recording: Option<RecordingRequest>,
        stop_time_s: Option<f64>,
    ) -> Result<()> {
        let names: Vec<String> = self
            .vars
            .iter()
            .filter(|v| matches!(v.quantity, Quantity::NetworkInput(_)))
            .map(|v| v.name.clone())
            .collect();
        let sim = crate::NetworkSimulation::start(
            &self.scene,
            Some(engine),
            &names,
            recording.as_ref(),
            stop_time_s,
        )?;
        self.network = Some(sim);
        // by the index of every input the network has: a caller may drive a few
        let all = self
            .scene
            .network
            .as_ref()
            .map_or(0, |n| crate::network_inputs(n).len());
        self.network_pushed = vec![f64::NAN; all];
        self.push_network_inputs()?;
        self.refresh_network_outputs();
        self.run = next_run();
        Ok(())
    }

    /// Hands the network's inputs that changed since the last call to its run (held from
    /// now on).
    fn push_network_inputs(&mut self) -> Result<()> {
        let Some(sim) = self.network.as_mut() else {
            return Ok(());
        };
        for v in &self.vars {
            let Quantity::NetworkInput(j) = v.quantity else {
                continue;
            };
            let x = self.reals[v.vr as usize];
            if self.network_pushed.get(j) != Some(&x) {
                sim.set_input(&v.name, x)?;
                self.network_pushed[j] = x;
            }
        }
        Ok(())
    }

    /// Reads the network's outputs now.
    fn refresh_network_outputs(&mut self) {
        if let Some(sim) = self.network.as_mut() {
            self.network_outputs = sim.output_values();
        }
    }

    /// [`CoSimulation::advance_to`] of a network scene.
    pub(super) fn advance_network<'a>(
        &mut self,
        t_end: f64,
        stop: Option<&'a AtomicBool>,
        progress: Option<&'a mut dyn FnMut(f64)>,
    ) -> Result<bool> {
        self.push_network_inputs()?;
        let sim = self.network.as_mut().expect("a network while running");
        let result = sim.advance_polled(t_end, stop, progress);
        let reached = (sim.time_s() - t_end).abs() <= 1e-12 * t_end.abs().max(1.0);
        self.refresh_network_outputs();
        match result {
            Ok(()) => Ok(reached),
            Err(e) => {
                // a bad input (a value, a call) leaves the run usable; an engine failure not
                self.failed |= !e.is_bad_input();
                Err(e)
            }
        }
    }
}
