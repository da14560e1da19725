//! The 3D view: body poses (`/tf`, `foxglove.FrameTransforms`), the pack's geometry
//! (`/scene`, `foxglove.SceneUpdate`) and its load colours (`/scene/loads`, the same schema).
//!
//! Frames: `world` is fixed, z along the shaft axis. The shaft's frame `shaft` and each
//! disc's frame `disc/<name>` sit on the axis (a disc's at its mid-plane `z_m`) and turn about
//! +z by the body's angle. Entities are `frame_locked`, so they follow their frame.
//!
//! **Static bodies and load colours are on separate topics**, so that a viewer that restores
//! "the latest message of each topic" after a seek or on opening (Foxglove, Lichtblick) always
//! has the whole pack. `/scene` holds one message at t = 0 with the static bodies and nothing
//! else is ever sent on it: the shaft cylinder with a stripe, and each disc as a
//! triangle-mesh annulus with a rim marker and its spline teeth (steel grey): inside the bore
//! of a friction disc, outside the rim of a separator plate. The meshes come from parry3d-f64
//! (the geometry library under the multibody engine): the annulus as convex wedges
//! (`ConvexPolyhedron` hulls), each tooth as a `Cuboid`, triangulated by parry. Teeth are
//! drawn as they are, one per tooth, up to [`MAX_TEETH`] per disc. The shaft is drawn over
//! the discs' axial span plus a margin ([`drawn_shaft`]) unless the run info gives its
//! geometry.
//!
//! `/scene/loads` holds the load colours, and **every message carries every disc**, so that
//! its latest message alone restores all colours:
//! - `disc/<name>/load`: a translucent ring over the disc's spline teeth (a line loop as
//!   wide as the teeth are deep, about 400 bytes), coloured by the largest `|load_n|` since
//!   the previous update (grey = no load, yellow = half, red = the colour scale).
//! - `disc/<name>/teeth`, only for samples that carry per-tooth loads: the teeth redrawn as
//!   cubes, each coloured by its own largest `|load|` (about 130 bytes per tooth).
//!
//! A message is sent only when some colour changed (levels in steps of 1/16), so quiet
//! stretches cost nothing. Redrawing every tooth for a lumped load (one colour for all) was
//! measured at 10 kB per disc and update, 70 % of a recording's bytes and most of its
//! writing time; the ring says the same in a few hundred bytes.
//!
//! A thermal run adds `/scene/temperatures` (the same schema, the same rule: every message
//! carries every body): `disc/<name>/temperature`, a coat just outside each body's faces
//! and rims coloured by its temperature (blue .. yellow .. red over the recording's range),
//! and `temperature/legend`, a text above the pack's end naming the range in K and deg C and
//! the oil's temperature. Sent when a body's colour level changed (steps of 1/32 of the
//! range), about 5 kB per body.

use crate::info::{DiscGeometry, RunInfo, ShaftGeometry};
use foxglove::schemas::{
    line_primitive, packed_element_field, Color, CubePrimitive, CylinderPrimitive, FrameTransform,
    FrameTransforms, LinePrimitive, PackedElementField, Point3, PointCloud, Pose, Quaternion,
    SceneEntity, SceneUpdate, TextPrimitive, Timestamp, TriangleListPrimitive, Vector3,
};
use parry3d_f64::math::Vector;
use parry3d_f64::shape::{ConvexPolyhedron, Cuboid};
use std::f64::consts::PI;

/// The fixed frame.
pub const WORLD_FRAME: &str = "world";
/// The shaft's frame.
pub const SHAFT_FRAME: &str = "shaft";

/// The frame of the disc whose topic segment is `segment` (`disc/<segment>`).
pub fn disc_frame(segment: &str) -> String {
    format!("disc/{segment}")
}

/// Segments of the annulus meshes.
const SEGMENTS: u32 = 64;
/// Teeth drawn when a disc's tooth count is unknown (0).
const MARKERS: u32 = 8;
/// At most this many teeth are drawn per disc (a disc with more is drawn with this many,
/// evenly spaced). Real splines have up to about 150 teeth; the static teeth mesh costs about
/// 340 bytes per tooth, once per recording.
pub const MAX_TEETH: u32 = 400;
/// Segments of a load ring (a line loop).
const RING_SEGMENTS: u32 = 32;

pub(crate) fn timestamp(log_time_ns: u64) -> Timestamp {
    Timestamp::new(
        (log_time_ns / 1_000_000_000).min(u64::from(u32::MAX)) as u32,
        (log_time_ns % 1_000_000_000) as u32,
    )
}

pub(crate) fn about_z(angle_rad: f64) -> Quaternion {
    let h = 0.5 * angle_rad;
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: h.sin(),
        w: h.cos(),
    }
}

