//! The 3D view of a network recording (what a user sees of a driveline in Foxglove and
//! Rerun), laid out once from the network:
//! - **The bodies** side by side along x, evenly spaced and centred on the world's origin (where
//!   a viewer's camera looks first), each a disc whose radius says how heavy it is.
//! - **The couplings** as a wiring diagram hanging in front of the bodies: each coupling a lane
//!   of its own below the bodies' plane, joined by drops to each of its ports (two, or three for
//!   a planetary set: sun, ring and carrier), coloured by its mode; its label on its lane,
//!   staggered along x so that neighbouring lanes' labels do not overlap.
//! - **Each planetary set** drawn behind the bodies as a gearset turning at its members' speeds:
//!   the ring, the sun, the carrier and its planets (a double-pinion set's sun and ring planets),
//!   every part in a frame of its own on `/tf`, sized from its tooth counts.
//! - **The automatic's state** (a scene with a `[transmission]`): the engaged gear and the shift
//!   phase as the run makes them, as a line of text over the scene ([`Status`]).
//!
//! For Rerun, which draws point clouds but not scene updates, the couplings and the gearsets
//! are point clouds too.

use crate::view3d::{about_z, annulus_points, cloud, entity, pose, push_point, rgba, v3};
use crate::view3d::{timestamp, WORLD_FRAME};
use clutchpack_model::network::{ClutchMode, CouplingKind, Network, Transmission};
use foxglove::schemas::{
    line_primitive, CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, Point3,
    PointCloud, SceneEntity, SceneUpdate, TextPrimitive,
};
use std::f64::consts::PI;

/// Thickness of the steel disc a body is drawn as, m: its drawn radius is that of a disc of
/// this thickness with the body's inertia (the drawing says how heavy a body is, not its
/// shape), between [`MIN_DRAWN_RADIUS_M`] and [`MAX_DRAWN_RADIUS_M`].
pub(crate) const DRAWN_THICKNESS_M: f64 = 0.02;
/// Smallest drawn radius, m (a fixed body's).
const MIN_DRAWN_RADIUS_M: f64 = 0.05;
/// Largest drawn radius, m (a vehicle reduced to a shaft would be metres wide; more than three
/// times the smallest and the light bodies vanish beside it).
const MAX_DRAWN_RADIUS_M: f64 = 0.16;
/// Steel, kg/m^3.
const STEEL_DENSITY_KG_M3: f64 = 7850.0;
/// Gap between two neighbouring bodies' rims, m.
const BODY_GAP_M: f64 = 0.14;
/// Vertical pitch of the couplings' lanes, m: about 17 px at the scale a 10-body diagram is
/// first shown, more than a label's 12 px.
const LANE_PITCH_M: f64 = 0.13;
/// The drawn ring radius of a planetary set, m.
const SET_RING_M: f64 = 0.2;
/// Planets drawn per set.
const PLANETS: usize = 3;

/// The drawn radius of a body of inertia `j` (kg m^2), m: a steel disc
/// [`DRAWN_THICKNESS_M`] thick, `J = pi rho t r^4 / 2`, clamped.
fn drawn_radius_m(j: f64, fixed: bool) -> f64 {
    if fixed || j.is_nan() || j <= 0.0 {
        return MIN_DRAWN_RADIUS_M;
    }
    (2.0 * j / (PI * STEEL_DENSITY_KG_M3 * DRAWN_THICKNESS_M))
        .powf(0.25)
        .clamp(MIN_DRAWN_RADIUS_M, MAX_DRAWN_RADIUS_M)
}

/// The colour of a coupling: grey for a gear or a spring, and for a clutch by mode (free
/// light grey, slipping orange, locked green).
pub(crate) fn coupling_color(mode: Option<ClutchMode>) -> Option<foxglove::schemas::Color> {
    match mode {
        None => rgba(0.55, 0.58, 0.62, 1.0),
        Some(ClutchMode::Free) => rgba(0.8, 0.8, 0.8, 1.0),
        Some(ClutchMode::Locked) => rgba(0.1, 0.75, 0.25, 1.0),
        Some(_) => rgba(1.0, 0.55, 0.0, 1.0),
    }
}

