//! The tables a pack run and a network run both print: a thermal run's temperatures and
//! heat balance, the figures window by window.

/// Prints a run's figures window by window (`--windows`): the worst body in each window, then
/// each body's largest peak and damage rate by window (nothing without windows).
pub fn print_windows(windows: &[clutchpack_sdk::WindowRow]) {
    if !windows.is_empty() {
        out!("by window (the worst body in each; damage rate: lumped teeth, MODEL.md section 7)");
        out!(
            "{:>8} {:>8} {:>8} {:>11} {:<12} {:>10} {:>12} {:<12} {:>9} {:>9}",
            "t0_s",
            "t1_s",
            "impacts",
            "peak_abs_n",
            "body",
            "p99_abs_n",
            "damage_1/h",
            "body",
            "oil_k",
            "hottest_k"
        );
        let k = |t: Option<f64>| t.map_or("-".to_string(), |t| format!("{t:.2}"));
        for w in windows {
            out!(
                "{:>8.3} {:>8.3} {:>8} {:>11.1} {:<12} {:>10.1} {:>12.4e} {:<12} {:>9} {:>9}",
                w.t0_s,
                w.t1_s,
                w.impacts,
                w.peak_abs_n,
                w.peak_body,
                w.p99_abs_n,
                w.damage_rate_per_h,
                w.damage_body,
                k(w.oil_k),
                k(w.hottest_body_k)
            );
        }
    }
    if let Some(first) = windows.first() {
        out!("largest per-tooth |peak| (N) and damage rate (1/h) by body and window end (s)");
        let mut head = format!("{:<12}", "body");
        for w in windows {
            head.push_str(&format!(" {:>10.3}", w.t1_s));
        }
        out!("{head}");
        for (i, b) in first.bodies.iter().enumerate() {
            let mut peaks = format!("{:<12}", b.name);
            let mut rates = format!("{:<12}", "");
            for w in windows {
                let bw = w.bodies.get(i);
                peaks.push_str(&format!(" {:>10.1}", bw.map_or(0.0, |b| b.peak_abs_n)));
                rates.push_str(&format!(
                    " {:>10.3e}",
                    bw.map_or(0.0, |b| b.damage_rate_per_h)
                ));
            }
            out!("{peaks}");
            out!("{rates}");
        }
    }
}

/// Prints a thermal run's temperatures (K) and heat balance (J) (MODEL.md section 9).
pub fn print_thermal(th: &clutchpack_sdk::ThermalSummary) {
    out!("temperatures (K; [thermal], MODEL.md section 9)");
    out!("{:<12} {:>10} {:>10}", "body", "final", "max");
    for b in &th.bodies {
        out!("{:<12} {:>10.3} {:>10.3}", b.name, b.final_k, b.max_k);
    }
    out!(
        "{:<12} {:>10.3} {:>10.3}",
        "oil",
        th.oil_final_k,
        th.oil_max_k
    );
    out!(
        "heat (J): generated {:.6} (faces {:.6}, gaps {:.6}, teeth {:.6}) = stored {:.6} \
         (bodies {:.6}, oil {:.6}) + cooler {:.6}; balance error {:.3e}",
        th.generated_j,
        th.friction_heat_j,
        th.gap_heat_j,
        th.impact_heat_j,
        th.stored_bodies_j + th.stored_oil_j,
        th.stored_bodies_j,
        th.stored_oil_j,
        th.cooler_j,
        th.balance_error_j
    );
}
