//! Cross-engine checks (issue 3): the multibody engine (rapier3d-f64, per-tooth hook) and the
//! reference engine (DOPRI5 with located events) are independent solver paths of the same
//! model. The rattle is chaotic (MODEL.md section 6), so they are compared impact by impact
//! over the first 50 ms only: same impacts, each peak within 0.5 % or 2 N (whichever is
//! larger), each onset within 2 us.
//!
//! The reference engine is the oracle here: it runs at tolerance 1e-12 (converged to about
//! 4e-9 s in onset over these 50 ms: 1e-12 and 1e-13 agree that well). The multibody engine
//! runs at its defaults on the paper case. On the four-disc pack, disc 3 has a grazing impact
//! (27 N) at 36.6 ms that amplifies every earlier difference about twenty-fold; there the
//! multibody engine at its default 128 steps per contact is 4.8 us off the oracle by 50 ms
//! (and the reference at its own default tolerance 1e-9 is 2.3 us off), so the pack is
//! checked with 512 steps per contact (0.14 us off).

use clutchpack_model::checks::{first_lock_s, heat_j};
use clutchpack_model::{Collector, Engine, ImpactEvent};
use clutchpack_multibody::{AdaptiveStepping, MultibodyEngine, MultibodyOptions, Stepping};
use clutchpack_reference::{ReferenceEngine, ReferenceOptions, Scheme};
use clutchpack_scene::Override;
use std::path::Path;

fn scene(file: &str, sets: &[&str]) -> clutchpack_scene::Scene {
    // 50 ms unless `sets` says otherwise
    let mut o: Vec<Override> = vec!["simulation.duration_s=0.05".parse().unwrap()];
    o.extend(sets.iter().map(|s| s.parse().unwrap()));
    clutchpack_scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file), &o).unwrap()
}

fn impacts(engine: &mut dyn Engine, duration: f64) -> Vec<ImpactEvent> {
    let mut c = Collector::default();
    engine.run(duration, &mut c).unwrap();
    // impacts cut off by the end of the run are not comparable
    let mut v: Vec<ImpactEvent> = c
        .impacts
        .into_iter()
        .filter(|e| e.t_off_s < duration)
        .collect();
    v.sort_by(|a, b| (a.disc, a.t_on_s).partial_cmp(&(b.disc, b.t_on_s)).unwrap());
    v
}

/// The reference's impacts `r` and the multibody engine's `m` agree one by one: as many, on
/// the same bodies and flanks, every peak within `peak.0` relative or `peak.1` N (the larger)
/// and every onset within `dt_s`; prints the count and the worst differences under `label`.
fn agree_one_by_one(
    label: &str,
    r: &[ImpactEvent],
    m: &[ImpactEvent],
    peak: (f64, f64),
    dt_s: f64,
) {
    assert_eq!(r.len(), m.len(), "{label}: impact counts");
    let (mut worst_rel, mut worst_dt) = (0.0f64, 0.0f64);
    for (a, b) in r.iter().zip(m) {
        assert_eq!(
            (a.disc, a.flank),
            (b.disc, b.flank),
            "{label}: {a:?} vs {b:?}"
        );
        assert!(
            (a.peak_n - b.peak_n).abs() <= (peak.0 * a.peak_n.abs()).max(peak.1),
            "{label}: peak {} vs {} ({a:?} vs {b:?})",
            a.peak_n,
            b.peak_n
        );
        assert!(
            (a.t_on_s - b.t_on_s).abs() <= dt_s,
            "{label}: onset {} vs {} ({a:?} vs {b:?})",
            a.t_on_s,
            b.t_on_s
        );
        worst_rel = worst_rel.max((a.peak_n - b.peak_n).abs() / a.peak_n.abs());
        worst_dt = worst_dt.max((a.t_on_s - b.t_on_s).abs());
    }
    println!(
        "{label}: {} impacts, worst peak {worst_rel:.2e}, worst onset {worst_dt:.2e} s",
        r.len()
    );
}

