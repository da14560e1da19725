//! A fit's parameters and matched signals as asked (`KEY[=START][:LO:HI][:log]`,
//! `SIGNAL[=COLUMN][:WEIGHT]`), and each parameter checked against its key's definition and
//! the scene's text before any run.

use crate::{Error, Result};
use std::str::FromStr;

/// One fitted parameter as asked: `KEY[=START][:LO:HI][:log]`.
#[derive(Debug, Clone, PartialEq)]
pub struct FitParam {
    /// The key as written: one dotted key (`couplings[1].force.start_s`), `[*]` for every
    /// item of an array that sets it (`couplings[*].mu`), or several keys joined by `,`,
    /// all set to the one value.
    pub key: String,
    /// The start value, in the key's unit; `None`: the scene's own value (else the key's
    /// default).
    pub start: Option<f64>,
    /// Lower bound, the key's unit (`-inf`: none but the key's rule).
    pub lower: f64,
    /// Upper bound, the key's unit (`+inf`: none but the key's rule).
    pub upper: f64,
    /// Fit `ln x` instead of `x` (a positive key spanning decades); bounds must be > 0.
    pub log: bool,
}

impl FromStr for FitParam {
    type Err = Error;

    /// `KEY`, `KEY=START`, `KEY:LO:HI`, `KEY=START:LO:HI`, each optionally ending `:log`;
    /// anything else is [`Error::BadInput`] naming the argument.
    fn from_str(s: &str) -> Result<Self> {
        let mut parts: Vec<&str> = s.split(':').collect();
        let log = parts.len() > 1 && parts.last() == Some(&"log");
        if log {
            parts.pop();
        }
        let num = |t: &str, what: &str| {
            t.trim().parse::<f64>().map_err(|_| {
                Error::BadInput(format!("--param {s:?}: {what} {t:?} is not a number"))
            })
        };
        let (lower, upper) = match parts.len() {
            1 => (f64::NEG_INFINITY, f64::INFINITY),
            3 => (num(parts[1], "lower bound")?, num(parts[2], "upper bound")?),
            _ => {
                return Err(Error::BadInput(format!(
                    "--param {s:?}: expected KEY[=START][:LO:HI][:log] (bounds come as a pair)"
                )))
            }
        };
        let (key, start) = match parts[0].split_once('=') {
            Some((k, v)) => (k, Some(num(v, "start value")?)),
            None => (parts[0], None),
        };
        if key.trim().is_empty() {
            return Err(Error::BadInput(format!("--param {s:?}: no key")));
        }
        Ok(FitParam {
            key: key.trim().to_string(),
            start,
            lower,
            upper,
            log,
        })
    }
}

/// One measured series matched to a signal: `SIGNAL=COLUMN[:WEIGHT]`.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSignal {
    /// The signal of the run (`J1`, `J1.speed_rad_s`, `clutch2.torque_n_m`).
    pub signal: String,
    /// The column of the data file that measures it (same unit as the signal).
    pub column: String,
    /// Its residuals' weight (> 0; 1 / the measurement's standard deviation makes the
    /// reported intervals those of weighted least squares).
    pub weight: f64,
}

impl FromStr for FitSignal {
    type Err = Error;

    /// `SIGNAL`, `SIGNAL=COLUMN` or `SIGNAL=COLUMN:WEIGHT` (the column defaults to the
    /// signal's name, the weight to 1); anything else is [`Error::BadInput`] naming the
    /// argument.
    fn from_str(s: &str) -> Result<Self> {
        let (signal, rest) = s.split_once('=').unwrap_or((s, s));
        let (column, weight) = match rest.rsplit_once(':') {
            Some((c, w)) => (
                c,
                w.trim().parse::<f64>().map_err(|_| {
                    Error::BadInput(format!("--match {s:?}: weight {w:?} is not a number"))
                })?,
            ),
            None => (rest, 1.0),
        };
        if !(weight.is_finite() && weight > 0.0) {
            return Err(Error::BadInput(format!(
                "--match {s:?}: the weight must be > 0, got {weight}"
            )));
        }
        if signal.trim().is_empty() || column.trim().is_empty() {
            return Err(Error::BadInput(format!(
                "--match {s:?}: expected SIGNAL=COLUMN[:WEIGHT]"
            )));
        }
        Ok(FitSignal {
            signal: signal.trim().to_string(),
            column: column.trim().to_string(),
            weight,
        })
    }
}

/// One parameter, checked: its keys, the key's unit, and its bounds and start in internal
/// coordinates.
#[derive(Debug, Clone)]
pub(super) struct Param {
    pub(super) asked: FitParam,
    pub(super) keys: Vec<String>,
    pub(super) unit: &'static str,
    pub(super) start: f64,
    /// The scene's own value of its (first) key, else the key's default (the truth of a
    /// coverage study), the key's unit.
    pub(super) scene_value: Option<f64>,
    pub(super) lower: f64,
    pub(super) upper: f64,
}

impl Param {
    pub(super) fn to_internal(&self, x: f64) -> f64 {
        if self.asked.log {
            x.ln()
        } else {
            x
        }
    }

