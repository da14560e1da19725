//! `compare` of network recordings' shifts (an automatic's schedule, MODEL.md section 10): per
//! shift and run, the on-coming element's heat and lock, the output torque's extremes and the
//! flags the run's summary holds (`clutchpack_sdk::shifts`), and which run's shift heats its
//! on-coming element most.

use serde_json::Value;

/// The lines `compare` prints for the shifts of `runs` (`(run, its summary's shifts)`), none
/// when no run has a shift.
pub fn lines(runs: &[(String, Vec<Value>)]) -> Vec<String> {
    let mut out = Vec::new();
    if runs.iter().all(|(_, s)| s.is_empty()) {
        return out;
    }
    out.push("shifts (per run: the on-coming element's heat and lock, the output torque while the shift is under way):".into());
    let num = |v: &Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
    let text = |v: &Value, k: &str| v[k].as_str().unwrap_or("?").to_string();
    let mut hottest: Option<(f64, String)> = None;
    for (run, shifts) in runs {
        for sh in shifts {
            let flags = match (sh["tie_up"] == true, sh["flare"] == true) {
                (true, true) => "  TIE-UP, FLARE",
                (true, false) => "  TIE-UP",
                (false, true) => "  FLARE",
                (false, false) => "",
            };
            let what = format!(
                "{} -> {} ({})",
                text(sh, "from"),
                text(sh, "to"),
                text(sh, "on_coming")
            );
            out.push(format!(
                "  {run}: {what}: {:.1} J, locked {}, output torque {:.1} .. {:.1} N m{flags}",
                num(sh, "on_coming_heat_j"),
                sh["on_coming_locked_s"]
                    .as_f64()
                    .map_or("never".to_string(), |t| format!("at {t:.6} s")),
                num(sh, "output_torque_min_n_m"),
                num(sh, "output_torque_max_n_m"),
            ));
            let heat = num(sh, "on_coming_heat_j");
            if hottest.as_ref().is_none_or(|(h, _)| heat > *h) {
                hottest = Some((heat, format!("{what} in {run} ({heat:.1} J)")));
            }
        }
    }
    if let Some((_, h)) = hottest {
        out.push(format!(
            "the shift that heats its on-coming element most: {h}"
        ));
    }
    out
}
