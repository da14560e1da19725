//! Reading a network recording back ([`crate::Recorder::create_network_output`]'s file) into the samples the
//! engine gave: every body's angle and speed, every coupling's torque and a clutch's mode.

use crate::network::{META_NETWORK, SUMMARY_ATTACHMENT};
use crate::{proto, topics};
use clutchpack_model::network::{ClutchMode, NetworkSample};
use foxglove::schemas::Log;
use std::collections::BTreeMap;

/// What a network recording holds, read back ([`read_network`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedNetwork {
    /// The bodies' names, in scene order.
    pub bodies: Vec<String>,
    /// Whether each body is fixed (the housing), in scene order.
    pub fixed: Vec<bool>,
    /// The couplings' names, in scene order.
    pub couplings: Vec<String>,
    /// Every sample, in time order, as the engine gave it (a clutch's mode from its label;
    /// other couplings' `None`).
    pub samples: Vec<NetworkSample>,
    /// Every tooth impact on `/network/impacts` with its name: a gear mesh's its coupling's,
    /// a pack's disc's or plate's `<pack>/discs/<disc>` or `<pack>/plates/<plate>`
    /// ([`crate::impact_name`]); in file order (their contacts' closing); then the
    /// [`Self::open_contacts`] last.
    pub impacts: Vec<(String, clutchpack_model::ImpactEvent)>,
    /// How many of [`Self::impacts`], the last, are contacts still open where the file ends
    /// (a run killed while they lasted): each as `/network/contacts` last logged it, closed
    /// then (its peak so far), as a run stopped there would have closed it. 0 in a finished
    /// recording (its run closed every contact at its end).
    pub open_contacts: usize,
    /// The clutch mode changes' log lines (`K2: slip- -> locked at t = ... s`), in file order.
    pub events: Vec<String>,
    /// The attached summary (the JSON of `run --summary-json`), if the run finished.
    pub summary_json: Option<Vec<u8>>,
}

impl RecordedNetwork {
    /// Each impact as `(name, t_peak s, peak N)`, in file order (`run --plot`'s impacts).
    pub fn impact_peaks(&self) -> Vec<(String, f64, f64)> {
        self.impacts
            .iter()
            .map(|(name, e)| (name.clone(), e.t_peak_s, e.peak_n))
            .collect()
    }
}

