//! Network scenes (`[[bodies]]` and `[[couplings]]`, MODEL.md section 8): the shipped example
//! reaches the model as the case built in code, and a bad network is explained at its key.

use clutchpack_scene::{load, parse, SceneError};
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// `scenes/coupled-clutches.toml` is exactly `cases::coupled_clutches()` (Modelica's
/// CoupledClutches), degrees turned into radians.
#[test]
fn coupled_clutches_scene_is_the_case() {
    let scene = load(&root().join("scenes/coupled-clutches.toml"), &[]).unwrap();
    assert_eq!(
        scene.network.as_ref(),
        Some(&clutchpack_model::cases::coupled_clutches())
    );
    assert_eq!(scene.simulation.duration_s, 1.5);
    assert!(scene.pack.discs.is_empty());
}

const TWO: &str = r#"
[simulation]
duration_s = 1.0

[[bodies]]
name = "engine"
inertia_kg_m2 = 0.2
initial_speed_rad_s = 100.0
[bodies.drive]
kind = "constant"
value_n_m = 50.0

[[bodies]]
name = "vehicle"
inertia_kg_m2 = 10.0
[bodies.road_load]
quadratic_n_m_s2_rad2 = 0.01

[[couplings]]
name = "launch"
kind = "clutch"
a = "engine"
b = "vehicle"
mu = 0.1
max_normal_force_n = 5000.0
cgeo_m = 0.2
[couplings.force]
kind = "ramp"
height = 1.0
start_s = 0.1
duration_s = 0.2
"#;

fn problems(text: &str) -> Vec<String> {
    match parse(text, "scenes/net.toml", Path::new("."), &[]) {
        Ok(_) => panic!("should be refused"),
        Err(SceneError::Invalid { problems, .. }) => {
            problems.iter().map(|p| p.to_string()).collect()
        }
        Err(e) => panic!("{e}"),
    }
}

/// A coupling naming an unknown body, a loop of ideal gears, a body nothing moves, a key of
/// another kind and a pack's section are each reported at their key, all at once.
#[test]
fn bad_networks_are_explained_at_their_keys() {
    let ok = parse(TWO, "scenes/net.toml", Path::new("."), &[]).unwrap();
    assert_eq!(ok.network.unwrap().couplings.len(), 1);
    let bad = TWO.replace("b = \"vehicle\"", "b = \"vehicel\"");
    let p = problems(&bad);
    assert_eq!(p.len(), 1, "{p:?}");
    assert!(
        p[0].contains("couplings[0].b = \"vehicel\"") && p[0].contains("\"engine\", \"vehicle\""),
        "{p:?}"
    );
    let looped = format!(
        "{TWO}\n[[couplings]]\nname = \"g1\"\nkind = \"ideal_gear\"\na = \"engine\"\nb = \"vehicle\"\nratio = 10.0\nmu = 0.1\n"
    );
    let p = problems(&looped);
    assert!(
        p.iter()
            .any(|m| m.contains("couplings[1].mu") && m.contains("remove it")),
        "{p:?}"
    );
    let looped = looped.replace("ratio = 10.0\nmu = 0.1\n", "ratio = 10.0\n")
        + "\n[[couplings]]\nname = \"g2\"\nkind = \"ideal_gear\"\na = \"engine\"\nb = \"vehicle\"\nratio = 10.0\n";
    let p = problems(&looped.replace("initial_speed_rad_s = 100.0", "initial_speed_rad_s = 0.0"));
    assert!(
        p.iter()
            .any(|m| m.contains("couplings[2].b") && m.contains("loop of ideal gears")),
        "{p:?}"
    );
    let idle = TWO
        .replace(
            "[bodies.drive]\nkind = \"constant\"\nvalue_n_m = 50.0\n",
            "",
        )
        .replace("initial_speed_rad_s = 100.0", "");
    let p = problems(&idle);
    assert!(
        p.iter()
            .any(|m| m.contains("bodies[0].drive") && m.contains("nothing moves")),
        "{p:?}"
    );
    let with_pack = format!("{TWO}\n[drum]\ninertia_kg_m2 = 1.0\n");
    let p = problems(&with_pack);
    assert!(
        p.iter()
            .any(|m| m.starts_with("drum") && m.contains("network")),
        "{p:?}"
    );
}