/// Runs both engines on `file` with `sets` for 50 ms and compares their impacts;
/// `steps_per_contact` overrides the multibody engine's adaptive default.
fn assert_engines_agree(file: &str, sets: &[&str], steps_per_contact: Option<f64>) {
    assert_engines_agree_within(file, sets, steps_per_contact, None, 2e-6);
}

/// [`assert_engines_agree`] with the multibody engine's longest step `mb_max_step_s` (else
/// the scene's) and an onset bound of `onset_s` (s).
fn assert_engines_agree_within(
    file: &str,
    sets: &[&str],
    steps_per_contact: Option<f64>,
    mb_max_step_s: Option<f64>,
    onset_s: f64,
) {
    let s = scene(file, sets);
    let duration = s.simulation.duration_s;
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        max_step_s: s.simulation.max_step_s,
        record_rate_hz: s.simulation.record_rate_hz,
    };
    let mut oracle = ReferenceEngine::new(s.pack.clone(), oracle).with_scheme(Scheme::Monolithic);
    let reference = impacts(&mut oracle, duration);
    let mut options = MultibodyOptions::default();
    if steps_per_contact.is_some() || mb_max_step_s.is_some() {
        let defaults = AdaptiveStepping::default();
        options.stepping = Stepping::Adaptive(AdaptiveStepping {
            steps_per_contact: steps_per_contact.unwrap_or(defaults.steps_per_contact),
            max_step_s: mb_max_step_s.unwrap_or(s.simulation.max_step_s),
            ..defaults
        });
    }
    let multibody = impacts(
        &mut MultibodyEngine::new(s.pack.clone(), options).unwrap(),
        duration,
    );
    // every body strikes again and again: at least once per 5 ms on average
    let per_body = (duration / 0.005).round() as usize;
    assert!(
        reference.len() >= per_body * (s.pack.discs.len() + s.pack.plates.len()),
        "{file} {sets:?}: {}",
        reference.len()
    );
    agree_one_by_one(
        &format!("{file} {sets:?}"),
        &reference,
        &multibody,
        (0.005, 2.0),
        onset_s,
    );
}

#[test]
fn paper_case_dry() {
    assert_engines_agree("scenes/hu-table2.toml", &[], None);
}

#[test]
fn paper_case_25um() {
    assert_engines_agree(
        "scenes/hu-table2.toml",
        &["defaults.oil.film_thickness_m=25e-6"],
        None,
    );
}

#[test]
fn paper_case_50um() {
    assert_engines_agree(
        "scenes/hu-table2.toml",
        &["defaults.oil.film_thickness_m=50e-6"],
        None,
    );
}

#[test]
fn four_disc_pack() {
    assert_engines_agree("scenes/pack-4-rattle.toml", &[], Some(512.0));
}

/// Issues 21 and 20: the whole open brake (8 discs, 9 plates on the housing, the open gaps'
/// drag coupling neighbours) in both engines, every disc's and plate's impacts one by one,
/// peak within 0.5 % or 2 N and onset within 2 us (issue 21), over the first **50 ms**,
/// against the oracle (tolerance 1e-12, which agrees with 1e-13 to 1.2e-8 s in onset and
/// 5e-6 in peak over 50 ms). The multibody engine runs its multirate scheme with world steps
/// of at most 1e-5 s: disc-5 grazes at 27 ms and amplifies any earlier difference, and at
/// `run`'s 1e-4 s disc-5's impact at 30.5 ms is 3.1 us off (2.5e-5 s: 1.4 us; 1e-5 s: 0.25
/// us, measured with the peaks within 1.1e-4; with the discs' speeds held at their mean in
/// the plates' gap drag it was 24 us by 50 ms at 1e-4 s). Measured here: 291 impacts.
#[test]
fn open_brake_pack_8_with_plates() {
    assert_engines_agree_within(
        "scenes/pack-8-brake.toml",
        &["simulation.duration_s=0.05"],
        None,
        Some(1e-5),
        2e-6,
    );
}

