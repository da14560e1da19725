//! The text of `clutchpack replay`: what a recording holds, for a reader at a terminal.

use clutchpack_sdk::record::RecordingReader;

/// What the file holds, as text for `clutchpack replay`: the file and its state, the run
/// (program, engine, scene and its hash, overrides; the inputs a co-simulation's caller
/// drove), the topics with their schemas,
/// message counts and time spans, and the per-disc summary (stored, or recomputed from
/// the recovered impacts and marked so). Lines end with `\n`.
pub fn describe(r: &RecordingReader) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let i = r.info();
    let state = match r.damage() {
        None => "complete".to_string(),
        Some(d) => d.to_string(),
    };
    let _ = writeln!(
        s,
        "{} ({} bytes): {state}",
        r.path().display(),
        r.file_bytes()
    );
    if let Some(run) = i.metadata(clutchpack_sdk::record::info::META_RUN) {
        let g = |k: &str| run.get(k).map(String::as_str).unwrap_or("?");
        let sha = g("scene_sha256");
        let _ = writeln!(
            s,
            "run: {} {}, engine {}, scene {} ({}, sha256 {}), overrides {}",
            g("program"),
            g("program_version"),
            g("engine"),
            g("scene_name"),
            g("scene_file"),
            sha.chars().take(12).collect::<String>(),
            g("overrides")
        );
    }
    // a run advanced call by call (Python's Simulation, an FMU): which inputs its caller drove
    let params = i.metadata(clutchpack_sdk::record::info::META_PARAMS);
    if let Some(p) = params.filter(|p| p.get("co_simulation").is_some_and(|v| v == "true")) {
        let _ = writeln!(
            s,
            "co-simulation: inputs driven by the caller: {}{}",
            p.get("driven_inputs").map_or("?", String::as_str),
            p.get("stop_time_s")
                .map_or(String::new(), |t| format!("; stop time {t} s"))
        );
    }
    match (i.start_s, i.end_s) {
        (Some(a), Some(b)) => {
            let _ = writeln!(
                s,
                "{} messages on {} topics, t = {} .. {} s",
                i.messages,
                i.topics.len(),
                short(a),
                short(b)
            );
        }
        _ => {
            let _ = writeln!(s, "no messages, {} topics", i.topics.len());
        }
    }
    let w = i
        .topics
        .iter()
        .map(|t| t.topic.len())
        .max()
        .unwrap_or(5)
        .max(5);
    let ws = i
        .topics
        .iter()
        .map(|t| t.schema_name.len())
        .max()
        .unwrap_or(6)
        .max(6);
    let _ = writeln!(
        s,
        "  {:<w$}  {:<ws$}  {:>9}  span (s)",
        "topic", "schema", "messages"
    );
    for t in &i.topics {
        let span = if t.messages > 0 {
            format!("{} .. {}", short(t.first_s), short(t.last_s))
        } else {
            "-".into()
        };
        let _ = writeln!(
            s,
            "  {:<w$}  {:<ws$}  {:>9}  {span}",
            t.topic, t.schema_name, t.messages
        );
    }
    let (summary, note) = match r.summary() {
        Some(x) => (x.clone(), "stored"),
        None => (
            r.summary_or_recomputed(),
            "recomputed from the recovered impacts",
        ),
    };
    if !summary.discs.is_empty() {
        let _ = writeln!(
            s,
            "summary ({note}; per-tooth loads in N, t_end = {} s):",
            short(summary.t_end_s)
        );
        let wd = summary
            .discs
            .iter()
            .map(|d| d.name.len())
            .max()
            .unwrap_or(4)
            .max(4);
        let _ = writeln!(
            s,
            "  {:<wd$}  {:>12}  {:>12}  {:>12}  {:>8}  {:>14}",
            "disc", "max_positive", "max_negative", "p99_abs", "impacts", "mean_top10_abs"
        );
        for d in &summary.discs {
            let _ = writeln!(
                s,
                "  {:<wd$}  {:>12.1}  {:>12.1}  {:>12.1}  {:>8}  {:>14.1}",
                d.name,
                d.max_positive_n,
                d.max_negative_n,
                d.p99_abs_n,
                d.impacts,
                d.mean_top10_abs_n
            );
        }
        if !summary.fatigue.is_empty() {
            let _ = writeln!(
                s,
                "fatigue of the spline teeth (stored; MODEL.md section 7, at this duty):"
            );
            let _ = writeln!(
                s,
                "  {:<wd$}  {:>12}  {:>10}  {:>10}  {:>12}  {:>16}",
                "disc", "damage [1/h]", "life [h]", "S_eq [N]", "max sigma_F", "worst tooth"
            );
            let life = |h: Option<f64>| h.map_or("unlimited".to_string(), |h| format!("{h:.3e}"));
            for (i, d) in summary.discs.iter().enumerate() {
                let Some(f) = summary.fatigue_of(i) else {
                    continue;
                };
                let worst = f
                    .worst_tooth
                    .map_or("-".to_string(), |(k, l, _)| format!("{k}: {} h", life(l)));
                let _ = writeln!(
                    s,
                    "  {:<wd$}  {:>12.4e}  {:>10}  {:>10.1}  {:>8.1} MPa  {:>16}",
                    d.name,
                    f.damage_rate_per_h,
                    life(f.life_h),
                    f.eq_load_range_n,
                    f.max_root_stress_pa * 1e-6,
                    worst
                );
            }
        }
    }
    describe_network(r, &mut s);
    let interfaces = r.interface_stats();
    if !interfaces.is_empty() {
        let _ = writeln!(s, "friction interfaces (from the piston side):");
        let table = clutchpack_sdk::analysis::interface_table(
            &interfaces,
            clutchpack_sdk::analysis::TableFormat::Text,
        );
        for line in table.lines() {
            let _ = writeln!(s, "  {line}");
        }
    }
    s
}