    pub(super) fn to_value(&self, u: f64) -> f64 {
        if self.asked.log {
            u.exp()
        } else {
            u
        }
    }
}

/// One parameter checked against its key's definition and the scene's text.
pub(super) fn check_param(
    p: &FitParam,
    text: &str,
    shown: &str,
    seen: &mut Vec<String>,
) -> Result<Param> {
    let bad = |m: String| Error::BadInput(format!("--param {}: {m}", p.key));
    let mut keys = Vec::new();
    for k in p.key.split(',').map(str::trim) {
        keys.extend(clutchpack_scene::expand_wildcards(text, k).map_err(bad)?);
    }
    let mut def = None;
    let mut from_file = None;
    for k in &keys {
        let d = clutchpack_scene::numeric_key(k).map_err(|e| bad(format!("{k}: {e}")))?;
        if seen.contains(k) {
            return Err(bad(format!(
                "{k} is fitted twice, or also fixed with --set"
            )));
        }
        seen.push(k.clone());
        if from_file.is_none() {
            from_file = clutchpack_scene::number_in_text(text, k)
                .map_err(|e| bad(format!("{shown}: {e}")))?;
        }
        def.get_or_insert(d);
    }
    let def = def.ok_or_else(|| bad("no key".into()))?;
    let start = p.start.or(from_file).or(def.default).ok_or_else(|| {
        bad(format!(
            "{shown} does not set it and it has no numeric default: give a start value \
             (KEY=START)"
        ))
    })?;
    if p.lower >= p.upper {
        return Err(bad(format!(
            "the bounds are reversed or empty (lower {} >= upper {})",
            p.lower, p.upper
        )));
    }
    for (what, x) in [
        ("lower bound", p.lower),
        ("upper bound", p.upper),
        ("start", start),
    ] {
        if x.is_finite() {
            def.check(x).map_err(|rule| {
                bad(format!("{what} {x} is outside the key's own rule ({rule})"))
            })?;
        }
    }
    if !(p.lower..=p.upper).contains(&start) {
        return Err(bad(format!(
            "the start {start} lies outside the bounds [{}, {}]",
            p.lower, p.upper
        )));
    }
    if p.log && !(p.lower > 0.0 || (p.lower.is_infinite() && start > 0.0)) {
        return Err(bad(format!(
            "a log scale needs a lower bound > 0 (got {})",
            p.lower
        )));
    }
    let mut param = Param {
        asked: p.clone(),
        keys,
        unit: def.unit,
        start,
        scene_value: from_file.or(def.default),
        lower: p.lower,
        upper: p.upper,
    };
    param.lower = if p.log {
        if p.lower > 0.0 {
            p.lower.ln()
        } else {
            f64::NEG_INFINITY
        }
    } else {
        p.lower
    };
    param.upper = param.to_internal(p.upper);
    Ok(param)
}

/// The keys a variant column sets (`--variant KEY`: dotted, `[*]` and `,` as a parameter's
/// key), each numeric, neither fitted nor fixed with `--set` (`seen`).
pub(super) fn check_variant(key: &str, text: &str, seen: &[String]) -> Result<Vec<String>> {
    let bad = |m: String| Error::BadInput(format!("--variant {key}: {m}"));
    let mut keys = Vec::new();
    for k in key.split(',').map(str::trim) {
        keys.extend(clutchpack_scene::expand_wildcards(text, k).map_err(bad)?);
    }
    for k in &keys {
        clutchpack_scene::numeric_key(k).map_err(|e| bad(format!("{k}: {e}")))?;
        if seen.contains(k) {
            return Err(bad(format!("{k} is also fitted, or fixed with --set")));
        }
    }
    Ok(keys)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_parse() {
        let p: FitParam = "couplings[*].mu=0.35:0.1:1:log".parse().unwrap();
        assert_eq!(
            p,
            FitParam {
                key: "couplings[*].mu".into(),
                start: Some(0.35),
                lower: 0.1,
                upper: 1.0,
                log: true
            }
        );
        let p: FitParam = "a.b".parse().unwrap();
        assert!(p.start.is_none() && p.lower.is_infinite() && !p.log);
        let p: FitParam = "a.b:0:2".parse().unwrap();
        assert_eq!((p.lower, p.upper), (0.0, 2.0));
        assert!("a.b:0".parse::<FitParam>().is_err());
        assert!("a.b=x".parse::<FitParam>().is_err());
        assert!("=1".parse::<FitParam>().is_err());
    }

    #[test]
    fn signals_parse() {
        let s: FitSignal = "J1=w1:2.5".parse().unwrap();
        assert_eq!(
            (s.signal.as_str(), s.column.as_str(), s.weight),
            ("J1", "w1", 2.5)
        );
        let s: FitSignal = "J2".parse().unwrap();
        assert_eq!((s.column.as_str(), s.weight), ("J2", 1.0));
        assert!("J1=w1:0".parse::<FitSignal>().is_err());
        assert!("J1=w1:x".parse::<FitSignal>().is_err());
    }
}
