//! `[drive]` and `[shaft]`: what drives the shaft, and whether the shaft follows a speed or
//! has an inertia of its own.

use super::{Checker, Field};
use crate::csv;
use crate::keys::{
    RawDrive as D, RawHarmonic as H, RawShaft as S, MAX_SPEED_RAD_S, MAX_TORQUE_N_M,
};
use crate::schema::{show, Key, RawTable};
use clutchpack_model::{Harmonic, Shaft, ShaftExcitation, SpeedProfile, Table};
use std::path::Path;
use toml::Value;

/// `drive.kind`, in the order of the key's names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum DriveKind {
    Sine,
    Harmonics,
    SpeedTable,
    TorqueTable,
}

impl DriveKind {
    /// Every kind, in the order of `drive.kind`'s names.
    const ALL: [DriveKind; 4] = [
        DriveKind::Sine,
        DriveKind::Harmonics,
        DriveKind::SpeedTable,
        DriveKind::TorqueTable,
    ];

    /// The name as written in the file.
    fn name(self) -> &'static str {
        match D::kind.kind {
            crate::schema::Kind::Choice(names) => names[self as usize],
            _ => "?",
        }
    }

    /// The `[drive]` keys this kind takes besides `kind`.
    fn keys(self) -> &'static [&'static str] {
        match self {
            DriveKind::Sine => &[
                "omega0_rad_s",
                "amplitude_rad_s",
                "frequency_hz",
                "phase_deg",
            ],
            DriveKind::Harmonics => &["omega0_rad_s", "harmonics"],
            DriveKind::SpeedTable | DriveKind::TorqueTable => &["file", "interpolation"],
        }
    }
}

/// What the `[drive]` table describes.
pub(super) enum Drive {
    /// A speed history (sine, harmonics, speed table).
    Profile(SpeedProfile),
    /// A torque history in N m (torque table).
    Torque(Table),
}

/// `[drive]`: its kind (for the shaft's rules) and the drive itself.
pub(super) fn drive(
    ck: &mut Checker,
    raw: Option<&D>,
    base_dir: &Path,
) -> (Field<DriveKind>, Option<Drive>) {
    drive_at(ck, raw, base_dir, "drive")
}