/// Issue 21: the open 8-disc brake of the MuJoCo anchor (`cases::staggered_brake(8)`: dry
/// staggered discs, 9 dry plates on the housing, the open gaps) in both engines (the
/// multibody engine's shared step), every disc's
/// and plate's impacts one by one over the first 25 ms, peak within 0.5 % or 2 N, onset
/// within 2 us; the multibody engine at a longest step of 2.5e-7 s (see
/// `open_brake_pack_8_with_plates` for why), the reference at 1e-12. Measured: 117 impacts,
/// worst peak 3.6e-4, worst onset 0.94 us. Over 50 ms the two engines' impact sequences part
/// (230 impacts in the reference's, not the same count in the multibody engine's).
#[test]
fn staggered_brake_8_with_plates() {
    // the shared step (issue 20 made the multirate scheme the default for this pack:
    // `staggered_brake_8_multirate`)
    let options = MultibodyOptions {
        scheme: clutchpack_multibody::Scheme::Shared,
        ..MultibodyOptions::with_settings(1e4, 2.5e-7, false)
    };
    brake_8_agrees(
        "staggered brake 8, shared step",
        options,
        (0.005, 2.0),
        2e-6,
        0.025,
    );
}

/// The open 8-disc brake of the MuJoCo anchor over its first `duration` s in the reference
/// engine at tolerance 1e-12 and in the multibody engine with `options`: the same impacts on
/// the same flanks, every peak within `peak.0` relative or `peak.1` N, every onset within
/// `dt_s`.
fn brake_8_agrees(
    label: &str,
    options: MultibodyOptions,
    peak: (f64, f64),
    dt_s: f64,
    duration: f64,
) {
    let pack = clutchpack_model::cases::staggered_brake(8);
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        ..ReferenceOptions::default()
    };
    let r = impacts(&mut ReferenceEngine::new(pack.clone(), oracle), duration);
    let multirate = options.scheme != clutchpack_multibody::Scheme::Shared;
    let mut engine = MultibodyEngine::new(pack, options).unwrap();
    assert_eq!(
        engine.is_multirate(),
        multirate,
        "{}",
        engine.scheme_explanation()
    );
    let m = impacts(&mut engine, duration);
    assert!(r.len() >= 5 * 17, "{}", r.len());
    assert!(r.iter().any(|e| e.disc >= 8), "the plates strike");
    agree_one_by_one(label, &r, &m, peak, dt_s);
}

/// Issue 20: the multibody engine's multirate scheme on the open 8-disc brake of the MuJoCo
/// anchor (`cases::staggered_brake(8)`: 8 staggered discs, 9 plates on the housing, the open
/// gaps' drag) against the reference engine at tolerance 1e-12, every disc's and plate's
/// impacts one by one: the same impacts on the same flanks, every peak within 0.1 % and every
/// onset within 1 us (issue 20's limits; the oracle is stricter than the shared step
/// at a tight setting, and independent).
/// - Over the first 25 ms at the settings `run` gives it (world steps of at most 0.1 ms):
///   measured worst peak 3.3e-4, worst onset 0.46 us (0.82 us, at a plate, while the plates'
///   gap drag held the discs' speeds at their mean over a world step).
/// - Over the first 50 ms with world steps of at most 1e-5 s: a disc grazes at about 27 ms and
///   amplifies any difference (at 0.1 ms the scheme is 37 us off by 50 ms, and two impacts
///   change flank); measured 230 impacts, worst peak 4.5e-5, worst onset 0.084 us (0.16 us
///   with the discs' speeds held).
#[test]
fn staggered_brake_8_multirate() {
    // the settings `run` gives it: world steps of at most 0.1 ms
    let options = MultibodyOptions::with_settings(1e4, 1e-4, false);
    brake_8_agrees(
        "staggered brake 8, multirate",
        options,
        (1e-3, 0.0),
        1e-6,
        0.025,
    );
    let options = MultibodyOptions::with_settings(1e4, 1e-5, false);
    brake_8_agrees(
        "staggered brake 8, multirate, 50 ms",
        options,
        (1e-3, 0.0),
        1e-6,
        0.05,
    );
}

