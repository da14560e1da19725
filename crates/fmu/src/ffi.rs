//! The FMI 2.0 co-simulation C functions (`fmi2Functions.h`), unprefixed, over
//! [`Instance`]. Each one checks its pointers, runs inside `catch_unwind` (a bug becomes
//! `fmi2Error` with a logged reason, never an abort of the host) and logs every error with
//! the instance's name through the host's logger.
//!
//! # Safety
//! Every function takes the pointers FMI 2.0 defines, as a host passes them: a component
//! from `fmi2Instantiate` (not yet freed), arrays of the stated lengths, NUL-terminated
//! strings. Null components and arrays are refused with `fmi2Error`, and so are components
//! and states that are not live (freed already, or never made here: a registry of live
//! addresses), so that a host's double free answers an error rather than crashing. (Said
//! once here rather than under each of the 35 functions.)

#![allow(clippy::missing_safety_doc)]

use crate::instance::{load_resources, FmiError, FmiResult, Instance, SavedState};
use std::collections::BTreeSet;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

/// The live components (from `fmi2Instantiate`, not yet freed) and the live states (from
/// `fmi2GetFMUstate`, not yet freed), by address: a pointer the host passes is used only if
/// it is live, so that a double free, a freed component or a freed state answers
/// `fmi2Error` (or nothing, for `fmi2FreeInstance`) instead of crashing the host.
struct Registry {
    components: BTreeSet<usize>,
    states: BTreeSet<usize>,
}

static LIVE: Mutex<Registry> = Mutex::new(Registry {
    components: BTreeSet::new(),
    states: BTreeSet::new(),
});

fn live() -> MutexGuard<'static, Registry> {
    // the registry is two sets of addresses: a panic elsewhere cannot leave them half-made
    LIVE.lock().unwrap_or_else(|p| p.into_inner())
}

const NOT_A_STATE: &str = "not a live state of this FMU (freed already, or never made by \
     fmi2GetFMUstate)";

/// `fmi2Status`.
const OK: c_int = 0;
const WARNING: c_int = 1;
const DISCARD: c_int = 2;
const ERROR: c_int = 3;
/// `fmi2Type::fmi2CoSimulation`.
const CO_SIMULATION: c_int = 1;

type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    _allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    _free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    _step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    component_environment: *mut c_void,
}

/// What `fmi2Component` points to.
struct Component {
    instance: Instance,
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    /// Strings handed out by `fmi2GetString`, valid until the next call.
    strings: Vec<CString>,
}

/// Sends `message` to the host's logger (as the argument of a `%s`, never as a format).
fn log_to(
    logger: Option<Logger>,
    env: *mut c_void,
    name: &CStr,
    status: c_int,
    category: &CStr,
    message: &str,
) {
    let Some(logger) = logger else { return };
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    // SAFETY: the host's logger with its own environment, NUL-terminated strings, and a
    // "%s" format whose one argument is `text`.
    unsafe {
        logger(
            env,
            name.as_ptr(),
            status,
            category.as_ptr(),
            c"%s".as_ptr(),
            text.as_ptr(),
        )
    };
}

impl Component {
    fn log(&self, status: c_int, message: &str) {
        let category = if status >= ERROR {
            c"logStatusError"
        } else {
            c"logStatusWarning"
        };
        log_to(
            self.logger,
            self.environment,
            &self.name,
            status,
            category,
            message,
        );
    }
}

/// Runs `f` on the component `c`, catching panics; an error is logged after `what` (the
/// function's name) and returned as `fmi2Error`.
fn with(c: *mut c_void, what: &str, f: impl FnOnce(&mut Component) -> FmiResult<c_int>) -> c_int {
    if c.is_null() || !live().components.contains(&(c as usize)) {
        // null, freed, or never one of ours: nothing to log to
        return ERROR;
    }
    // SAFETY: a live component from fmi2Instantiate (the registry says so).
    let comp = unsafe { &mut *(c as *mut Component) };
    match catch_unwind(AssertUnwindSafe(|| f(comp))) {
        Ok(Ok(status)) => status,
        Ok(Err(e)) => {
            comp.log(ERROR, &format!("{what}: {e}"));
            ERROR
        }
        Err(panic) => {
            let why = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            comp.log(
                ERROR,
                &format!("{what}: internal error (a bug in clutchpack; please report it): {why}"),
            );
            ERROR
        }
    }
}

