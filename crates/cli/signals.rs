//! Stop requests from the operating system, one mechanism for every long command.
//!
//! SIGINT (Ctrl-C), SIGTERM (`kill`, a scheduler's time limit or its `--signal` warning) and
//! SIGHUP (a closed terminal) all ask the running command to stop cleanly: the engines poll
//! [`flag`] and return early, the outputs are written with what came before, and the process
//! exits with `128 + signal` ([`exit_code`]). A second signal of any of the three while the
//! first is being honoured ends the process at once with the same code (a user who presses
//! Ctrl-C twice means it).

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

/// The signals that ask a command to stop.
pub const STOP_SIGNALS: [i32; 3] = [SIGINT, SIGTERM, SIGHUP];

struct StopState {
    /// Set by the first stop signal; engines and loops poll it.
    flag: Arc<AtomicBool>,
    /// The number of the first signal received (0: none).
    signal: Arc<AtomicUsize>,
}

static STATE: OnceLock<StopState> = OnceLock::new();

fn state() -> &'static StopState {
    STATE.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in STOP_SIGNALS {
            // Order matters: the conditional shutdown sees the flag before this signal sets
            // it, so it fires only on a second signal. Failing to install a handler only
            // loses the clean stop (the default action still ends the process).
            let _ =
                signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(&flag));
            let _ = signal_hook::flag::register_usize(sig, Arc::clone(&signal), sig as usize);
            let _ = signal_hook::flag::register(sig, Arc::clone(&flag));
        }
        StopState { flag, signal }
    })
}

/// Installs the handlers (once per process) and returns the stop flag, set by the first
/// SIGINT, SIGTERM or SIGHUP.
pub fn flag() -> Arc<AtomicBool> {
    Arc::clone(&state().flag)
}

/// The first stop signal received, if any.
pub fn received() -> Option<i32> {
    let s = STATE.get()?.signal.load(Ordering::SeqCst);
    (s != 0).then_some(s as i32)
}

/// The conventional exit code of a process stopped by the first received signal
/// (`128 + signal`: 130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP); 130 if the flag was set
/// without a signal (tests).
pub fn exit_code() -> ExitCode {
    ExitCode::from((128 + received().unwrap_or(SIGINT)) as u8)
}

/// A short name of the first received signal, for messages ("SIGTERM").
pub fn received_name() -> &'static str {
    match received() {
        Some(SIGTERM) => "SIGTERM",
        Some(SIGHUP) => "SIGHUP",
        _ => "SIGINT",
    }
}