pub(crate) fn v3(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

pub(crate) fn pose(x: f64, y: f64, z: f64, angle_rad: f64) -> Option<Pose> {
    Some(Pose {
        position: Some(v3(x, y, z)),
        orientation: Some(about_z(angle_rad)),
    })
}

pub(crate) fn rgba(r: f64, g: f64, b: f64, a: f64) -> Option<Color> {
    Some(Color { r, g, b, a })
}

/// The colour of a load level `x = |load| / scale`, clamped to 0..=1: grey at 0, yellow at
/// 0.5, red at 1.
pub fn load_color(x: f64) -> Color {
    three_stops(x, [0.6, 0.6, 0.6], [1.0, 0.85, 0.0], [1.0, 0.0, 0.0])
}

/// The colour at level `x` (clamped to 0..=1; not finite: 1) of a scale running linearly
/// from `low` at 0 through `mid` at 0.5 to `high` at 1 (RGB in 0..=1, opaque).
fn three_stops(x: f64, low: [f64; 3], mid: [f64; 3], high: [f64; 3]) -> Color {
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let (a, b, s) = if x < 0.5 {
        (low, mid, x / 0.5)
    } else {
        (mid, high, (x - 0.5) / 0.5)
    };
    let mix = |i: usize| a[i] + s * (b[i] - a[i]);
    Color {
        r: mix(0),
        g: mix(1),
        b: mix(2),
        a: 1.0,
    }
}

/// Poses of the shaft and the discs at `log_time_ns` (ns): rotations about +z by the angles
/// (rad), discs at their `z_m`.
pub(crate) fn frame_transforms(
    log_time_ns: u64,
    shaft_angle_rad: f64,
    discs: &[(String, f64, f64)], // (frame, z_m, angle_rad)
) -> FrameTransforms {
    let ts = timestamp(log_time_ns);
    let mut transforms = Vec::with_capacity(discs.len() + 1);
    transforms.push(FrameTransform {
        timestamp: Some(ts),
        parent_frame_id: WORLD_FRAME.into(),
        child_frame_id: SHAFT_FRAME.into(),
        translation: Some(v3(0.0, 0.0, 0.0)),
        rotation: Some(about_z(shaft_angle_rad)),
    });
    for (frame, z_m, angle) in discs {
        transforms.push(FrameTransform {
            timestamp: Some(ts),
            parent_frame_id: WORLD_FRAME.into(),
            child_frame_id: frame.clone(),
            translation: Some(v3(0.0, 0.0, *z_m)),
            rotation: Some(about_z(*angle)),
        });
    }
    FrameTransforms { transforms }
}

/// Sets the time (ns), the angles (rad) and the discs' radial positions of transforms built by
/// [`frame_transforms`] in place (the shaft first, then the discs in order), without
/// allocating. A disc's centre offset `[x, y]` (m) is in the shaft's frame; the transform
/// places it in the world frame (rotated by the shaft's angle), keeping the disc's axial
/// position.
pub(crate) fn update_transforms(
    tf: &mut FrameTransforms,
    log_time_ns: u64,
    shaft_angle_rad: f64,
    discs: impl Iterator<Item = (f64, [f64; 2])>,
) {
    let ts = timestamp(log_time_ns);
    let (s, c) = shaft_angle_rad.sin_cos();
    let poses = std::iter::once((shaft_angle_rad, None)).chain(discs.map(|(a, o)| (a, Some(o))));
    for (t, (angle, offset)) in tf.transforms.iter_mut().zip(poses) {
        t.timestamp = Some(ts);
        t.rotation = Some(about_z(angle));
        if let (Some([x, y]), Some(tr)) = (offset, t.translation.as_mut()) {
            tr.x = c * x - s * y;
            tr.y = s * x + c * y;
        }
    }
}

/// The radius of a disc's spline in m: its rim for a plate with an external spline, its
/// bore for a friction disc.
fn spline_radius(d: &DiscGeometry) -> f64 {
    if d.teeth_outside {
        d.outer_radius_m
    } else {
        d.inner_radius_m
    }
}

/// The radial depth of a disc's drawn teeth in m.
fn tooth_depth(d: &DiscGeometry) -> f64 {
    (0.12 * spline_radius(d).abs()).min(0.5 * (d.outer_radius_m - d.inner_radius_m).abs())
}

/// The radial position in m of the centre of a disc's drawn teeth: inside its bore for a
/// friction disc, outside its rim for a plate with an external spline.
fn tooth_centre_radius(d: &DiscGeometry) -> f64 {
    let depth = tooth_depth(d).max(1e-6);
    if d.teeth_outside {
        d.outer_radius_m.max(d.inner_radius_m) + 0.5 * depth
    } else {
        d.inner_radius_m.min(d.outer_radius_m) - 0.5 * depth
    }
}

/// An empty triangle list in its frame, of one colour.
fn mesh(color: Option<Color>) -> TriangleListPrimitive {
    TriangleListPrimitive {
        pose: pose(0.0, 0.0, 0.0, 0.0),
        points: Vec::new(),
        color,
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

/// Appends parry's triangulation `(points, triangles)` of a shape, each point moved by
/// `place`, to `m`.
fn append(
    m: &mut TriangleListPrimitive,
    (points, triangles): (Vec<Vector>, Vec<[u32; 3]>),
    place: impl Fn(Vector) -> Vector,
) {
    let base = m.points.len() as u32;
    m.points.extend(points.into_iter().map(|p| {
        let q = place(p);
        Point3 {
            x: q.x,
            y: q.y,
            z: q.z,
        }
    }));
    m.indices
        .extend(triangles.iter().flat_map(|t| t.map(|i| i + base)));
}

/// A closed annulus between radii `r0 < r1`, thickness `h`, centred on its frame's origin:
/// [`SEGMENTS`] convex wedges (parry's `ConvexPolyhedron` hulls of their eight corners),
/// triangulated by parry with outward normals.
fn annulus(r0: f64, r1: f64, h: f64, color: Option<Color>) -> TriangleListPrimitive {
    let mut m = mesh(color);
    for i in 0..SEGMENTS {
        let (a0, a1) = (
            2.0 * PI * f64::from(i) / f64::from(SEGMENTS),
            2.0 * PI * f64::from(i + 1) / f64::from(SEGMENTS),
        );
        let mut corners = Vec::with_capacity(8);
        for (r, a) in [(r0, a0), (r1, a0), (r0, a1), (r1, a1)] {
            for z in [-0.5 * h, 0.5 * h] {
                corners.push(Vector::new(r * a.cos(), r * a.sin(), z));
            }
        }
        if let Some(wedge) = ConvexPolyhedron::from_convex_hull(&corners) {
            append(&mut m, wedge.to_trimesh(), |p| p);
        }
    }
    m
}

/// The drawn teeth of `d` as one mesh: parry cuboids (radial depth, half the pitch wide, the
/// disc's thickness) placed round the spline and triangulated by parry.
fn teeth_mesh(d: &DiscGeometry, color: Option<Color>) -> TriangleListPrimitive {
    let n = drawn_teeth(d);
    let mut m = mesh(color);
    let (size, r) = (tooth_size(d), tooth_centre_radius(d));
    let cuboid = Cuboid::new(Vector::new(0.5 * size.x, 0.5 * size.y, 0.5 * size.z));
    for i in 0..n {
        let a = 2.0 * PI * f64::from(i) / f64::from(n);
        let (s, c) = a.sin_cos();
        append(&mut m, cuboid.to_trimesh(), |p| {
            Vector::new(r * c + p.x * c - p.y * s, r * s + p.x * s + p.y * c, p.z)
        });
    }
    m
}

/// A drawn tooth's size in m: radial depth, width (half the pitch), thickness.
fn tooth_size(d: &DiscGeometry) -> Vector3 {
    let n = drawn_teeth(d);
    let width = 0.5 * 2.0 * PI * spline_radius(d).abs() / f64::from(n);
    v3(
        tooth_depth(d).max(1e-6),
        width.max(1e-6),
        d.thickness_m.abs().max(1e-6),
    )
}

pub(crate) fn entity(log_time_ns: u64, frame: &str, id: &str) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp(log_time_ns)),
        frame_id: frame.into(),
        id: id.into(),
        lifetime: None,
        frame_locked: true,
        ..Default::default()
    }
}

