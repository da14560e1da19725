//! What the subcommands share and the library does not do for them: the bad-input marker
//! (exit 2), `--engine`'s parser and the progress bar.

use clutchpack_sdk::EngineChoice;

/// Marks an error as bad input (exit code 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// `--engine`'s value parser: the engine names the scene crate defines
/// ([`EngineChoice::names`]), listed in `--help` and in the error for any other name.
pub fn engine_parser() -> impl clap::builder::TypedValueParser<Value = EngineChoice> {
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(EngineChoice::names())
        .try_map(|s| s.parse::<EngineChoice>())
}

/// The sdk's errors that are the input's fault are bad input (exit 2), as are scene errors.
pub fn is_bad_input(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.is::<BadInput>()
            || c.is::<clutchpack_sdk::scene::SceneError>()
            || c.downcast_ref::<clutchpack_sdk::Error>()
                .is_some_and(clutchpack_sdk::Error::is_bad_input)
    })
}

/// A progress bar on stderr for a run of `duration_s` simulated seconds (hidden when stderr
/// is not a terminal).
pub fn time_progress(duration_s: f64, label: &str) -> indicatif::ProgressBar {
    let pb = indicatif::ProgressBar::new((duration_s * 1e6) as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template(
            "{prefix} [{bar:30}] {msg} {percent:>3}% eta {eta}",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    pb.set_prefix(label.to_string());
    pb
}

/// Moves `pb` to the simulated time `t_s` reached, with the speed in its message: once per
/// thousandth of the bar (engines poll every step; formatting the message each time cost 3 %
/// of a network run).
pub fn show_time(pb: &indicatif::ProgressBar, t_s: f64) {
    if pb.is_hidden() {
        // nothing is drawn (stderr is no terminal): no message to format (formatting it at
        // every world step was 1 % of the 16-disc brake pack's run)
        return;
    }
    let at = (t_s * 1e6) as u64;
    let tick = pb.length().unwrap_or(0) / 1000;
    if at < pb.position().saturating_add(tick.max(1)) {
        return;
    }
    pb.set_position(at);
    let wall = pb.elapsed().as_secs_f64().max(1e-9);
    pb.set_message(format!(
        "t = {t_s:.4} s, {:.3} simulated s per wall s",
        t_s / wall
    ));
}
