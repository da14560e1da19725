//! Topic names. A disc's topics use its *segment*: the scene name with every character other
//! than `A-Z a-z 0-9 _ -` replaced by `_` (see [`crate::topic_segment`]).

/// Body poses, `foxglove.FrameTransforms`.
pub const TF: &str = "/tf";
/// Pack geometry and load colours, `foxglove.SceneUpdate`.
pub const SCENE: &str = "/scene";
/// Shaft angle and speed, `clutchpack.ShaftState`.
pub const SHAFT: &str = "/shaft";
/// Impact events, `clutchpack.Impact`.
pub const IMPACTS: &str = "/impacts";
/// Per-disc summary at the end of the run, `clutchpack.RunSummary`.
pub const SUMMARY: &str = "/summary";
/// Prefix of the per-disc topics.
pub const DISCS_PREFIX: &str = "/discs/";

/// `/discs/<segment>/spline`, `clutchpack.SplineState`.
pub fn spline(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/spline")
}

/// `/discs/<segment>/teeth`, `clutchpack.ToothLoads`.
pub fn teeth(segment: &str) -> String {
    format!("{DISCS_PREFIX}{segment}/teeth")
}

/// Prefix of the friction interfaces' topics.
pub const INTERFACES_PREFIX: &str = "/interfaces/";

/// `/interfaces/<segment>`, `clutchpack.InterfaceState`; the segment of an interface is
/// `<lower>__<upper>` of its two bodies' segments (see [`crate::FrictionInterface`]).
pub fn interface(segment: &str) -> String {
    format!("{INTERFACES_PREFIX}{segment}")
}
