//! The gear meshes' contact events on a network run (MODEL.md section 8): the onset, where
//! the tooth law's per-event memory is taken (as the pack engine does at a spline contact),
//! the peak of the force located by golden-section search on the dense output of the step
//! that holds it, and the separation, which closes a [`clutchpack_model::ImpactEvent`] (the spline's type:
//! the same statistics and fatigue apply).

use super::{mesh_kinematics, Equations};
use crate::dopri::Dense;
use crate::stepper::golden_peak;
use clutchpack_model::ImpactTracker;
use clutchpack_model::Observer;

/// Samples of the force per step in contact, beside the step's end, before the refinement.
const PROBES: usize = 16;

/// Every mesh's open contact event and the step holding its largest force so far.
#[derive(Clone)]
pub(super) struct Meshes {
    trackers: Vec<ImpactTracker>,
    /// Per coupling: the dense output of the step with the largest |F| so far, and where.
    best: Vec<Option<(Dense, f64, f64)>>,
    ybuf: Vec<f64>,
}

impl Meshes {
    pub fn new(couplings: usize, dim: usize) -> Meshes {
        Meshes {
            trackers: (0..couplings).map(ImpactTracker::new).collect(),
            best: vec![None; couplings],
            ybuf: vec![0.0; dim],
        }
    }

    /// The force on `k`'s flank at `t` on `dense`, as the event's peak is signed (eq 6:
    /// negative when body `a` leads, `x > 0`).
    fn load(eq: &mut Equations, k: usize, dense: &Dense, t: f64, ybuf: &mut [f64]) -> f64 {
        let g = eq.net.couplings[k].mesh().expect("a mesh");
        let Some(e) = eq.contacts[k] else { return 0.0 };
        dense.eval(t, ybuf);
        -g.force_n(&mesh_kinematics(&eq.net, k, g, ybuf), &e)
    }

    /// Every mesh's open contact as it would close at `t` (`(coupling, None, event)`, its
    /// peak the largest located so far), appended to `out`.
    pub fn open(
        &self,
        t: f64,
        out: &mut Vec<(usize, Option<usize>, clutchpack_model::ImpactEvent)>,
    ) {
        for (k, tracker) in self.trackers.iter().enumerate() {
            let probe = self.best[k].as_ref().map(|b| (b.1, b.2));
            out.extend(tracker.peek_with(t, probe).map(|e| (k, None, e)));
        }
    }

    /// Observes the meshes in contact over the accepted step `[t0, t1]` of `dense`.
    pub fn observe(&mut self, eq: &mut Equations, dense: &Dense, t0: f64, t1: f64) {
        for k in 0..self.trackers.len() {
            if eq.contacts[k].is_none() {
                continue;
            }
            let mut top: Option<(f64, f64)> = None;
            for j in 1..=PROBES {
                let t = t0 + (t1 - t0) * j as f64 / PROBES as f64;
                let f = Self::load(eq, k, dense, t, &mut self.ybuf);
                if top.is_none_or(|(_, b)| f.abs() > b) {
                    top = Some((t, f.abs()));
                }
            }
            let (t, f) = top.expect("probes");
            let prior = self.best[k].as_ref().map_or(-1.0, |b| b.2);
            if f > prior {
                self.best[k] = Some((dense.clone(), t, f));
            }
        }
    }

    /// Opens and closes contact events at an event at `t` (`crossed[k] <= 0`: `k`'s guard
    /// crossed; `None`: every mesh checked, as at t = 0): an onset takes the law's memory, a
    /// separation refines the peak and sends the impact.
    pub fn switch(
        &mut self,
        eq: &mut Equations,
        t: f64,
        y: &[f64],
        crossed: Option<&[f64]>,
        obs: &mut dyn Observer,
    ) {
        for k in 0..self.trackers.len() {
            let Some(g) = eq.net.couplings[k].mesh() else {
                continue;
            };
            if crossed.is_some_and(|c| c[k] > 0.0) {
                continue;
            }
            let kin = mesh_kinematics(&eq.net, k, g, y);
            let inside = g.law.engagement_depth_m(&kin) > 0.0;
            match (eq.contacts[k], inside) {
                (None, true) => {
                    eq.contacts[k] = Some(g.law.engage(&kin));
                    self.trackers[k].begin(t, kin.flank, kin.v_n_m_s);
                    self.best[k] = None;
                }
                (Some(_), false) => {
                    self.close(eq, k, t, obs);
                    eq.contacts[k] = None;
                }
                _ => {}
            }
        }
    }

    /// Closes `k`'s open event at `t`: its peak refined on the best step's dense output.
    fn close(&mut self, eq: &mut Equations, k: usize, t: f64, obs: &mut dyn Observer) {
        if let Some((dense, tb, _)) = self.best[k].take() {
            let span = dense.h / PROBES as f64;
            let (a, b) = (
                (tb - span).max(dense.t0),
                (tb + span).min(dense.t0 + dense.h),
            );
            let ybuf = &mut self.ybuf;
            let (tp, fp) = golden_peak(a, b, |tt| Self::load(eq, k, &dense, tt, ybuf));
            self.trackers[k].observe(tp, fp);
        }
        if let Some(e) = self.trackers[k].end(t) {
            obs.mesh_impact(&e);
        }
    }

    /// Closes every open event at the end of the run (`t_off` the end).
    pub fn finish(&mut self, eq: &mut Equations, t: f64, obs: &mut dyn Observer) {
        for k in 0..self.trackers.len() {
            if eq.contacts[k].is_some() {
                self.close(eq, k, t, obs);
            }
        }
    }
}