/// Issue 9: the multibody engine's two schemes on the 8-disc staggered pack
/// (`clutchpack_model::cases::staggered_pack`, discs striking out of step) over 50 ms, impact
/// by impact against the reference engine at tolerance 1e-12 (the oracle: 1e-12 and 1e-13
/// agree to 4e-9 s in onset and 1.4e-6 in peak here): the same impacts on the same flanks,
/// every peak within 0.1 % and every onset within 1 us (the limits).
///
/// The pack is chaotic like the four-disc one: disc 5 (index 4) amplifies early differences
/// a thousandfold by 40-50 ms. The multirate scheme (the default for this pack) runs at its
/// defaults, 128 steps per contact graded at the kinks (measured 8.9e-8 s and 3.0e-5 worst);
/// the shared step at its default 128 is 1.3 us off at 48.9 ms (its early onsets 1e-9 s off),
/// so it is checked at 512 steps per contact, as the four-disc pack is (8.2e-8 s, 2.7e-5).
mod staggered {
    use super::impacts;
    use clutchpack_model::cases::staggered_pack;
    use clutchpack_model::ImpactEvent;
    use clutchpack_multibody::{
        AdaptiveStepping, MultibodyEngine, MultibodyOptions, Scheme, Stepping,
    };
    use clutchpack_reference::{ReferenceEngine, ReferenceOptions};

    const DURATION_S: f64 = 0.05;

    fn oracle() -> Vec<ImpactEvent> {
        let settings = ReferenceOptions {
            tolerance: 1e-12,
            ..ReferenceOptions::default()
        };
        impacts(
            &mut ReferenceEngine::new(staggered_pack(8), settings)
                .with_scheme(clutchpack_reference::Scheme::Monolithic),
            DURATION_S,
        )
    }

    fn multibody(scheme: Scheme, steps_per_contact: f64) -> (Vec<ImpactEvent>, bool) {
        let options = MultibodyOptions {
            scheme,
            stepping: Stepping::Adaptive(AdaptiveStepping {
                steps_per_contact,
                ..AdaptiveStepping::default()
            }),
            ..MultibodyOptions::default()
        };
        let mut e = MultibodyEngine::new(staggered_pack(8), options).unwrap();
        (impacts(&mut e, DURATION_S), e.is_multirate())
    }

    fn assert_agree(scheme: Scheme, steps_per_contact: f64) {
        let reference = oracle();
        let (multibody, multirate) = multibody(scheme, steps_per_contact);
        assert_eq!(multirate, scheme == Scheme::Multirate);
        // every disc strikes again and again within 50 ms
        assert!(reference.len() >= 8 * 15, "{}", reference.len());
        assert_eq!(
            reference.len(),
            multibody.len(),
            "{scheme:?}: impact counts"
        );
        let (mut worst_rel, mut worst_dt) = (0.0f64, 0.0f64);
        for (r, m) in reference.iter().zip(&multibody) {
            assert_eq!(
                (r.disc, r.flank),
                (m.disc, m.flank),
                "{scheme:?}: {r:?} vs {m:?}"
            );
            let rel = (r.peak_n - m.peak_n).abs() / r.peak_n.abs();
            assert!(
                rel <= 1e-3,
                "{scheme:?}: peak {} vs {} ({r:?})",
                r.peak_n,
                m.peak_n
            );
            let dt = (r.t_on_s - m.t_on_s).abs();
            assert!(
                dt <= 1e-6,
                "{scheme:?}: onset {} vs {} ({r:?})",
                r.t_on_s,
                m.t_on_s
            );
            worst_rel = worst_rel.max(rel);
            worst_dt = worst_dt.max(dt);
        }
        println!(
            "staggered-8 {scheme:?}: {} impacts, worst peak difference {worst_rel:.2e} \
             relative, worst onset {worst_dt:.2e} s",
            reference.len()
        );
    }

    #[test]
    fn multirate_scheme_agrees_with_the_reference() {
        let defaults = AdaptiveStepping::default();
        assert_agree(Scheme::Multirate, defaults.steps_per_contact);
    }

    #[test]
    fn shared_step_agrees_with_the_reference() {
        assert_agree(Scheme::Shared, 512.0);
    }
}

