//! Consistency checks of an engine's output stream that hold for every engine and scheme,
//! shared by the engines' tests so that each is written once: the time order of each disc's
//! samples and contact samples ([`OrderedCollector`]), the agreement of the contact samples
//! with the located impact peaks ([`check_contact_samples`]), each friction interface's
//! first lock and heat ([`first_lock_s`], [`heat_j`]), and the period and decrement of a
//! free oscillation ([`free_oscillation`], the spring-damper's closed-form tests).

use crate::clutch::InterfaceSample;
use crate::impact::ImpactEvent;
use crate::stream::{Collector, DiscSample, Observer, Sample};

/// A [`Collector`] that also notes every time a disc's samples and contact samples, taken
/// together, go back in time (engines send each disc's stream in non-decreasing time order).
#[derive(Debug, Default)]
pub struct OrderedCollector {
    /// Everything the engine sent.
    pub collector: Collector,
    /// Each disc's latest time so far, s.
    last_s: Vec<f64>,
    /// One line per event that came before its disc's previous one.
    pub out_of_order: Vec<String>,
}

impl OrderedCollector {
    fn at(&mut self, disc: usize, t_s: f64, what: &str) {
        if self.last_s.len() <= disc {
            self.last_s.resize(disc + 1, f64::NEG_INFINITY);
        }
        if t_s < self.last_s[disc] {
            self.out_of_order.push(format!(
                "disc {disc}: {what} at {t_s} s after {} s",
                self.last_s[disc]
            ));
        }
        self.last_s[disc] = t_s;
    }
}

impl Observer for OrderedCollector {
    fn sample(&mut self, s: &Sample) {
        for d in 0..s.discs.len() {
            self.at(d, s.t_s, "sample");
        }
        self.collector.sample(s);
    }
    fn impact(&mut self, e: &ImpactEvent) {
        self.collector.impact(e);
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.collector.interfaces(t_s, interfaces);
    }
    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        self.at(disc, t_s, "contact sample");
        self.collector.contact_sample(disc, t_s, state);
    }
    fn wants_contact_samples(&self) -> bool {
        true
    }
}

/// How well a run's contact samples resolve its impacts ([`check_contact_samples`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSampleFit {
    /// Largest relative shortfall of an impact's largest contact-sample `|load|` below its
    /// located `|peak|` (dimensionless, >= 0).
    pub worst_shortfall: f64,
    /// Mean number of contact samples per impact.
    pub points_per_contact: f64,
}

/// Checks the contact samples of `c` (discs `0..discs`) against its impacts: each disc's
/// contact samples in time order; within each impact's contact window, the largest `|load|`
/// has the peak's sign, is at most the located `|peak|` (it is the maximum of the same
/// trajectory; 1e-9 relative for rounding) and at most `tolerance` (relative) below it; every
/// contact sample lies inside a contact window of its disc. The first violation is the error.
pub fn check_contact_samples(
    c: &Collector,
    discs: usize,
    tolerance: f64,
) -> Result<ContactSampleFit, String> {
    if c.impacts.is_empty() {
        return Err("no impacts".into());
    }
    for d in 0..discs {
        let mut ts = c.contacts.iter().filter(|(i, _, _)| *i == d).map(|x| x.1);
        let mut prev = f64::NEG_INFINITY;
        if ts.any(|t| {
            let back = t < prev;
            prev = t;
            back
        }) {
            return Err(format!("disc {d}'s contact samples are out of time order"));
        }
    }
    let mut worst: f64 = 0.0;
    let mut points = 0usize;
    for e in &c.impacts {
        let inside = c
            .contacts
            .iter()
            .filter(|(i, t, _)| *i == e.disc && *t >= e.t_on_s && *t <= e.t_off_s);
        let (n, max) = inside.fold((0usize, 0.0_f64), |(n, m), (_, _, s)| {
            let f = s.load_n;
            (n + 1, if f.abs() > m.abs() { f } else { m })
        });
        points += n;
        let short = (e.peak_n.abs() - max.abs()) / e.peak_n.abs();
        if short > tolerance || max.signum() != e.peak_n.signum() {
            return Err(format!(
                "impact at {:.6} s of disc {}: largest contact-sample load {max} N, located peak \
                 {} N ({n} points)",
                e.t_peak_s, e.disc, e.peak_n
            ));
        }
        if max.abs() > e.peak_n.abs() * (1.0 + 1e-9) {
            return Err(format!(
                "impact at {:.6} s of disc {}: contact-sample load {max} N above the located \
                 peak {} N",
                e.t_peak_s, e.disc, e.peak_n
            ));
        }
        worst = worst.max(short);
    }
    for (d, t, s) in &c.contacts {
        let inside = c
            .impacts
            .iter()
            .any(|e| e.disc == *d && *t >= e.t_on_s && *t <= e.t_off_s);
        if !inside {
            return Err(format!(
                "disc {d}'s contact sample at {t} s ({} N) is in no contact window",
                s.load_n
            ));
        }
    }
    Ok(ContactSampleFit {
        worst_shortfall: worst,
        points_per_contact: points as f64 / c.impacts.len() as f64,
    })
}