/// One planetary set's drawing (its parts in frames `planetary/<set>/<part>`).
struct SetDrawing {
    /// The sun, ring and carrier bodies.
    sun: usize,
    ring: usize,
    carrier: usize,
    /// The set's centre, m.
    x_m: f64,
    y_m: f64,
    /// Drawn radii, m: sun, ring.
    r_sun_m: f64,
    r_ring_m: f64,
    /// The planets: `(orbit radius m, radius m, angle factor k)`, each turning at
    /// `theta_C + k (theta_M - theta_C)` with `M` the member it meshes (sun when `k < 0`).
    planets: Vec<(f64, f64, f64, bool)>,
    /// Frames: sun, ring, carrier, the set's own (not turning), then each planet's.
    frames: Vec<String>,
    label: String,
    /// Whether its label stands in front of it (toward the bodies) rather than behind.
    label_in_front: bool,
}

/// The layout and the drawings of a network's 3D view.
pub(crate) struct View {
    /// Each body's centre on x, m (y = 0, z = 0).
    pub x_m: Vec<f64>,
    /// Each body's drawn radius, m.
    pub radii: Vec<f64>,
    /// The largest drawn radius, m.
    pub max_radius_m: f64,
    /// The bodies' pitch along x, m.
    pitch_m: f64,
    sets: Vec<SetDrawing>,
}

/// The frame of the `i`-th place on the bodies' row (`row/<i>`, not turning): body `i`'s frame
/// turns in it, and a pack's rings stand on it. Each place's parent is the one before (the
/// first's the world), so that a viewer's lines from a frame to its parent run along the row
/// rather than fanning out from the origin.
pub(crate) fn row_frame(i: usize) -> String {
    format!("row/{i}")
}

impl View {
    /// The view of `net`.
    pub fn new(net: &Network) -> View {
        let radii: Vec<f64> = net
            .bodies
            .iter()
            .map(|b| drawn_radius_m(b.inertia_kg_m2, b.is_fixed()))
            .collect();
        let max_radius_m = radii.iter().fold(MIN_DRAWN_RADIUS_M, |a, &r| a.max(r));
        let pitch = 2.0 * max_radius_m + BODY_GAP_M;
        let centred = |i: usize, n: usize| (i as f64 - 0.5 * (n as f64 - 1.0)) * pitch;
        let n = radii.len();
        let x_m = (0..n).map(|i| centred(i, n)).collect();
        let planetary: Vec<_> = net
            .couplings
            .iter()
            .filter_map(|c| match &c.kind {
                CouplingKind::Planetary(p) => Some((c, p)),
                _ => None,
            })
            .collect();
        let m = planetary.len();
        let set_pitch = (2.0 * SET_RING_M + BODY_GAP_M).max(n as f64 * pitch / m.max(1) as f64);
        let y_m = max_radius_m + BODY_GAP_M + SET_RING_M;
        let sets = planetary
            .into_iter()
            .enumerate()
            .map(|(i, (c, p))| {
                let (zs, zr) = (f64::from(p.sun_teeth), f64::from(p.ring_teeth));
                let r_ring_m = SET_RING_M;
                let r_sun_m = SET_RING_M * zs / zr;
                let planets: Vec<(f64, f64, f64, bool)> = if p.double_pinion {
                    // a sun planet and a ring planet per pair, each a quarter of the gap
                    let rp = 0.25 * (r_ring_m - r_sun_m);
                    let zp = 0.25 * (zr - zs);
                    (0..PLANETS)
                        .flat_map(|_| {
                            [
                                (r_sun_m + rp, rp, -zs / zp, false),
                                (r_ring_m - rp, rp, zr / zp, true),
                            ]
                        })
                        .collect()
                } else {
                    // z_P = (z_R - z_S) / 2; the planet turns at w_C + (w_R - w_C) z_R / z_P
                    let rp = 0.5 * (r_ring_m - r_sun_m);
                    let zp = 0.5 * (zr - zs);
                    (0..PLANETS)
                        .map(|_| (r_sun_m + rp, rp, zr / zp, true))
                        .collect()
                };
                let seg = crate::write::unique_segments(std::slice::from_ref(&c.name)).remove(0);
                let mut frames: Vec<String> = ["sun", "ring", "carrier", "set"]
                    .iter()
                    .map(|part| format!("planetary/{seg}/{part}"))
                    .collect();
                frames.extend((0..planets.len()).map(|j| format!("planetary/{seg}/planet{j}")));
                SetDrawing {
                    sun: c.a,
                    ring: c.b,
                    carrier: p.carrier,
                    x_m: (i as f64 - 0.5 * (m as f64 - 1.0)) * set_pitch,
                    y_m,
                    r_sun_m,
                    r_ring_m,
                    planets,
                    frames,
                    label_in_front: i % 2 == 1,
                    label: c.name.clone(),
                }
            })
            .collect();
        View {
            x_m,
            radii,
            max_radius_m,
            pitch_m: pitch,
            sets,
        }
    }