/// Issue 21: `pack-6-engagement` (6 discs rattling, 7 plates on a drum, the piston ramping at
/// 50-80 ms) in both engines (the multibody engine at its defaults: the multirate scheme until
/// the piston may push at 50 ms, the shared step from there): every interface's first lock
/// within 0.5 % and its heat within 1 % (measured 4.7e-4 and 2.6e-4; 1e5 Hz samples place a
/// lock to 10 us; 2.0e-4 and 1.2e-3 when the shared step ran from the start). Then, with the
/// multibody engine's world step at 5e-5 s, every impact one by one, peak within 0.5 % or 2 N
/// and onset within 2 us: the discs' over the first 50 ms (the open clutch; measured 137
/// impacts, worst peak 1.0e-3, worst onset 0.52 us; 1.1 us at the default 1e-4 s), the
/// plates' over the first 30 ms (47 impacts, 2.3e-3, 0.28 us). The plates ride on a free drum,
/// barely touching its teeth (2-30 N at 0.02-0.07 m/s), and such light impacts are
/// ill-conditioned: beyond about 35 ms they part even between the reference at tolerances
/// 1e-9 and 1e-12. Before the plates' gap drag took the discs' speeds as affine over a world
/// step (their first moment from the sub-steps) instead of held at their mean, the plates
/// parted from 15 ms (24 us off); before the multirate scheme ran the drum, the shared step's
/// first-order gap drag limited the discs' agreement to the first 25 ms.
#[test]
fn engagement_pack_6_locks_and_heats_alike() {
    let s = scene(
        "scenes/pack-6-engagement.toml",
        &[
            "simulation.duration_s=0.12",
            "simulation.record_rate_hz=1e5",
        ],
    );
    let duration = s.simulation.duration_s;
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        max_step_s: s.simulation.max_step_s,
        record_rate_hz: s.simulation.record_rate_hz,
    };
    let mut reference = Collector::default();
    ReferenceEngine::new(s.pack.clone(), oracle)
        .run(duration, &mut reference)
        .unwrap();
    let options = MultibodyOptions::with_settings(
        s.simulation.record_rate_hz,
        s.simulation.max_step_s,
        false,
    );
    let mut multibody = Collector::default();
    MultibodyEngine::new(s.pack.clone(), options)
        .unwrap()
        .run(duration, &mut multibody)
        .unwrap();
    let first_lock = |c: &Collector, m: usize| first_lock_s(c, m).expect("every face locks");
    let (mut worst_lock, mut worst_heat) = (0.0f64, 0.0f64);
    for m in 0..2 * s.pack.discs.len() {
        let (lr, lm) = (first_lock(&reference, m), first_lock(&multibody, m));
        let (hr, hm) = (heat_j(&reference, m), heat_j(&multibody, m));
        worst_lock = worst_lock.max((lr - lm).abs() / lr);
        worst_heat = worst_heat.max((hr - hm).abs() / hr);
        assert!(
            (lr - lm).abs() <= 5e-3 * lr,
            "interface {m}: lock {lr} vs {lm}"
        );
        assert!(
            (hr - hm).abs() <= 1e-2 * hr,
            "interface {m}: heat {hr} vs {hm}"
        );
    }
    println!("pack-6-engagement: locks within {worst_lock:.2e}, heat within {worst_heat:.2e}");

    // the discs' impacts over the first 50 ms
    let s = scene(
        "scenes/pack-6-engagement.toml",
        &["simulation.duration_s=0.05"],
    );
    let nd = s.pack.discs.len();
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        ..ReferenceOptions::default()
    };
    let discs = |v: Vec<ImpactEvent>| v.into_iter().filter(|e| e.disc < nd).collect::<Vec<_>>();
    let all_r = impacts(&mut ReferenceEngine::new(s.pack.clone(), oracle), 0.05);
    let options = MultibodyOptions::with_settings(1e4, 5e-5, false);
    let mut e = MultibodyEngine::new(s.pack.clone(), options).unwrap();
    assert!(e.is_multirate(), "{}", e.scheme_explanation());
    let all_m = impacts(&mut e, 0.05);
    // the plates' over the first 30 ms
    let plates = |v: &[ImpactEvent]| {
        v.iter()
            .filter(|e| e.disc >= nd && e.t_on_s < 0.03)
            .copied()
            .collect::<Vec<_>>()
    };
    let (pr, pm) = (plates(&all_r), plates(&all_m));
    assert!(pr.len() >= 5 * (nd + 1), "{}", pr.len());
    agree_one_by_one(
        "pack-6-engagement, plates, first 30 ms",
        &pr,
        &pm,
        (0.005, 2.0),
        2e-6,
    );
    let (r, m) = (discs(all_r), discs(all_m));
    assert!(r.len() >= 5 * nd, "{}", r.len());
    agree_one_by_one(
        "pack-6-engagement, discs, first 50 ms",
        &r,
        &m,
        (0.005, 2.0),
        2e-6,
    );
}