/// `n` elements at `p` as a slice (empty for `n = 0`); `None` for a null pointer with `n > 0`.
///
/// # Safety
/// `p` points to `n` elements (module docs).
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// As [`slice`], mutable.
///
/// # Safety
/// `p` points to `n` elements (module docs).
unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

/// The error of a null array with a non-zero length.
fn null_array<T>() -> FmiResult<T> {
    Err(FmiError::Argument(
        "a null array with a non-zero length".into(),
    ))
}

/// A NUL-terminated string, or `None` for null or invalid UTF-8.
///
/// # Safety
/// `p` is null or NUL-terminated.
unsafe fn text<'a>(p: *const c_char) -> Option<&'a str> {
    if p.is_null() {
        None
    } else {
        unsafe { CStr::from_ptr(p) }.to_str().ok()
    }
}

/// The folder of `fmuResourceLocation`, a `file:` URI (percent-encoded).
pub fn resource_folder(uri: &str) -> FmiResult<PathBuf> {
    let rest = uri
        .strip_prefix("file://localhost/")
        .map(|r| format!("/{r}"))
        .or_else(|| uri.strip_prefix("file:///").map(|r| format!("/{r}")))
        .or_else(|| uri.strip_prefix("file:/").map(|r| format!("/{r}")))
        .ok_or_else(|| {
            FmiError::Argument(format!("fmuResourceLocation {uri:?}: expected a file: URI"))
        })?;
    let path = percent_encoding::percent_decode_str(&rest)
        .decode_utf8()
        .map_err(|e| FmiError::Argument(format!("fmuResourceLocation {uri:?}: {e}")))?;
    Ok(PathBuf::from(path.as_ref()))
}

/// `fmi2GetTypesPlatform`.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: reads the scene from the resources and checks the GUID; null (after
/// logging why) on any problem.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    let (logger, env) = if functions.is_null() {
        (None, std::ptr::null_mut())
    } else {
        // SAFETY: the host's callbacks (module docs)
        let f = unsafe { &*functions };
        (f.logger, f.component_environment)
    };
    let name = unsafe { text(instance_name) }.unwrap_or("clutchpack");
    let cname = CString::new(name).unwrap_or_default();
    let fail = |why: String| {
        log_to(logger, env, &cname, ERROR, c"logStatusError", &why);
        std::ptr::null_mut()
    };
    let made = catch_unwind(AssertUnwindSafe(|| -> FmiResult<Instance> {
        let bad = |why: &str| FmiError::Argument(why.into());
        if fmu_type != CO_SIMULATION {
            return Err(bad("this FMU is for co-simulation only (fmi2CoSimulation)"));
        }
        let guid = unsafe { text(guid) }.ok_or_else(|| bad("fmuGUID is null or not UTF-8"))?;
        let uri = unsafe { text(resource_location) }
            .ok_or_else(|| bad("fmuResourceLocation is null or not UTF-8"))?;
        let resources = resource_folder(uri)?;
        let scene = load_resources(&resources, guid)?;
        // no recording may be written over the FMU's own files
        Ok(Instance::new(scene)?.reading(crate::instance::own_files(&resources)))
    }));
    match made {
        Ok(Ok(instance)) => {
            let c = Box::into_raw(Box::new(Component {
                instance,
                name: cname,
                logger,
                environment: env,
                strings: Vec::new(),
            })) as *mut c_void;
            live().components.insert(c as usize);
            c
        }
        Ok(Err(why)) => fail(format!("fmi2Instantiate: {why}")),
        Err(_) => fail("fmi2Instantiate: internal error (a bug in clutchpack)".into()),
    }
}

/// `fmi2FreeInstance`: a run still going is finished first (its recording completed).
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if c.is_null() || !live().components.remove(&(c as usize)) {
        // null, freed already, or never one of ours: nothing to free
        return;
    }
    // SAFETY: a live component from fmi2Instantiate, now out of the registry: freed once
    let mut comp = unsafe { Box::from_raw(c as *mut Component) };
    let _ = catch_unwind(AssertUnwindSafe(|| comp.instance.reset()));
}