    /// The height of coupling `k`'s lane, m (below the bodies' plane, in front of them).
    fn lane(&self, k: usize) -> (f64, f64) {
        (
            -(self.max_radius_m + 0.5 * BODY_GAP_M),
            -(0.12 + LANE_PITCH_M * k as f64),
        )
    }

    /// Every coupling as a wire in the plane in front of the bodies: from each port's front
    /// rim down to the coupling's lane and along it, coloured by `modes[k]` (a clutch's mode),
    /// its name (and a clutch's mode) on its lane.
    pub fn coupling_scene(
        &self,
        net: &Network,
        modes: &[Option<ClutchMode>],
        log_time_ns: u64,
    ) -> SceneUpdate {
        let mut e = entity(log_time_ns, WORLD_FRAME, "couplings");
        for (k, c) in net.couplings.iter().enumerate() {
            let (y, z) = self.lane(k);
            let color = coupling_color(modes[k]);
            let p = |x: f64, z: f64| Point3 { x, y, z };
            let xs: Vec<f64> = c.ports().iter().map(|&b| self.x_m[b]).collect();
            let (lo, hi) = span(&xs);
            let mut points = vec![p(lo, z), p(hi, z)];
            for &x in &xs {
                points.extend([p(x, 0.0), p(x, z)]);
            }
            e.lines.push(LinePrimitive {
                r#type: line_primitive::Type::LineList as i32,
                pose: pose(0.0, 0.0, 0.0, 0.0),
                thickness: 4.0,
                scale_invariant: true,
                points,
                color,
                ..Default::default()
            });
            let label = match modes[k] {
                Some(mode) => format!("{} ({})", c.name, mode.label()),
                None => c.name.clone(),
            };
            e.texts.push(TextPrimitive {
                pose: pose(label_x(lo, hi, k), y, z + 0.03, 0.0),
                billboard: true,
                font_size: 12.0,
                scale_invariant: true,
                color,
                text: label,
            });
        }
        SceneUpdate {
            deletions: Vec::new(),
            entities: vec![e],
        }
    }

    /// The couplings' wires as points in the world frame (for Rerun), coloured as in
    /// [`Self::coupling_scene`]: a point every centimetre.
    pub fn coupling_points(&self, net: &Network, modes: &[Option<ClutchMode>]) -> PointCloud {
        let mut data = Vec::new();
        for (k, c) in net.couplings.iter().enumerate() {
            let (y, z) = self.lane(k);
            let col = coupling_color(modes[k]).unwrap_or_default();
            let c8 = [col.r, col.g, col.b, 1.0].map(|v| (255.0 * v).round() as u8);
            let xs: Vec<f64> = c.ports().iter().map(|&b| self.x_m[b]).collect();
            let (lo, hi) = span(&xs);
            let mut segment = |x0: f64, z0: f64, x1: f64, z1: f64| {
                let n = ((((x1 - x0).powi(2) + (z1 - z0).powi(2)).sqrt() / 0.01).ceil() as usize)
                    .max(1);
                for i in 0..=n {
                    let f = i as f64 / n as f64;
                    push_point(&mut data, x0 + f * (x1 - x0), y, z0 + f * (z1 - z0), c8);
                }
            };
            segment(lo, z, hi, z);
            for &x in &xs {
                segment(x, 0.0, x, z);
            }
        }
        cloud(WORLD_FRAME, data)
    }