/// Issue 20: an open clutch on an inertial shaft with its plates on a drum, both inertial
/// carriers in the multibody engine's multirate scheme (`pack-6-engagement` with the shaft
/// made inertial, J1 = 2 kg m^2 driven by `J1 d(profile)/dt`, the piston not yet pushing),
/// against the reference engine at 1e-12 (monolithic): every disc's and plate's impacts one by
/// one over the first 15 ms, peak within 0.1 % and onset within 1 us (issue 20's limits;
/// measured: 56 impacts, 3.7e-4 and 0.17 us). Not longer: this pack is chaotic beyond what
/// either engine resolves (the reference at 1e-10 and 1e-12 part at about 25 ms, at 1e-12
/// and 1e-13 at about 30 ms); the shared step's discs part from the reference at 4 ms.
#[test]
fn inertial_shaft_with_a_drum_multirate() {
    let s = scene(
        "scenes/pack-6-engagement.toml",
        &[
            "shaft.mode=inertial",
            "shaft.inertia_kg_m2=2",
            "simulation.duration_s=0.015",
        ],
    );
    let nd = s.pack.discs.len();
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        ..ReferenceOptions::default()
    };
    let r = impacts(&mut ReferenceEngine::new(s.pack.clone(), oracle), 0.015);
    let options = MultibodyOptions::with_settings(1e4, s.simulation.max_step_s, false);
    let mut e = MultibodyEngine::new(s.pack.clone(), options).unwrap();
    assert!(e.is_multirate(), "{}", e.scheme_explanation());
    let m = impacts(&mut e, 0.015);
    assert!(
        r.len() >= 5 * nd && r.iter().any(|e| e.disc >= nd),
        "{}",
        r.len()
    );
    agree_one_by_one(
        "inertial shaft and drum, first 15 ms",
        &r,
        &m,
        (1e-3, 0.0),
        1e-6,
    );
}

/// Separator plates without a stack run the multirate scheme (issue 20): each plate alone
/// against its drum (integrated with the plates that may touch it), each disc alone against
/// the shaft; nothing couples a plate to a disc. The staggered brake's two discs and three
/// plates, without its stack, the plates on a drum (0.5 kg m^2, load -300 N m, starting at
/// 195 rad/s, the plates staggered across +-0.6 of their half play), against the reference
/// engine at 1e-12 over the first 25 ms: every impact one by one within 0.1 % and 1 us.
/// Measured: 48 impacts, 9.2e-5 relative and 0.10 us. From about 23 ms the plates' light
/// impacts (35 N) amplify every difference about threefold each: over 30 ms the multirate
/// scheme and the shared step alike part from the reference at 27.7 ms (4.5 and 4.7 us at
/// worst), so the check stops at 25 ms.
#[test]
fn plates_without_a_stack_multirate() {
    let mut pack = clutchpack_model::cases::staggered_brake(2);
    pack.stack = None;
    pack.drum = Some(clutchpack_model::DrumModel {
        inertia_kg_m2: 0.5,
        load_torque_n_m: -300.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: 195.0,
    });
    for (j, p) in pack.plates.iter_mut().enumerate() {
        p.initial_rel_angle_rad = 0.6 * p.spline.half_play_rad() * (j as f64 - 1.0);
    }
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        ..ReferenceOptions::default()
    };
    let r = impacts(&mut ReferenceEngine::new(pack.clone(), oracle), 0.025);
    let mut e =
        MultibodyEngine::new(pack, MultibodyOptions::with_settings(1e4, 1e-4, false)).unwrap();
    assert!(e.is_multirate(), "{}", e.scheme_explanation());
    let m = impacts(&mut e, 0.025);
    let plates = r.iter().filter(|e| e.disc >= 2).count();
    assert!(plates >= 10 && r.len() > plates, "{r:?}");
    agree_one_by_one(
        "plates without a stack, first 25 ms",
        &r,
        &m,
        (1e-3, 0.0),
        1e-6,
    );
}