/// Reads a network recording back into its samples: `None` when `reader`'s file is not one
/// (no `clutchpack.network` metadata). A message that does not decode, or a sample missing a
/// body's or a coupling's message, is an error naming the topic and the time.
pub fn read_network(reader: &crate::RecordingReader) -> Option<Result<RecordedNetwork, String>> {
    use prost::Message as _;
    let info = reader.info();
    let meta = info.metadata(META_NETWORK)?;
    let count = |k: &str| {
        meta.get(k)
            .and_then(|v| v.parse::<usize>().ok())
            .unwrap_or(0)
    };
    let name = |k: String| meta.get(&k).cloned().unwrap_or_default();
    let bodies: Vec<String> = (0..count("bodies"))
        .map(|i| name(format!("body.{i}.name")))
        .collect();
    let fixed: Vec<bool> = (0..bodies.len())
        .map(|i| name(format!("body.{i}.fixed")) == "true")
        .collect();
    let couplings: Vec<String> = (0..count("couplings"))
        .map(|k| name(format!("coupling.{k}.name")))
        .collect();
    let index_of = |topic: &str, key: &str| -> Option<usize> {
        info.topic(topic)?.metadata.get(key)?.parse().ok()
    };
    // samples by log time (ns): each body's and coupling's message fill one sample
    let mut by_time: BTreeMap<u64, NetworkSample> = BTreeMap::new();
    let mut events = Vec::new();
    let mut impacts = Vec::new();
    let mut contacts = Vec::new();
    let mut error: Option<String> = None;
    let (n, m) = (bodies.len(), couplings.len());
    reader.for_each_message(|msg| {
        if error.is_some() {
            return;
        }
        let blank = || NetworkSample {
            t_s: 0.0,
            angle_rad: vec![f64::NAN; n],
            speed_rad_s: vec![f64::NAN; n],
            torque_n_m: vec![f64::NAN; m],
            mode: vec![None; m],
            reaction_n_m: Vec::new(),
        };
        let bad = |e: prost::DecodeError| {
            format!(
                "{} at {} ns: the message does not decode ({e})",
                msg.topic, msg.log_time_ns
            )
        };
        if msg.topic == topics::NETWORK_IMPACTS || msg.topic == topics::NETWORK_CONTACTS {
            let into = if msg.topic == topics::NETWORK_IMPACTS {
                &mut impacts
            } else {
                &mut contacts
            };
            match proto::Impact::decode(msg.data) {
                Ok(i) => into.push((i.disc.clone(), super::series::impact_event(&i))),
                Err(e) => error = Some(bad(e)),
            }
        } else if msg.topic == topics::NETWORK_EVENTS {
            match Log::decode(msg.data) {
                Ok(l) => events.push(l.message),
                Err(e) => error = Some(bad(e)),
            }
        } else if msg.schema_name == proto::SHAFT_STATE {
            let Some(i) = index_of(msg.topic, "body_index").filter(|&i| i < n) else {
                return;
            };
            match proto::ShaftState::decode(msg.data) {
                Ok(b) => {
                    let s = by_time.entry(msg.log_time_ns).or_insert_with(blank);
                    s.t_s = b.t_s;
                    s.angle_rad[i] = b.angle_rad;
                    s.speed_rad_s[i] = b.speed_rad_s;
                }
                Err(e) => error = Some(bad(e)),
            }
        } else if msg.schema_name == proto::COUPLING_STATE {
            match proto::CouplingState::decode(msg.data) {
                Ok(c) if (c.coupling_index as usize) < m => {
                    let k = c.coupling_index as usize;
                    let s = by_time.entry(msg.log_time_ns).or_insert_with(blank);
                    s.t_s = c.t_s;
                    s.torque_n_m[k] = c.torque_n_m;
                    s.mode[k] = match c.mode.as_str() {
                        "free" => Some(ClutchMode::Free),
                        "slip+" => Some(ClutchMode::Slipping(1)),
                        "slip-" => Some(ClutchMode::Slipping(-1)),
                        "locked" => Some(ClutchMode::Locked),
                        _ => None,
                    };
                }
                Ok(_) => {}
                Err(e) => error = Some(bad(e)),
            }
        }
    });
    if let Some(e) = error {
        return Some(Err(e));
    }
    let open_contacts = still_open(&mut impacts, contacts);
    let samples: Vec<NetworkSample> = by_time.into_values().collect();
    if let Some(s) = samples
        .iter()
        .find(|s| s.angle_rad.iter().chain(&s.torque_n_m).any(|x| x.is_nan()))
    {
        return Some(Err(format!(
            "the sample at t = {} s misses a body's or a coupling's message",
            s.t_s
        )));
    }
    let summary_json = info
        .attachments
        .iter()
        .find(|a| a.name == SUMMARY_ATTACHMENT)
        .map(|a| a.data.clone());
    Some(Ok(RecordedNetwork {
        bodies,
        fixed,
        couplings,
        samples,
        impacts,
        open_contacts,
        events,
        summary_json,
    }))
}

/// Appends to `impacts` the logged open `contacts` whose impact never closed in the file
/// (a contact is its name and its onset), each at its last logged state, in the order they
/// opened; returns how many.
fn still_open(
    impacts: &mut Vec<(String, clutchpack_model::ImpactEvent)>,
    contacts: Vec<(String, clutchpack_model::ImpactEvent)>,
) -> usize {
    let key = |(n, e): &(String, clutchpack_model::ImpactEvent)| (n.clone(), e.t_on_s.to_bits());
    let closed: std::collections::HashSet<_> = impacts.iter().map(key).collect();
    let mut open: BTreeMap<(String, u64), clutchpack_model::ImpactEvent> = BTreeMap::new();
    for c in contacts {
        let k = key(&c);
        if !closed.contains(&k) {
            open.insert(k, c.1);
        }
    }
    let mut open: Vec<_> = open.into_iter().map(|((n, _), e)| (n, e)).collect();
    open.sort_by(|a, b| a.1.t_on_s.total_cmp(&b.1.t_on_s));
    let n = open.len();
    impacts.extend(open);
    n
}
