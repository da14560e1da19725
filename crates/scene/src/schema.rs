//! The language of the key definitions: what a key is ([`Key`]: name, unit, kind and rule,
//! default, doc) and the [`table!`] macro that turns one table's definitions into its raw
//! serde struct and its key list. The definitions themselves are in [`crate::keys`]; what is
//! derived from them (every key path, `check --keys`, docs/scene-keys.md's table) in
//! [`crate::catalog`].
//!
//! Paths are written as in the file, with `[]` standing for any index of an array of tables:
//! `discs[].spline.teeth`.

use toml::Value;

/// One key of a scene file: everything the parse, the validation and the documentation know
/// about it. Written once, in [`crate::keys`], through [`table!`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Key {
    /// The table's path relative to its body for body tables (`""`, `"spline"`), else from
    /// the top (`"simulation"`, `"drive.harmonics[]"`); `""` at the top level.
    pub table: &'static str,
    /// The key's name in its table: `record_rate_hz`.
    pub name: &'static str,
    /// Unit as written in the reference (`"Hz"`, `"kg m^2"`), `""` for none.
    pub unit: &'static str,
    /// What kind of value it takes, with its range rule.
    pub kind: Kind,
    /// What an absent key means.
    pub default: Dflt,
    /// One line of meaning and of rules between keys (the rest of the reference line is
    /// generated from `unit`, `kind` and `default`).
    pub doc: &'static str,
}

/// What kind of value a key takes.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kind {
    /// A finite number (an integer is accepted) within a range.
    Number(Rule),
    /// An integer count, `>= 1` and `<= max`.
    Count {
        /// The largest count accepted (a plausibility bound).
        max: u32,
    },
    /// `true` or `false`.
    Bool,
    /// A string.
    Text,
    /// One of these strings.
    Choice(&'static [&'static str]),
    /// An array of finite numbers.
    Numbers,
    /// An array of strings.
    Texts,
    /// An array of rows, each an array of finite numbers (a 2-D table).
    NumberRows,
}

