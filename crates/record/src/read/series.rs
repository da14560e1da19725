//! What a recording holds, as series and model types: per-disc and per-interface series, the
//! load histories `plot` and `compare` use, the impacts, the samples, and the summary
//! recomputed from the impacts when the file has none.

use super::RecordingReader;
use crate::proto;
use crate::summary::RecordedSummary;
use crate::topics;
use clutchpack_model::{DiscSample, Flank, ImpactEvent, Sample};
use prost::Message as _;
use std::collections::BTreeMap;

/// One disc's recorded spline states (`/discs/<name>/spline`), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscSeries {
    /// Disc name.
    pub name: String,
    /// Topic segment (`/discs/<segment>/spline`).
    pub segment: String,
    /// Index of the disc in the scene.
    pub index: usize,
    /// The decoded messages.
    pub states: Vec<proto::SplineState>,
    /// Per-tooth loads, if they were recorded.
    pub teeth: Vec<proto::ToothLoads>,
}

/// One friction interface's recorded states (`/interfaces/<segment>`), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceSeries {
    /// The body below the interface (channel metadata `lower`).
    pub lower: String,
    /// The body above it (channel metadata `upper`).
    pub upper: String,
    /// Topic segment (`/interfaces/<segment>`).
    pub segment: String,
    /// Index of the interface along the stack.
    pub index: usize,
    /// The decoded messages.
    pub states: Vec<proto::InterfaceState>,
}

/// One disc's per-tooth load history: what `plot` draws and `compare` needs.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadHistory {
    /// Disc name.
    pub name: String,
    /// Sample times in s.
    pub t_s: Vec<f64>,
    /// Per-tooth load in N at each time (negative when the shaft leads).
    pub load_n: Vec<f64>,
}

impl RecordingReader {
    /// What each friction interface did over the recorded run ([`InterfaceStats`]), in
    /// stack order; named `<lower>__<upper>`. Streams: no state is kept, only the statistics.
    ///
    /// [`InterfaceStats`]: clutchpack_analysis::InterfaceStats
    pub fn interface_stats(&self) -> Vec<clutchpack_analysis::InterfaceStats> {
        let mut by_topic: BTreeMap<&str, (usize, clutchpack_analysis::InterfaceStats)> = self
            .interface_topics()
            .into_iter()
            .map(|(topic, f)| {
                let name = crate::FrictionInterface {
                    lower: f.lower,
                    upper: f.upper,
                }
                .name();
                (
                    topic,
                    (f.index, clutchpack_analysis::InterfaceStats::new(name)),
                )
            })
            .collect();
        if by_topic.is_empty() {
            return Vec::new();
        }
        self.for_each_message(|v| {
            if v.schema_name == proto::INTERFACE_STATE {
                if let (Some((_, st)), Ok(m)) = (
                    by_topic.get_mut(v.topic),
                    proto::InterfaceState::decode(v.data),
                ) {
                    st.update(m.t_s, &m.to_sample());
                }
            }
        });
        let mut out: Vec<(usize, clutchpack_analysis::InterfaceStats)> =
            by_topic.into_values().collect();
        out.sort_by_key(|(i, _)| *i);
        out.into_iter().map(|(_, st)| st).collect()
    }

    /// The friction interface topics (by topic name) with their series, states empty.
    fn interface_topics(&self) -> BTreeMap<&str, InterfaceSeries> {
        let mut by_topic = BTreeMap::new();
        for t in &self.info.topics {
            if t.schema_name == proto::INTERFACE_STATE {
                let meta = |k: &str| t.metadata.get(k).cloned().unwrap_or_default();
                let segment = t
                    .topic
                    .strip_prefix(topics::INTERFACES_PREFIX)
                    .unwrap_or(&t.topic)
                    .to_string();
                by_topic.insert(
                    t.topic.as_str(),
                    InterfaceSeries {
                        lower: meta("lower"),
                        upper: meta("upper"),
                        segment,
                        index: meta("interface_index").parse().unwrap_or(usize::MAX),
                        states: Vec::new(),
                    },
                );
            }
        }
        by_topic
    }

    /// The shaft states (`/shaft`) in file order. Holds them all (one per sample): for
    /// commands that need the whole history; [`RecordingReader::for_each_message`] streams.
    pub fn shaft_states(&self) -> Vec<proto::ShaftState> {
        let mut out = Vec::new();
        self.for_each_message(|v| {
            if v.schema_name == proto::SHAFT_STATE {
                if let Ok(m) = proto::ShaftState::decode(v.data) {
                    out.push(m);
                }
            }
        });
        out
    }

