//! The resolved pack as an element of a driveline network (MODEL.md sections 2-5 and 8): its
//! friction discs splined to body `a`, its separator plates to body `b` (a drum; the housing
//! when `b` is fixed). Its discs, plates, tooth contacts and faces are each engine's pack
//! session ([`super::Coupling::pack`]); the law says what the network needs of it: its
//! piston's breakpoints, its co-simulation input and outputs, its problems as a network's
//! element, its own bodies (the discs and plates the layers above name, draw and summarise),
//! the mode its faces start in, and its pressure under a shift schedule.

use super::element::{
    problem, ClutchMode, ElementLaw, InputSpec, Mode, OutputQuantity, OutputSpec, OwnBodies,
};
use super::gears::{pack_pressure, rated_pressure_pa};
use super::{CouplingKind, Network, NetworkInput, NetworkProblem, Signal};
use crate::PackModel;

impl ElementLaw for PackModel {
    fn kind_name(&self) -> &'static str {
        "pack"
    }

    /// Its piston pressure's.
    fn breakpoints(&self, out: &mut Vec<f64>) {
        if let Some(s) = &self.stack {
            s.piston.pressure.breakpoints(out);
        }
    }

    /// A turning disc carrier `a`, no couplings of its own (the network's replace them) and
    /// at least one friction disc.
    fn problems(
        &self,
        net: &Network,
        k: usize,
        ports: &[usize],
        out: &mut Vec<NetworkProblem>,
    ) -> bool {
        let a = ports[0];
        if net.bodies[a].is_fixed() {
            out.push(problem(
                k,
                "a",
                format!(
                    "\"{}\" is fixed: the friction discs' carrier must turn (the plates' carrier b may be the fixed housing)",
                    net.bodies[a].name
                ),
            ));
        }
        if !self.couplings.is_empty() {
            out.push(problem(
                k,
                "pack",
                "the pack's own [[couplings]] join its shaft and drum, which the network's bodies replace: put them in the network's [[couplings]]".into(),
            ));
        }
        if self.discs.is_empty() {
            out.push(problem(k, "pack", "the pack has no friction discs".into()));
        }
        true
    }

    /// Its piston pressure (`pressure_pa`, Pa), when it has a `[stack]`.
    fn input(&self) -> Option<InputSpec> {
        self.stack.as_ref().map(|_| InputSpec {
            input: NetworkInput::PackPressure,
            suffix: "pressure_pa",
            unit: "Pa",
            description: "piston pressure of pack {}, Pa (>= 0; the piston pushes with p A less \
                          its return spring)",
        })
    }

    fn input_value(&self, t_s: f64) -> f64 {
        self.stack
            .as_ref()
            .map_or(0.0, |s| s.piston.pressure.pressure_pa(t_s))
    }

    /// With a stack, its piston pressure the level times its rated pressure (its own
    /// profile's largest, [`super::gears::rated_pressure_pa`]), which must be above 0.
    fn scheduled(&self, level: &Signal) -> Result<Option<CouplingKind>, (&'static str, String)> {
        let Some(stack) = &self.stack else {
            return Ok(None);
        };
        let rated = rated_pressure_pa(&stack.piston.pressure);
        if rated.is_nan() || rated <= 0.0 {
            return Err((
                "pack",
                "is a shift element: its pack file's [stack.pressure] must rise above 0 Pa (its \
                 largest pressure is the element's rated pressure, which the schedule scales)"
                    .into(),
            ));
        }
        let Some(pressure) = pack_pressure(level, rated) else {
            return Ok(None);
        };
        let mut pack = self.clone();
        if let Some(s) = pack.stack.as_mut() {
            s.piston.pressure = pressure;
        }
        Ok(Some(CouplingKind::Pack(Box::new(pack))))
    }

    /// Its friction discs (on `a`) and separator plates (on `b`), stacked when it has a
    /// `[stack]`.
    fn own_bodies(&self) -> Option<OwnBodies<'_>> {
        Some(OwnBodies {
            discs: &self.discs,
            plates: &self.plates,
            stacked: self.stack.is_some(),
        })
    }

    /// Its faces start free; its session reports their changes.
    fn session_mode(&self) -> Mode {
        Some(ClutchMode::Free)
    }

    /// Its faces' heat (a thermal pack's temperatures follow it, by its discs and plates).
    fn outputs(&self) -> &'static [OutputSpec] {
        &[
            OutputSpec {
                suffix: "mode",
                unit: "1",
                description: "mode of the faces of pack {} as Modelica's Clutch numbers it: 2 \
                              free (none clamped), 1 slipping (some clamped), 0 locked (all)",
                quantity: OutputQuantity::Mode,
            },
            OutputSpec {
                suffix: "heat_j",
                unit: "J",
                description: "heat the faces of pack {} have made since t = 0, J",
                quantity: OutputQuantity::Heat,
            },
        ]
    }
}

impl Network {
    /// The pack scene this network is, if it is one (docs/DECISIONS.md, "A one-pack
    /// network is a pack scene"): its only element a resolved pack, its friction discs on a
    /// prescribed body (the pack's prescribed shaft, its profile) and its plates on the fixed
    /// body (the housing) or on a free body with at most a constant drive and its drag (the
    /// pack's drum: its inertia, the drive as its load torque, its drag and its speed), and no
    /// other body. Such a network runs as the pack's own session, to the bit; every other
    /// network (an inertial shaft, a drum with a varying load or a road load, a second element)
    /// takes the driveline path. The pack's thermal model, if any, is the network's
    /// [`Network::pack_thermal`] of its element.
    pub fn one_pack(&self) -> Option<PackModel> {
        let [c] = self.couplings.as_slice() else {
            return None;
        };
        let pack = c.pack()?;
        if self.bodies.len() != 2 || c.a == c.b || !pack.couplings.is_empty() {
            return None;
        }
        let (shaft, carrier) = (&self.bodies[c.a], &self.bodies[c.b]);
        let profile = shaft.prescribed()?;
        let drum = match &carrier.motion {
            super::Motion::Fixed => None,
            super::Motion::Prescribed(_) => return None,
            super::Motion::Free => {
                let load = match &carrier.drive {
                    None => 0.0,
                    Some(super::Signal::Constant(v)) => *v,
                    Some(_) => return None,
                };
                if carrier.firing.is_some() || carrier.road_load.is_some() || pack.plates.is_empty()
                {
                    return None;
                }
                Some(crate::DrumModel {
                    inertia_kg_m2: carrier.inertia_kg_m2,
                    load_torque_n_m: load,
                    drag_n_m_s_rad: carrier.drag_n_m_s_rad,
                    initial_speed_rad_s: carrier.initial_speed_rad_s,
                })
            }
        };
        Some(PackModel {
            shaft: crate::Shaft::Prescribed(profile.clone()),
            drum,
            ..pack.clone()
        })
    }
}