/// What an absent key means.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Dflt {
    /// The key must be given.
    Required,
    /// Required, allowed or refused depending on other keys; the text says when.
    When(&'static str),
    /// This number.
    Num(f64),
    /// This boolean.
    Bool(bool),
    /// This choice.
    Choice(&'static str),
    /// A default derived from other values, described by the text.
    Described(&'static str),
}

/// The range rule of a number (every number must also be finite). Bounds print in the
/// shortest form of [`fmt_bound`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum Rule {
    /// Any finite number.
    Finite,
    /// `> 0`.
    Positive,
    /// `>= 0`.
    NonNegative,
    /// In `[lo, hi]`.
    Closed(f64, f64),
    /// In `(lo, hi)`.
    Open(f64, f64),
    /// `> 0`, and within the plausibility bounds `[floor, ceil]` (see docs/DECISIONS.md,
    /// "Plausibility bounds"): `floor` 0 or `ceil` infinite for none.
    Bounded {
        /// Smallest plausible value (0: any positive value).
        floor: f64,
        /// Largest plausible value (infinity: no ceiling).
        ceil: f64,
    },
}

impl Rule {
    /// `Ok` if `x` (finite) holds, else the rule it breaks, e.g. `must be > 0`. `unit` is the
    /// key's unit, named after plausibility bounds.
    pub fn check(self, x: f64, unit: &str) -> Result<(), String> {
        let u = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        let ok = match self {
            Rule::Finite => true,
            Rule::Positive => x > 0.0,
            Rule::NonNegative => x >= 0.0,
            Rule::Closed(lo, hi) => (lo..=hi).contains(&x),
            Rule::Open(lo, hi) => x > lo && x < hi,
            Rule::Bounded { floor, ceil } => {
                return if x <= 0.0 {
                    Err("must be > 0".into())
                } else if x < floor {
                    Err(format!(
                        "must be >= {}{u} (plausibility bound)",
                        fmt_bound(floor)
                    ))
                } else if x > ceil {
                    Err(format!(
                        "must be <= {}{u} (plausibility bound)",
                        fmt_bound(ceil)
                    ))
                } else {
                    Ok(())
                };
            }
        };
        if ok {
            Ok(())
        } else {
            Err(format!("must be {}", self.doc()))
        }
    }

    /// The rule for the reference: `> 0`, `in [1e-14, 1e-3]`.
    pub fn doc(self) -> String {
        match self {
            Rule::Finite => "a finite number".into(),
            Rule::Positive => "> 0".into(),
            Rule::NonNegative => ">= 0".into(),
            Rule::Closed(lo, hi) => format!("in [{}, {}]", fmt_bound(lo), fmt_bound(hi)),
            Rule::Open(lo, hi) => {
                format!("in ({}, {}) (exclusive)", fmt_bound(lo), fmt_bound(hi))
            }
            Rule::Bounded { floor, ceil } => {
                let low = if floor > 0.0 {
                    format!(">= {}", fmt_bound(floor))
                } else {
                    "> 0".into()
                };
                if ceil.is_finite() {
                    format!("{low} and <= {}", fmt_bound(ceil))
                } else {
                    low
                }
            }
        }
    }
}

/// A number in its shortest round-trip form: `{}` or `{:e}`, whichever is shorter (`1e-14`,
/// `0.1`, `90`, `1e6`, `1e308`); integers below 1e6 in full (`10000`).
pub(crate) fn fmt_bound(x: f64) -> String {
    let plain = format!("{x}");
    if x.fract() == 0.0 && x.abs() < 1e6 {
        return plain;
    }
    let sci = format!("{x:e}");
    if sci.len() < plain.len() {
        sci
    } else {
        plain
    }
}

/// A number for messages: [`clutchpack_model::fmt_num`], the one format of every front end.
pub(crate) use clutchpack_model::fmt_num;

/// Most items of an array echoed in a message; a longer one is shown as its first items and
/// its length (a 100 000-number array was echoed whole, 600 KB, issue 36).
pub(crate) const SHOWN_ITEMS: usize = 4;

/// A value as written, in TOML syntax, for messages: huge or tiny floats as [`fmt_num`]
/// writes them (ordinary ones as TOML writes them, `3.0`), arrays of more than
/// [`SHOWN_ITEMS`] items as their first items and their length.
pub(crate) fn show(v: &Value) -> String {
    match v {
        Value::Float(x) if fmt_num(*x).contains('e') => fmt_num(*x),
        Value::Array(items) if items.len() > SHOWN_ITEMS => {
            let parts: Vec<String> = items[..SHOWN_ITEMS].iter().map(show).collect();
            format!("[{}, ... ({} items)]", parts.join(", "), items.len())
        }
        Value::Array(items) => {
            let parts: Vec<String> = items.iter().map(show).collect();
            format!("[{}]", parts.join(", "))
        }
        _ => v.to_string(),
    }
}

impl Key {
    /// The key's path relative to its table root: `spline.teeth`, `simulation.duration_s`.
    pub fn rel(&self) -> String {
        join(self.table, self.name)
    }

    /// The key's path under `at` (a body such as `discs[2]`, or `""`): `discs[2].spline.teeth`.
    pub fn at(&self, at: &str) -> String {
        let mut s = String::with_capacity(at.len() + self.table.len() + self.name.len() + 2);
        for part in [at, self.table] {
            if !part.is_empty() {
                s.push_str(part);
                s.push('.');
            }
        }
        s.push_str(self.name);
        s
    }

    /// The default number; a bug if the key's default is not a number.
    pub fn default_num(&self) -> f64 {
        match self.default {
            Dflt::Num(x) => x,
            _ => panic!("key {} has no numeric default", self.rel()),
        }
    }

    /// The default boolean; a bug if the key's default is not a boolean.
    pub fn default_bool(&self) -> bool {
        match self.default {
            Dflt::Bool(b) => b,
            _ => panic!("key {} has no boolean default", self.rel()),
        }
    }

    /// The index of the default choice among the key's names; a bug if there is none.
    pub fn default_choice(&self) -> usize {
        match (self.kind, self.default) {
            (Kind::Choice(names), Dflt::Choice(c)) => names
                .iter()
                .position(|n| *n == c)
                .unwrap_or_else(|| panic!("key {}: default {c} is not a choice", self.rel())),
            _ => panic!("key {} has no default choice", self.rel()),
        }
    }

    /// The reference line: `Hz, > 0 and <= 1e6; default 10000; rate of the samples`.
    pub fn doc_line(&self) -> String {
        let mut parts = Vec::new();
        let (unit, rule, default) = self.columns();
        let first = match (unit.is_empty(), rule.is_empty()) {
            (true, _) => rule,
            (false, true) => unit,
            (false, false) => format!("{unit}, {rule}"),
        };
        parts.push(first);
        parts.push(default);
        if !self.doc.is_empty() {
            parts.push(self.doc.trim().to_string());
        }
        parts.retain(|p| !p.is_empty());
        parts.join("; ")
    }

    /// The unit, rule and default columns of the reference.
    pub fn columns(&self) -> (String, String, String) {
        let rule = match self.kind {
            Kind::Number(r) => r.doc(),
            Kind::Count { max } => format!("integer >= 1 and <= {max}"),
            Kind::Bool => "true | false".into(),
            Kind::Text => "string".into(),
            Kind::Choice(names) => names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(" | "),
            Kind::Numbers => "array of finite numbers".into(),
            Kind::Texts => "array of strings".into(),
            Kind::NumberRows => "array of arrays of finite numbers (one per row)".into(),
        };
        let default = match self.default {
            Dflt::Required => "required".into(),
            Dflt::When(t) | Dflt::Described(t) => t.to_string(),
            Dflt::Num(x) => format!("default {}", fmt_bound(x)),
            Dflt::Bool(b) => format!("default {b}"),
            Dflt::Choice(c) => format!("default \"{c}\""),
        };
        (self.unit.to_string(), rule, default)
    }
}

/// `a.b`, or `b` if `a` is empty.
/// Whether the table path `table` is `base.child` (`child` when `base` is empty) or lies
/// under it: [`join`]'s path compared part by part, without building it (every key looked up
/// in a table asks it of each of the table's children).
pub(crate) fn is_under(table: &str, base: &str, child: &str) -> bool {
    let rest = if base.is_empty() {
        Some(table)
    } else {
        table.strip_prefix(base).and_then(|r| r.strip_prefix('.'))
    };
    rest.and_then(|r| r.strip_prefix(child))
        .is_some_and(|r| r.is_empty() || r.starts_with('.'))
}

/// `a.b`, or `b` when `a` is empty: a key's path from its parts. Pushed into one string of
/// the right capacity rather than formatted: a scene's validation builds a path for every key
/// of every body (a 33-body pack's paths were a third of the whole run's instructions when
/// formatted).
pub(crate) fn join(a: &str, b: &str) -> String {
    let mut s = String::with_capacity(a.len() + 1 + b.len());
    if !a.is_empty() {
        s.push_str(a);
        s.push('.');
    }
    s.push_str(b);
    s
}

/// A table of the file as its raw struct: the keys it defines and their values as written.
/// Implemented by [`table!`].
pub(crate) trait RawTable {
    /// The table path of this table's own keys (`Key::table`).
    fn base() -> &'static str;
    /// The value of `key` (of this table or of one of its sub-tables) as written.
    fn value(&self, key: &Key) -> Option<&Value> {
        self.get_in(Self::base(), key)
    }
    /// The value of `key` as written, looking into sub-tables by `key.table` relative to
    /// `base` (the table path of `Self`'s own keys); `None` if absent.
    fn get_in(&self, base: &str, key: &Key) -> Option<&Value>;
    /// Every leaf key under `prefix` (the path of this table, `[]` for array items), in
    /// definition order, sub-tables after their parent's leaves in the order declared.
    fn paths(prefix: &str, out: &mut Vec<(String, &'static Key)>);
}

/// Defines one table of the scene file: its raw serde struct (every leaf an
/// `Option<toml::Value>`, kept as written for the validation) and one [`Key`] per leaf, as an
/// associated constant of the same name (`RawSimulation::record_rate_hz`), listed in file
/// order by [`RawTable::keys`]. Sub-tables are declared as `name: table Type` or
/// `name: array Type` (an array of tables) after `children`.
///
/// ```ignore
/// table! {
///     /// `[simulation]`.
///     RawSimulation at "simulation" {
///         /// simulated duration
///         duration_s: "s", Kind::Number(Rule::Positive), Dflt::Required;
///     }
///     children { }
/// }
/// ```
macro_rules! table {
    (
        $(#[doc = $tdoc:literal])*
        $raw:ident at $path:literal {
            $(
                $(#[doc = $kdoc:literal])*
                $field:ident : $unit:literal, $kind:expr, $default:expr;
            )*
        }
        children { $( $child:ident : $how:ident $cty:ty ),* $(,)? }
    ) => {
        $(#[doc = $tdoc])*
        #[derive(Debug, Default, serde::Deserialize)]
        #[serde(expecting = "a table")]
        pub(crate) struct $raw {
            $( $(#[doc = $kdoc])* pub $field: Option<toml::Value>, )*
            $( #[doc = concat!("The `", stringify!($child), "` sub-table(s).")]
               pub $child: Option<$crate::schema::table!(@ty $how $cty)>, )*
        }

        #[allow(non_upper_case_globals, dead_code)]
        impl $raw {
            $(
                $(#[doc = $kdoc])*
                pub(crate) const $field: $crate::schema::Key = $crate::schema::Key {
                    table: $path,
                    name: stringify!($field),
                    unit: $unit,
                    kind: $kind,
                    default: $default,
                    doc: concat!($($kdoc),*),
                };
            )*
            /// Every leaf key of this table, in file order.
            pub(crate) const KEYS: &'static [$crate::schema::Key] = &[$(Self::$field),*];
        }

        impl $crate::schema::RawTable for $raw {
            fn base() -> &'static str {
                $path
            }

            #[allow(unused_variables)]
            fn get_in(&self, base: &str, key: &$crate::schema::Key) -> Option<&toml::Value> {
                if key.table == base {
                    return match key.name {
                        $( stringify!($field) => self.$field.as_ref(), )*
                        _ => None,
                    };
                }
                $(
                    if $crate::schema::is_under(key.table, base, stringify!($child)) {
                        let sub = $crate::schema::table!(@join base, stringify!($child));
                        return $crate::schema::table!(@get $how self.$child, sub, key);
                    }
                )*
                None
            }

            #[allow(unused_variables)]
            fn paths(prefix: &str, out: &mut Vec<(String, &'static $crate::schema::Key)>) {
                for k in Self::KEYS {
                    let p = if prefix.is_empty() {
                        k.name.to_string()
                    } else {
                        format!("{prefix}.{}", k.name)
                    };
                    out.push((p, k));
                }
                $(
                    let p = $crate::schema::table!(@join prefix, stringify!($child));
                    <$cty as $crate::schema::RawTable>::paths(
                        &$crate::schema::table!(@item $how p),
                        out,
                    );
                )*
            }
        }
    };
    (@ty table $t:ty) => { $t };
    (@ty array $t:ty) => { Vec<$t> };
    (@join $a:expr, $b:expr) => {
        $crate::schema::join($a, $b)
    };
    (@item table $p:expr) => { $p };
    (@item array $p:expr) => { format!("{}[]", $p) };
    // Array items are looked into only for their shape: values are read item by item.
    (@get table $v:expr, $sub:expr, $key:expr) => {
        $v.as_ref().and_then(|t| $crate::schema::RawTable::get_in(t, &$sub, $key))
    };
    (@get array $v:expr, $sub:expr, $key:expr) => { None };
}
pub(crate) use table;

#[cfg(test)]
mod tests {
    use super::*;

    /// The paths pushed together are the paths formatted (`a.b`, an empty part left out),
    /// for every key of the catalogue, under no body, a disc and the defaults.
    #[test]
    fn key_paths_are_their_parts_joined_by_dots() {
        let formatted = |a: &str, b: &str| {
            if a.is_empty() {
                b.to_string()
            } else {
                format!("{a}.{b}")
            }
        };
        let keys = crate::catalog::all_keys();
        assert!(keys.len() > 100, "{} keys", keys.len());
        for (_, k) in keys {
            let rel = formatted(k.table, k.name);
            assert_eq!(k.rel(), rel);
            for at in ["", "discs[2]", "defaults"] {
                assert_eq!(k.at(at), formatted(at, &rel), "{rel} at {at:?}");
            }
        }
        for (table, base, child, under) in [
            ("spline", "", "spline", true),
            ("spline.x", "", "spline", true),
            ("splines", "", "spline", false),
            ("thermal.friction", "thermal", "friction", true),
            ("thermal.friction.a", "thermal", "friction", true),
            ("thermal.frictions", "thermal", "friction", false),
            ("thermal", "thermal", "friction", false),
            ("thermalfriction", "thermal", "friction", false),
            ("oil", "thermal", "friction", false),
        ] {
            let sub = join(base, child);
            let formatted = table == sub || table.starts_with(&format!("{sub}."));
            assert_eq!(formatted, under, "{table} under {base}.{child}");
            assert_eq!(
                is_under(table, base, child),
                under,
                "{table} under {base}.{child}"
            );
        }
        assert_eq!(join("", "b"), "b");
        assert_eq!(join("a.x", "b"), "a.x.b");
    }

    #[test]
    fn numbers_print_short() {
        assert_eq!(fmt_bound(1e-14), "1e-14");
        assert_eq!(fmt_bound(1e-3), "1e-3");
        assert_eq!(fmt_bound(90.0), "90");
        assert_eq!(fmt_bound(0.1), "0.1");
        assert_eq!(fmt_bound(1e6), "1e6");
        assert_eq!(fmt_bound(10_000.0), "10000");
        assert_eq!(fmt_num(1e308), "1e308");
        assert_eq!(fmt_num(5e-324), "5e-324");
        assert_eq!(fmt_num(-0.156), "-0.156");
        assert_eq!(show(&Value::Float(1e308)), "1e308");
        assert_eq!(show(&Value::Float(-0.001)), "-0.001");
        assert_eq!(show(&Value::Float(0.0)), "0.0");
    }

    /// Issue 36: a 100 000-number array was echoed whole in an error (600 KB); it is shown
    /// as its first items and its length, a short one whole, nested ones summarised too.
    #[test]
    fn long_arrays_in_messages_are_summarised() {
        let long = Value::Array(vec![Value::Float(1e-6); 100_000]);
        assert_eq!(show(&long), "[1e-6, 1e-6, 1e-6, 1e-6, ... (100000 items)]");
        let short = Value::Array(vec![Value::Integer(1), Value::Float(2.5)]);
        assert_eq!(show(&short), "[1, 2.5]");
        let nested = Value::Array(vec![long.clone()]);
        assert!(show(&nested).len() < 60, "{}", show(&nested));
    }

    #[test]
    fn rules_say_what_they_need() {
        assert_eq!(Rule::Positive.check(-1.0, "m"), Err("must be > 0".into()));
        assert_eq!(
            Rule::Closed(1e-14, 1e-3).check(1.0, ""),
            Err("must be in [1e-14, 1e-3]".into())
        );
        let b = Rule::Bounded {
            floor: 1e-9,
            ceil: 1e6,
        };
        assert_eq!(b.check(0.0, "s"), Err("must be > 0".into()));
        assert_eq!(
            b.check(1e-300, "s"),
            Err("must be >= 1e-9 s (plausibility bound)".into())
        );
        assert_eq!(
            b.check(1e9, "Hz"),
            Err("must be <= 1e6 Hz (plausibility bound)".into())
        );
        assert!(b.check(1.0, "s").is_ok());
    }
}