/// The static scene: shaft and disc bodies, plus the teeth at zero load.
pub(crate) fn static_scene(info: &RunInfo, frames: &[String]) -> SceneUpdate {
    let s = drawn_shaft(info);
    let len = (s.z_max_m - s.z_min_m).abs().max(1e-6);
    let zc = 0.5 * (s.z_max_m + s.z_min_m);
    let mut shaft = entity(0, SHAFT_FRAME, "shaft");
    shaft.cylinders.push(CylinderPrimitive {
        pose: pose(0.0, 0.0, zc, 0.0),
        size: Some(v3(2.0 * s.radius_m, 2.0 * s.radius_m, len)),
        bottom_scale: 1.0,
        top_scale: 1.0,
        color: rgba(0.55, 0.58, 0.62, 1.0),
    });
    // a stripe along the shaft so its rotation shows
    shaft.cubes.push(CubePrimitive {
        pose: pose(s.radius_m, 0.0, zc, 0.0),
        size: Some(v3(0.2 * s.radius_m, 0.2 * s.radius_m, len * 1.001)),
        color: rgba(0.15, 0.3, 0.8, 1.0),
    });
    let mut entities = vec![shaft];
    for (d, frame) in info.discs.iter().zip(frames) {
        let mut e = entity(0, frame, frame);
        let (r0, r1) = (
            d.inner_radius_m.min(d.outer_radius_m),
            d.outer_radius_m.max(d.inner_radius_m),
        );
        let h = d.thickness_m.abs().max(1e-6);
        e.triangles
            .push(annulus(r0, r1, h, rgba(0.62, 0.48, 0.32, 1.0)));
        let w = 0.08 * (r1 - r0).max(1e-6);
        e.cubes.push(CubePrimitive {
            pose: pose(r1 - 2.0 * w, 0.0, 0.0, 0.0),
            size: Some(v3(2.0 * w, w, h * 1.02)),
            color: rgba(0.1, 0.1, 0.1, 1.0),
        });
        e.triangles.push(teeth_mesh(d, Some(STEEL)));
        entities.push(e);
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// The shaft as drawn: the run info's geometry when given; otherwise the derived radius over
/// the discs' axial span plus a margin of a quarter of that span (at least two disc
/// thicknesses) on each side, so that a thin pack is not drawn on a long rod.
pub(crate) fn drawn_shaft(info: &RunInfo) -> ShaftGeometry {
    let s = info.shaft_geometry();
    if info.shaft.is_some() || info.discs.is_empty() {
        return s;
    }
    let (lo, hi, h) = info.discs.iter().fold(
        (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64),
        |(lo, hi, h), d| {
            let t = 0.5 * d.thickness_m.abs();
            (
                lo.min(d.z_m - t),
                hi.max(d.z_m + t),
                h.max(d.thickness_m.abs()),
            )
        },
    );
    if !(lo.is_finite() && hi.is_finite()) {
        return s;
    }
    let margin = (0.25 * (hi - lo)).max(2.0 * h).max(1e-6);
    ShaftGeometry {
        radius_m: s.radius_m,
        z_min_m: lo - margin,
        z_max_m: hi + margin,
    }
}

/// The colour of the teeth in the static scene.
const STEEL: Color = Color {
    r: 0.45,
    g: 0.47,
    b: 0.5,
    a: 1.0,
};

/// Teeth drawn for a disc: its tooth count, or a few markers when unknown, at most
/// [`MAX_TEETH`].
pub(crate) fn drawn_teeth(d: &DiscGeometry) -> u32 {
    if d.teeth == 0 {
        MARKERS
    } else {
        d.teeth.min(MAX_TEETH)
    }
}

/// The drawn teeth of `d` as cubes round its spline, tooth `k` coloured `color(k)` (the
/// per-tooth view, whose colours change; the static teeth are [`teeth_mesh`]).
fn tooth_cubes(d: &DiscGeometry, color: impl Fn(usize) -> Color) -> Vec<CubePrimitive> {
    let n = drawn_teeth(d);
    let (size, r) = (tooth_size(d), tooth_centre_radius(d));
    (0..n)
        .map(|i| {
            let a = 2.0 * PI * f64::from(i) / f64::from(n);
            CubePrimitive {
                pose: pose(r * a.cos(), r * a.sin(), 0.0, a),
                size: Some(size),
                color: Some(color(i as usize)),
            }
        })
        .collect()
}

/// The radial band of a disc's drawn teeth in m, `(root side, tip side)`: inside the bore
/// of a friction disc, outside the rim of a plate.
fn teeth_band(d: &DiscGeometry) -> (f64, f64) {
    let c = tooth_centre_radius(d);
    let half = 0.5 * tooth_depth(d).max(1e-6);
    (c - half, c + half)
}

/// The load rings of the discs `levels` names, `(disc index, level)`, coloured by the level
/// `max |load| / scale` (0..=1): a translucent line loop of [`RING_SEGMENTS`] points at the
/// middle of the disc's teeth, a little wider than the teeth are deep, so it lies over the
/// teeth and leaves the bore open. The recorder passes every disc, so that one message
/// restores all colours.
pub(crate) fn load_scene(
    log_time_ns: u64,
    info: &RunInfo,
    frames: &[String],
    levels: &[(usize, f64)],
) -> SceneUpdate {
    let mut entities = Vec::with_capacity(levels.len());
    for &(i, level) in levels {
        let (Some(d), Some(frame)) = (info.discs.get(i), frames.get(i)) else {
            continue;
        };
        let mut e = entity(log_time_ns, frame, &format!("{frame}/load"));
        let (a, b) = teeth_band(d);
        let r = 0.5 * (a + b);
        let mut color = load_color(level);
        color.a = 0.8;
        e.lines.push(LinePrimitive {
            r#type: line_primitive::Type::LineLoop as i32,
            pose: pose(0.0, 0.0, 0.0, 0.0),
            thickness: 1.3 * (b - a).abs().max(1e-6),
            scale_invariant: false,
            points: (0..RING_SEGMENTS)
                .map(|k| {
                    let t = 2.0 * PI * f64::from(k) / f64::from(RING_SEGMENTS);
                    Point3 {
                        x: r * t.cos(),
                        y: r * t.sin(),
                        z: 0.0,
                    }
                })
                .collect(),
            color: Some(color),
            colors: Vec::new(),
            indices: Vec::new(),
        });
        entities.push(e);
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// The colour of a temperature level `x = (T - T_lo) / (T_hi - T_lo)`, clamped to 0..=1:
/// blue at 0, yellow at 0.5, red at 1 (the legend of [`temperature_scene`] names the
/// range).
pub fn temperature_color(x: f64) -> Color {
    three_stops(x, [0.1, 0.35, 1.0], [1.0, 0.85, 0.0], [1.0, 0.0, 0.0])
}

/// A coat over an annulus `r0..r1` between `z = -z` and `z = +z`: its two flat faces and
/// its outer and inner rims, as triangles of [`RING_SEGMENTS`] quads each (no thickness), so
/// that a body shows its colour from the axis' end and from the side of a stacked pack.
fn coat(r0: f64, r1: f64, z: f64, color: Color) -> TriangleListPrimitive {
    let mut m = mesh(Some(color));
    let n = RING_SEGMENTS;
    let at = |r: f64, k: u32, z: f64| {
        let a = 2.0 * PI * f64::from(k % n) / f64::from(n);
        Point3 {
            x: r * a.cos(),
            y: r * a.sin(),
            z,
        }
    };
    // each quad (p0, p1, q0, q1) as two triangles wound so that the normal (p1 - p0) x
    // (q0 - p0) points out of the body (viewers cull back faces): the face at +z up, the one
    // at -z down, the outer rim away from the axis, the inner rim towards it
    let quads = [
        ((r0, z), (r1, z)),
        ((r1, -z), (r0, -z)),
        ((r1, z), (r1, -z)),
        ((r0, -z), (r0, z)),
    ];
    for ((ra, za), (rb, zb)) in quads {
        for k in 0..n {
            let (p0, p1) = (at(ra, k, za), at(rb, k, zb));
            let (q0, q1) = (at(ra, k + 1, za), at(rb, k + 1, zb));
            m.points.extend([p0, p1, q0, q0, p1, q1]);
        }
    }
    m
}

/// The temperature colours of every body and a legend: `disc/<name>/temperature`, the
/// faces and rims of the body's annulus ([`coat`], just outside the body) coloured by
/// [`temperature_color`] of `(T - lo) / (hi - lo)`, and `temperature/legend` in the world
/// frame above the pack's end naming the range and the oil's temperature. `bodies_k`
/// (K) in the order of `info.discs`; `range_k` `(lo, hi)` in K.
pub(crate) fn temperature_scene(
    log_time_ns: u64,
    info: &RunInfo,
    frames: &[String],
    bodies_k: &[f64],
    oil_k: f64,
    range_k: (f64, f64),
) -> SceneUpdate {
    let (lo, hi) = range_k;
    let span = (hi - lo).max(f64::MIN_POSITIVE);
    let mut entities = Vec::with_capacity(bodies_k.len() + 1);
    let mut top = 0.0_f64;
    for ((d, frame), &t_k) in info.discs.iter().zip(frames).zip(bodies_k) {
        let mut e = entity(log_time_ns, frame, &format!("{frame}/temperature"));
        let (r0, r1) = (
            d.inner_radius_m.min(d.outer_radius_m),
            d.outer_radius_m.max(d.inner_radius_m),
        );
        top = top.max(r1);
        let z = 0.5 * d.thickness_m.abs().max(1e-6) * 1.05;
        // just outside the body (the rims 1 % out), so the coat hides its surfaces
        let color = temperature_color((t_k - lo) / span);
        e.triangles.push(coat(0.99 * r0, 1.01 * r1, z, color));
        entities.push(e);
    }
    let s = drawn_shaft(info);
    let c = |t_k: f64| {
        let deg_c = clutchpack_model::thermal::deg_c_from_kelvin(t_k);
        format!("{t_k:.1} K ({deg_c:.1} degC)")
    };
    let mut legend = entity(log_time_ns, WORLD_FRAME, "temperature/legend");
    legend.frame_locked = false;
    legend.texts.push(TextPrimitive {
        pose: pose(0.0, 0.0, s.z_max_m + 0.5 * top.max(1e-3), 0.0),
        billboard: true,
        font_size: 14.0,
        scale_invariant: true,
        color: rgba(1.0, 1.0, 1.0, 1.0),
        text: format!(
            "faces by temperature: blue {} .. yellow .. red {}; oil {}",
            c(lo),
            c(hi),
            c(oil_k)
        ),
    });
    entities.push(legend);
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// The per-tooth view of the discs `levels` names, `(disc index, level of each drawn tooth)`:
/// the teeth redrawn as cubes, tooth `k` coloured by its level `max |load_k| / scale`
/// (0..=1). Other discs' teeth are left as they are.
pub(crate) fn teeth_scene(
    log_time_ns: u64,
    info: &RunInfo,
    frames: &[String],
    levels: &[(usize, &[f64])],
) -> SceneUpdate {
    let mut entities = Vec::with_capacity(levels.len());
    for &(i, tooth_levels) in levels {
        let (Some(d), Some(frame)) = (info.discs.get(i), frames.get(i)) else {
            continue;
        };
        let mut e = entity(log_time_ns, frame, &format!("{frame}/teeth"));
        e.cubes = tooth_cubes(d, |k| {
            load_color(tooth_levels.get(k).copied().unwrap_or(0.0))
        });
        entities.push(e);
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// Points round the circle of radius `r` per [`PointCloud`] face ring.
const CLOUD_AROUND: u32 = 120;

/// One point of a [`PointCloud`]: position in m (f32 x, y, z) and colour `c` (r, g, b, a),
/// stored in the order b, g, r, a: as one little-endian `u32` that is `0xAARRGGBB`, the packed
/// `rgba` field Foxglove colours points by when it finds one (otherwise it paints them with a
/// colour map of their first field), and as the four named bytes Rerun reads.
pub(crate) fn push_point(data: &mut Vec<u8>, x: f64, y: f64, z: f64, c: [u8; 4]) {
    for v in [x, y, z] {
        data.extend_from_slice(&(v as f32).to_le_bytes());
    }
    data.extend_from_slice(&[c[2], c[1], c[0], c[3]]);
}

/// A point cloud in `frame` from packed points (16 bytes each, see [`push_point`]).
pub(crate) fn cloud(frame: &str, data: Vec<u8>) -> PointCloud {
    use packed_element_field::NumericType;
    let field = |name: &str, offset: u32, t: NumericType| PackedElementField {
        name: name.into(),
        offset,
        r#type: t as i32,
    };
    PointCloud {
        timestamp: Some(timestamp(0)),
        frame_id: frame.into(),
        pose: pose(0.0, 0.0, 0.0, 0.0),
        point_stride: 16,
        fields: vec![
            field("x", 0, NumericType::Float32),
            field("y", 4, NumericType::Float32),
            field("z", 8, NumericType::Float32),
            field("rgba", 12, NumericType::Uint32),
            field("blue", 12, NumericType::Uint8),
            field("green", 13, NumericType::Uint8),
            field("red", 14, NumericType::Uint8),
            field("alpha", 15, NumericType::Uint8),
        ],
        data: data.into(),
    }
}

/// Points on the surface of the annulus `r0..r1`, thickness `h`, centred on its frame: both
/// faces on seven rings from `r0` to `r1` and both rims, [`CLOUD_AROUND`] points round.
pub(crate) fn annulus_points(data: &mut Vec<u8>, r0: f64, r1: f64, h: f64, c: [u8; 4]) {
    let rings = 6u32;
    for k in 0..CLOUD_AROUND {
        let a = 2.0 * PI * f64::from(k) / f64::from(CLOUD_AROUND);
        let (s, co) = a.sin_cos();
        for j in 0..=rings {
            let r = r0 + (r1 - r0) * f64::from(j) / f64::from(rings.max(1));
            for z in [-0.5 * h, 0.5 * h] {
                push_point(data, r * co, r * s, z, c);
            }
        }
        for r in [r0, r1] {
            push_point(data, r * co, r * s, 0.0, c);
        }
    }
}

/// The pack as point clouds, one per body: `(frame, cloud)` for the shaft (its surface and
/// the blue stripe) and each disc (both faces, rims, and the corners and centre of each drawn
/// tooth), in the bodies' own frames so that they turn with `/tf`. For viewers that draw
/// `foxglove.PointCloud` but not `foxglove.SceneUpdate` (Rerun decodes it as `Points3D`).
/// About 1 700 points (27 kB) per disc plus 9 per tooth, written once at t = 0.
pub(crate) fn pack_points(info: &RunInfo, frames: &[String]) -> Vec<(String, PointCloud)> {
    let grey = [140, 148, 158, 255];
    let mut out = Vec::with_capacity(info.discs.len() + 1);
    let s = drawn_shaft(info);
    let mut data = Vec::new();
    let len = (s.z_max_m - s.z_min_m).abs();
    let along = 24u32;
    for k in 0..CLOUD_AROUND {
        let a = 2.0 * PI * f64::from(k) / f64::from(CLOUD_AROUND);
        let stripe = !(CLOUD_AROUND / 24..=CLOUD_AROUND - CLOUD_AROUND / 24).contains(&k);
        let c = if stripe { [38, 77, 204, 255] } else { grey };
        for j in 0..=along {
            let z = s.z_min_m + len * f64::from(j) / f64::from(along);
            push_point(&mut data, s.radius_m * a.cos(), s.radius_m * a.sin(), z, c);
        }
    }
    out.push((SHAFT_FRAME.to_string(), cloud(SHAFT_FRAME, data)));
    for (d, frame) in info.discs.iter().zip(frames) {
        let mut data = Vec::new();
        let (r0, r1) = (
            d.inner_radius_m.min(d.outer_radius_m),
            d.outer_radius_m.max(d.inner_radius_m),
        );
        let h = d.thickness_m.abs().max(1e-6);
        annulus_points(&mut data, r0, r1, h, [158, 122, 82, 255]);
        let n = drawn_teeth(d);
        let (size, r) = (tooth_size(d), tooth_centre_radius(d));
        let steel = [115, 120, 128, 255];
        for i in 0..n {
            let a = 2.0 * PI * f64::from(i) / f64::from(n);
            let (sn, cs) = a.sin_cos();
            let mut put = |u: f64, v: f64, z: f64| {
                push_point(
                    &mut data,
                    r * cs + u * cs - v * sn,
                    r * sn + u * sn + v * cs,
                    z,
                    steel,
                )
            };
            put(0.0, 0.0, 0.0);
            for u in [-0.5 * size.x, 0.5 * size.x] {
                for v in [-0.5 * size.y, 0.5 * size.y] {
                    for z in [-0.5 * size.z, 0.5 * size.z] {
                        put(u, v, z);
                    }
                }
            }
        }
        out.push((frame.clone(), cloud(frame, data)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A disc's centre offset, given in the shaft's frame, lands in the world frame rotated by
    /// the shaft's angle: an offset of 1 mm along the shaft's x at a shaft angle of 90 deg is
    /// 1 mm along the world's y. The axial position is kept; the shaft stays on the axis.
    #[test]
    fn disc_offsets_follow_the_shaft_into_the_world_frame() {
        let mut tf = frame_transforms(0, 0.0, &[("disc/a".into(), 0.01, 0.0)]);
        update_transforms(&mut tf, 5, PI / 2.0, [(0.3, [1e-3, 0.0])].into_iter());
        let shaft = tf.transforms[0].translation.as_ref().unwrap();
        assert_eq!((shaft.x, shaft.y, shaft.z), (0.0, 0.0, 0.0));
        let d = tf.transforms[1].translation.as_ref().unwrap();
        assert!(d.x.abs() < 1e-18, "{d:?}");
        assert!((d.y - 1e-3).abs() < 1e-18, "{d:?}");
        assert_eq!(d.z, 0.01);
        let q = tf.transforms[1].rotation.as_ref().unwrap();
        assert!((2.0 * q.w * q.z - 0.3f64.sin()).abs() < 1e-12);
    }

    /// The quaternion of a rotation about +z by 90 degrees maps x onto y, and the colour map
    /// hits its three anchors.
    #[test]
    fn rotation_and_colours() {
        let q = about_z(PI / 2.0);
        // rotate (1, 0, 0): for a z-rotation, x' = 1 - 2 z^2, y' = 2 w z
        assert!((1.0 - 2.0 * q.z * q.z).abs() < 1e-12);
        assert!((2.0 * q.w * q.z - 1.0).abs() < 1e-12);
        assert_eq!(load_color(0.0).r, 0.6);
        assert_eq!((load_color(0.5).r, load_color(0.5).g), (1.0, 0.85));
        assert_eq!((load_color(2.0).g, load_color(f64::NAN).g), (0.0, 0.0));
    }

    fn disc(teeth: u32, z_m: f64) -> DiscGeometry {
        DiscGeometry {
            name: "d".into(),
            inner_radius_m: 0.05,
            outer_radius_m: 0.08,
            thickness_m: 0.002,
            z_m,
            teeth,
            teeth_outside: false,
        }
    }

    /// Teeth are drawn as many as the disc has, up to [`MAX_TEETH`]; an unknown count gets
    /// [`MARKERS`].
    #[test]
    fn teeth_are_drawn_as_they_are_up_to_the_cap() {
        assert_eq!(drawn_teeth(&disc(150, 0.0)), 150);
        assert_eq!(drawn_teeth(&disc(MAX_TEETH, 0.0)), MAX_TEETH);
        assert_eq!(drawn_teeth(&disc(MAX_TEETH + 1, 0.0)), MAX_TEETH);
        assert_eq!(drawn_teeth(&disc(0, 0.0)), MARKERS);
    }

    /// Without a given shaft, the shaft spans the discs plus a quarter of their span (at
    /// least two disc thicknesses) at each end: a 36 mm pack gets a 54 mm shaft, not one a
    /// disc diameter longer at each end.
    #[test]
    fn the_shaft_is_scaled_to_the_pack() {
        let info = RunInfo {
            discs: (0..10)
                .map(|k| disc(30, 0.001 + 0.00377 * f64::from(k)))
                .collect(),
            ..Default::default()
        };
        // discs span z = 0 .. 0.03593 + 0.001
        let (lo, hi) = (0.0, 0.00377 * 9.0 + 0.002);
        let s = drawn_shaft(&info);
        let m = 0.25 * (hi - lo);
        assert!((s.z_min_m - (lo - m)).abs() < 1e-12, "{s:?}");
        assert!((s.z_max_m - (hi + m)).abs() < 1e-12, "{s:?}");
        assert_eq!(s.radius_m, info.shaft_geometry().radius_m);
        // one thin disc: two thicknesses each side
        let one = RunInfo {
            discs: vec![disc(30, 0.0)],
            ..Default::default()
        };
        let s = drawn_shaft(&one);
        assert!((s.z_max_m - 0.005).abs() < 1e-12 && (s.z_min_m + 0.005).abs() < 1e-12);
        // a given shaft is drawn as given
        let given = ShaftGeometry {
            radius_m: 0.01,
            z_min_m: -1.0,
            z_max_m: 1.0,
        };
        let info = RunInfo {
            shaft: Some(given.clone()),
            ..info
        };
        assert_eq!(drawn_shaft(&info), given);
    }

    /// A thermal update colours every body by its temperature over the range (blue at its
    /// low end, red at its high end and beyond), with a coat just outside the body's faces
    /// and rims, and carries the legend naming the range and the oil.
    #[test]
    fn temperature_colours_coat_every_body_and_name_the_range() {
        let info = RunInfo {
            discs: vec![disc(30, 0.0), disc(30, 0.01)],
            ..Default::default()
        };
        let frames = ["disc/a".to_string(), "disc/b".to_string()];
        let u = temperature_scene(5, &info, &frames, &[313.15, 450.0], 320.0, (313.15, 413.15));
        assert_eq!(u.entities.len(), 3);
        for (e, want) in u
            .entities
            .iter()
            .zip([temperature_color(0.0), temperature_color(1.0)])
        {
            assert!(e.id.ends_with("/temperature"), "{}", e.id);
            let m = &e.triangles[0];
            assert_eq!(m.color, Some(want));
            // four quads' rings of RING_SEGMENTS quads, two triangles each
            assert_eq!(m.points.len(), 4 * RING_SEGMENTS as usize * 6);
            for p in &m.points {
                let r = p.x.hypot(p.y);
                assert!(
                    (0.99 * 0.05 - 1e-12..=1.01 * 0.08 + 1e-12).contains(&r),
                    "{r}"
                );
                assert!(p.z.abs() >= 0.001 - 1e-12, "outside the body: {}", p.z);
            }
        }
        // every triangle faces out of the body (viewers cull back faces): along +-z on a
        // face, away from the axis on the outer rim, towards it on the inner
        for t in u.entities[0].triangles[0].points.chunks(3) {
            let (a, b, c) = (&t[0], &t[1], &t[2]);
            let (e1, e2) = (
                [b.x - a.x, b.y - a.y, b.z - a.z],
                [c.x - a.x, c.y - a.y, c.z - a.z],
            );
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let m = [
                (a.x + b.x + c.x) / 3.0,
                (a.y + b.y + c.y) / 3.0,
                (a.z + b.z + c.z) / 3.0,
            ];
            let radial = n[0] * m[0] + n[1] * m[1];
            let out = if a.z == b.z && b.z == c.z {
                n[2] * m[2]
            } else if m[0].hypot(m[1]) > 0.065 {
                radial
            } else {
                -radial
            };
            assert!(out > 0.0, "a triangle faces into the body at {m:?}");
        }
        assert_eq!(
            (temperature_color(0.0).b, temperature_color(1.0).r),
            (1.0, 1.0)
        );
        let legend = &u.entities[2].texts[0].text;
        assert!(
            legend.contains("313.1 K (40.0 degC)") && legend.contains("413.1 K (140.0 degC)"),
            "{legend}"
        );
        assert!(legend.contains("oil 320.0 K"), "{legend}");
    }

    /// Every disc's load ring lies over its teeth: a closed loop at the middle of the teeth
    /// band, as wide as the band and a little more, coloured by the level.
    #[test]
    fn load_rings_lie_over_the_teeth() {
        let info = RunInfo {
            discs: vec![disc(30, 0.0), disc(30, 0.01)],
            ..Default::default()
        };
        let frames = ["disc/a".to_string(), "disc/b".to_string()];
        let u = load_scene(5, &info, &frames, &[(0, 0.0), (1, 1.0)]);
        assert_eq!(u.entities.len(), 2);
        let (a, b) = teeth_band(&info.discs[0]);
        assert!(b <= 0.05 + 1e-12 && a < b, "inside the bore: {a} {b}");
        for (e, level) in u.entities.iter().zip([0.0, 1.0]) {
            let l = &e.lines[0];
            assert_eq!(l.r#type, line_primitive::Type::LineLoop as i32);
            assert_eq!(l.points.len(), RING_SEGMENTS as usize);
            for p in &l.points {
                assert!((p.x.hypot(p.y) - 0.5 * (a + b)).abs() < 1e-12);
            }
            assert!((l.thickness - 1.3 * (b - a)).abs() < 1e-12);
            assert_eq!(l.color.unwrap().g, load_color(level).g);
        }
    }

    /// Signed volume `sum (p0 . (p1 x p2)) / 6` of a triangle list: the enclosed volume for
    /// a closed surface with outward normals (negative for inward ones).
    fn signed_volume(m: &TriangleListPrimitive) -> f64 {
        let p = |i: u32| {
            let q = &m.points[i as usize];
            [q.x, q.y, q.z]
        };
        m.indices
            .chunks(3)
            .map(|t| {
                let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
                let cross = [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ];
                (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
            })
            .sum()
    }

    /// The annulus mesh (parry's hulls of the wedges) is closed with outward normals: by the
    /// divergence theorem its signed volume is the volume of the polygonal ring,
    /// `n/2 sin(2 pi/n) (r1^2 - r0^2) h`, positive (a reversed winding would make it
    /// negative, a missing face or wedge a different value).
    #[test]
    fn annulus_mesh_is_closed_and_outward() {
        let (r0, r1, h) = (0.03, 0.06, 0.002);
        let m = annulus(r0, r1, h, None);
        assert_eq!(
            m.points.len(),
            8 * SEGMENTS as usize,
            "eight corners per wedge"
        );
        let v = signed_volume(&m);
        let n = f64::from(SEGMENTS);
        let want = n / 2.0 * (2.0 * PI / n).sin() * (r1 * r1 - r0 * r0) * h;
        assert!((v - want).abs() < 1e-12 * want.max(1.0), "{v} vs {want}");
        assert!(v > 0.0);
    }

    /// The teeth mesh holds one closed, outward parry cuboid per drawn tooth (total volume
    /// `n` times a tooth's), inside the bore of a friction disc and outside the rim of a plate
    /// with an external spline.
    #[test]
    fn teeth_sit_on_the_spline_side() {
        let disc = DiscGeometry {
            name: "d".into(),
            inner_radius_m: 0.231,
            outer_radius_m: 0.290,
            thickness_m: 0.003,
            z_m: 0.0,
            teeth: 40,
            teeth_outside: false,
        };
        let plate = DiscGeometry {
            inner_radius_m: 0.235,
            outer_radius_m: 0.305,
            teeth_outside: true,
            ..disc.clone()
        };
        for d in [&disc, &plate] {
            let m = teeth_mesh(d, None);
            let s = tooth_size(d);
            let want = 40.0 * s.x * s.y * s.z;
            let v = signed_volume(&m);
            assert!((v - want).abs() < 1e-9 * want, "{v} vs {want}");
            let radii: Vec<f64> = m.points.iter().map(|p| p.x.hypot(p.y)).collect();
            let (lo, hi) = radii
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), &r| (a.min(r), b.max(r)));
            if d.teeth_outside {
                assert!(lo >= d.outer_radius_m - 1e-12, "plate teeth from {lo}");
                assert!(
                    hi > d.outer_radius_m + 0.9 * s.x,
                    "they stand outside the rim"
                );
            } else {
                // the root corners of a tooth reach just past the bore: hypot(Ri, w/2)
                let root = d.inner_radius_m.hypot(0.5 * s.y);
                assert!(hi <= root + 1e-12, "disc teeth up to {hi}");
                assert!(lo < d.inner_radius_m - 0.9 * s.x, "they stand in the bore");
            }
        }
    }
}