    /// Every planetary set's parts as entities in their frames: the ring, the sun, the carrier
    /// (a dark plate under the planets) and the planets, each with a marker on its rim; the
    /// set's name and members over it.
    pub fn set_entities(&self) -> Vec<SceneEntity> {
        let mut out = Vec::new();
        let t = DRAWN_THICKNESS_M;
        for s in &self.sets {
            let disc = |frame: &str, r: f64, z: f64, grey: f64| {
                let mut e = entity(0, frame, frame);
                e.cylinders.push(CylinderPrimitive {
                    pose: pose(0.0, 0.0, z, 0.0),
                    size: Some(v3(2.0 * r, 2.0 * r, t)),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color: rgba(grey, grey, grey * 1.05, 1.0),
                });
                e.cubes.push(CubePrimitive {
                    pose: pose(0.8 * r, 0.0, z, 0.0),
                    size: Some(v3(0.3 * r, 0.15 * r, 1.6 * t)),
                    color: rgba(0.1, 0.1, 0.1, 1.0),
                });
                e
            };
            out.push(disc(&s.frames[1], s.r_ring_m, -t, 0.45));
            out.push(disc(&s.frames[0], s.r_sun_m, t, 0.8));
            let orbit = s.planets.iter().fold(0.0f64, |a, p| a.max(p.0));
            out.push(disc(&s.frames[2], orbit, 0.0, 0.25));
            for (j, p) in s.planets.iter().enumerate() {
                out.push(disc(&s.frames[4 + j], p.1, t, 0.65));
            }
            let mut label = entity(0, &s.frames[3], &s.frames[3]);
            let side = if s.label_in_front { -1.0 } else { 1.0 };
            label.texts.push(TextPrimitive {
                pose: pose(0.0, side * (s.r_ring_m + 0.05), 0.05, 0.0),
                billboard: true,
                font_size: 13.0,
                scale_invariant: true,
                color: rgba(1.0, 1.0, 1.0, 1.0),
                text: s.label.clone(),
            });
            out.push(label);
        }
        out
    }

    /// Every planetary set's parts as point clouds in their frames (for Rerun).
    pub fn set_clouds(&self) -> Vec<(String, PointCloud)> {
        let mut out = Vec::new();
        let t = DRAWN_THICKNESS_M;
        let marked = |r0: f64, r1: f64, grey: u8| {
            let mut data = Vec::new();
            annulus_points(&mut data, r0, r1, t, [grey, grey, grey, 255]);
            for i in 0..6 {
                let x = r1 * (0.7 + 0.05 * f64::from(i));
                push_point(&mut data, x, 0.0, 0.6 * t, [20, 20, 20, 255]);
            }
            data
        };
        for s in &self.sets {
            out.push((
                s.frames[0].clone(),
                cloud(&s.frames[0], marked(0.2 * s.r_sun_m, s.r_sun_m, 205)),
            ));
            out.push((
                s.frames[1].clone(),
                cloud(&s.frames[1], marked(0.85 * s.r_ring_m, s.r_ring_m, 115)),
            ));
            let orbit = s.planets.iter().fold(0.0f64, |a, p| a.max(p.0));
            out.push((
                s.frames[2].clone(),
                cloud(&s.frames[2], marked(0.2 * orbit, 0.3 * orbit, 64)),
            ));
            for (j, p) in s.planets.iter().enumerate() {
                let f = &s.frames[4 + j];
                out.push((f.clone(), cloud(f, marked(0.3 * p.1, p.1, 166))));
            }
        }
        out
    }

