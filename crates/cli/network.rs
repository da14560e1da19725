//! What `clutchpack run` prints and draws of a network scene's run (`[[bodies]]`, MODEL.md
//! section 8; the run itself is `run.rs`'s, as any scene's): the clutches' mode changes and
//! heat, the bodies' final speeds and the energy balance, each resolved pack's bodies,
//! temperatures and windows; `--plot` (speeds and coupling torques against time); and `plot`
//! of a network recording (its figure, or its packs' load spectra).

use crate::common::BadInput;
use anyhow::{Context, Result};
use clutchpack_sdk::scene::Scene;
use clutchpack_sdk::NetworkSummary;
use std::path::Path;
use std::process::ExitCode;

/// The windows of every resolved pack of a network's run (`--windows-plot`), each named by
/// its pack.
pub fn windows(s: &NetworkSummary) -> Vec<(Option<&str>, &[clutchpack_sdk::WindowRow])> {
    s.couplings
        .iter()
        .filter(|c| !c.windows.is_empty())
        .map(|c| (Some(c.name.as_str()), c.windows.as_slice()))
        .collect()
}

/// The tables of a network's run: its line, the bodies' final speeds, the couplings (heat,
/// torques, locks; gear meshes' and packs' impacts, packs' bodies, temperatures and
/// windows), the mode changes, an automatic's shifts and the energy balance.
pub fn print(s: &NetworkSummary) {
    out!(
        "{}: {:.3} s simulated with the {} engine (network of {} bodies, {} couplings) in {:.3} s wall ({} steps, {} events)",
        s.scene,
        s.simulated_s,
        s.engine,
        s.bodies.len(),
        s.couplings.len(),
        s.wall_time_s,
        s.steps,
        s.events
    );
    out!("bodies (speeds at the end):");
    for b in &s.bodies {
        out!("  {:<16} {:>12.6} rad/s", b.name, b.final_speed_rad_s);
    }
    out!("couplings:");
    for c in &s.couplings {
        let locks: Vec<String> = c.lock_times_s.iter().map(|t| format!("{t:.6}")).collect();
        out!(
            "  {:<16} {:<10} heat {:>12.3} J  torque {:>10.3} to {:>10.3} N m  end: {:<6} {:>10.3} N m  locked at [{}] s",
            c.name,
            c.kind,
            c.heat_j,
            c.min_torque_n_m,
            c.max_torque_n_m,
            c.final_mode.unwrap_or("-"),
            c.final_torque_n_m,
            locks.join(", ")
        );
    }
    for c in s.couplings.iter().filter(|c| c.kind == "gear_mesh") {
        out!(
            "  {:<16} gear mesh: {} tooth impacts, largest peak {:.3} N per tooth pair",
            c.name,
            c.impacts,
            c.largest_peak_n
        );
    }
    for c in s.couplings.iter().filter(|c| !c.pack_bodies.is_empty()) {
        out!(
            "  {:<16} pack: {} tooth impacts; per body: impacts, largest peak per tooth, \
             its teeth's damage per hour of this duty and life:",
            c.name,
            c.impacts
        );
        // the first of equals (a locked pack's discs share their load)
        let first_max = |key: &dyn Fn(&clutchpack_sdk::PackBodySummary) -> f64| {
            c.pack_bodies.iter().fold(
                None,
                |w: Option<&clutchpack_sdk::PackBodySummary>, b| match w {
                    Some(w) if key(w) >= key(b) => Some(w),
                    _ => Some(b),
                },
            )
        };
        let largest = first_max(&|b| b.largest_peak_n.abs());
        let most_damaged = first_max(&|b| b.damage_rate_per_h);
        for b in &c.pack_bodies {
            let mut mark = String::new();
            if largest.is_some_and(|w| w.name == b.name) && b.impacts > 0 {
                mark.push_str("  <- the largest peak");
            }
            if most_damaged.is_some_and(|w| w.name == b.name) && b.damage_rate_per_h > 0.0 {
                mark.push_str("  <- the shortest life");
            }
            let life = b
                .life_h
                .map_or_else(|| "unlimited".to_string(), |h| format!("{h:.3e} h"));
            out!(
                "    {:<14} {:>6} {:>12.3} N  {:>10.3e} /h  {:>12}{mark}",
                b.name,
                b.impacts,
                b.largest_peak_n,
                b.damage_rate_per_h,
                life
            );
        }
        if let Some(th) = &c.thermal {
            out!("  {}:", c.name);
            crate::tables::print_thermal(th);
        }
        if !c.windows.is_empty() {
            out!("  {}:", c.name);
            crate::tables::print_windows(&c.windows);
        }
    }
    let mut changes: Vec<(&str, &clutchpack_sdk::ModeChange)> = s
        .couplings
        .iter()
        .flat_map(|c| c.changes.iter().map(move |m| (c.name.as_str(), m)))
        .collect();
    changes.sort_by(|x, y| x.1.t_s.total_cmp(&y.1.t_s));
    if !changes.is_empty() {
        out!("clutch mode changes:");
        for (name, m) in changes {
            // the largest torque step elsewhere at that instant (a lock's output torque step)
            let step = m
                .torque_steps_n_m
                .iter()
                .zip(&s.couplings)
                .filter(|(_, c)| c.name != name)
                .max_by(|x, y| x.0.abs().total_cmp(&y.0.abs()));
            let step = match step {
                Some((d, c)) if d.abs() > 1e-9 => format!("  ({} steps by {d:+.3} N m)", c.name),
                _ => String::new(),
            };
            out!(
                "  {:>12.6} s  {:<16} {} -> {}{step}",
                m.t_s,
                name,
                m.from,
                m.to
            );
        }
    }
    if !s.shifts.is_empty() {
        out!("shifts (as the run made them; heat and output torque from the samples):");
    }
    for sh in &s.shifts {
        let at = |t: Option<f64>| t.map_or("never".to_string(), |t| format!("{t:.6} s"));
        let phase = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{t:.3} s"));
        let flags = match (sh.tie_up, sh.flare) {
            (true, true) => "  TIE-UP, FLARE",
            (true, false) => "  TIE-UP",
            (false, true) => "  FLARE",
            (false, false) => "",
        };
        out!(
            "  {} -> {} at {:.3} s: {} released {}, {} locked {}; torque phase {}, inertia phase {}; heat {} {:.1} J, {} {:.1} J; output torque {:.1} before, {:.1} .. {:.1} during, {:.1} after N m{flags}",
            sh.from,
            sh.to,
            sh.start_s,
            sh.off_going,
            at(sh.off_going_released_s),
            sh.on_coming,
            at(sh.on_coming_locked_s),
            phase(sh.torque_phase_s),
            phase(sh.inertia_phase_s),
            sh.off_going,
            sh.off_going_heat_j,
            sh.on_coming,
            sh.on_coming_heat_j,
            sh.output_torque_before_n_m,
            sh.output_torque_min_n_m,
            sh.output_torque_max_n_m,
            sh.output_torque_after_n_m
        );
    }
    let (e, residual_j) = (&s.energy.terms, s.energy.residual_j);
    // the prescribed bodies' work, when there is one (other networks print as before)
    let prescribed = if e.prescribed_work_j != 0.0 {
        format!(", prescribed bodies {:.6} J", e.prescribed_work_j)
    } else {
        String::new()
    };
    out!(
        "energy: drives {:.6} J{prescribed}, loads {:.6} J, drag {:.6} J, clutch heat {:.6} J, packs {:.6} J, kinetic change {:.6} J (balance {:.3e} J)",
        e.drive_work_j,
        e.load_work_j,
        e.drag_loss_j,
        e.clutch_heat_j,
        e.pack_loss_j,
        e.kinetic_change_j,
        residual_j
    );
}