/// `fmi2SetDebugLogging`: errors and warnings are always logged; nothing else is.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    _on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> c_int {
    with(c, "fmi2SetDebugLogging", |_| Ok(OK))
}

/// `fmi2SetupExperiment`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start: f64,
    stop_defined: c_int,
    stop: f64,
) -> c_int {
    with(c, "fmi2SetupExperiment", |comp| {
        let stop = (stop_defined != 0).then_some(stop);
        comp.instance.setup_experiment(start, stop).map(|()| OK)
    })
}

/// `fmi2EnterInitializationMode`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> c_int {
    with(c, "fmi2EnterInitializationMode", |comp| {
        comp.instance.enter_initialization().map(|()| OK)
    })
}

/// `fmi2ExitInitializationMode`: starts the run.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> c_int {
    with(c, "fmi2ExitInitializationMode", |comp| {
        comp.instance.exit_initialization().map(|()| OK)
    })
}

/// `fmi2Terminate`: finishes the run and its recording.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> c_int {
    with(c, "fmi2Terminate", |comp| {
        let warnings = comp.instance.terminate();
        for w in &warnings {
            comp.log(WARNING, &format!("fmi2Terminate: {w}"));
        }
        Ok(if warnings.is_empty() { OK } else { WARNING })
    })
}

/// `fmi2Reset`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> c_int {
    with(c, "fmi2Reset", |comp| {
        comp.instance.reset();
        Ok(OK)
    })
}

/// `fmi2GetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    value: *mut f64,
) -> c_int {
    with(c, "fmi2GetReal", |comp| {
        let (vr, out) = unsafe { (slice(vr, n), slice_mut(value, n)) };
        let (Some(vr), Some(out)) = (vr, out) else {
            return null_array();
        };
        for (r, o) in vr.iter().zip(out.iter_mut()) {
            *o = comp.instance.get_real(*r)?;
        }
        Ok(OK)
    })
}

/// `fmi2GetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    value: *mut c_int,
) -> c_int {
    with(c, "fmi2GetInteger", |comp| {
        let (vr, out) = unsafe { (slice(vr, n), slice_mut(value, n)) };
        let (Some(vr), Some(out)) = (vr, out) else {
            return null_array();
        };
        for (r, o) in vr.iter().zip(out.iter_mut()) {
            *o = comp.instance.get_integer(*r)?;
        }
        Ok(OK)
    })
}

/// `fmi2GetBoolean`: the FMU has no Boolean variables.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    _value: *mut c_int,
) -> c_int {
    with(c, "fmi2GetBoolean", |_| no_booleans(vr, n))
}

/// `fmi2SetBoolean`: the FMU has no Boolean variables.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    _value: *const c_int,
) -> c_int {
    with(c, "fmi2SetBoolean", |_| no_booleans(vr, n))
}

fn no_booleans(vr: *const u32, n: usize) -> FmiResult<c_int> {
    match unsafe { slice(vr, n) } {
        Some([]) => Ok(OK),
        Some(v) => Err(FmiError::Argument(format!(
            "no Boolean variable has the value reference {}",
            v[0]
        ))),
        None => null_array(),
    }
}

/// `fmi2GetString`: the strings stay valid until the next call on the instance.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    value: *mut *const c_char,
) -> c_int {
    with(c, "fmi2GetString", |comp| {
        let (vr, out) = unsafe { (slice(vr, n), slice_mut(value, n)) };
        let (Some(vr), Some(out)) = (vr, out) else {
            return null_array();
        };
        comp.strings.clear();
        for r in vr {
            let s = comp.instance.get_string(*r)?;
            comp.strings
                .push(CString::new(s.replace('\0', " ")).unwrap_or_default());
        }
        for (o, s) in out.iter_mut().zip(&comp.strings) {
            *o = s.as_ptr();
        }
        Ok(OK)
    })
}

