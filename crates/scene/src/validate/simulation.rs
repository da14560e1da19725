//! `[simulation]`: run settings, with the plausibility bounds of what the engines and memory
//! can do (docs/DECISIONS.md, "Plausibility bounds").

use super::Checker;
use crate::keys::{RawSimulation as S, MAX_SAMPLES};
use crate::schema::{fmt_bound, fmt_num, Key, RawTable};
use crate::{EngineChoice, SchemeChoice, Simulation};

/// `[simulation]`.
pub(super) fn simulation(ck: &mut Checker, raw: Option<&S>) -> Option<Simulation> {
    let empty = S::default();
    let r = raw.unwrap_or(&empty);
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), r.value(k), k);
    let duration = num(ck, &S::duration_s).required(
        ck,
        &S::duration_s.rel(),
        "required; set it in [simulation]",
    );
    let engine = ck
        .choice(
            &S::engine.rel(),
            r.engine.as_ref(),
            &S::engine,
            &[EngineChoice::Reference, EngineChoice::Multibody],
        )
        .optional();
    let scheme = ck
        .choice(
            &S::scheme.rel(),
            r.scheme.as_ref(),
            &S::scheme,
            &[
                SchemeChoice::Auto,
                SchemeChoice::Shared,
                SchemeChoice::Multirate,
            ],
        )
        .or(SchemeChoice::Auto);
    let rate = num(ck, &S::record_rate_hz).or(S::record_rate_hz.default_num());
    let tolerance = num(ck, &S::tolerance).or(S::tolerance.default_num());
    let max_step = num(ck, &S::max_step_s).or(S::max_step_s.default_num());
    let per_tooth = ck
        .boolean(&S::record_per_tooth.rel(), r.record_per_tooth.as_ref())
        .or(S::record_per_tooth.default_bool());
    let contact_samples = ck
        .boolean(
            &S::record_contact_samples.rel(),
            r.record_contact_samples.as_ref(),
        )
        .or(S::record_contact_samples.default_bool());
    // Every sample is emitted to the observers (and recorded): their number is bounded.
    if let (Some(d), Some(f)) = (duration, rate) {
        let samples = d * f;
        if samples > MAX_SAMPLES {
            ck.report(
                S::record_rate_hz.rel(),
                Some(fmt_num(f)),
                format!(
                    "{} x {} = {} s x {} Hz = {} samples: must be <= {} samples (plausibility \
                     bound: shorten the run or lower the rate)",
                    S::duration_s.name,
                    S::record_rate_hz.name,
                    fmt_num(d),
                    fmt_num(f),
                    fmt_num(samples),
                    fmt_bound(MAX_SAMPLES)
                ),
            );
            return None;
        }
    }
    Some(Simulation {
        duration_s: duration?,
        engine: engine?,
        scheme: scheme?,
        record_rate_hz: rate?,
        tolerance: tolerance?,
        max_step_s: max_step?,
        record_per_tooth: per_tooth?,
        record_contact_samples: contact_samples?,
    })
}
