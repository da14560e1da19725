//! Hardening, round 3 (networks, thermal packs, frame-stepped runs): the promises the packs
//! keep, kept by the surfaces added since. Each test is named after the defect it protects
//! against; the reproducers are those of the issue. No test times anything: "before the run"
//! is checked by what was (not) written.

use super::hardening::{exit_2, repo};
use super::{run, scratch, stderr};

/// Item 1: a pack file that names a network scene back (a network whose pack is the network
/// itself, or a -> b -> a) recursed until the stack overflowed (SIGABRT from `check`, `run`,
/// `fmu` and `sweep`). Every command now exits 2 naming `couplings[k].pack`, before any work.
#[test]
fn pack_file_naming_a_network_back_is_refused() {
    let d = scratch("hard3-pack-cycle");
    let net = std::fs::read_to_string(repo("scenes/dct-upshift.toml")).unwrap();
    // the K2 pack file is the network itself
    let k2 = net
        .find("pack = \"dct-k2.toml\"")
        .expect("dct-upshift names dct-k2.toml");
    let own = format!(
        "{}pack = \"self.toml\"{}",
        &net[..k2],
        &net[k2 + "pack = \"dct-k2.toml\"".len()..]
    )
    .replace(
        "\"dct-k1.toml\"",
        &format!("{:?}", repo("scenes/dct-k1.toml")),
    );
    std::fs::write(d.join("self.toml"), &own).unwrap();
    // a -> b -> a
    let a = own.replace("\"self.toml\"", "\"b.toml\"");
    let b = own.replace("\"self.toml\"", "\"a.toml\"");
    std::fs::write(d.join("a.toml"), &a).unwrap();
    std::fs::write(d.join("b.toml"), &b).unwrap();
    for scene in ["self.toml", "a.toml"] {
        let path = d.join(scene).display().to_string();
        let fmu = d.join("x.fmu").display().to_string();
        for args in [
            vec!["check", &path],
            vec!["run", &path, "--no-record"],
            vec!["fmu", &path, "--out", &fmu],
            vec![
                "sweep",
                &path,
                "--param",
                "simulation.duration_s",
                "--values",
                "0.01",
            ],
        ] {
            let err = exit_2(&run(&args), &format!("{args:?}"));
            assert!(
                err.contains("couplings[2].pack") && err.contains("is a network scene"),
                "{args:?}: {err}"
            );
        }
        assert!(!d.join("x.fmu").exists());
    }
}

/// `check` of `scene` with `sets` (each `--set key=value`): exit 2 naming `key` in its message
/// with `needle`.
fn refused_at(scene: &str, sets: &[&str], key: &str, needle: &str) {
    let mut args = vec!["check", scene];
    for s in sets {
        args.extend(["--set", s]);
    }
    let err = exit_2(&run(&args), &format!("{sets:?}"));
    assert!(
        err.contains(key) && err.contains(needle),
        "{sets:?}: expected {key} ... {needle} in: {err}"
    );
}

