//! The clutches' modes at an event of a network run (MODEL.md section 8; Modelica's `Clutch`):
//! which clutches lock, slip or go free, settled together, and the speeds of a new rigid group
//! made common with its momentum kept.

use super::{sample, ClutchEvent, Equations, Freedom};
use clutchpack_model::network::{friction, SlipEnd};
use clutchpack_model::Observer;

/// Settles the clutches' modes at an event at `t` (MODEL.md section 8; Modelica's `Clutch`):
/// free while `fn <= 0`; a clutch whose slip crossed zero (`crossed`: its guard `<= 0`), or
/// that engages at zero slip, is tried locked; a locked clutch whose holding torque exceeds
/// its static limit slips towards that torque; repeated until every locked clutch holds.
pub(super) fn settle(
    eq: &mut Equations,
    t: f64,
    y: &mut [f64],
    crossed: &[f64],
    obs: &mut dyn Observer,
    events: &mut u64,
) {
    let net = std::sync::Arc::clone(&eq.net);
    let n = net.bodies.len();
    let before = eq.modes.clone();
    let state_before = sample(eq, t, y);
    let mut modes = before.clone();
    for (k, c) in net.couplings.iter().enumerate() {
        // the slip's zero located as this event: its guard crossed (the stick/slip rule's
        // `SlipEnd::Located`)
        let crossed = crossed.get(k).is_some_and(|g| *g <= 0.0);
        let end = SlipEnd::Located { crossed };
        modes[k] = c.law().settle(t, modes[k], y[n + c.a], y[n + c.b], end);
    }
    // lock what locks; release the locked clutch that is furthest over its limit, and again
    for _ in 0..=net.couplings.len() {
        eq.set_modes(&modes);
        project_speeds(eq, y);
        eq.torques(t, y);
        eq.rigid_torques();
        match friction::furthest_over(&net, &modes, &eq.coupling_torque, t) {
            Some((k, to)) => modes[k] = Some(to),
            None => break,
        }
    }
    eq.set_modes(&modes);
    hold_road_loads(eq, t, y, crossed);
    *events += 1;
    if before != modes {
        obs.switched(&state_before, &sample(eq, t, y));
    }
    for (k, (b, a)) in before.iter().zip(&modes).enumerate() {
        if let (Some(from), Some(to)) = (b, a) {
            if from != to {
                obs.clutch_event(&ClutchEvent {
                    t_s: t,
                    coupling: k,
                    from: *from,
                    to: *to,
                });
            }
        }
    }
}

/// Sets every rigid group's speeds onto its rows, momentum kept (a lock's merge; 0 for a
/// held group).
fn project_speeds(eq: &Equations, y: &mut [f64]) {
    let n = eq.net.bodies.len();
    eq.clusters.project(&eq.net, &mut y[n..2 * n]);
}

/// Settles the road loads at `t` (the module docs of `mod.rs`; issue 48, item 4): a held body
/// whose group now moves (a clutch locked it to a moving group) is released; a body whose
/// speed reached zero (`crossed`: its guard `<= 0`) or stands at zero is held with its group
/// at rest while the group's other torques stay within the held bodies' breakaway, and
/// otherwise starts (or goes on) towards them. Each body left moving takes its direction.
fn hold_road_loads(eq: &mut Equations, t: f64, y: &mut [f64], crossed: &[f64]) {
    let n = eq.net.bodies.len();
    let loaded: Vec<usize> = (0..n).filter(|&i| eq.breakaway(i) > 0.0).collect();
    if loaded.is_empty() {
        return;
    }
    let at = eq.body_guard_at();
    // a held body whose guard reached zero: its group's torque reached the breakaway
    let broke: Vec<bool> = (0..n)
        .map(|i| eq.held[i] && crossed.get(at + i).is_some_and(|g| *g <= 0.0))
        .collect();
    for &i in &loaded {
        if eq.held[i] && y[n + i] != 0.0 {
            eq.held[i] = false;
        }
        let reached = !broke[i] && crossed.get(at + i).is_some_and(|g| *g <= 0.0);
        // the hold acts on a group of one degree of freedom in which the body turns
        let holdable =
            eq.clusters.freedom[eq.clusters.of[i]] == Freedom::One && eq.clusters.g[i] != 0.0;
        if !eq.held[i] && (reached || y[n + i] == 0.0) && holdable {
            // the group at rest (a located zero of its speed: within 1e-12 rad/s of it)
            let c = eq.clusters.of[i];
            for j in 0..n {
                if eq.clusters.of[j] == c {
                    y[n + j] = 0.0;
                }
            }
            eq.held[i] = true;
        }
    }
    if !eq.held.contains(&true) {
        for &i in &loaded {
            eq.moving[i] = if y[n + i] == 0.0 {
                0.0
            } else {
                y[n + i].signum()
            };
        }
        return;
    }
    // the groups' torques without the reactions; a group over its breakaway starts
    eq.torques(t, y);
    for &i in &loaded {
        let c = eq.clusters.of[i];
        let (gt, cap) = (eq.hold_torque[c], eq.hold_capacity[c]);
        if eq.held[i] && (gt.abs() > cap || broke[i]) {
            eq.held[i] = false;
        }
        eq.moving[i] = if eq.held[i] {
            0.0
        } else if y[n + i] != 0.0 {
            y[n + i].signum()
        } else {
            // at rest, starting: towards the group's torque, in the body's own sense
            (gt * eq.clusters.g[i]).signum()
        };
    }
    eq.torques(t, y);
}
