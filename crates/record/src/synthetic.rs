//! A small synthetic run for tests, examples and the independent-reader check: two discs
//! whose per-tooth loads are half-sine pulses of alternating sign, with the impacts detected
//! from them by [`clutchpack_model::detect_impacts`]. No engine is involved.

use crate::info::{DiscGeometry, FrictionInterface, RunInfo};
use clutchpack_model::{detect_impacts, DiscSample, ImpactEvent, InterfaceSample, Sample};
use std::f64::consts::PI;

/// Samples and impacts of a synthetic run.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticRun {
    /// The run description (engine `synthetic`, a two-line scene text).
    pub info: RunInfo,
    /// The samples, every `dt_s`.
    pub samples: Vec<Sample>,
    /// The impacts of both discs, ordered by their separation time.
    pub impacts: Vec<ImpactEvent>,
    /// The one friction interface (between the two discs) at each sample's time (s).
    pub interfaces: Vec<(f64, Vec<InterfaceSample>)>,
}

/// Teeth per disc in the synthetic run.
pub const TEETH: usize = 6;

/// `n` samples every `dt_s` seconds (s) of two discs named `d1` and `disc 2` (a name that
/// needs a topic-safe segment). Disc `i`'s load is a train of half-sine pulses of 0.6 ms
/// every 1.5 ms, of peak `(500 + 100 i) N`, alternating in sign, and its teeth share it
/// unevenly (`load (1 + 0.05 k)` for tooth `k`). One friction interface joins the two discs:
/// its clamp force ramps up at 1 MN/s, it slips at the discs' speed difference with
/// `mu = 0.12` and locks from 2 ms on.
pub fn synthetic_run(n: usize, dt_s: f64) -> SyntheticRun {
    let names = ["d1", "disc 2"];
    let info = RunInfo {
        program_version: env!("CARGO_PKG_VERSION").into(),
        engine: "synthetic".into(),
        scene_name: "synthetic".into(),
        scene_file: "synthetic.toml".into(),
        scene_text: "# synthetic two-disc pack\nname = \"synthetic\"\n".into(),
        overrides: vec!["discs.d1.backlash_m=50e-6".into()],
        solver: [("dt_s".to_string(), format!("{dt_s:?}"))].into(),
        params: [("samples".to_string(), n.to_string())].into(),
        shaft: None,
        discs: names
            .iter()
            .enumerate()
            .map(|(i, name)| DiscGeometry {
                name: name.to_string(),
                inner_radius_m: 0.03,
                outer_radius_m: 0.06,
                thickness_m: 0.002,
                z_m: 0.004 * i as f64,
                teeth: 24,
                teeth_outside: false,
            })
            .collect(),
        interfaces: vec![FrictionInterface {
            lower: names[0].into(),
            upper: names[1].into(),
        }],
    };
    let (period, width) = (1.5e-3, 0.6e-3);
    let load = |i: usize, t: f64| -> f64 {
        let k = (t / period).floor();
        let tau = t - k * period - 0.2e-3 * i as f64;
        if (0.0..width).contains(&tau) {
            let sign = if (k as i64 + i as i64) % 2 == 0 {
                -1.0
            } else {
                1.0
            };
            sign * (500.0 + 100.0 * i as f64) * (PI * tau / width).sin()
        } else {
            0.0
        }
    };
    let mut samples = Vec::with_capacity(n);
    for s in 0..n {
        let t = s as f64 * dt_s;
        let shaft_angle = 100.0 * t;
        let discs = (0..names.len())
            .map(|i| {
                let f = load(i, t);
                let phi = 1e-3 * (2.0 * PI * t / period + i as f64).sin();
                DiscSample {
                    angle_rad: shaft_angle - phi,
                    speed_rad_s: 100.0 - 1e-3 * 2.0 * PI / period * (2.0 * PI * t / period).cos(),
                    rel_angle_rad: phi,
                    penetration_m: if f != 0.0 {
                        1e-6 * (f / 600.0).abs()
                    } else {
                        -2e-6
                    },
                    closing_speed_m_s: 0.05 * (2.0 * PI * t / period).cos(),
                    load_n: f,
                    torque_n_m: -(TEETH as f64) * f * 0.028,
                    engaged: f != 0.0,
                    stiffness: if f != 0.0 { 3e9 } else { 0.0 },
                    tooth_loads_n: (0..TEETH).map(|k| f * (1.0 + 0.05 * k as f64)).collect(),
                    center_offset_m: [0.0, 0.0],
                }
            })
            .collect();
        samples.push(Sample {
            t_s: t,
            shaft_angle_rad: shaft_angle,
            shaft_speed_rad_s: 100.0,
            discs,
        });
    }
    let mut heat_j = 0.0;
    let interfaces = samples
        .iter()
        .map(|s| {
            let locked = s.t_s >= 2e-3;
            let slip = if locked {
                0.0
            } else {
                s.discs[1].speed_rad_s - s.discs[0].speed_rad_s
            };
            let (r_eff, clamp_n) = (0.045, 1e6 * s.t_s);
            let mu = if locked { 0.0 } else { 0.12 };
            let torque_n_m = -mu * clamp_n * r_eff * slip.signum();
            heat_j -= torque_n_m * slip * dt_s;
            let f = InterfaceSample {
                slip_rad_s: slip,
                slip_m_s: slip * r_eff,
                mu,
                clamp_n,
                torque_n_m,
                locked,
                dissipated_j: heat_j,
            };
            (s.t_s, vec![f])
        })
        .collect();
    let mut impacts = Vec::new();
    for i in 0..names.len() {
        let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
        let f: Vec<f64> = samples.iter().map(|s| s.discs[i].load_n).collect();
        let v: Vec<f64> = samples
            .iter()
            .map(|s| s.discs[i].closing_speed_m_s)
            .collect();
        impacts.extend(detect_impacts(i, &t, &f, &v));
    }
    impacts.sort_by(|a, b| a.t_off_s.total_cmp(&b.t_off_s).then(a.disc.cmp(&b.disc)));
    SyntheticRun {
        info,
        samples,
        impacts,
        interfaces,
    }
}

impl SyntheticRun {
    /// Feeds the run to `observer` in time order: each sample and its interfaces, then the
    /// impacts that closed at or before it.
    pub fn play(&self, observer: &mut dyn clutchpack_model::Observer) {
        let mut next = 0;
        for (s, (t, f)) in self.samples.iter().zip(&self.interfaces) {
            observer.sample(s);
            observer.interfaces(*t, f);
            while next < self.impacts.len() && self.impacts[next].t_off_s <= s.t_s {
                observer.impact(&self.impacts[next]);
                next += 1;
            }
        }
        for e in &self.impacts[next..] {
            observer.impact(e);
        }
    }
}