/// A `[drive]` table at the path `at` (`drive`, or a network body's `bodies[2].speed`, which
/// takes the same forms): its kind and the drive, every problem reported under `at`.
pub(super) fn drive_at(
    ck: &mut Checker,
    raw: Option<&D>,
    base_dir: &Path,
    at: &str,
) -> (Field<DriveKind>, Option<Drive>) {
    let empty = D::default();
    let r = raw.unwrap_or(&empty);
    // the key's path under `at` (the table's own keys are written under "drive")
    let path = |k: &Key| k.rel().replacen("drive", at, 1);
    let num = |ck: &mut Checker, k: &Key| ck.num(&path(k), r.value(k), k);
    let kind_field = ck.choice(&path(&D::kind), r.kind.as_ref(), &D::kind, &DriveKind::ALL);
    let kind = match kind_field.clone() {
        Field::Absent => {
            ck.report(
                path(&D::kind),
                None,
                format!(
                    "missing (required: \"sine\", \"harmonics\", \"speed_table\" or \
                     \"torque_table\"; set it in [{at}])"
                ),
            );
            return (Field::Absent, None);
        }
        Field::Invalid => return (Field::Invalid, None),
        Field::Valid(k) => k,
    };

    // Keys of other kinds are errors: they would be silently ignored otherwise.
    let given: [(&str, Option<&Value>, bool); 7] = [
        (
            "omega0_rad_s",
            r.omega0_rad_s.as_ref(),
            r.omega0_rad_s.is_some(),
        ),
        (
            "amplitude_rad_s",
            r.amplitude_rad_s.as_ref(),
            r.amplitude_rad_s.is_some(),
        ),
        (
            "frequency_hz",
            r.frequency_hz.as_ref(),
            r.frequency_hz.is_some(),
        ),
        ("phase_deg", r.phase_deg.as_ref(), r.phase_deg.is_some()),
        ("harmonics", None, r.harmonics.is_some()),
        ("file", r.file.as_ref(), r.file.is_some()),
        (
            "interpolation",
            r.interpolation.as_ref(),
            r.interpolation.is_some(),
        ),
    ];
    for (key, value, present) in given {
        if present && !kind.keys().contains(&key) {
            ck.report(
                format!("{at}.{key}"),
                value.map(show),
                format!(
                    "not used by {at}.kind = \"{}\" (it takes: {})",
                    kind.name(),
                    kind.keys().join(", ")
                ),
            );
        }
    }

    let required = |what: &str| {
        format!(
            "required with {at}.kind = \"{}\"; set it in [{at}]{what}",
            kind.name()
        )
    };
    let drive = match kind {
        DriveKind::Sine => {
            let omega0 =
                num(ck, &D::omega0_rad_s).required(ck, &path(&D::omega0_rad_s), &required(""));
            let amplitude = num(ck, &D::amplitude_rad_s).required(
                ck,
                &path(&D::amplitude_rad_s),
                &required(""),
            );
            let frequency =
                num(ck, &D::frequency_hz).required(ck, &path(&D::frequency_hz), &required(""));
            let phase = num(ck, &D::phase_deg).or(D::phase_deg.default_num());
            (|| {
                Some(Drive::Profile(SpeedProfile::Harmonics {
                    omega0_rad_s: omega0?,
                    harmonics: vec![Harmonic {
                        amplitude_rad_s: amplitude?,
                        frequency_hz: frequency?,
                        phase_rad: phase?.to_radians(),
                    }],
                }))
            })()
        }
        DriveKind::Harmonics => {
            let omega0 =
                num(ck, &D::omega0_rad_s).required(ck, &path(&D::omega0_rad_s), &required(""));
            let raw_harmonics = r.harmonics.as_deref().unwrap_or_default();
            if raw_harmonics.is_empty() {
                ck.report(
                    format!("{at}.harmonics"),
                    None,
                    format!(
                        "missing ({at}.kind = \"harmonics\" needs at least one [[{at}.harmonics]] \
                         entry with amplitude_rad_s and frequency_hz)"
                    ),
                );
            }
            let mut harmonics = Some(Vec::new());
            for (i, h) in raw_harmonics.iter().enumerate() {
                let key = |k: &Key| format!("{at}.harmonics[{i}].{}", k.name);
                let hint = &format!("required; set it in [[{at}.harmonics]]");
                let item = |ck: &mut Checker, k: &Key| ck.num(&key(k), h.value(k), k);
                let amplitude =
                    item(ck, &H::amplitude_rad_s).required(ck, &key(&H::amplitude_rad_s), hint);
                let frequency =
                    item(ck, &H::frequency_hz).required(ck, &key(&H::frequency_hz), hint);
                let phase = item(ck, &H::phase_deg).or(H::phase_deg.default_num());
                match (amplitude, frequency, phase, harmonics.as_mut()) {
                    (Some(a), Some(f), Some(p), Some(v)) => v.push(Harmonic {
                        amplitude_rad_s: a,
                        frequency_hz: f,
                        phase_rad: p.to_radians(),
                    }),
                    _ => harmonics = None,
                }
            }
            match (omega0, harmonics) {
                (Some(omega0_rad_s), Some(harmonics)) if !harmonics.is_empty() => {
                    Some(Drive::Profile(SpeedProfile::Harmonics {
                        omega0_rad_s,
                        harmonics,
                    }))
                }
                _ => None,
            }
        }
        DriveKind::SpeedTable | DriveKind::TorqueTable => {
            let column = if kind == DriveKind::SpeedTable {
                "speed_rad_s"
            } else {
                "torque_n_m"
            };
            let file = ck.text(&path(&D::file), r.file.as_ref()).required(
                ck,
                &path(&D::file),
                &required(&format!(
                    " (a CSV file with columns time_s and {column}, relative to the scene \
                     file's folder)"
                )),
            );
            let hold = ck
                .choice(
                    &path(&D::interpolation),
                    r.interpolation.as_ref(),
                    &D::interpolation,
                    &[false, true],
                )
                .or(false);
            file.zip(hold).and_then(|(file, hold)| {
                let range = if kind == DriveKind::SpeedTable {
                    (-MAX_SPEED_RAD_S, MAX_SPEED_RAD_S)
                } else {
                    (-MAX_TORQUE_N_M, MAX_TORQUE_N_M)
                };
                ck.files.push(base_dir.join(&file));
                match csv::read_table(&base_dir.join(&file), &file, column, range) {
                    Ok(table) if hold => Some(if kind == DriveKind::SpeedTable {
                        Drive::Profile(SpeedProfile::Table(table.held()))
                    } else {
                        Drive::Torque(table.held())
                    }),
                    Ok(table) if kind == DriveKind::SpeedTable => {
                        Some(Drive::Profile(SpeedProfile::Table(table)))
                    }
                    Ok(table) => Some(Drive::Torque(table)),
                    Err(message) => {
                        ck.report(path(&D::file), r.file.as_ref().map(show), message);
                        None
                    }
                }
            })
        }
    };
    (Field::Valid(kind), drive)
}

