//! `clutchpack check`: validates scene files (and, with `--engine`, that the engine can run
//! them) without running anything; `--keys` prints the reference of every scene key.

use crate::common::{self, BadInput};
use anyhow::Result;
use clutchpack_sdk::scene::EngineChoice;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `clutchpack check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Scene files to validate.
    #[arg(required_unless_present = "keys")]
    pub scenes: Vec<PathBuf>,
    /// Also check that this engine can run each scene (else the engine `run` would choose:
    /// the scene's `simulation.engine`, else the one that fits the pack).
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Override a scene key in every scene checked, `KEY=VALUE` (TOML value) as `run --set`
    /// takes it: what `run` with the same overrides would accept. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<clutchpack_sdk::scene::Override>,
    /// Print the reference of every scene key and exit.
    #[arg(long)]
    pub keys: bool,
    /// With `--keys`: print the reference as docs/scene-keys.md's Markdown table.
    #[arg(long, requires = "keys")]
    pub markdown: bool,
}

pub fn check(a: CheckArgs) -> Result<ExitCode> {
    if a.keys {
        if a.markdown {
            out!("{}", clutchpack_sdk::scene::keys_markdown());
        } else {
            out!("{}", clutchpack_sdk::scene::keys_doc());
        }
        return Ok(ExitCode::SUCCESS);
    }
    let mut bad = 0;
    for p in &a.scenes {
        // The scene's rules, then what `run` decides before any step: the engine and whether
        // it can run the scene (`Simulation::new`, the one home of that decision: an engine
        // that cannot run the pack, a scheme it cannot run it with), with `run`'s message.
        let checked = clutchpack_sdk::load_scene(Some(p), &a.sets).and_then(|s| {
            if let Some(net) = &s.network {
                // a network runs on either engine (its own rules checked in the load)
                let engine = s.engine(a.engine, &p.display().to_string())?;
                // its resolved packs: `K1 (4 discs, 5 plates)`
                let packs: Vec<String> = net
                    .couplings
                    .iter()
                    .filter_map(|c| {
                        let own = c.law().own_bodies()?;
                        Some(format!(
                            "{} ({} discs, {} plates)",
                            c.name,
                            own.discs.len(),
                            own.plates.len()
                        ))
                    })
                    .collect();
                let packs = if packs.is_empty() {
                    String::new()
                } else {
                    format!("; resolved packs {}", packs.join(", "))
                };
                let gears = s
                    .transmission
                    .as_ref()
                    .map_or(String::new(), |tr| gear_table(net, tr));
                return Ok(format!(
                    "network of {} bodies and {} couplings{packs}, {} s, {} engine){gears}",
                    net.bodies.len(),
                    net.couplings.len(),
                    s.simulation.duration_s,
                    engine.name()
                ));
            }
            // the engine choice first with the file as the origin of its problems (each at
            // its key), as before; `Simulation::new` makes the same choice, then builds it
            s.engine(a.engine, &p.display().to_string())?;
            let (discs, duration_s) = (s.pack.discs.len(), s.simulation.duration_s);
            let sim = clutchpack_sdk::Simulation::new(s, a.engine)?;
            Ok(format!(
                "{discs} discs, {duration_s} s, {} engine",
                sim.engine_name()
            ))
        });
        match checked {
            // a network's text closes its own parenthesis (a gear table follows it)
            Ok(what) if what.starts_with("network of") => out!("{}: ok ({what}", p.display()),
            Ok(what) => out!("{}: ok ({what})", p.display()),
            Err(e) => {
                eprintln!("{e}");
                bad += 1;
            }
        }
    }
    if bad > 0 {
        return Err(BadInput(format!(
            "{bad} of {} scene files are invalid",
            a.scenes.len()
        ))
        .into());
    }
    Ok(ExitCode::SUCCESS)
}

/// The gears of `tr` on `net` (MODEL.md section 10), from the constraints alone: each gear's
/// ratio `w_in / w_out`, its closed elements and its open elements' slip per unit input
/// speed, then every body's speed per unit input speed in each gear. The scene's validation
/// has checked every gear's kinematics.
fn gear_table(
    net: &clutchpack_sdk::model::network::Network,
    tr: &clutchpack_sdk::model::network::Transmission,
) -> String {
    use std::fmt::Write as _;
    let name = |k: usize| net.couplings[k].name.as_str();
    let mut s = format!(
        "\ngears of \"{}\" to \"{}\" (ratio w_in / w_out; the open elements' slip w_b - w_a per unit input speed):",
        net.bodies[tr.input].name, net.bodies[tr.output].name
    );
    let kin: Vec<_> = (0..tr.gears.len())
        .filter_map(|i| tr.kinematics(net, i).ok())
        .collect();
    for (g, k) in tr.gears.iter().zip(&kin) {
        let closed: Vec<&str> = g.closed.iter().map(|&c| name(c)).collect();
        let open: Vec<String> = k
            .open_slips
            .iter()
            .map(|(c, w)| format!("{} {w:+.4}", name(*c)))
            .collect();
        let _ = write!(
            s,
            "\n  {:>4}  {:>10.6}  closed {:<12} open {}",
            g.name,
            k.ratio,
            closed.join(" "),
            open.join(", ")
        );
    }
    let _ = write!(s, "\nspeeds per unit input speed:\n  {:>4}", "gear");
    let moving: Vec<usize> = (0..net.bodies.len())
        .filter(|&i| !net.bodies[i].is_fixed())
        .collect();
    for &i in &moving {
        let _ = write!(s, " {:>9}", net.bodies[i].name);
    }
    for (g, k) in tr.gears.iter().zip(&kin) {
        let _ = write!(s, "\n  {:>4}", g.name);
        for &i in &moving {
            // (+ 0.0: a member at rest prints 0, not -0)
            let _ = write!(s, " {:>9.4}", k.speeds_per_input[i] + 0.0);
        }
    }
    s
}