const MESH: &str = r#"
[simulation]
duration_s = 0.01

[[bodies]]
name = "pinion"
inertia_kg_m2 = 0.02
initial_speed_rad_s = 10.0

[[bodies]]
name = "wheel"
inertia_kg_m2 = 0.5

[[couplings]]
name = "mesh"
kind = "gear_mesh"
a = "pinion"
b = "wheel"
base_radius_a_m = 0.03
base_radius_b_m = 0.09
backlash_m = 1e-4
mesh_offset_m = 2e-5
[couplings.contact]
law = "dry"
modulus_pa = 210e9
curvature_radius_m = 5e-3
"#;

/// A gear mesh reaches the model with its law; a start outside the free play, a missing
/// modulus and a clutch's key on a mesh are each reported at their key.
#[test]
fn gear_mesh_keys() {
    let s = parse(MESH, "scenes/mesh.toml", Path::new("."), &[]).unwrap();
    let net = s.network.unwrap();
    let clutchpack_model::network::CouplingKind::GearMesh(g) = &net.couplings[0].kind else {
        panic!("a mesh")
    };
    assert_eq!(
        (g.base_radius_b_m, g.initial_offset_m, g.internal),
        (0.09, 2e-5, false)
    );
    assert_eq!(g.law.kind, clutchpack_model::LawKind::Dry);
    let p = problems(&MESH.replace("mesh_offset_m = 2e-5", "mesh_offset_m = 6e-5"));
    assert!(
        p.iter()
            .any(|m| m.contains("couplings[0].mesh_offset_m = 0.00006") && m.contains("free play")),
        "{p:?}"
    );
    let p = problems(
        &MESH
            .replace("modulus_pa = 210e9\n", "mu = 0.1\n")
            .replace("[couplings.contact]", "mu = 0.1\n[couplings.contact]"),
    );
    assert!(
        p.iter()
            .any(|m| m.contains("couplings[0].contact.modulus_pa") && m.contains("missing")),
        "{p:?}"
    );
    assert!(
        p.iter()
            .any(|m| m.contains("couplings[0].mu") && m.contains("remove it")),
        "{p:?}"
    );
}