    /// The frames at `log_time_ns` for the bodies' angles `angle_rad` (rad): each body's
    /// (`frames[i]`, turning in its place on the row), the row's places ([`row_frame`]), and
    /// the planetary sets': each set's own frame (the first's parent the world, the others' the
    /// set before), its sun, ring and carrier turning in it with their bodies, and each planet
    /// in the carrier's frame at its place on its orbit, turning at
    /// `theta_C + k (theta_M - theta_C)` (its mesh with the ring, `k = z_R / z_P`, or with the
    /// sun, `k = -z_S / z_P`; angles measured from the start). `out` is updated in place when
    /// it holds this view's transforms already (from an earlier call), else they are appended.
    pub fn transforms(
        &self,
        frames: &[String],
        log_time_ns: u64,
        angle_rad: &[f64],
        out: &mut Vec<FrameTransform>,
    ) {
        let ts = timestamp(log_time_ns);
        // the frames' names are made only when `out` does not hold them yet: a recording's
        // samples update its transforms in place, without allocating
        let mut at = 0;
        let mut put = |names: &dyn Fn() -> (String, String), x: f64, y: f64, angle: f64| {
            match out.get_mut(at) {
                Some(t) => {
                    t.timestamp = Some(ts);
                    t.translation = Some(v3(x, y, 0.0));
                    t.rotation = Some(about_z(angle));
                }
                None => {
                    let (parent_frame_id, child_frame_id) = names();
                    out.push(FrameTransform {
                        timestamp: Some(ts),
                        parent_frame_id,
                        child_frame_id,
                        translation: Some(v3(x, y, 0.0)),
                        rotation: Some(about_z(angle)),
                    });
                }
            }
            at += 1;
        };
        for (i, (frame, &angle)) in frames.iter().zip(angle_rad).enumerate() {
            put(&|| (row_frame(i), frame.clone()), 0.0, 0.0, angle);
        }
        for i in 0..frames.len() {
            match i {
                0 => put(
                    &|| (WORLD_FRAME.into(), row_frame(0)),
                    self.x_m[0],
                    0.0,
                    0.0,
                ),
                _ => put(&|| (row_frame(i - 1), row_frame(i)), self.pitch_m, 0.0, 0.0),
            }
        }
        let mut before: Option<&SetDrawing> = None;
        for s in &self.sets {
            let (ts_, tr, tc) = (angle_rad[s.sun], angle_rad[s.ring], angle_rad[s.carrier]);
            let named = |parent: &str, child: &str| (parent.to_string(), child.to_string());
            match before {
                None => put(&|| named(WORLD_FRAME, &s.frames[3]), s.x_m, s.y_m, 0.0),
                Some(b) => put(
                    &|| named(&b.frames[3], &s.frames[3]),
                    s.x_m - b.x_m,
                    0.0,
                    0.0,
                ),
            }
            before = Some(s);
            put(&|| named(&s.frames[3], &s.frames[0]), 0.0, 0.0, ts_);
            put(&|| named(&s.frames[3], &s.frames[1]), 0.0, 0.0, tr);
            put(&|| named(&s.frames[3], &s.frames[2]), 0.0, 0.0, tc);
            let per_pair = if s.planets.len() > PLANETS { 2 } else { 1 };
            for (j, &(orbit, _, k, on_ring)) in s.planets.iter().enumerate() {
                let place = 2.0 * PI * (j / per_pair) as f64 / PLANETS as f64
                    + if per_pair == 2 && on_ring { 0.35 } else { 0.0 };
                let member = if on_ring { tr } else { ts_ };
                put(
                    &|| named(&s.frames[2], &s.frames[4 + j]),
                    orbit * place.cos(),
                    orbit * place.sin(),
                    k * (member - tc),
                );
            }
        }
    }

    /// The lowest lane's height, m (below it the status line stands).
    pub fn bottom_m(&self, couplings: usize) -> f64 {
        self.lane(couplings.saturating_sub(1)).1
    }

