//! Tests of the network's equations (`super::Equations`): the guards' partial evaluations
//! and the torques without the accelerations, each against the whole evaluation to the bit,
//! on `scenes/eight-speed-packs.toml` (issue 45).

use super::*;
use crate::system::Face;

/// The guards of `scenes/eight-speed-packs.toml` (C and E resolved; the lumped brakes A
/// and B locked, as in first gear, so that the guards take the forces) at 0.15 s of a state in
/// which every other disc and plate is pressed into its spline beyond its play (in
/// contact) and the faces are locked, slipping and open in turn: the event bisection
/// evaluated every guard at each trial (issue 45); now only those asked, each to the bit of
/// the whole evaluation, and the stacks take the loads of the carriers' reactions, the same
/// stacks to the bit as those that take the loads themselves.
#[test]
fn event_bisection_evaluated_every_guard_at_each_trial() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/eight-speed-packs.toml");
    let net = clutchpack_scene::load(&path, &[]).unwrap().network.unwrap();
    // first gear's lumped brakes locked (as the run settles them at t = 0)
    let modes: Vec<_> = (net.couplings.iter())
        .map(|c| match c.name.as_str() {
            "A" | "B" => Some(ClutchMode::Locked),
            _ => c.law().initial_mode(),
        })
        .collect();
    let mut eq = Equations::new(Arc::new(net.clone()), modes);
    assert!(eq.modes.contains(&Some(ClutchMode::Locked)));
    let n = net.bodies.len();
    let mut y = vec![0.0; eq.dim()];
    for (i, b) in net.bodies.iter().enumerate() {
        y[n + i] = b.initial_speed_rad_s;
    }
    let (mut in_contact, faces) = (0, [Face::Locked, Face::Slip(1.0), Face::Open]);
    for p in eq.packs.iter_mut() {
        let d = p.sys.dim();
        y[p.at..p.at + d].copy_from_slice(&p.sys.initial_state());
        for slot in 0..p.sys.ids.len() {
            let half = p.sys.disc(slot).spline.half_play_rad();
            let sign = if slot % 4 == 0 { 1.0 } else { -1.0 };
            let push = if slot % 2 == 0 { 1.02 } else { 0.5 };
            y[p.at + 2 * slot] = sign * push * half;
            y[p.at + 2 * slot + 1] = 0.3 * sign;
            let part = &y[p.at..p.at + d];
            if p.sys.depth(slot, part) > 0.0 {
                p.modes[slot] = Some(p.sys.disc(slot).law.engage(&p.sys.kin(slot, part)));
                in_contact += 1;
            }
        }
        for m in 0..p.sys.faces.len() {
            p.sys.faces[m] = faces[m % 3];
        }
    }
    assert!(in_contact >= 4, "{in_contact} bodies in contact");
    let t = 0.15;
    let mut full = vec![0.0; eq.guard_len()];
    eq.guards(t, &y, &mut full);
    assert!(full.iter().any(|g| *g < 0.0) && full.iter().any(|g| *g > 0.0));
    // every guard alone, then each pack's faces, each pack's bodies, the couplings
    let mut masks: Vec<Vec<bool>> = (0..full.len())
        .map(|i| (0..full.len()).map(|j| j == i).collect())
        .collect();
    for p in &eq.packs {
        let (at, nb, all) = (p.guard_at, p.sys.ids.len(), p.guards());
        masks.push(
            (0..full.len())
                .map(|j| j >= at + nb && j < at + all)
                .collect(),
        );
        masks.push((0..full.len()).map(|j| j >= at && j < at + nb).collect());
    }
    masks.push((0..full.len()).map(|j| j < net.couplings.len()).collect());
    for want in &masks {
        let mut some = vec![f64::NAN; full.len()];
        eq.guards_of(t, &y, &mut some, want);
        for j in 0..full.len() {
            if want[j] {
                assert_eq!(some[j].to_bits(), full[j].to_bits(), "guard {j}");
            } else {
                // left as it was, or a face of a pack with a face asked (its stack's)
                let same = some[j].to_bits() == full[j].to_bits();
                assert!(some[j].is_nan() || same, "guard {j}");
            }
        }
    }
    // the loads of the reactions (`forces`) against the stack's own; the carried packs'
    // reactions from the loads (their own loop, `System::reactions_from_n_m`) against
    // the general sum taking each load itself
    eq.forces(t, &y);
    for (p, loads) in eq.packs.iter().zip(&eq.loads) {
        let (part, c) = (p.part(&y), [y[n + p.a], 0.0, y[n + p.b], 0.0]);
        let own = p.sys.stack_eval(t, part, &p.modes, &c, None);
        let given = p.sys.stack_eval(t, part, &p.modes, &c, Some(loads));
        assert_eq!(format!("{own:?}"), format!("{given:?}"));
        let r = p.sys.reactions_n_m(part, &p.modes);
        assert_eq!(
            r.map(f64::to_bits),
            p.sys.reactions_from_n_m(loads, &p.modes).map(f64::to_bits)
        );
        assert!(r.iter().any(|x| *x != 0.0), "{r:?}: bodies in contact");
    }
}