/// `[bodies.firing]` reaches the model with its phases in radians and 4 strokes by default;
/// strokes other than 2 or 4, a phase per amplitude missing, no cylinders and firing on the
/// fixed housing are each reported at their key, all at once.
#[test]
fn firing_keys() {
    let firing = "[bodies.firing]\ncylinders = 4\namplitudes_n_m = [300.0, 90.0]\nphases_deg = [0.0, 90.0]\n";
    let text = TWO.replace("value_n_m = 50.0\n", &format!("value_n_m = 50.0\n{firing}"));
    let s = parse(&text, "scenes/net.toml", Path::new("."), &[]).unwrap();
    let f = s.network.unwrap().bodies[0].firing.clone().expect("firing");
    assert_eq!((f.cylinders, f.strokes, f.order()), (4, 4, 2.0));
    assert_eq!(f.amplitudes_n_m, vec![300.0, 90.0]);
    assert!((f.phases_rad[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let bad = text
        .replace("cylinders = 4\n", "strokes = 3\n")
        .replace("phases_deg = [0.0, 90.0]", "phases_deg = [0.0]");
    let p = problems(&bad);
    for (key, says) in [
        ("bodies[0].firing.cylinders", "required"),
        ("bodies[0].firing.strokes = 3", "must be 4 or 2"),
        ("bodies[0].firing.phases_deg", "2"),
    ] {
        assert!(
            p.iter().any(|m| m.contains(key) && m.contains(says)),
            "{key}: {p:?}"
        );
    }
    let housing = format!("{TWO}\n[[bodies]]\nname = \"housing\"\nfixed = true\n{firing}");
    let p = problems(&housing);
    assert!(
        p.iter()
            .any(|m| m.contains("bodies[2].firing") && m.contains("fixed body")),
        "{p:?}"
    );
}

/// A motor at a prescribed speed engaging a load (`[bodies.speed]`, the forms of `[drive]`).
const PRESCRIBED: &str = r#"
[simulation]
duration_s = 1.0

[[bodies]]
name = "motor"
[bodies.speed]
kind = "sine"
omega0_rad_s = 100.0
amplitude_rad_s = 2.0
frequency_hz = 10.0

[[bodies]]
name = "load"
inertia_kg_m2 = 0.5

[[bodies]]
name = "housing"
fixed = true

[[couplings]]
name = "clutch"
kind = "clutch"
a = "motor"
b = "load"
mu = 0.1
max_normal_force_n = 5000.0
cgeo_m = 0.2
[couplings.force]
kind = "constant"
value = 1.0
"#;

/// `[bodies.speed]` makes a body prescribed (its profile, its speed at t = 0 the profile's);
/// a prescribed body with an inertia, an initial speed, a drive, a drag, a torque table, or
/// also fixed is refused at its key; so are a gear tying it to another prescribed body or to
/// the housing and a clutch that could lock it to the fixed body (over-constraints).
#[test]
fn prescribed_bodies_and_their_bad_keys() {
    let ok = parse(PRESCRIBED, "scenes/net.toml", Path::new("."), &[]).unwrap();
    let net = ok.network.unwrap();
    let motor = &net.bodies[0];
    assert_eq!(
        motor.motion,
        clutchpack_model::network::Motion::Prescribed(clutchpack_model::SpeedProfile::sine(
            100.0, 2.0, 10.0
        ))
    );
    assert_eq!(motor.initial_speed_rad_s, 100.0);
    let has = |p: &[String], key: &str, what: &str| {
        assert!(
            p.iter().any(|m| m.contains(key) && m.contains(what)),
            "{key} ({what}) not in {p:?}"
        )
    };
    let bad = PRESCRIBED.replace(
        "name = \"motor\"\n",
        "name = \"motor\"\ninertia_kg_m2 = 1.0\ninitial_speed_rad_s = 5.0\nfixed = true\n\
         drag_n_m_s_rad = 0.1\n[bodies.drive]\nkind = \"constant\"\nvalue_n_m = 1.0\n",
    );
    let p = problems(&bad);
    has(&p, "bodies[0].inertia_kg_m2", "no inertia");
    has(&p, "bodies[0].initial_speed_rad_s", "starts at its");
    has(&p, "bodies[0].fixed", "not both");
    let p = problems(&PRESCRIBED.replace(
        "frequency_hz = 10.0\n",
        "frequency_hz = 10.0\n[bodies.drive]\nkind = \"constant\"\nvalue_n_m = 1.0\n",
    ));
    has(&p, "bodies[0].drive", "prescribed body follows its speed");
    let p = problems(&PRESCRIBED.replace("kind = \"sine\"", "kind = \"torque_table\""));
    has(&p, "bodies[0].speed.", "not used by bodies[0].speed.kind");
    let p = problems(&PRESCRIBED.replace("b = \"load\"", "b = \"housing\""));
    has(
        &p,
        "couplings[0].b",
        "could lock two bodies whose motions are given",
    );
    // two prescribed bodies geared: the gear over-constrains them (their motions are given)
    let geared = format!(
        "{PRESCRIBED}\n[[bodies]]\nname = \"motor2\"\n[bodies.speed]\nkind = \"sine\"\n\
         omega0_rad_s = 100.0\namplitude_rad_s = 2.0\nfrequency_hz = 10.0\n\
         [[couplings]]\nname = \"g\"\nkind = \"ideal_gear\"\na = \"motor2\"\n\
         b = \"motor\"\nratio = 1.0\n"
    );
    let p = problems(&geared);
    has(&p, "couplings[1].b", "over-constrains its bodies");
    // and a gear from it to the housing
    let p = problems(&format!(
        "{PRESCRIBED}\n[[couplings]]\nname = \"g\"\nkind = \"ideal_gear\"\na = \"motor\"\n\
         b = \"housing\"\nratio = 1.0\n"
    ));
    has(
        &p,
        "couplings[1].b",
        "ties the prescribed body \"motor\" to the fixed one",
    );
}
