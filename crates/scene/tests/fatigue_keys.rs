//! The fatigue keys of a body (`fatigue.*`: tooth form; `material.*`: S-N curve and failure,
//! MODEL.md section 7): defaults, inheritance from `[defaults]`, and bad values reported with
//! their key path, the value as written and the rule (the CLI exits 2 on them).

use clutchpack_model::fatigue::{FatigueParams, Material, MinerRule, ToothForm};
use clutchpack_scene::{parse, Override, Scene, SceneError};
use std::path::Path;

/// Two paper discs; disc 2 overrides its face width and Miner rule.
const TWO_DISCS: &str = r#"
[simulation]
duration_s = 0.3

[drive]
kind = "sine"
omega0_rad_s = 200.0
amplitude_rad_s = 4.378
frequency_hz = 104.0

[defaults]
inertia_kg_m2 = 0.156

[defaults.spline]
teeth = 154
pitch_radius_m = 0.231
pressure_angle_deg = 20.0
backlash_m = 0.75e-3

[defaults.contact]
modulus_pa = 210e9
curvature_radius_m = 1.75e-3

[defaults.material]
slope = 8.0

[[discs]]
name = "a"

[[discs]]
name = "b"
[discs.fatigue]
face_width_m = 4e-3
[discs.material]
miner_rule = "elementary"
"#;

fn load(overrides: &[&str]) -> Result<Scene, SceneError> {
    let sets: Vec<Override> = overrides.iter().map(|s| s.parse().unwrap()).collect();
    parse(TWO_DISCS, "scenes/test.toml", Path::new("."), &sets)
}

/// Built-in defaults are the model's (one definition), `[defaults]` applies to every disc,
/// a disc's own value wins.
#[test]
fn defaults_inherit_and_override() {
    let s = load(&[]).unwrap();
    assert_eq!(s.fatigue.len(), 2);
    let m = Material {
        slope: 8.0,
        ..Material::default()
    };
    assert_eq!(
        s.fatigue[0],
        FatigueParams {
            form: ToothForm::default(),
            material: m
        }
    );
    assert_eq!(s.fatigue[1].form.face_width_m, 4e-3);
    assert_eq!(s.fatigue[1].material.rule, MinerRule::Elementary);
    assert_eq!(s.fatigue[1].material.slope, 8.0);
}

/// Each bad tooth-form or material value is one problem: key, value as written, rule.
#[test]
fn bad_values_name_key_value_and_rule() {
    let cases: [(&str, &str, &str, &str); 9] = [
        (
            "defaults.fatigue.form_factor=0",
            "defaults.fatigue.form_factor",
            "0",
            "must be > 0",
        ),
        (
            "discs[1].fatigue.stress_correction_factor=0.5",
            "discs[1].fatigue.stress_correction_factor",
            "0.5",
            "must be in [1, 10]",
        ),
        (
            "defaults.fatigue.load_distribution_factor=0.9",
            "defaults.fatigue.load_distribution_factor",
            "0.9",
            "must be in [1, 10]",
        ),
        (
            "discs[0].fatigue.face_width_m=-3e-3",
            "discs[0].fatigue.face_width_m",
            "-0.003",
            "must be > 0",
        ),
        (
            "defaults.fatigue.working_depth_m=0",
            "defaults.fatigue.working_depth_m",
            "0",
            "must be > 0",
        ),
        (
            "defaults.material.endurance_amplitude_pa=-315e6",
            "defaults.material.endurance_amplitude_pa",
            "-315000000.0",
            "must be > 0",
        ),
        (
            "discs[1].material.knee_cycles=0",
            "discs[1].material.knee_cycles",
            "0",
            "must be > 0",
        ),
        (
            "defaults.material.slope=1",
            "defaults.material.slope",
            "1",
            "must be in (1, 50)",
        ),
        (
            "discs[0].material.miner_rule=\"palmgren\"",
            "discs[0].material.miner_rule",
            "\"palmgren\"",
            "must be one of: \"original\", \"elementary\", \"haibach\"",
        ),
    ];
    for (set, key, value, rule) in cases {
        let e = load(&[set]).expect_err(set);
        let p = &e.problems()[0];
        assert_eq!(e.problems().len(), 1, "{e}");
        assert_eq!(p.key, key);
        assert_eq!(p.value.as_deref(), Some(value), "{e}");
        assert!(p.rule.starts_with(rule), "{e}");
        assert!(e
            .to_string()
            .starts_with(&format!("scenes/test.toml: {key} = {value}: {rule}")));
    }
    let e = load(&[
        "defaults.material.critical_damage=0",
        "discs[1].fatigue.oops=1",
    ])
    .unwrap_err();
    assert_eq!(e.problems().len(), 2, "{e}");
    assert!(
        e.problems().iter().any(|p| p.key == "discs[1].fatigue.oops"
            && p.rule.contains("expected one of: form_factor,")),
        "{e}"
    );
}