/// The shift's evaluations took, at every guard probe, bisection trial, sample and
/// settling, the bodies' accelerations that only the right-hand side reads, and at every
/// right-hand side each carried pack's drag power body by body with no drag to sum
/// (issue 45: the resolved-pack shift's cost against its packs run alone). At the state
/// of `event_bisection_evaluated_every_guard_at_each_trial`'s kind (bodies in contact,
/// the lumped brakes A and B locked, the faces in every mode), for every gear's modes:
/// [`Equations::torques`] leaves every torque, load and reaction that
/// [`Equations::forces`] computes, to the bit (no margin: the same operations), and the
/// accelerations are those of the right-hand side; the packs' drag power without drag
/// is the general sum's +0 and, with a drag, the general sum.
#[test]
fn guard_probes_took_the_accelerations_and_the_drag_for_nothing() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/eight-speed-packs.toml");
    let net = clutchpack_scene::load(&path, &[]).unwrap().network.unwrap();
    let n = net.bodies.len();
    for locked in [&["A", "B"][..], &["A", "B", "D"], &["B"]] {
        let modes: Vec<_> = (net.couplings.iter())
            .map(|c| match c.name.as_str() {
                name if locked.contains(&name) => Some(ClutchMode::Locked),
                _ => c.law().initial_mode(),
            })
            .collect();
        let mut eq = Equations::new(Arc::new(net.clone()), modes);
        let mut y = vec![0.0; eq.dim()];
        for (i, b) in net.bodies.iter().enumerate() {
            y[n + i] = b.initial_speed_rad_s + 3.0 * i as f64;
        }
        let faces = [Face::Locked, Face::Slip(-1.0), Face::Open];
        let mut in_contact = 0;
        for p in eq.packs.iter_mut() {
            let d = p.sys.dim();
            for slot in 0..p.sys.ids.len() {
                let half = p.sys.disc(slot).spline.half_play_rad();
                let sign = if slot % 3 == 0 { 1.0 } else { -1.0 };
                y[p.at + 2 * slot] = sign * if slot % 2 == 0 { 1.03 } else { 0.4 } * half;
                y[p.at + 2 * slot + 1] = -0.2 * sign;
                let part = &y[p.at..p.at + d];
                if p.sys.depth(slot, part) > 0.0 {
                    p.modes[slot] = Some(p.sys.disc(slot).law.engage(&p.sys.kin(slot, part)));
                    in_contact += 1;
                }
            }
            for m in 0..p.sys.faces.len() {
                p.sys.faces[m] = faces[(m + 1) % 3];
            }
        }
        assert!(in_contact >= 4, "{in_contact} bodies in contact");
        let t = 0.12;
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        eq.forces(t, &y);
        eq.rigid_torques();
        let (torque, coupling, acc) = (bits(&eq.torque), bits(&eq.coupling_torque), bits(&eq.acc));
        let loads: Vec<_> = eq.loads.iter().map(|l| bits(l)).collect();
        let mut dy = vec![0.0; eq.dim()];
        eq.rhs(t, &y, &mut dy);
        assert_eq!(bits(&dy[n..2 * n]), acc, "{locked:?}");
        eq.acc.iter_mut().for_each(|a| *a = f64::NAN);
        eq.torques(t, &y);
        eq.rigid_torques();
        assert_eq!(bits(&eq.torque), torque, "{locked:?}");
        assert_eq!(bits(&eq.coupling_torque), coupling, "{locked:?}");
        assert_eq!(eq.loads.iter().map(|l| bits(l)).collect::<Vec<_>>(), loads);
        assert!(
            eq.acc.iter().all(|a| a.is_nan()),
            "torques left acc as it was"
        );
        // the guards read only what the probes interpolate (`probe_inputs`), and a pack's
        // guards alone only what a bisection of theirs interpolates (`guard_inputs`): the
        // other components NaN, the same guards to the bit
        let only = |ranges: &[std::ops::Range<usize>]| {
            let mut part = vec![f64::NAN; y.len()];
            for r in ranges {
                part[r.clone()].copy_from_slice(&y[r.clone()]);
            }
            part
        };
        let mut whole = vec![0.0; eq.guard_len()];
        eq.guards(t, &y, &mut whole);
        let mut probed = vec![0.0; eq.guard_len()];
        eq.guards(t, &only(&eq.probe_inputs()), &mut probed);
        assert_eq!(bits(&probed), bits(&whole), "{locked:?}");
        for k in 0..eq.packs.len() {
            let (at, len) = (eq.packs[k].guard_at, eq.packs[k].guards());
            let want: Vec<bool> = (0..whole.len()).map(|j| j >= at && j < at + len).collect();
            let ranges = eq.guard_inputs(&want).expect("a pack's guards alone");
            let mut some = vec![0.0; whole.len()];
            eq.guards_of(t, &only(&ranges), &mut some, &want);
            assert_eq!(bits(&some[at..at + len]), bits(&whole[at..at + len]));
        }
        let mut want = vec![false; whole.len()];
        want[0] = true;
        assert!(
            eq.guard_inputs(&want).is_none(),
            "a coupling's guard reads every body"
        );
        // the packs' drag power: +0 without drag, the general sum with one
        let w = &y[n..2 * n];
        for p in eq.packs.iter_mut() {
            assert!(!p.drag);
            assert_eq!(p.drag_power_w(&y, w).to_bits(), 0.0f64.to_bits());
            p.drag = true;
            assert_eq!(p.drag_power_w(&y, w).to_bits(), 0.0f64.to_bits());
            let mut pack = (*p.sys.pack).clone();
            pack.discs[0].drag_n_m_s_rad = 1e-3;
            p.set_pack(Arc::new(pack));
            assert!(p.drag);
            let wb = w[p.a] - y[p.at + 1];
            assert_eq!(p.drag_power_w(&y, w), 1e-3 * wb * wb);
        }
    }
}