/// `fmi2SetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    value: *const f64,
) -> c_int {
    with(c, "fmi2SetReal", |comp| {
        let (vr, values) = unsafe { (slice(vr, n), slice(value, n)) };
        let (Some(vr), Some(values)) = (vr, values) else {
            return null_array();
        };
        for (r, v) in vr.iter().zip(values) {
            comp.instance.set_real(*r, *v)?;
        }
        Ok(OK)
    })
}

/// `fmi2SetInteger`: the one Integer variable is an output.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    _value: *const c_int,
) -> c_int {
    with(c, "fmi2SetInteger", |_| match unsafe { slice(vr, n) } {
        Some([]) => Ok(OK),
        Some(_) => Err(FmiError::Argument(
            "the Integer variables (impacts, last_impact.body) are outputs".into(),
        )),
        None => null_array(),
    })
}

/// `fmi2SetString`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    value: *const *const c_char,
) -> c_int {
    with(c, "fmi2SetString", |comp| {
        let (vr, values) = unsafe { (slice(vr, n), slice(value, n)) };
        let (Some(vr), Some(values)) = (vr, values) else {
            return null_array();
        };
        for (r, v) in vr.iter().zip(values) {
            let v = unsafe { text(*v) }
                .ok_or_else(|| FmiError::Argument("a null or non-UTF-8 string".into()))?;
            comp.instance.set_string(*r, v)?;
        }
        Ok(OK)
    })
}

/// `fmi2GetFMUstate`: a new state, or the one given overwritten.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    with(c, "fmi2GetFMUstate", |comp| {
        if state.is_null() {
            return Err(FmiError::Argument("a null state pointer".into()));
        }
        // SAFETY: a state pointer from the host (null or from fmi2GetFMUstate)
        let old = unsafe { *state };
        if !old.is_null() && !live().states.contains(&(old as usize)) {
            return Err(FmiError::Argument(format!(
                "the state to overwrite is {NOT_A_STATE}"
            )));
        }
        let saved = comp.instance.save()?;
        if old.is_null() {
            let new = Box::into_raw(Box::new(saved)) as *mut c_void;
            live().states.insert(new as usize);
            unsafe { *state = new };
        } else {
            // SAFETY: a live state (the registry says so)
            unsafe { *(old as *mut SavedState) = saved };
        }
        Ok(OK)
    })
}

/// `fmi2SetFMUstate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> c_int {
    with(c, "fmi2SetFMUstate", |comp| {
        if state.is_null() {
            return Err(FmiError::Argument("a null state".into()));
        }
        if !live().states.contains(&(state as usize)) {
            return Err(FmiError::Argument(format!("the state is {NOT_A_STATE}")));
        }
        // SAFETY: a live state from fmi2GetFMUstate (the registry says so)
        let saved = unsafe { &*(state as *const SavedState) };
        comp.instance.restore(saved).map(|()| OK)
    })
}

/// `fmi2FreeFMUstate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> c_int {
    with(c, "fmi2FreeFMUstate", |_| {
        if state.is_null() || unsafe { *state }.is_null() {
            return Ok(OK);
        }
        let p = unsafe { *state };
        if !live().states.remove(&(p as usize)) {
            return Err(FmiError::Argument(format!("the state is {NOT_A_STATE}")));
        }
        // SAFETY: a live state from fmi2GetFMUstate, now out of the registry: freed once
        drop(unsafe { Box::from_raw(p as *mut SavedState) });
        unsafe { *state = std::ptr::null_mut() };
        Ok(OK)
    })
}

const NO_SERIALIZE: &str = "this FMU cannot serialize its state (canSerializeFMUstate = false): \
     a state holds the engine's integration in memory; use fmi2GetFMUstate";

/// `fmi2SerializedFMUstateSize`: not supported.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: *mut c_void,
    _s: *mut c_void,
    _size: *mut usize,
) -> c_int {
    with(c, "fmi2SerializedFMUstateSize", |_| {
        Err(FmiError::Unsupported(NO_SERIALIZE))
    })
}

/// `fmi2SerializeFMUstate`: not supported.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    _s: *mut c_void,
    _b: *mut c_char,
    _n: usize,
) -> c_int {
    with(c, "fmi2SerializeFMUstate", |_| {
        Err(FmiError::Unsupported(NO_SERIALIZE))
    })
}