/// `shaft.mode`, in the order of the key's names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ShaftMode {
    Prescribed,
    Inertial,
}

/// `[shaft]`, combined with the drive.
pub(super) fn shaft(
    ck: &mut Checker,
    raw: Option<&S>,
    kind: Field<DriveKind>,
    drive: Option<Drive>,
) -> Option<Shaft> {
    let empty = S::default();
    let r = raw.unwrap_or(&empty);
    let modes = [ShaftMode::Prescribed, ShaftMode::Inertial];
    let mode = ck
        .choice(&S::mode.rel(), r.mode.as_ref(), &S::mode, &modes)
        .or(modes[S::mode.default_choice()]);

    let inertial_only = "only allowed with shaft.mode = \"inertial\" (a prescribed shaft follows \
                         its speed whatever the load)";
    let (inertia, damping) = if mode == Some(ShaftMode::Prescribed) {
        ck.not_allowed(
            &S::inertia_kg_m2.rel(),
            r.inertia_kg_m2.as_ref(),
            inertial_only,
        );
        ck.not_allowed(
            &S::damping_n_m_s_rad.rel(),
            r.damping_n_m_s_rad.as_ref(),
            inertial_only,
        );
        (None, None)
    } else {
        let inertia = ck
            .num(
                &S::inertia_kg_m2.rel(),
                r.value(&S::inertia_kg_m2),
                &S::inertia_kg_m2,
            )
            .required(
                ck,
                &S::inertia_kg_m2.rel(),
                "required with shaft.mode = \"inertial\"; set it in [shaft]",
            );
        let damping = ck
            .num(
                &S::damping_n_m_s_rad.rel(),
                r.value(&S::damping_n_m_s_rad),
                &S::damping_n_m_s_rad,
            )
            .or(S::damping_n_m_s_rad.default_num());
        // the damping to ground is a drag: the same bound on its time constant J / C
        // (issue 36: J = 1e-6 kg m^2 with C = 1e6 N m s/rad collapsed the step after 26 s)
        let resolvable = match (inertia, damping) {
            (Some(j), Some(c)) => super::bodies::drag_resolvable(
                ck,
                (&S::inertia_kg_m2.rel(), j),
                (&S::damping_n_m_s_rad.rel(), c),
            ),
            _ => true,
        };
        (inertia, damping.filter(|_| resolvable))
    };

    let torque_drive = kind == Field::Valid(DriveKind::TorqueTable);
    let initial_speed = if torque_drive {
        ck.num(
            &S::initial_speed_rad_s.rel(),
            r.value(&S::initial_speed_rad_s),
            &S::initial_speed_rad_s,
        )
        .required(
            ck,
            &S::initial_speed_rad_s.rel(),
            "required with drive.kind = \"torque_table\" (a torque does not set the \
                 starting speed); set it in [shaft]",
        )
    } else {
        if let Field::Valid(k) = kind {
            ck.not_allowed(
                &S::initial_speed_rad_s.rel(),
                r.initial_speed_rad_s.as_ref(),
                &format!(
                    "only allowed with drive.kind = \"torque_table\" (drive.kind = \"{}\" sets \
                     the starting speed)",
                    k.name()
                ),
            );
        }
        None
    };
    if torque_drive && mode == Some(ShaftMode::Prescribed) {
        ck.report(
            D::kind.rel(),
            Some("\"torque_table\"".into()),
            "needs shaft.mode = \"inertial\" (a prescribed shaft follows a speed, not a torque)",
        );
        return None;
    }

    match (mode?, drive?) {
        (ShaftMode::Prescribed, Drive::Profile(p)) => Some(Shaft::Prescribed(p)),
        (ShaftMode::Prescribed, Drive::Torque(_)) => None,
        (ShaftMode::Inertial, drive) => Some(Shaft::Inertial {
            inertia_kg_m2: inertia?,
            damping_n_m_s_rad: damping?,
            excitation: match drive {
                Drive::Profile(p) => ShaftExcitation::Profile(p),
                Drive::Torque(table) => ShaftExcitation::Torque {
                    table,
                    initial_speed_rad_s: initial_speed?,
                },
            },
        }),
    }
}