    /// Every friction interface's states, in stack order (empty for a pack without a stack).
    /// Holds every state in memory (one pass over the file).
    pub fn interface_series(&self) -> Vec<InterfaceSeries> {
        let mut by_topic = self.interface_topics();
        if by_topic.is_empty() {
            return Vec::new();
        }
        self.for_each_message(|v| {
            if v.schema_name == proto::INTERFACE_STATE {
                if let (Some(series), Ok(m)) = (
                    by_topic.get_mut(v.topic),
                    proto::InterfaceState::decode(v.data),
                ) {
                    series.states.push(m);
                }
            }
        });
        let mut out: Vec<InterfaceSeries> = by_topic.into_values().collect();
        out.sort_by_key(|s| s.index);
        out
    }

    /// Every disc's spline states (and per-tooth loads when recorded), in disc-index order.
    /// Holds them all (one per disc and sample): for commands that need the whole history
    /// (`plot`); [`RecordingReader::for_each_message`] streams.
    pub fn disc_series(&self) -> Vec<DiscSeries> {
        let names = self.disc_names();
        let mut by_index: BTreeMap<u32, DiscSeries> = BTreeMap::new();
        fn get<'m>(
            by_index: &'m mut BTreeMap<u32, DiscSeries>,
            names: &[String],
            i: u32,
            topic: &str,
        ) -> &'m mut DiscSeries {
            by_index.entry(i).or_insert_with(|| DiscSeries {
                name: names
                    .get(i as usize)
                    .cloned()
                    .unwrap_or_else(|| segment_of(topic).to_string()),
                segment: segment_of(topic).to_string(),
                index: i as usize,
                states: Vec::new(),
                teeth: Vec::new(),
            })
        }
        self.for_each_message(|v| match v.schema_name {
            proto::SPLINE_STATE => {
                if let Ok(m) = proto::SplineState::decode(v.data) {
                    get(&mut by_index, &names, m.disc_index, v.topic)
                        .states
                        .push(m);
                }
            }
            proto::TOOTH_LOADS => {
                if let Ok(m) = proto::ToothLoads::decode(v.data) {
                    get(&mut by_index, &names, m.disc_index, v.topic)
                        .teeth
                        .push(m);
                }
            }
            _ => {}
        });
        by_index.into_values().collect()
    }

    /// Each disc's dense load series (`/discs/<name>/load`: the samples' loads and, in
    /// between, the contact samples', in file order, which is time order), indexed by disc
    /// index (empty for a disc without the topic, e.g. a recording made without contact
    /// samples). [`Self::samples`] and [`Self::load_histories`] do not include them.
    pub fn dense_loads(&self) -> Vec<Vec<proto::LoadSample>> {
        self.by_index(proto::LOAD_SAMPLE, |m: &proto::LoadSample| m.disc_index)
    }

    /// The messages of schema `schema` (decoded as `M`), grouped by the index `index` gives
    /// each (a disc's or a body's), each group in file order.
    fn by_index<M: prost::Message + Default>(
        &self,
        schema: &str,
        index: impl Fn(&M) -> u32,
    ) -> Vec<Vec<M>> {
        let mut out: Vec<Vec<M>> = Vec::new();
        self.for_each_message(|v| {
            if v.schema_name == schema {
                if let Ok(m) = M::decode(v.data) {
                    let i = index(&m) as usize;
                    if out.len() <= i {
                        out.resize_with(i + 1, Vec::new);
                    }
                    out[i].push(m);
                }
            }
        });
        out
    }

    /// A thermal run's temperatures (`/discs/<name>/temperature` and `/oil/temperature`),
    /// indexed by body index (the discs, then the plates; the oil last, at the number of
    /// bodies), each in file order, which is time order; empty for an isothermal recording.
    pub fn temperatures(&self) -> Vec<Vec<proto::Temperature>> {
        self.by_index(proto::TEMPERATURE, |m: &proto::Temperature| m.body_index)
    }

    /// Each disc's per-tooth load history (t in s, load in N), in disc-index order: what
    /// `plot` draws, so every sample of every disc is held.
    pub fn load_histories(&self) -> Vec<LoadHistory> {
        self.disc_series()
            .into_iter()
            .map(|d| LoadHistory {
                name: d.name,
                t_s: d.states.iter().map(|s| s.t_s).collect(),
                load_n: d.states.iter().map(|s| s.load_n).collect(),
            })
            .collect()
    }

    /// The impact events (`/impacts`) in file order (the order they closed). Holds them all
    /// (a few tens of bytes each: about 2000 per simulated second of a rattling 4-disc pack).
    pub fn impacts(&self) -> Vec<ImpactEvent> {
        let mut out = Vec::new();
        self.for_each_message(|v| {
            // `/discs/<segment>/impacts` repeat these per disc for plots
            if v.schema_name == proto::IMPACT && v.topic == topics::IMPACTS {
                if let Ok(m) = proto::Impact::decode(v.data) {
                    out.push(impact_event(&m));
                }
            }
        });
        out
    }

    /// The stored summary, or (for a run that did not finish) the summary of the recovered
    /// impacts up to the last recovered message.
    pub fn summary_or_recomputed(&self) -> RecordedSummary {
        if let Some(s) = self.summary() {
            return s.clone();
        }
        RecordedSummary::from_impacts(
            &self.disc_names(),
            &self.impacts(),
            self.info.end_s.unwrap_or(0.0),
        )
    }

    /// The samples, rebuilt from `/shaft` and the disc topics (the k-th message of each makes
    /// the k-th sample). A sample only partly recovered (cut by a truncation) is left out;
    /// `tooth_loads_n` is empty unless per-tooth loads were recorded. Holds every sample
    /// (`plot --spectrum` replays them through the fatigue collector).
    pub fn samples(&self) -> Vec<Sample> {
        let shaft = self.shaft_states();
        let discs = self.disc_series();
        let mut out = Vec::with_capacity(shaft.len());
        let mut tooth_cursor = vec![0usize; discs.len()];
        'samples: for (k, sh) in shaft.iter().enumerate() {
            let mut sample = Sample {
                t_s: sh.t_s,
                shaft_angle_rad: sh.angle_rad,
                shaft_speed_rad_s: sh.speed_rad_s,
                discs: Vec::with_capacity(discs.len()),
            };
            for (d, c) in discs.iter().zip(tooth_cursor.iter_mut()) {
                let Some(s) = d.states.get(k) else {
                    break 'samples;
                };
                if s.t_s != sh.t_s {
                    break 'samples;
                }
                while d.teeth.get(*c).is_some_and(|t| t.t_s < sh.t_s) {
                    *c += 1;
                }
                let tooth_loads_n = match d.teeth.get(*c) {
                    Some(t) if t.t_s == sh.t_s => t.loads_n.clone(),
                    _ => Vec::new(),
                };
                sample.discs.push(DiscSample {
                    angle_rad: s.angle_rad,
                    speed_rad_s: s.speed_rad_s,
                    rel_angle_rad: s.rel_angle_rad,
                    penetration_m: s.penetration_m,
                    closing_speed_m_s: s.closing_speed_m_s,
                    load_n: s.load_n,
                    torque_n_m: s.torque_n_m,
                    engaged: s.engaged,
                    stiffness: s.stiffness_n_m1_5,
                    tooth_loads_n,
                    center_offset_m: [0.0, 0.0],
                });
            }
            out.push(sample);
        }
        out
    }
}

/// An `/impacts` message as the model's impact event.
pub(crate) fn impact_event(m: &proto::Impact) -> ImpactEvent {
    ImpactEvent {
        disc: m.disc_index as usize,
        t_on_s: m.t_on_s,
        t_peak_s: m.t_peak_s,
        t_off_s: m.t_off_s,
        flank: match proto::Flank::try_from(m.flank) {
            Ok(proto::Flank::DiscLeads) => Flank::DiscLeads,
            Ok(proto::Flank::ShaftLeads) => Flank::ShaftLeads,
            // unset: the sign of the load says it (eq (6))
            _ => {
                if m.peak_n > 0.0 {
                    Flank::DiscLeads
                } else {
                    Flank::ShaftLeads
                }
            }
        },
        v_on_m_s: m.v_on_m_s,
        peak_n: m.peak_n,
    }
}

/// The `<segment>` of `/discs/<segment>/...`.
pub(crate) fn segment_of(topic: &str) -> &str {
    let rest = topic.strip_prefix(topics::DISCS_PREFIX).unwrap_or(topic);
    rest.split('/').next().unwrap_or(rest)
}