/// Issue 35: a thermal scene run on both engines at its own settings; every body's and the
/// oil's final temperature rise, relative to the reference engine's, is returned as the worst
/// (its body named), the per-body rises and the heat of both printed; both balance their heat
/// to rounding and send the same number of temperature points.
fn thermal_agreement(file: &str, sets: &[&str]) -> (f64, String) {
    let o: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
    let s = clutchpack_scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file), &o).unwrap();
    let sim = &s.simulation;
    let duration = sim.duration_s;
    let mut rc = Collector::default();
    let r = ReferenceEngine::new(
        s.pack.clone(),
        ReferenceOptions {
            tolerance: sim.tolerance,
            max_step_s: sim.max_step_s,
            record_rate_hz: sim.record_rate_hz,
        },
    )
    .with_thermal(s.thermal.clone())
    .run(duration, &mut rc)
    .unwrap()
    .thermal
    .unwrap();
    let mut mc = Collector::default();
    let m = MultibodyEngine::new(
        s.pack.clone(),
        MultibodyOptions::with_settings(sim.record_rate_hz, sim.max_step_s, false),
    )
    .unwrap()
    .with_thermal(s.thermal.clone())
    .run(duration, &mut mc)
    .unwrap()
    .thermal
    .unwrap();
    let t0 = s.thermal.as_ref().unwrap().initial_k;
    let mut worst = (0.0f64, String::new());
    let names: Vec<String> = s
        .pack
        .discs
        .iter()
        .chain(&s.pack.plates)
        .map(|d| d.name.clone())
        .chain(["oil".to_string()])
        .collect();
    let finals = |x: &clutchpack_model::thermal::ThermalReport| {
        let mut v = x.final_k.clone();
        v.push(x.oil_final_k);
        v
    };
    for ((name, tr), tm) in names.iter().zip(finals(&r)).zip(finals(&m)) {
        let rise = tr - t0;
        let off = (tm - tr).abs() / rise;
        println!(
            "{file} {name}: reference +{rise:.5} K, multibody +{:.5} K, {off:.2e} of the rise",
            tm - t0
        );
        if off > worst.0 {
            worst = (off, name.clone());
        }
    }
    println!(
        "{file}: heat: reference {:.2} J (faces {:.2}, gaps {:.3}, teeth {:.3}), multibody \
         {:.2} J (faces {:.2}, gaps {:.3}, teeth {:.3}); worst rise {:.2e} ({})",
        r.generated_j(),
        r.friction_heat_j,
        r.gap_heat_j,
        r.impact_heat_j,
        m.generated_j(),
        m.friction_heat_j,
        m.gap_heat_j,
        m.impact_heat_j,
        worst.0,
        worst.1
    );
    assert_eq!(rc.temperatures.len(), mc.temperatures.len());
    for x in [&r, &m] {
        assert!((x.accounted_j() - x.generated_j()).abs() <= 1e-12 * x.generated_j());
    }
    worst
}

/// Issue 35: pack-6-thermal (pack-6-engagement with temperatures: the rattle, the piston's
/// ramp, the faces slipping until they lock; 0.3 s, 300 windows of 1 ms) on both engines:
/// every body's and the oil's final temperature rise within 0.1 % (issue 35's bound) of the
/// reference engine's. The faces' heat (38.4 kJ of 39.7) dominates and is set by the
/// engagement's slip, which both engines resolve alike (the heat per face within 1 %,
/// `engagement_pack_6_locks_and_heats_alike`; here the faces' total within 6e-6); the rattle
/// before it is chaotic, and the teeth's heat (37 J, into the oil) differs by 5e-3.
/// Measured: worst 2.4e-4 of the rise (plate-7, +3.960 K; the oil 2.2e-4 of +0.678 K).
#[test]
fn thermal_pack_6_heats_alike() {
    let (worst, body) = thermal_agreement("scenes/pack-6-thermal.toml", &[]);
    assert!(worst <= 1e-3, "{body} off by {worst:.3e} of its rise");
}