/// The time of the first sample in which interface `m` is locked, s (`None`: it never is).
pub fn first_lock_s(c: &Collector, m: usize) -> Option<f64> {
    c.interfaces
        .iter()
        .find(|(_, f)| f[m].locked)
        .map(|(t, _)| *t)
}

/// The heat interface `m` had dissipated by the last sample, J (0 without samples).
pub fn heat_j(c: &Collector, m: usize) -> f64 {
    c.interfaces.last().map_or(0.0, |(_, f)| f[m].dissipated_j)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn impact(disc: usize, t_on_s: f64, t_peak_s: f64, t_off_s: f64, peak_n: f64) -> ImpactEvent {
        ImpactEvent {
            disc,
            t_on_s,
            t_peak_s,
            t_off_s,
            flank: crate::spline::Flank::ShaftLeads,
            v_on_m_s: 1.0,
            peak_n,
        }
    }

    fn point(disc: usize, t_s: f64, load_n: f64) -> (usize, f64, DiscSample) {
        (
            disc,
            t_s,
            DiscSample {
                load_n,
                ..DiscSample::default()
            },
        )
    }

    /// A contact resolved to 1 % passes a 2 % tolerance and fails a 0.5 % one; a point
    /// outside every window, a point above the peak, a wrong sign and points out of order are
    /// each caught.
    #[test]
    fn contact_sample_check_catches_each_violation() {
        let mut c = Collector {
            impacts: vec![impact(0, 1.0, 1.5, 2.0, -100.0)],
            contacts: vec![point(0, 1.0, 0.0), point(0, 1.5, -99.0), point(0, 2.0, 0.0)],
            ..Collector::default()
        };
        let fit = check_contact_samples(&c, 1, 0.02).unwrap();
        assert!((fit.worst_shortfall - 0.01).abs() < 1e-12);
        assert_eq!(fit.points_per_contact, 3.0);
        assert!(check_contact_samples(&c, 1, 0.005).is_err());
        let mut outside = c.clone();
        outside.contacts.push(point(0, 2.5, -1.0));
        assert!(check_contact_samples(&outside, 1, 0.02).is_err());
        let mut above = c.clone();
        above.contacts[1].2.load_n = -100.1;
        assert!(check_contact_samples(&above, 1, 0.02).is_err());
        let mut sign = c.clone();
        sign.contacts[1].2.load_n = 99.5;
        assert!(check_contact_samples(&sign, 1, 0.02).is_err());
        c.contacts.swap(0, 2);
        assert!(check_contact_samples(&c, 1, 0.02)
            .unwrap_err()
            .contains("out of time order"));
    }

    #[test]
    fn ordered_collector_notes_a_step_back() {
        let mut o = OrderedCollector::default();
        o.contact_sample(0, 1.0, &DiscSample::default());
        o.contact_sample(1, 0.5, &DiscSample::default());
        assert!(o.out_of_order.is_empty());
        o.contact_sample(0, 0.9, &DiscSample::default());
        assert_eq!(o.out_of_order.len(), 1);
        assert_eq!(o.collector.contacts.len(), 3);
    }
}

/// The period and decay of a free oscillation about 0 (a spring-damper's twist less its free
/// angle), sampled as `(t_s, x)` in time order: the mean period, s (between the first and the
/// last upward zero crossing, each interpolated linearly between its two samples) and the
/// mean logarithmic decrement (dimensionless: `ln(x_i / x_{i+1})` over successive maxima,
/// each the vertex of the parabola through the largest sample and its two neighbours);
/// `None` with fewer than two crossings or maxima.
pub fn free_oscillation(samples: &[(f64, f64)]) -> Option<(f64, f64)> {
    let mut ups = Vec::new();
    let mut peaks = Vec::new();
    for w in samples.windows(3) {
        let [(t0, x0), (t1, x1), (_, x2)] = [w[0], w[1], w[2]];
        if x0 < 0.0 && x1 >= 0.0 {
            ups.push(t0 + (t1 - t0) * (-x0) / (x1 - x0));
        }
        if x1 > 0.0 && x1 > x0 && x1 >= x2 {
            // vertex of the parabola through three equally spaced samples
            let (a, b) = (0.5 * (x0 + x2) - x1, 0.5 * (x2 - x0));
            peaks.push(x1 - b * b / (4.0 * a));
        }
    }
    if ups.len() < 2 || peaks.len() < 2 {
        return None;
    }
    let period = (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64;
    let decrement = (peaks[0] / peaks[peaks.len() - 1]).ln() / (peaks.len() - 1) as f64;
    Some((period, decrement))
}

#[cfg(test)]
mod oscillation_tests {
    /// A sampled damped cosine gives back its period and decrement.
    #[test]
    fn free_oscillation_of_a_damped_cosine() {
        let (wd, delta) = (2.0 * std::f64::consts::PI * 5.0, 0.1);
        let sigma = delta * wd / (2.0 * std::f64::consts::PI);
        let x: Vec<(f64, f64)> = (0..20_000)
            .map(|k| {
                let t = k as f64 * 1e-4;
                (t, (-sigma * t).exp() * (wd * t).cos())
            })
            .collect();
        let (p, d) = super::free_oscillation(&x).unwrap();
        assert!((p - 0.2).abs() < 1e-6, "{p}");
        assert!((d - delta).abs() < 1e-4, "{d}");
    }
}