/// The figure: the bodies' speeds and the couplings' torques against time, and the packs'
/// tooth impacts.
pub fn plot(path: &Path, scene: &Scene, outcome: &clutchpack_sdk::NetworkOutcome) -> Result<()> {
    let net = scene.network.as_ref().expect("a network scene");
    let bodies: Vec<(&str, bool)> = net
        .bodies
        .iter()
        .map(|b| (b.name.as_str(), b.is_fixed()))
        .collect();
    let couplings: Vec<&str> = net.couplings.iter().map(|c| c.name.as_str()).collect();
    // an automatic's output torque (a transmission with a schedule)
    let output = scene
        .transmission
        .as_ref()
        .and_then(|tr| clutchpack_sdk::shifts::output_torque_series(net, tr, &outcome.history));
    plot_samples(
        path,
        &scene.name,
        outcome.summary.engine,
        &bodies,
        &couplings,
        &outcome.history,
        &outcome.impacts,
        output,
    )
}

/// `plot --spectrum` of a network recording: the exceedance spectrum of the contact peaks of
/// every body with tooth impacts (a pack's discs and plates, a gear mesh), in coupling order.
fn plot_spectrum(
    net: &clutchpack_sdk::record::RecordedNetwork,
    scene: &str,
    file: &Path,
    out: &Path,
) -> Result<ExitCode> {
    let duration = net.samples.last().map_or(0.0, |s| s.t_s);
    let mut peaks: Vec<(String, Vec<f64>)> = Vec::new();
    for (name, e) in &net.impacts {
        match peaks.iter_mut().find(|(n, _)| n == name) {
            Some((_, p)) => p.push(e.peak_n),
            None => peaks.push((name.clone(), vec![e.peak_n])),
        }
    }
    if peaks.is_empty() || duration <= 0.0 {
        return Err(BadInput(format!(
            "--spectrum: {} holds no tooth impacts (its couplings are lumped: a spectrum needs \
             a resolved pack or a gear mesh)",
            file.display()
        ))
        .into());
    }
    // in coupling order (the impacts come in the order their contacts closed)
    let coupling_of = |name: &str| {
        net.couplings
            .iter()
            .position(|c| name == c || name.starts_with(&format!("{c}/")))
            .unwrap_or(usize::MAX)
    };
    // a pack's discs before its plates, each in their numbering (`plate-2` before `plate-10`)
    let role = |name: &str| match name.split('/').nth(1) {
        Some("discs") => 0,
        Some("plates") => 1,
        _ => 2,
    };
    peaks.sort_by_key(|(n, _)| (coupling_of(n), role(n), n.len(), n.clone()));
    let spectra: Vec<(String, Vec<(f64, f64)>)> = peaks
        .into_iter()
        .map(|(n, p)| {
            let s = clutchpack_sdk::analysis::cycles::exceedance_spectrum(&p, duration);
            (n, s)
        })
        .collect();
    clutchpack_sdk::analysis::fatigue_plot::plot_spectrum(
        out,
        &format!("{scene}: tooth load spectra"),
        &spectra,
        &[],
    )
    .with_context(|| format!("plotting {}", out.display()))?;
    out!("{}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// `plot` of the network recording `file` (read by `reader` into `net`) to the figure `out`:
/// the figure of `run --plot` (speeds and coupling torques), or with `spectrum` the tooth
/// load spectra.
pub fn plot_recording(
    reader: &clutchpack_sdk::record::RecordingReader,
    net: &clutchpack_sdk::record::RecordedNetwork,
    file: &Path,
    out: &Path,
    spectrum: bool,
) -> Result<ExitCode> {
    let run = reader.info().metadata("clutchpack.run");
    let get = |k: &str| run.and_then(|m| m.get(k).cloned()).unwrap_or_default();
    if spectrum {
        return plot_spectrum(net, &get("scene_name"), file, out);
    }
    let bodies: Vec<(&str, bool)> = net
        .bodies
        .iter()
        .zip(&net.fixed)
        .map(|(n, f)| (n.as_str(), *f))
        .collect();
    let couplings: Vec<&str> = net.couplings.iter().map(String::as_str).collect();
    plot_samples(
        out,
        &get("scene_name"),
        &get("engine"),
        &bodies,
        &couplings,
        &net.samples,
        &net.impact_peaks(),
        None,
    )?;
    out!("{}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// The figure of a network's run: every turning body's speed and every coupling's torque on
/// its body a against time; `bodies` are (name, fixed) in scene order. With `impacts`
/// (`(name, t_peak s, peak N)` as [`clutchpack_sdk::NetworkOutcome::impacts`] names them) a
/// third panel: each impact's |peak| per tooth at its time, one colour per pack's discs, per
/// pack's plates and per gear mesh, or, when 10 bodies or fewer have impacts, one colour per
/// disc and per plate (each body's peaks). With `output` (`(t s, N m)`) a panel of an
/// automatic's output torque. `run --plot` of a network scene and `plot` of a network
/// recording draw it.
#[allow(clippy::too_many_arguments)]
pub fn plot_samples(
    path: &Path,
    scene: &str,
    engine: &str,
    bodies: &[(&str, bool)],
    couplings: &[&str],
    history: &[clutchpack_sdk::NetworkSample],
    impacts: &[(String, f64, f64)],
    output: Option<Vec<(f64, f64)>>,
) -> Result<()> {
    let series = |name: &str, f: &dyn Fn(&clutchpack_sdk::NetworkSample) -> f64| {
        (
            name.to_string(),
            history.iter().map(|s| (s.t_s, f(s))).collect::<Vec<_>>(),
        )
    };
    let speeds = bodies
        .iter()
        .enumerate()
        .filter(|(_, (_, fixed))| !fixed)
        .map(|(i, (name, _))| series(name, &|s| s.speed_rad_s[i]))
        .collect();
    let torques = couplings
        .iter()
        .enumerate()
        .map(|(k, name)| series(name, &|s| s.torque_n_m[k]))
        .collect();
    let mut panels = vec![
        clutchpack_sdk::analysis::Panel {
            y_label: "speed [rad/s]".into(),
            series: speeds,
            markers_only: false,
        },
        clutchpack_sdk::analysis::Panel {
            y_label: "torque on body a [N m]".into(),
            series: torques,
            markers_only: false,
        },
    ];
    if let Some(output) = output {
        panels.push(clutchpack_sdk::analysis::Panel {
            y_label: "output torque [N m]".into(),
            series: vec![("transmission on its output".into(), output)],
            markers_only: false,
        });
    }
    if !impacts.is_empty() {
        // one series per disc and plate ("K1/discs/disc-3" -> "K1 disc-3") when there are few
        // enough for a legend, else per pack's discs, per pack's plates ("K1 discs"); per mesh
        let mut names: Vec<&str> = impacts.iter().map(|i| i.0.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        let per_body = names.len() <= 10;
        let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
        for (name, t, peak) in impacts {
            let mut parts = name.splitn(3, '/');
            let group = match (parts.next(), parts.next(), parts.next()) {
                (Some(pack), Some(_), Some(body)) if per_body => format!("{pack} {body}"),
                (Some(pack), Some(role), _) => format!("{pack} {role}"),
                _ => name.clone(),
            };
            match groups.iter_mut().find(|g| g.0 == group) {
                Some(g) => g.1.push((*t, peak.abs())),
                None => groups.push((group, vec![(*t, peak.abs())])),
            }
        }
        groups.sort_by(|a, b| a.0.cmp(&b.0));
        panels.push(clutchpack_sdk::analysis::Panel {
            y_label: "impact |peak| per tooth [N]".into(),
            series: groups,
            markers_only: true,
        });
    }
    let title = if impacts.is_empty() {
        format!("{scene}: speeds and coupling torques ({engine} engine)")
    } else {
        format!("{scene}: speeds, coupling torques and tooth impacts ({engine} engine)")
    };
    crate::outputs::write_with(path, |tmp| {
        clutchpack_sdk::analysis::plot_panels(tmp, &title, "t [s]", &panels)
            .with_context(|| format!("plotting {}", path.display()))
    })
}