/// `fmi2DeSerializeFMUstate`: not supported.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    _b: *const c_char,
    _n: usize,
    _s: *mut *mut c_void,
) -> c_int {
    with(c, "fmi2DeSerializeFMUstate", |_| {
        Err(FmiError::Unsupported(NO_SERIALIZE))
    })
}

/// `fmi2GetDirectionalDerivative`: not provided.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _u: *const u32,
    _nu: usize,
    _k: *const u32,
    _nk: usize,
    _dk: *const f64,
    _du: *mut f64,
) -> c_int {
    with(c, "fmi2GetDirectionalDerivative", |_| {
        Err(FmiError::Unsupported(
            "not provided (providesDirectionalDerivative = false)",
        ))
    })
}

/// `fmi2SetRealInputDerivatives`: the slope of the shaft's speed or drive torque (order 1),
/// a first-order hold over the coming steps.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    order: *const c_int,
    value: *const f64,
) -> c_int {
    with(c, "fmi2SetRealInputDerivatives", |comp| {
        let (vr, order, value) = unsafe { (slice(vr, n), slice(order, n), slice(value, n)) };
        let (Some(vr), Some(order), Some(value)) = (vr, order, value) else {
            return null_array();
        };
        for ((r, o), v) in vr.iter().zip(order).zip(value) {
            comp.instance.set_real_derivative(*r, *o, *v)?;
        }
        Ok(OK)
    })
}

/// `fmi2GetRealOutputDerivatives`: not provided.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> c_int {
    with(c, "fmi2GetRealOutputDerivatives", |_| {
        Err(FmiError::Unsupported(
            "not provided (maxOutputDerivativeOrder = 0)",
        ))
    })
}

/// `fmi2DoStep`: the inputs set are held from `current` to `current + h`.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current: f64,
    h: f64,
    _no_set_prior: c_int,
) -> c_int {
    with(c, "fmi2DoStep", |comp| {
        comp.instance.do_step(current, h).map(|()| OK)
    })
}

/// `fmi2CancelStep`: steps are synchronous; nothing to cancel.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> c_int {
    with(c, "fmi2CancelStep", |_| {
        Err(FmiError::Unsupported(
            "fmi2DoStep is synchronous (canRunAsynchronuously = false)",
        ))
    })
}

/// `fmi2GetStatus`: steps are synchronous, nothing is pending.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> c_int {
    with(c, "fmi2GetStatus", |_| Ok(DISCARD))
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` gives the time the run stands at.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> c_int {
    with(c, "fmi2GetRealStatus", |comp| {
        // fmi2StatusKind::fmi2LastSuccessfulTime
        if kind == 2 && !value.is_null() {
            unsafe { *value = comp.instance.time_s() };
            Ok(OK)
        } else {
            Ok(DISCARD)
        }
    })
}

/// `fmi2GetIntegerStatus`: nothing to report.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut c_int,
) -> c_int {
    with(c, "fmi2GetIntegerStatus", |_| Ok(DISCARD))
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` is never asked by the FMU (it never ends a
/// run on its own).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut c_int,
) -> c_int {
    with(c, "fmi2GetBooleanStatus", |_| Ok(DISCARD))
}

/// `fmi2GetStringStatus`: nothing to report.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut *const c_char,
) -> c_int {
    with(c, "fmi2GetStringStatus", |_| Ok(DISCARD))
}

#[cfg(test)]
mod tests {
    use super::resource_folder;
    use std::path::PathBuf;

    #[test]
    fn resource_uris_become_folders() {
        for (uri, path) in [
            ("file:///tmp/a%20b/resources", "/tmp/a b/resources"),
            ("file:/tmp/x/resources/", "/tmp/x/resources/"),
            ("file://localhost/tmp/y", "/tmp/y"),
        ] {
            assert_eq!(resource_folder(uri).unwrap(), PathBuf::from(path), "{uri}");
        }
        assert!(resource_folder("http://example.com/r").is_err());
        assert!(resource_folder("/tmp/plain").is_err());
    }
}
