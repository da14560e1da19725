//! Helpers the integration tests share: the impacts of an `--impacts-csv` and their
//! comparison impact by impact.

use std::collections::BTreeMap;
use std::path::Path;

/// One tooth impact: onset, separation (s) and peak (N, per tooth, signed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact {
    pub t_on_s: f64,
    pub t_off_s: f64,
    pub peak_n: f64,
}

/// The impacts of an `--impacts-csv` of a network run, by body name in the order they
/// closed (the whole name: `<pack>/discs/<disc>`, so that two packs' `disc-1` stay apart).
pub fn network_impacts(csv: &Path) -> BTreeMap<String, Vec<Impact>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (name, on, off, peak) = (col("name"), col("t_on_s"), col("t_off_s"), col("peak_n"));
    let mut out: BTreeMap<String, Vec<Impact>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        out.entry(f[name].to_string()).or_default().push(Impact {
            t_on_s: num(on),
            t_off_s: num(off),
            peak_n: num(peak),
        });
    }
    out
}

/// How far apart two runs' impacts are one by one (each body's `i`-th impact in `a` against
/// its `i`-th in `b`), over those of `a` that separated before `until_s` (s): `(how many,
/// the largest onset difference s, the largest peak difference relative to a's)`. Panics
/// when `b` lacks a body's impact that `a` has.
pub fn impacts_apart(
    a: &BTreeMap<String, Vec<Impact>>,
    b: &BTreeMap<String, Vec<Impact>>,
    until_s: f64,
) -> (usize, f64, f64) {
    let (mut n, mut onset_s, mut peak) = (0, 0.0f64, 0.0f64);
    for (body, list) in a {
        let other = b
            .get(body)
            .unwrap_or_else(|| panic!("{body}: no impacts in the other run"));
        for (i, e) in list.iter().enumerate().filter(|(_, e)| e.t_off_s < until_s) {
            let o = other
                .get(i)
                .unwrap_or_else(|| panic!("{body}: impact {i} missing in the other run"));
            onset_s = onset_s.max((o.t_on_s - e.t_on_s).abs());
            peak = peak.max(((o.peak_n - e.peak_n) / e.peak_n).abs());
            n += 1;
        }
    }
    (n, onset_s, peak)
}