/// A network recording's bodies and couplings (its `clutchpack.network` metadata) and, from
/// its attached summary (the JSON of `run --summary-json`), each clutch's lock times and heat
/// and the energy balance's residual. Nothing for a pack's recording.
fn describe_network(r: &RecordingReader, s: &mut String) {
    use std::fmt::Write as _;
    let i = r.info();
    let Some(net) = i.metadata(clutchpack_sdk::record::META_NETWORK) else {
        return;
    };
    let count = |k: &str| {
        net.get(k)
            .and_then(|v| v.parse::<usize>().ok())
            .unwrap_or(0)
    };
    let g = |k: String| net.get(&k).map(String::as_str).unwrap_or("?").to_string();
    let bodies: Vec<String> = (0..count("bodies"))
        .map(|b| g(format!("body.{b}.name")))
        .collect();
    let _ = writeln!(
        s,
        "network: {} bodies ({})",
        bodies.len(),
        bodies.join(", ")
    );
    let _ = writeln!(s, "couplings:");
    for k in 0..count("couplings") {
        let _ = writeln!(
            s,
            "  {:<20} {:<14} {} -> {}",
            g(format!("coupling.{k}.name")),
            g(format!("coupling.{k}.kind")),
            g(format!("coupling.{k}.a")),
            g(format!("coupling.{k}.b"))
        );
    }
    let stored = i
        .attachments
        .iter()
        .find(|a| a.name == clutchpack_sdk::record::SUMMARY_ATTACHMENT)
        .and_then(|a| serde_json::from_slice::<serde_json::Value>(&a.data).ok());
    let Some(summary) = stored else {
        let _ = writeln!(s, "no stored summary (the run did not finish)");
        return;
    };
    let _ = writeln!(s, "summary (stored; t_end = {} s):", summary["simulated_s"]);
    for c in summary["couplings"].as_array().into_iter().flatten() {
        if c["kind"] != "clutch" && c["kind"] != "one_way_clutch" {
            continue;
        }
        let locks: Vec<String> = c["lock_times_s"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(serde_json::Value::as_f64)
            .map(short)
            .collect();
        let _ = writeln!(
            s,
            "  {:<20} heat {:.3} J, locked at [{}] s",
            c["name"].as_str().unwrap_or("?"),
            c["heat_j"].as_f64().unwrap_or(f64::NAN),
            locks.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "  energy balance residual {:.3e} J",
        summary["energy"]["residual_j"].as_f64().unwrap_or(f64::NAN)
    );
}

/// A time in s with at most 9 decimals, trailing zeros dropped (`0.00399`, not
/// `0.0039900000000000005`).
fn short(x: f64) -> String {
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_sdk::record::synthetic::synthetic_run;
    use clutchpack_sdk::record::{open, RecordOptions, Recorder};

    /// The text names the file's state, the engine, every topic, the stored summary and the
    /// time span (0 .. 399 samples of 10 us, printed without float noise).
    #[test]
    fn describes_a_complete_recording() {
        let run = synthetic_run(400, 1e-5);
        let dir = std::env::temp_dir().join(format!("clutchpack-describe-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("describe.mcap");
        let opts = RecordOptions {
            deterministic: true,
            ..Default::default()
        };
        let mut rec = Recorder::create(&path, &run.info, &opts).unwrap();
        run.play(&mut rec);
        let path = rec.finish(None).unwrap();
        let text = describe(&open(&path).unwrap());
        std::fs::remove_dir_all(&dir).ok();
        assert!(text.contains("complete"), "{text}");
        assert!(text.contains("engine synthetic"), "{text}");
        assert!(text.contains("/discs/disc_2/spline"), "{text}");
        assert!(text.contains("summary (stored"), "{text}");
        assert!(text.contains("t = 0 .. 0.00399 s"), "{text}");
    }

    #[test]
    fn short_times() {
        assert_eq!(short(0.0039900000000000005), "0.00399");
        assert_eq!(short(-0.0), "0");
        assert_eq!(short(2.0), "2");
    }
}
