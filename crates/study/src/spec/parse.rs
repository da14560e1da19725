//! Parsing a study file: `parse` reads each table in its own function (as the scene crate's
//! `validate/` does by section), every problem at once with its key, then builds each
//! factor level's scene to report what the scene rejects before any case runs.

use super::check::{range, scene_problems, Ck};
use super::*;

/// What `[study]` gives.
struct StudyTable {
    name: String,
    scene: Option<String>,
    engine: Option<EngineChoice>,
    seed: u64,
    outputs: Vec<String>,
}

/// Validates study text. `file` names the file in messages, `dir` is the folder that the
/// scene path is relative to. Every problem is reported at once, including those the scene
/// finds with the factors' levels applied.
pub fn parse(text: &str, file: &str, dir: &Path) -> Result<Study, SpecError> {
    let invalid = |problems| SpecError::Invalid {
        file: file.to_string(),
        problems,
    };
    let doc: Table = text.parse().map_err(|e: toml::de::Error| {
        let key = match e.span() {
            Some(s) => {
                let before = &text[..s.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("line {line} column {col}")
            }
            None => "file".to_string(),
        };
        invalid(vec![Problem {
            key,
            value: None,
            rule: e.message().to_string(),
        }])
    })?;
    let mut ck = Ck {
        problems: Vec::new(),
    };
    ck.unknown(
        "",
        &doc,
        &["study", "ensemble", "set", "factor", "random", "spacing"],
    );

    let StudyTable {
        name,
        scene: scene_rel,
        engine,
        seed,
        outputs,
    } = study_table(&mut ck, &doc, file);
    let (members, placement, phase) = ensemble_table(&mut ck, &doc);
    let set = set_table(&mut ck, &doc);
    let factors = factor_tables(&mut ck, &doc);
    let random = random_tables(&mut ck, &doc, &factors);
    let spacing = spacing_table(&mut ck, &doc, &factors);

    let mut study = Study {
        name,
        file: file.to_string(),
        scene_path: scene_rel
            .as_deref()
            .map(|s| dir.join(s))
            .unwrap_or_default(),
        scene_text: String::new(),
        engine,
        seed,
        members,
        placement,
        phase,
        outputs,
        set,
        factors,
        random,
        spacing,
        hash: String::new(),
    };
    if study.cases() > MAX_CASES {
        let mut terms: Vec<String> = study
            .factors
            .iter()
            .map(|f| format!("{} ({})", f.levels.len(), f.key))
            .collect();
        terms.push(format!("{} (ensemble.members)", study.members));
        let total = match study.cases() {
            u64::MAX => "more than 2^64".to_string(),
            n => n.to_string(),
        };
        ck.bad(
            "factor",
            None,
            format!(
                "{} = {total} cases; a study may have at most {MAX_CASES}",
                terms.join(" x ")
            ),
        );
    }
    if scene_rel.is_some() {
        match clutchpack_scene::read_input(&study.scene_path) {
            Ok(t) => study.scene_text = t,
            Err(e) => ck.bad(
                "study.scene",
                doc.get("study").and_then(|st| st.get("scene")),
                format!("cannot read {}: {e}", study.scene_path.display()),
            ),
        }
    }
    if !ck.problems.is_empty() {
        return Err(invalid(ck.problems));
    }
    probe_scenes(&mut ck, &study);
    if !ck.problems.is_empty() {
        ck.problems.dedup();
        return Err(invalid(ck.problems));
    }
    let mut h = Sha256::new();
    h.update(text.as_bytes());
    h.update([0u8]);
    h.update(study.scene_text.as_bytes());
    study.hash = h.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(study)
}

/// `[study]`: the name (else the file's stem), the scene, the engine, the seed, the outputs.
fn study_table(ck: &mut Ck, doc: &Table, file: &str) -> StudyTable {
    let empty = Table::new();
    let st = ck.table("study", doc.get("study")).unwrap_or(&empty);
    if doc.get("study").is_none() {
        ck.bad(
            "study",
            None,
            "missing (required table with at least `scene`)",
        );
    }
    ck.unknown("study", st, &["name", "scene", "engine", "seed", "outputs"]);
    let name = match ck.string("study.name", st.get("name")) {
        Some(n) => {
            if !is_study_name(n) {
                ck.bad("study.name", st.get("name"), format!("must be {NAME_RULE}"));
            }
            n.to_string()
        }
        None => {
            let stem = Path::new(file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "study".into());
            if st.get("name").is_none() && !is_study_name(&stem) {
                ck.bad(
                    "study.name",
                    None,
                    format!(
                        "missing, and the file name {stem:?} it defaults to is not a study \
                         name: set study.name ({NAME_RULE})"
                    ),
                );
            }
            stem
        }
    };
    let scene_rel = ck.string("study.scene", st.get("scene"));
    if st.get("scene").is_none() && doc.get("study").is_some() {
        ck.bad(
            "study.scene",
            None,
            "missing (required: the base scene file, relative to the study file)",
        );
    }
    let engine = ck
        .choice("study.engine", st.get("engine"), &EngineChoice::names())
        .map(|i| EngineChoice::ALL[i]);
    let seed = match st.get("seed") {
        None => 0,
        Some(Value::Integer(i)) if *i >= 0 => *i as u64,
        Some(other) => {
            ck.bad("study.seed", Some(other), "must be an integer >= 0");
            0
        }
    };
    let mut outputs: Vec<String> = STATS.iter().map(|s| s.to_string()).collect();
    if let Some(v) = st.get("outputs") {
        match v.as_array() {
            Some(a) => {
                let mut o = vec!["peak_abs_n".to_string()];
                for (i, x) in a.iter().enumerate() {
                    match x.as_str() {
                        Some(s) if STATS.contains(&s) => {
                            if !o.iter().any(|y| y == s) {
                                o.push(s.to_string())
                            }
                        }
                        _ => ck.bad(
                            &format!("study.outputs[{i}]"),
                            Some(x),
                            format!("must be one of: {}", STATS.join(", ")),
                        ),
                    }
                }
                outputs = o;
            }
            None => ck.bad(
                "study.outputs",
                Some(v),
                "must be an array of statistic names",
            ),
        }
    }
    StudyTable {
        name,
        scene: scene_rel.map(str::to_string),
        engine,
        seed,
        outputs,
    }
}

/// `[ensemble]`: members per design point, the initial positions and the drive phase.
fn ensemble_table(ck: &mut Ck, doc: &Table) -> (u64, Placement, Phase) {
    let empty = Table::new();
    let en = ck.table("ensemble", doc.get("ensemble")).unwrap_or(&empty);
    ck.unknown(
        "ensemble",
        en,
        &["members", "initial_positions", "drive_phase"],
    );
    let members = ck
        .count("ensemble.members", en.get("members"), 1, MAX_CASES)
        .unwrap_or(1);
    let placement = match ck.choice(
        "ensemble.initial_positions",
        en.get("initial_positions"),
        &["scene", "spread", "random"],
    ) {
        Some(0) => Placement::Scene,
        Some(1) => Placement::Spread,
        Some(_) => Placement::Random,
        None if members > 1 && en.get("initial_positions").is_none() => Placement::Spread,
        None => Placement::Scene,
    };
    let phase = match ck.choice(
        "ensemble.drive_phase",
        en.get("drive_phase"),
        &["scene", "spread", "random"],
    ) {
        Some(1) => Phase::Spread,
        Some(2) => Phase::Random,
        _ => Phase::Scene,
    };
    (members, placement, phase)
}

/// `[set]`: overrides of the base scene for every case, values as text.
fn set_table(ck: &mut Ck, doc: &Table) -> Vec<Override> {
    let mut set = Vec::new();
    if let Some(t) = ck.table("set", doc.get("set")) {
        for (k, v) in t {
            set.push(Override {
                key: k.clone(),
                value: match v {
                    Value::String(s) => s.clone(),
                    other => other.to_string(),
                },
            });
        }
    }
    set
}

/// `[[factor]]`: the design factors and their levels.
fn factor_tables(ck: &mut Ck, doc: &Table) -> Vec<Factor> {
    let mut factors = Vec::new();
    for (i, f) in ck
        .tables("factor", doc.get("factor"))
        .into_iter()
        .enumerate()
    {
        let p = format!("factor[{i}]");
        ck.unknown(&p, f, &["key", "values", "linear", "log"]);
        let key = ck.string(&format!("{p}.key"), f.get("key"));
        if f.get("key").is_none() {
            ck.bad(
                &format!("{p}.key"),
                None,
                "missing (required: a scene key path or spacing.grade)",
            );
        }
        let given: Vec<&str> = ["values", "linear", "log"]
            .into_iter()
            .filter(|k| f.contains_key(*k))
            .collect();
        if given.len() != 1 {
            ck.bad(
                &p,
                None,
                format!(
                    "exactly one of values, linear, log is required (found {})",
                    if given.is_empty() {
                        "none".to_string()
                    } else {
                        given.join(", ")
                    }
                ),
            );
            continue;
        }
        let kind = given[0];
        let vkey = format!("{p}.{kind}");
        let v = &f[kind];
        let levels = match kind {
            "values" => match v.as_array() {
                Some(a) if !a.is_empty() => {
                    let mut out = Vec::new();
                    for (j, x) in a.iter().enumerate() {
                        if let Some(n) = ck.number(&format!("{vkey}[{j}]"), Some(x)) {
                            out.push(n)
                        }
                    }
                    (out.len() == a.len()).then_some(out)
                }
                _ => {
                    ck.bad(&vkey, Some(v), "must be a non-empty array of numbers");
                    None
                }
            },
            _ => range(&mut *ck, &vkey, v, kind == "log"),
        };
        if let (Some(key), Some(levels)) = (key, levels) {
            if key == GRADE_KEY {
                for (j, g) in levels.iter().enumerate() {
                    if g.fract() != 0.0 || !(1..=11i64).contains(&(*g as i64)) {
                        ck.bad(
                            &format!("{vkey}[{j}]"),
                            Some(&Value::Float(*g)),
                            "a tolerance class of ISO 1328-1:2013 must be an integer in 1..=11",
                        );
                    }
                }
                if !doc.contains_key("spacing") {
                    ck.bad(
                        &format!("{p}.key"),
                        Some(&Value::String(key.into())),
                        "spacing.grade needs a [spacing] table (which discs, which distribution)",
                    );
                }
            }
            if factors.iter().any(|x: &Factor| x.key == key) {
                ck.bad(
                    &format!("{p}.key"),
                    Some(&Value::String(key.into())),
                    "each key may be a factor once",
                );
            }
            factors.push(Factor {
                key: key.to_string(),
                levels,
            });
        }
    }
    factors
}

/// `[[random]]`: the keys drawn at random, each from its distribution; a key may be a factor
/// or a draw once.
fn random_tables(ck: &mut Ck, doc: &Table, factors: &[Factor]) -> Vec<RandomFactor> {
    let mut random = Vec::new();
    for (i, r) in ck
        .tables("random", doc.get("random"))
        .into_iter()
        .enumerate()
    {
        let p = format!("random[{i}]");
        ck.unknown(&p, r, &["key", "dist", "low", "high", "mean", "std"]);
        let key = ck.string(&format!("{p}.key"), r.get("key"));
        if r.get("key").is_none() {
            ck.bad(
                &format!("{p}.key"),
                None,
                "missing (required: a scene key path)",
            );
        }
        let dk = format!("{p}.dist");
        if r.get("dist").is_none() {
            ck.bad(
                &dk,
                None,
                "missing (required: uniform, normal or truncated_normal)",
            );
        }
        let kind = ck.choice(
            &dk,
            r.get("dist"),
            &["uniform", "normal", "truncated_normal"],
        );
        let num = |ck: &mut Ck, k: &str| ck.required_number(&format!("{p}.{k}"), r.get(k));
        let dist = match kind {
            Some(0) => match (num(&mut *ck, "low"), num(&mut *ck, "high")) {
                (Some(low), Some(high)) if low < high => Some(Distribution::Uniform { low, high }),
                (Some(_), Some(_)) => {
                    ck.bad(&format!("{p}.high"), r.get("high"), "must be > low");
                    None
                }
                _ => None,
            },
            Some(1) => match (num(&mut *ck, "mean"), num(&mut *ck, "std")) {
                (Some(mean), Some(std)) if std > 0.0 => Some(Distribution::Normal { mean, std }),
                (Some(_), Some(_)) => {
                    ck.bad(&format!("{p}.std"), r.get("std"), "must be > 0");
                    None
                }
                _ => None,
            },
            Some(_) => {
                let (m, s, l, h) = (
                    num(&mut *ck, "mean"),
                    num(&mut *ck, "std"),
                    num(&mut *ck, "low"),
                    num(&mut *ck, "high"),
                );
                match (m, s, l, h) {
                    (Some(mean), Some(std), Some(low), Some(high)) => {
                        let mut ok = true;
                        if std <= 0.0 {
                            ck.bad(&format!("{p}.std"), r.get("std"), "must be > 0");
                            ok = false;
                        }
                        if low >= high {
                            ck.bad(&format!("{p}.high"), r.get("high"), "must be > low");
                            ok = false;
                        } else if std > 0.0 && (low - mean > 4.0 * std || mean - high > 4.0 * std) {
                            ck.bad(&format!("{p}.low"), r.get("low"), "the interval [low, high] must come within 4 std of the mean (else almost every draw is rejected)");
                            ok = false;
                        }
                        ok.then_some(Distribution::TruncatedNormal {
                            mean,
                            std,
                            low,
                            high,
                        })
                    }
                    _ => None,
                }
            }
            None => None,
        };
        if let (Some(key), Some(dist)) = (key, dist) {
            if factors.iter().any(|f| f.key == key)
                || random.iter().any(|x: &RandomFactor| x.key == key)
            {
                ck.bad(
                    &format!("{p}.key"),
                    Some(&Value::String(key.into())),
                    "each key may be a factor or a random draw once",
                );
            }
            random.push(RandomFactor {
                key: key.to_string(),
                dist,
            });
        }
    }
    random
}

/// `[spacing]`: per-tooth spacing errors drawn from an ISO 1328-1:2013 tolerance class.
fn spacing_table(ck: &mut Ck, doc: &Table, factors: &[Factor]) -> Option<Spacing> {
    ck.table("spacing", doc.get("spacing")).map(|t| {
        ck.unknown(
            "spacing",
            t,
            &["standard", "grade", "discs", "distribution"],
        );
        if let Some(s) = t.get("standard") {
            if s.as_str() != Some("ISO 1328-1:2013") {
                ck.bad(
                    "spacing.standard",
                    Some(s),
                    "must be \"ISO 1328-1:2013\" (the only standard implemented)",
                );
            }
        }
        let grade_factor = factors.iter().any(|f| f.key == GRADE_KEY);
        let grade = match t.get("grade") {
            Some(Value::Integer(g)) if (1..=11i64).contains(g) => *g as u32,
            Some(other) => {
                ck.bad(
                    "spacing.grade",
                    Some(other),
                    "must be a tolerance class of ISO 1328-1:2013, an integer in 1..=11",
                );
                5
            }
            None if grade_factor => 5,
            None => {
                ck.bad(
                    "spacing.grade",
                    None,
                    "missing (required unless a factor varies spacing.grade)",
                );
                5
            }
        };
        let discs = t.get("discs").and_then(|v| match v.as_array() {
            Some(a) => {
                let mut out = Vec::new();
                for (j, x) in a.iter().enumerate() {
                    match x.as_integer() {
                        Some(i) if i >= 0 => out.push(i as usize),
                        _ => ck.bad(
                            &format!("spacing.discs[{j}]"),
                            Some(x),
                            "must be a disc index >= 0 (from 0, in scene order)",
                        ),
                    }
                }
                Some(out)
            }
            None => {
                ck.bad(
                    "spacing.discs",
                    Some(v),
                    "must be an array of disc indexes (default: every disc)",
                );
                None
            }
        });
        let distribution = match ck.choice(
            "spacing.distribution",
            t.get("distribution"),
            &["truncated_normal", "uniform"],
        ) {
            Some(1) => PitchDistribution::Uniform,
            _ => PitchDistribution::TruncatedNormal,
        };
        Spacing {
            grade,
            discs,
            distribution,
        }
    })
}

/// The scene with each level of each factor (the others at their first level), member 0,
/// and with each random key at its distribution's centre, built and checked: every key and
/// value the scene rejects is named, before any case runs.
fn probe_scenes(ck: &mut Ck, study: &Study) {
    // The scene with each level of each factor (the others at their first level), member 0,
    // and with each random key at its distribution's centre: every key and value the scene
    // rejects is named here, before any case runs.
    let mut probes: Vec<(String, Option<String>, Case)> =
        vec![("study.scene".into(), None, study.case(0))];
    for (i, f) in study.factors.iter().enumerate() {
        for j in probe_levels(&f.levels) {
            let l = f.levels[j];
            let mut c = study.case(0);
            c.values[i] = l;
            probes.push((
                format!("factor[{i}].levels[{j}] ({})", f.key),
                Some(number_text(l)),
                c,
            ));
        }
    }
    // ... and the study's engine must be able to run each of them (`clutchpack check
    // --engine`'s rule): a study of spacing errors on the reference engine would only fail
    // every case.
    let engine = study.engine;
    let origin = study.scene_path.display().to_string();
    for (k, (p, value, case)) in probes.into_iter().enumerate() {
        let checked = study.scene(&case).and_then(|scene| {
            if k == 0 {
                spacing_discs_exist(ck, study, &scene);
            }
            scene.engine(engine, &origin).map(|_| ())
        });
        if let Err(e) = checked {
            for sp in scene_problems(&e) {
                ck.bad_text(&p, value.clone(), format!("the scene rejects it: {sp}"));
            }
        }
    }
}

/// The most levels of one factor whose scenes the validation builds (each is parsed and
/// validated in full); a longer list is probed at this many evenly spaced levels, its
/// smallest and largest among them.
const MAX_PROBED_LEVELS: usize = 1000;

/// Indexes of the levels of one factor that the validation probes: all of them up to
/// [`MAX_PROBED_LEVELS`], else that many evenly spaced ones plus the smallest and the largest
/// (a scene's rules are bounds, which a range's extremes test).
fn probe_levels(levels: &[f64]) -> Vec<usize> {
    let n = levels.len();
    if n <= MAX_PROBED_LEVELS {
        return (0..n).collect();
    }
    let mut idx: Vec<usize> = (0..MAX_PROBED_LEVELS)
        .map(|k| k * (n - 1) / (MAX_PROBED_LEVELS - 1))
        .collect();
    let by = |a: &usize, b: &usize| levels[*a].total_cmp(&levels[*b]);
    idx.extend((0..n).min_by(by));
    idx.extend((0..n).max_by(by));
    idx.sort_unstable();
    idx.dedup();
    idx
}

/// `spacing.discs` must name discs of the scene.
fn spacing_discs_exist(ck: &mut Ck, study: &Study, scene: &Scene) {
    let n = scene.pack.discs.len();
    let Some(list) = study.spacing.as_ref().and_then(|sp| sp.discs.as_ref()) else {
        return;
    };
    for (j, &i) in list.iter().enumerate() {
        if i >= n {
            ck.bad_text(
                &format!("spacing.discs[{j}]"),
                Some(i.to_string()),
                format!(
                    "must be a disc index of the scene, 0..={} (it has {n} discs)",
                    n.saturating_sub(1)
                ),
            );
        }
    }
}
