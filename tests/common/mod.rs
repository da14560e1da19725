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

/// The impacts of an `--impacts-csv` (a pack run's, first column `disc`, or a network run's,
/// `name`), by body in the order they closed; a network's `<pack>/discs/<disc>` named by its
/// last part (`<disc>`), as a pack run names it.
pub fn impacts(csv: &Path) -> BTreeMap<String, Vec<Impact>> {
    read_impacts(csv, |name| name.rsplit('/').next().unwrap())
}

/// The impacts of an `--impacts-csv` of a network run, by body name in the order they
/// closed (the whole name: `<pack>/discs/<disc>`, so that two packs' `disc-1` stay apart).
pub fn network_impacts(csv: &Path) -> BTreeMap<String, Vec<Impact>> {
    read_impacts(csv, |name| name)
}

/// The impacts of an `--impacts-csv`, each body named by `body` of its name column.
fn read_impacts(csv: &Path, body: impl Fn(&str) -> &str) -> BTreeMap<String, Vec<Impact>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let name = head
        .iter()
        .position(|h| *h == "name")
        .unwrap_or_else(|| col("disc"));
    let (on, off, peak) = (col("t_on_s"), col("t_off_s"), col("peak_n"));
    let mut out: BTreeMap<String, Vec<Impact>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        out.entry(body(f[name]).to_string())
            .or_default()
            .push(Impact {
                t_on_s: num(on),
                t_off_s: num(off),
                peak_n: num(peak),
            });
    }
    out
}

/// How far apart two runs' impacts are over those closed before a time: how many were
/// compared, the largest onset difference (s) and the largest relative peak difference, one
/// by one on every body, and the bodies whose counts differ `(body, a's, b's)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Apart {
    pub compared: usize,
    pub onset_s: f64,
    pub peak: f64,
    pub counts: Vec<(String, usize, usize)>,
}

/// [`Apart`] of the impacts `a` and `b` closed before `until_s` (s).
pub fn apart(
    a: &BTreeMap<String, Vec<Impact>>,
    b: &BTreeMap<String, Vec<Impact>>,
    until_s: f64,
) -> Apart {
    let mut out = Apart {
        compared: 0,
        onset_s: 0.0,
        peak: 0.0,
        counts: Vec::new(),
    };
    let before = |list: Option<&Vec<Impact>>| -> Vec<Impact> {
        list.map_or(Vec::new(), |l| {
            l.iter().filter(|e| e.t_off_s < until_s).copied().collect()
        })
    };
    let bodies: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    for body in bodies {
        let (x, y) = (before(a.get(body)), before(b.get(body)));
        if x.len() != y.len() {
            out.counts.push((body.clone(), x.len(), y.len()));
        }
        for (p, q) in x.iter().zip(&y) {
            out.compared += 1;
            out.onset_s = out.onset_s.max((p.t_on_s - q.t_on_s).abs());
            out.peak = out.peak.max(((p.peak_n - q.peak_n) / p.peak_n).abs());
        }
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