    /// The y of the lanes' plane, m.
    pub fn lanes_y_m(&self) -> f64 {
        self.lane(0).0
    }
}

/// The least and greatest of `xs` (m).
fn span(xs: &[f64]) -> (f64, f64) {
    xs.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

/// Where coupling `k`'s label sits on its lane `lo..hi` (m): at a quarter, the middle or three
/// quarters of the way, by turns, so that neighbouring lanes' labels stand apart.
fn label_x(lo: f64, hi: f64, k: usize) -> f64 {
    lo + (hi - lo) * [0.5, 0.25, 0.75][k % 3]
}

/// An automatic's state as a recording shows it: the gear engaged and, during a shift, its
/// phase as the run makes it, from the clutches' modes (a gear is engaged when all of its
/// elements are locked; a shift's fill lasts its scheduled time, its torque phase until the
/// off-going element lets go, its inertia phase until the on-coming element locks).
pub(crate) struct Status {
    tr: Transmission,
}

impl Status {
    /// The status of `tr`.
    pub fn new(tr: &Transmission) -> Status {
        Status { tr: tr.clone() }
    }

    /// The status line at `t_s` (s) with the modes `modes`: `gear 2`, or during a shift
    /// `gear 1 · shift 1 -> 2: torque phase`.
    pub fn label(&self, t_s: f64, modes: &[Option<ClutchMode>]) -> String {
        let name = |g: Option<usize>| g.map_or("-", |g| self.tr.gears[g].name.as_str());
        let engaged = self.tr.engaged(modes);
        let mut from = self.tr.initial_gear;
        for s in &self.tr.shifts {
            let to = Some(s.to);
            if t_s >= s.at_s && engaged != to {
                let next_starts = self
                    .tr
                    .shifts
                    .iter()
                    .find(|n| n.at_s > s.at_s)
                    .is_some_and(|n| t_s >= n.at_s);
                if !next_starts {
                    let locked =
                        |k: &usize| modes.get(*k).copied().flatten() == Some(ClutchMode::Locked);
                    let off_going_holds = from.is_some_and(|f| {
                        self.tr.gears[f]
                            .closed
                            .iter()
                            .filter(|k| !self.tr.gears[s.to].closed.contains(k))
                            .all(locked)
                    });
                    let phase = if t_s < s.at_s + s.fill_s {
                        "fill"
                    } else if off_going_holds {
                        "torque phase"
                    } else {
                        "inertia phase"
                    };
                    let shift = format!("shift {} -> {}: {phase}", name(from), name(to));
                    return match engaged {
                        Some(g) => format!("gear {} \u{b7} {shift}", name(Some(g))),
                        None => shift,
                    };
                }
            }
            if t_s >= s.at_s {
                from = to;
            }
        }
        format!("gear {}", name(engaged))
    }

    /// The status line as a text at `(0, y_m, z_m)` in the world (m).
    pub fn scene(label: &str, y_m: f64, z_m: f64, log_time_ns: u64) -> SceneUpdate {
        let mut e = entity(log_time_ns, WORLD_FRAME, "status");
        e.texts.push(TextPrimitive {
            pose: pose(0.0, y_m, z_m, 0.0),
            billboard: true,
            font_size: 18.0,
            scale_invariant: true,
            color: rgba(1.0, 0.9, 0.3, 1.0),
            text: label.into(),
        });
        SceneUpdate {
            deletions: Vec::new(),
            entities: vec![e],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bodies_are_centred_on_the_origin_and_evenly_spaced() {
        let (net, _) = clutchpack_model::cases::eight_speed();
        let v = View::new(&net);
        let n = v.x_m.len();
        assert!((v.x_m[0] + v.x_m[n - 1]).abs() < 1e-12);
        let pitch = v.x_m[1] - v.x_m[0];
        assert!(v
            .x_m
            .windows(2)
            .all(|w| (w[1] - w[0] - pitch).abs() < 1e-12));
        // every body's disc clears its neighbours'
        assert!(pitch >= 2.0 * v.max_radius_m + BODY_GAP_M - 1e-12);
        assert_eq!(v.sets.len(), 4, "the 8-speed's four planetary sets");
    }

    /// A planet rolls on the ring: with the carrier held and the ring turned by `d`, the
    /// planet's own angle turns by `d z_R / z_P` (a simple set).
    #[test]
    fn a_planet_rolls_on_its_ring() {
        let (net, _) = clutchpack_model::cases::eight_speed();
        let v = View::new(&net);
        let s = &v.sets[0];
        let mut angles = vec![0.0; net.bodies.len()];
        angles[s.ring] = 0.1;
        let mut out = Vec::new();
        let frames: Vec<String> = (0..angles.len()).map(|i| format!("b{i}")).collect();
        v.transforms(&frames, 0, &angles, &mut out);
        let planet0 = &s.frames[4];
        let t = out
            .iter()
            .find(|t| &t.child_frame_id == planet0)
            .expect("planet 0");
        let set = net.couplings.iter().find(|c| c.a == s.sun && c.b == s.ring);
        let Some(CouplingKind::Planetary(p)) = set.map(|c| &c.kind) else {
            panic!("a planetary set");
        };
        let zp = 0.5 * f64::from(p.ring_teeth - p.sun_teeth);
        assert_eq!(
            t.parent_frame_id, s.frames[2],
            "a planet turns in its carrier's frame"
        );
        let q = t.rotation.unwrap();
        let angle = 2.0 * q.z.atan2(q.w);
        assert!((angle - 0.1 * f64::from(p.ring_teeth) / zp).abs() < 1e-12);
    }

    #[test]
    fn the_status_follows_the_modes_through_a_shift() {
        let (net, mut tr) = clutchpack_model::cases::eight_speed();
        let gear = |name: &str| {
            tr.gears
                .iter()
                .position(|g| g.name == name)
                .expect("a gear")
        };
        let (first, second) = (gear("1"), gear("2"));
        tr.initial_gear = Some(first);
        tr.shifts = vec![clutchpack_model::network::Shift {
            at_s: 1.0,
            to: second,
            fill_s: 0.02,
            fill_level: 0.1,
            torque_phase_s: 0.1,
            torque_level: 1.0,
            inertia_phase_s: 0.2,
        }];
        let status = Status::new(&tr);
        let mut modes: Vec<Option<ClutchMode>> = net
            .couplings
            .iter()
            .map(|c| c.law().initial_mode())
            .collect();
        for &k in &tr.gears[first].closed {
            modes[k] = Some(ClutchMode::Locked);
        }
        let s = &tr.shifts[0];
        let g = |i: usize| tr.gears[i].name.clone();
        assert_eq!(status.label(0.0, &modes), format!("gear {}", g(first)));
        let during = status.label(s.at_s + 0.5 * s.fill_s, &modes);
        assert!(during.ends_with("fill"), "{during}");
        let torque = status.label(s.at_s + s.fill_s + 1e-3, &modes);
        assert!(torque.ends_with("torque phase"), "{torque}");
        // the off-going element lets go
        let off: Vec<usize> = tr.gears[first]
            .closed
            .iter()
            .copied()
            .filter(|k| !tr.gears[s.to].closed.contains(k))
            .collect();
        for &k in &off {
            modes[k] = Some(ClutchMode::Slipping(1));
        }
        let inertia = status.label(s.at_s + s.fill_s + 1e-3, &modes);
        assert!(inertia.starts_with("shift"), "{inertia}");
        assert!(inertia.ends_with("inertia phase"), "{inertia}");
        for &k in &tr.gears[s.to].closed {
            modes[k] = Some(ClutchMode::Locked);
        }
        for &k in &off {
            modes[k] = Some(ClutchMode::Free);
        }
        assert_eq!(
            status.label(s.at_s + 0.2, &modes),
            format!("gear {}", g(s.to))
        );
    }
}
