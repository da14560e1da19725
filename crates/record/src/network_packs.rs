//! The resolved packs of a network recording in 3D: each pack's discs and plates as thin rings
//! stacked along its disc carrier's axis, above that body's own disc in the view (the bodies
//! lie side by side along x, each turning about its z axis), every ring in a frame of its own
//! (`pack/<pack>/<body>`) that turns with the body's absolute angle, so that the discs'
//! rattle against their carrier and the faces' slip show as the rings' markers drift apart.

use crate::view3d::{about_z, entity, pose, rgba, timestamp, v3};
use crate::write::unique_segments;
use clutchpack_model::network::Network;
use foxglove::schemas::{
    CubePrimitive, CylinderPrimitive, FrameTransform, FrameTransforms, SceneEntity, TextPrimitive,
};

/// Thickness of a drawn disc or plate, m.
const RING_THICKNESS_M: f64 = 0.015;
/// Axial pitch of the drawn stack, m (a tall stack over its carrier, seen from the side).
const RING_PITCH_M: f64 = 0.03;

/// One pack's drawing.
struct PackDrawing {
    /// The pack's coupling index.
    coupling: usize,
    /// Each body's frame (discs, then plates), its height on the axis (m) and its drawn
    /// radius (m).
    rings: Vec<(String, f64, f64)>,
    /// The disc carrier's place on the row ([`crate::network_view::row_frame`]).
    place: String,
    /// How many of the rings are friction discs (the rest are plates).
    discs: usize,
    /// The pack's label: its name and its discs and plates.
    label: String,
}

/// Every pack of a network, drawn.
pub(crate) struct PacksDrawing {
    packs: Vec<PackDrawing>,
}

impl PacksDrawing {
    /// The packs of `net` drawn on their disc carriers' places on the row, with the bodies'
    /// drawn radii `radii` (m): a pack's rings a little wider than its carrier's disc (the
    /// plates the wider), stacked in stack order (plate, disc, ..., plate) upwards from just
    /// above it.
    pub fn new(net: &Network, radii: &[f64], body_thickness_m: f64) -> PacksDrawing {
        let packs = net
            .couplings
            .iter()
            .enumerate()
            .filter_map(|(k, c)| {
                let own = c.law().own_bodies()?;
                let names = own.names();
                let pack_segment = unique_segments(std::slice::from_ref(&c.name)).remove(0);
                let segments = unique_segments(&names);
                let nd = own.discs.len();
                let r = radii[c.a];
                let rings = segments
                    .iter()
                    .enumerate()
                    .map(|(i, seg)| {
                        // stack order when the pack has a stack; else discs, then plates
                        let level = own.level(i);
                        let z = 0.5 * body_thickness_m + RING_PITCH_M * (level as f64 + 1.0);
                        let radius = if i < nd { 1.2 * r } else { 1.35 * r };
                        (format!("pack/{pack_segment}/{seg}"), z, radius)
                    })
                    .collect();
                Some(PackDrawing {
                    label: format!("{} ({nd} discs, {} plates)", c.name, own.plates.len()),
                    coupling: k,
                    rings,
                    place: crate::network_view::row_frame(c.a),
                    discs: nd,
                })
            })
            .collect();
        PacksDrawing { packs }
    }

    /// Every ring as an entity in its frame: a friction disc brown, a plate steel grey, each
    /// with a dark marker on its rim; the pack's name above its top ring.
    pub fn entities(&self) -> Vec<SceneEntity> {
        let mut out = Vec::new();
        for p in &self.packs {
            let top = p
                .rings
                .iter()
                .map(|r| r.1)
                .fold(f64::NEG_INFINITY, f64::max);
            for (i, (frame, z, r)) in p.rings.iter().enumerate() {
                let mut e = entity(0, frame, frame);
                let color = if i < p.discs {
                    rgba(0.55, 0.33, 0.15, 1.0)
                } else {
                    rgba(0.72, 0.74, 0.78, 1.0)
                };
                e.cylinders.push(CylinderPrimitive {
                    pose: pose(0.0, 0.0, 0.0, 0.0),
                    size: Some(v3(2.0 * r, 2.0 * r, RING_THICKNESS_M)),
                    bottom_scale: 1.0,
                    top_scale: 1.0,
                    color,
                });
                e.cubes.push(CubePrimitive {
                    pose: pose(0.9 * r, 0.0, 0.0, 0.0),
                    size: Some(v3(0.2 * r, 0.08 * r, 1.4 * RING_THICKNESS_M)),
                    color: rgba(0.1, 0.1, 0.1, 1.0),
                });
                if *z == top {
                    e.texts.push(TextPrimitive {
                        pose: pose(0.0, 0.0, 2.0 * RING_PITCH_M, 0.0),
                        billboard: true,
                        font_size: 13.0,
                        scale_invariant: true,
                        color: rgba(1.0, 1.0, 1.0, 1.0),
                        text: p.label.clone(),
                    });
                }
                out.push(e);
            }
        }
        out
    }

    /// Every ring as points in its frame (for Rerun, which does not draw scene updates): a
    /// disc brown, a plate grey, each with a dark marker, as in [`Self::entities`].
    pub fn clouds(&self) -> Vec<(String, foxglove::schemas::PointCloud)> {
        let mut out = Vec::new();
        for p in &self.packs {
            for (i, (frame, _, r)) in p.rings.iter().enumerate() {
                let color = if i < p.discs {
                    [140, 84, 38, 255]
                } else {
                    [184, 189, 199, 255]
                };
                let mut data = Vec::new();
                crate::view3d::annulus_points(&mut data, 0.75 * r, *r, RING_THICKNESS_M, color);
                for k in 0..5 {
                    let x = r * (0.8 + 0.04 * f64::from(k));
                    crate::view3d::push_point(
                        &mut data,
                        x,
                        0.0,
                        RING_THICKNESS_M,
                        [20, 20, 20, 255],
                    );
                }
                out.push((frame.clone(), crate::view3d::cloud(frame, data)));
            }
        }
        out
    }

    /// The pack of coupling `coupling`'s rings at `log_time_ns` with its bodies' absolute
    /// angles `angle_rad` (rad, discs then plates), or `None` when it is not a pack drawn.
    pub fn transforms(
        &self,
        coupling: usize,
        log_time_ns: u64,
        angle_rad: &[f64],
    ) -> Option<FrameTransforms> {
        let p = self.packs.iter().find(|p| p.coupling == coupling)?;
        let ts = timestamp(log_time_ns);
        Some(FrameTransforms {
            transforms: p
                .rings
                .iter()
                .zip(angle_rad)
                .map(|((frame, z, _), angle)| FrameTransform {
                    timestamp: Some(ts),
                    parent_frame_id: p.place.clone(),
                    child_frame_id: frame.clone(),
                    translation: Some(v3(0.0, 0.0, *z)),
                    rotation: Some(about_z(*angle)),
                })
                .collect(),
        })
    }
}