/// Issue 35: the duty cycle's first 3 s on both engines (pack-6-duty-cycle: the engagement,
/// 1.5 s locked driving the drum, the release, the open pack rattling while the drum's load
/// brakes it, the second engagement's start): the gaps' drag now heats the oil as much as the
/// faces heat the plates (31 kJ and 39 kJ). The scene's faces take `mu(v, T)` from its
/// `[thermal.friction]` table at their temperatures, window by window, in both engines.
/// Every final temperature rise within 0.1 % of the reference engine's. Measured: worst
/// 2.3e-4 of the rise (the oil, +9.692 K; the plates within 1.2e-4, plate-7 +4.092 K; the
/// discs within 6.6e-5); the faces' heat 39 313.5 and 39 313.0 J (1.2e-5), the teeth's 929 J
/// and 939 J (the chaotic rattle's 1 %, which is the oil's difference). (Before the table:
/// worst 1.5e-4, disc-4.)
#[test]
fn thermal_duty_cycle_heats_alike() {
    let s = scene(
        "scenes/pack-6-duty-cycle.toml",
        &["simulation.duration_s=3"],
    );
    assert!(
        s.thermal.as_ref().is_some_and(|t| t.friction.is_some()),
        "the duty cycle's faces take mu(v, T)"
    );
    let (worst, body) = thermal_agreement(
        "scenes/pack-6-duty-cycle.toml",
        &["simulation.duration_s=3"],
    );
    assert!(worst <= 1e-3, "{body} off by {worst:.3e} of its rise");
}

/// Issue 33, "growth is cheap": `scenes/pack-4-damper.toml`, pack-4-rattle's four discs
/// rattling on an inertial shaft (J1 = 2 kg m^2, the paper's drive as a torque) joined by a
/// torsional spring-damper (MODEL.md section 8: 5000 N m/rad, 5 N m s/rad) to a drum of
/// 0.5 kg m^2 with one plate rattling on it. The multibody engine runs it on the shared step
/// (the multirate scheme integrates the shaft and the drum apart within a world step), the
/// reference engine monolithic at 1e-12. Every disc's and the plate's impacts one by one over
/// the first 15 ms: peak within 0.1 %, onset within 1.5 us (measured: 32 impacts, 2.95e-4 and
/// 0.79 us). Not longer: the shared step's first impact outside the paper case's bounds
/// (0.5 %, 2 us) comes at 16.8 ms (disc 1), the reference at 1e-10 and 1e-12 part at 31.9 ms.
#[test]
fn damper_pack_4_inertial_shaft_spring_to_the_drum() {
    let s = scene(
        "scenes/pack-4-damper.toml",
        &["simulation.duration_s=0.015"],
    );
    assert_eq!(s.pack.couplings.len(), 1);
    let nd = s.pack.discs.len();
    let oracle = ReferenceOptions {
        tolerance: 1e-12,
        max_step_s: s.simulation.max_step_s,
        record_rate_hz: s.simulation.record_rate_hz,
    };
    let r = impacts(&mut ReferenceEngine::new(s.pack.clone(), oracle), 0.015);
    let options = MultibodyOptions::with_settings(1e4, s.simulation.max_step_s, false);
    let mut e = MultibodyEngine::new(s.pack.clone(), options).unwrap();
    assert!(!e.is_multirate(), "{}", e.scheme_explanation());
    let m = impacts(&mut e, 0.015);
    assert!(
        r.len() >= 6 * nd && r.iter().any(|e| e.disc >= nd),
        "{}",
        r.len()
    );
    agree_one_by_one("pack-4-damper, first 15 ms", &r, &m, (1e-3, 0.0), 1.5e-6);
}