/// Item 5: the keys a network adds have bounds that keep a run finite, as the pack's keys do:
/// a spring damping with a 1e-10 s time constant, a free angle of 1e15 rad, a preload of
/// 1e8 N m, 65 firing harmonics or one of 1e8 N m, a body drag of 1e9 N m s/rad, a clutch
/// force of 1e300, and a table row of 1e300 (a torque table and a force table) were accepted
/// by `check` and then ran for hours or diverged. Each is refused at its key, with the bound.
#[test]
fn network_keys_without_bounds_are_refused_by_check() {
    let lumped = repo("scenes/dct-upshift-lumped.toml");
    let s = lumped.as_str();
    refused_at(
        s,
        &["couplings[0].damping_n_m_s_per_rad=1e9"],
        "couplings[0].damping_n_m_s_per_rad = 1e9",
        "damping time constant",
    );
    refused_at(
        s,
        &["couplings[0].free_angle_rad=1e15"],
        "couplings[0].free_angle_rad = 1e15",
        "must be",
    );
    refused_at(
        s,
        &[
            "couplings[0].stiffness_n_m_per_rad=1e9",
            "couplings[0].free_angle_rad=0.1",
        ],
        "couplings[0].free_angle_rad = 0.1",
        "preload torque",
    );
    let many = format!(
        "bodies[0].firing.amplitudes_n_m=[{}]",
        ["1.0"; 65].join(",")
    );
    refused_at(s, &[&many], "bodies[0].firing.amplitudes_n_m", "at most 64");
    refused_at(
        s,
        &["bodies[0].firing.amplitudes_n_m=[1e8, 100.0]"],
        "bodies[0].firing.amplitudes_n_m[0] = 100000000",
        "plausibility bound",
    );
    refused_at(
        s,
        &["bodies[1].drag_n_m_s_rad=1e9"],
        "bodies[1].drag_n_m_s_rad = 1e9",
        "drag time constant",
    );
    refused_at(
        s,
        &["couplings[1].force.height=1e300"],
        "couplings[1].force.height = 1e300",
        "must be",
    );
    // table rows: a force table (K2's) and a torque table (the engine's drive)
    let d = scratch("hard3-bounds");
    let k2 = std::fs::read_to_string(repo("scenes/dct-upshift-k2.csv")).unwrap();
    std::fs::write(d.join("k2.csv"), format!("{k2}9.0,1e300\n")).unwrap();
    std::fs::write(d.join("torque.csv"), "time_s,torque_n_m\n0,100\n1,1e300\n").unwrap();
    let net = std::fs::read_to_string(&lumped).unwrap();
    let scene = d.join("net.toml");
    std::fs::write(&scene, net.replace("dct-upshift-k2.csv", "k2.csv")).unwrap();
    let scene = scene.display().to_string();
    refused_at(
        &scene,
        &[],
        "couplings[2].force.file",
        "force = 1e300 is outside",
    );
    let drive = "kind = \"constant\"\nvalue_n_m = 250.0";
    assert!(
        net.contains(drive),
        "the crank's drive in dct-upshift-lumped.toml"
    );
    let tabled = d.join("tabled.toml");
    std::fs::write(
        &tabled,
        net.replacen(drive, "kind = \"table\"\nfile = \"torque.csv\"", 1),
    )
    .unwrap();
    refused_at(
        &tabled.display().to_string(),
        &[],
        "bodies[0].drive.file",
        "torque_n_m = 1e300 is outside",
    );
    // a road load's quadratic part of 4294967296 on the car (a fuzzed launch.toml ran over
    // 60 s on the multibody engine), and its constant part beyond the torque bound
    let launch = repo("scenes/launch.toml");
    refused_at(
        &launch,
        &["bodies[3].road_load.quadratic_n_m_s2_rad2=4294967296"],
        "bodies[3].road_load.quadratic_n_m_s2_rad2 = 4294967296",
        "must be in [0, 1e7]",
    );
    refused_at(
        &launch,
        &["bodies[3].road_load.quadratic_n_m_s2_rad2=1e6"],
        "bodies[3].road_load.quadratic_n_m_s2_rad2 = 1000000",
        "time constant",
    );
    refused_at(
        &launch,
        &["bodies[3].road_load.constant_n_m=1e8"],
        "bodies[3].road_load.constant_n_m",
        "must be",
    );
    // a plate's loss coefficient of 1e6 s/m (a fuzzed pack-6-thermal.toml ran 0.3 s for
    // over 60 s; the stall check stops only far larger values)
    refused_at(
        &repo("scenes/pack-6-thermal.toml"),
        &["plate_defaults.contact.loss_coefficient_s_m=1e6"],
        "plate_defaults.contact.loss_coefficient_s_m = 1000000",
        "must be in [0, 1000]",
    );
    // the shipped scenes stay within every bound
    let o = run(&[
        "check",
        s,
        &repo("scenes/dct-upshift.toml"),
        &repo("scenes/launch.toml"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// Item 6: outputs overwrote the files the scene reads: a network's pack files and force
/// tables, a pack's speed table (`run --out`/`--summary-json`/`--impacts-csv`/
/// `--fatigue-json` and `fmu --out` replaced them, exit 0). Each is refused before the run
/// (exit 2 naming the flag and the input), and the input is left as it was. The scenes are
/// copied to a scratch folder first, so that a regression cannot destroy the shipped files.
#[test]
fn outputs_over_the_files_a_scene_reads_are_refused() {
    let d = scratch("hard3-inputs");
    for f in [
        "dct-upshift.toml",
        "dct-k1.toml",
        "dct-k2.toml",
        "dct-upshift-lumped.toml",
        "dct-upshift-k2.csv",
        "pack-8-brake.toml",
    ] {
        std::fs::copy(repo(&format!("scenes/{f}")), d.join(f)).unwrap();
    }
    // a pack with a speed table: pack-8-brake's drive replaced by a table
    std::fs::write(
        d.join("speed.csv"),
        "time_s,speed_rad_s\n0,100\n0.01,110\n0.02,100\n",
    )
    .unwrap();
    let brake = std::fs::read_to_string(d.join("pack-8-brake.toml")).unwrap();
    let drive_at = brake.find("[drive]").expect("pack-8-brake has a [drive]");
    let end = brake[drive_at + 7..]
        .find("\n[")
        .map_or(brake.len(), |e| drive_at + 7 + e);
    let tabled = format!(
        "{}[drive]\nkind = \"speed_table\"\nfile = \"speed.csv\"\n{}",
        &brake[..drive_at],
        &brake[end..]
    );
    std::fs::write(d.join("tabled.toml"), tabled).unwrap();
    let p = |f: &str| d.join(f).display().to_string();
    let cases: [(&str, &str); 3] = [
        ("dct-upshift.toml", "dct-k2.toml"),
        ("dct-upshift-lumped.toml", "dct-upshift-k2.csv"),
        ("tabled.toml", "speed.csv"),
    ];
    let o = run(&["check", &p("tabled.toml")]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for (scene, input) in cases {
        let before = std::fs::read(d.join(input)).unwrap();
        for flag in ["--out", "--summary-json", "--impacts-csv", "--fatigue-json"] {
            let o = run(&["run", &p(scene), "--duration", "0.001", flag, &p(input)]);
            let err = exit_2(&o, &format!("{scene} {flag}"));
            assert!(
                err.contains(flag) && err.contains("is an input of this run"),
                "{scene} {flag}: {err}"
            );
        }
        let o = run(&["fmu", &p(scene), "--out", &p(input)]);
        let err = exit_2(&o, &format!("fmu {scene}"));
        assert!(
            err.contains("is an input of this run"),
            "fmu {scene}: {err}"
        );
        assert_eq!(std::fs::read(d.join(input)).unwrap(), before, "{input}");
    }
}

/// Item 10: an empty body name passed `check` and `run`, and `clutchpack fmu` packed an FMU
/// whose variables `bodies.''.speed_rad_s` failed `fmpy validate`. A name is part of every
/// output and variable name of its part: empty, a separator (`.`, `[`, `]`), a quote or a
/// space at an end is refused at its key, by every command, before any work.
#[test]
fn empty_body_name_is_refused() {
    let lumped = repo("scenes/dct-upshift-lumped.toml");
    let d = scratch("hard3-names");
    let fmu = d.join("x.fmu").display().to_string();
    for (set, key) in [
        ("bodies[5].name=\"\"", "bodies[5].name"),
        ("bodies[5].name=\"a.b\"", "bodies[5].name"),
        ("bodies[5].name=\" vehicle\"", "bodies[5].name"),
        ("couplings[1].name=\"\"", "couplings[1].name"),
    ] {
        for args in [
            vec!["check", &lumped, "--set", set],
            vec!["run", &lumped, "--no-record", "--set", set],
            vec!["fmu", &lumped, "--out", &fmu, "--set", set],
        ] {
            let err = exit_2(&run(&args), &format!("{args:?}"));
            assert!(
                err.contains(key) && err.contains("must not"),
                "{args:?}: {err}"
            );
        }
        assert!(!d.join("x.fmu").exists());
    }
}

/// Across all items: the seeded fuzz of the packs (tests/reliability.rs) on the surfaces
/// added since: 1200 mutations of the network and thermal scenes (one to three each: a
/// hostile value, a line dropped, doubled or its key renamed) go through `check`; a sample
/// of the accepted ones and of the refused ones runs 10 ms on each engine. Every `check`
/// exits 0 or 2; every run ends within 60 s (a hang guard, not a timing) with 0, 2, or 1
/// saying the run diverged; a run that exits 0 prints no `inf` or `NaN`; nothing panics.
#[test]
fn mutated_network_and_thermal_scenes_end_with_exit_0_1_or_2() {
    use super::reliability::{accepted_by_check, mutated_scenes, run_ends_cleanly};
    use std::time::Duration;
    let d = scratch("hard3-fuzz");
    for f in [
        "dct-k1.toml",
        "dct-k2.toml",
        "dct-upshift-k2.csv",
        "launch-clutch.csv",
    ] {
        std::fs::copy(repo(&format!("scenes/{f}")), d.join(f)).unwrap();
    }
    let sources: Vec<String> = [
        "dct-upshift-lumped",
        "launch",
        "coupled-clutches",
        "dct-upshift",
        "pack-6-thermal",
        "pack-8-idle-thermal",
    ]
    .iter()
    .map(|n| std::fs::read_to_string(repo(&format!("scenes/{n}.toml"))).unwrap())
    .collect();
    let files = mutated_scenes(&d, &sources, 1200, 0x5eed_4800_0000_0003, "n");
    let accepted = accepted_by_check(&files, 300);
    assert!(
        accepted.len() > 100,
        "some mutations are harmless: {}",
        accepted.len()
    );
    let mut sample: Vec<&std::path::PathBuf> =
        accepted.iter().step_by(accepted.len() / 30 + 1).collect();
    sample.extend(files.iter().step_by(100));
    let mut diverged = Vec::new();
    for f in sample {
        for engine in ["reference", "multibody"] {
            let args = ["--no-record", "--duration", "0.01", "--engine", engine];
            if !run_ends_cleanly(&args, f, Duration::from_secs(60)) {
                diverged.push(format!("{engine} {}", f.display()));
            }
        }
    }
    eprintln!(
        "{} of {} mutations accepted; diverged (exit 1, said so): {diverged:?}",
        accepted.len(),
        files.len()
    );
}
