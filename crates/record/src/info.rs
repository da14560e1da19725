//! What a recording says about its run: [`RunInfo`] (program, engine, scene, solver settings,
//! geometry), stored as MCAP metadata records plus the scene file as an attachment, and read
//! back by [`RunInfo::from_metadata`].

use sha2::{Digest, Sha256};
use std::collections::BTreeMap;

/// Name of the metadata record with the run's identity (program, engine, scene, hash).
pub const META_RUN: &str = "clutchpack.run";
/// Name of the metadata record with the solver settings ([`RunInfo::solver`]).
pub const META_SOLVER: &str = "clutchpack.solver";
/// Name of the metadata record with the pack geometry ([`RunInfo::shaft`], [`RunInfo::discs`]).
pub const META_GEOMETRY: &str = "clutchpack.geometry";
/// Name of the metadata record with the other run parameters ([`RunInfo::params`]).
pub const META_PARAMS: &str = "clutchpack.params";
/// Name of the metadata record written by `finish` with the engine's run statistics.
pub const META_STATS: &str = "clutchpack.stats";
/// Media type of the scene attachment.
pub const SCENE_MEDIA_TYPE: &str = "application/toml";

/// Geometry of one friction disc, for the 3D scene and the metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscGeometry {
    /// Disc name from the scene (also its topic segment, see [`crate::topic_segment`]).
    pub name: String,
    /// Inner (spline) radius in m.
    pub inner_radius_m: f64,
    /// Outer radius in m.
    pub outer_radius_m: f64,
    /// Axial thickness in m.
    pub thickness_m: f64,
    /// Axial position of the disc's mid-plane along +z in m.
    pub z_m: f64,
    /// Number of spline teeth (0 draws a few markers instead).
    pub teeth: u32,
    /// The teeth are on the outer edge (a separator plate splined to a housing or drum)
    /// rather than the inner one (a friction disc on the shaft).
    pub teeth_outside: bool,
}

/// One friction interface of the stack: the faces between two neighbouring bodies (a
/// separator plate and a friction disc), named by the two bodies, the lower one (nearer the
/// piston) first.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrictionInterface {
    /// Name of the body below the interface (nearer the piston).
    pub lower: String,
    /// Name of the body above it.
    pub upper: String,
}

impl FrictionInterface {
    /// `<lower>__<upper>`: the interface's name in tables and summaries.
    pub fn name(&self) -> String {
        format!("{}__{}", self.lower, self.upper)
    }

    /// `<lower>__<upper>` of the bodies' topic segments ([`crate::topic_segment`]): the
    /// interface's topic segment, `/interfaces/<segment>`.
    pub fn segment(&self) -> String {
        format!(
            "{}__{}",
            crate::topic_segment(&self.lower),
            crate::topic_segment(&self.upper)
        )
    }
}

/// Geometry of the shaft (a cylinder along z).
#[derive(Debug, Clone, PartialEq)]
pub struct ShaftGeometry {
    /// Radius in m.
    pub radius_m: f64,
    /// Lower end along z in m.
    pub z_min_m: f64,
    /// Upper end along z in m.
    pub z_max_m: f64,
}

/// Everything a recording stores about its run, so that it describes itself and can be run
/// again: the scene text (attached verbatim) plus the `--set` overrides reproduce the run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunInfo {
    /// Version of the program that ran (the CLI's `CARGO_PKG_VERSION`).
    pub program_version: String,
    /// Engine name (`"reference"`, `"multibody"`).
    pub engine: String,
    /// Scene name.
    pub scene_name: String,
    /// File name of the scene (the attachment's name; `scene.toml` when empty).
    pub scene_file: String,
    /// The scene file's text, attached verbatim; its SHA-256 is stored as `scene_sha256`.
    pub scene_text: String,
    /// The `--set key=value` overrides applied on top of the scene, as typed.
    pub overrides: Vec<String>,
    /// Solver settings as key/values (`dt_s = 1e-6`, `tolerance = ...`), with units in keys.
    pub solver: BTreeMap<String, String>,
    /// Other run parameters as key/values (`duration_s`, `sample_rate_hz`, ...).
    pub params: BTreeMap<String, String>,
    /// The shaft; `None` derives a cylinder just inside the discs' teeth spanning the pack.
    pub shaft: Option<ShaftGeometry>,
    /// The discs, in scene order (the order of `Sample::discs`).
    pub discs: Vec<DiscGeometry>,
    /// The stack's friction interfaces in stack order (the order of the engine's
    /// interface samples); empty for a pack without a stack.
    pub interfaces: Vec<FrictionInterface>,
}

impl RunInfo {
    /// The disc names in scene order.
    pub fn disc_names(&self) -> Vec<String> {
        self.discs.iter().map(|d| d.name.clone()).collect()
    }

    /// The scene attachment's name.
    pub fn scene_file_name(&self) -> &str {
        if self.scene_file.is_empty() {
            "scene.toml"
        } else {
            &self.scene_file
        }
    }

    /// SHA-256 of the scene text, lowercase hex.
    pub fn scene_sha256(&self) -> String {
        sha256_hex(self.scene_text.as_bytes())
    }

    /// The shaft geometry, given or derived: radius just inside the smallest disc's teeth
    /// (`0.85 r_inner`), spanning the discs with a margin of one outer radius.
    pub fn shaft_geometry(&self) -> ShaftGeometry {
        if let Some(s) = &self.shaft {
            return s.clone();
        }
        let r_in = self
            .discs
            .iter()
            .map(|d| d.inner_radius_m)
            .fold(f64::INFINITY, f64::min);
        let r_in = if r_in.is_finite() && r_in > 0.0 {
            r_in
        } else {
            0.02
        };
        let r_out = self
            .discs
            .iter()
            .map(|d| d.outer_radius_m)
            .fold(0.0, f64::max)
            .max(r_in);
        let z_lo = self
            .discs
            .iter()
            .map(|d| d.z_m - d.thickness_m / 2.0)
            .fold(f64::INFINITY, f64::min);
        let z_hi = self
            .discs
            .iter()
            .map(|d| d.z_m + d.thickness_m / 2.0)
            .fold(f64::NEG_INFINITY, f64::max);
        let (z_lo, z_hi) = if z_lo.is_finite() && z_hi.is_finite() {
            (z_lo, z_hi)
        } else {
            (0.0, 0.0)
        };
        ShaftGeometry {
            radius_m: 0.85 * r_in,
            z_min_m: z_lo - r_out,
            z_max_m: z_hi + r_out,
        }
    }

    /// The metadata records (name, key/values) that store this info; `extra_run` adds keys
    /// to `clutchpack.run` (the recorder's options, `recorded_at_utc`).
    pub(crate) fn to_metadata(
        &self,
        extra_run: &[(String, String)],
    ) -> Vec<(String, BTreeMap<String, String>)> {
        let mut run = BTreeMap::new();
        run.insert("program".into(), "clutchpack".into());
        run.insert("program_version".into(), self.program_version.clone());
        run.insert("engine".into(), self.engine.clone());
        run.insert("scene_name".into(), self.scene_name.clone());
        run.insert("scene_file".into(), self.scene_file_name().to_string());
        run.insert("scene_sha256".into(), self.scene_sha256());
        run.insert("scene_bytes".into(), self.scene_text.len().to_string());
        run.insert("overrides".into(), json_list(&self.overrides));
        run.insert("disc_names".into(), json_list(&self.disc_names()));
        run.insert(
            "recorder".into(),
            format!("clutchpack_record {}", env!("CARGO_PKG_VERSION")),
        );
        for (k, v) in extra_run {
            run.insert(k.clone(), v.clone());
        }
        let mut geo = BTreeMap::new();
        let s = self.shaft_geometry();
        geo.insert("shaft.radius_m".into(), num(s.radius_m));
        geo.insert("shaft.z_min_m".into(), num(s.z_min_m));
        geo.insert("shaft.z_max_m".into(), num(s.z_max_m));
        geo.insert("discs".into(), self.discs.len().to_string());
        for (i, d) in self.discs.iter().enumerate() {
            geo.insert(format!("disc.{i}.name"), d.name.clone());
            geo.insert(format!("disc.{i}.inner_radius_m"), num(d.inner_radius_m));
            geo.insert(format!("disc.{i}.outer_radius_m"), num(d.outer_radius_m));
            geo.insert(format!("disc.{i}.thickness_m"), num(d.thickness_m));
            geo.insert(format!("disc.{i}.z_m"), num(d.z_m));
            geo.insert(format!("disc.{i}.teeth"), d.teeth.to_string());
            if d.teeth_outside {
                geo.insert(format!("disc.{i}.teeth_outside"), "true".into());
            }
        }
        if !self.interfaces.is_empty() {
            geo.insert("interfaces".into(), self.interfaces.len().to_string());
            for (m, f) in self.interfaces.iter().enumerate() {
                geo.insert(format!("interface.{m}.lower"), f.lower.clone());
                geo.insert(format!("interface.{m}.upper"), f.upper.clone());
            }
        }
        vec![
            (META_RUN.to_string(), run),
            (META_SOLVER.to_string(), self.solver.clone()),
            (META_GEOMETRY.to_string(), geo),
            (META_PARAMS.to_string(), self.params.clone()),
        ]
    }

    /// Rebuilds the run info from a recording's metadata records and its scene attachment
    /// (`scene_text`); `None` when the `clutchpack.run` record is missing (not our file).
    pub fn from_metadata(
        metadata: &[(String, BTreeMap<String, String>)],
        scene_text: Option<&str>,
    ) -> Option<RunInfo> {
        let get = |name: &str| metadata.iter().find(|(n, _)| n == name).map(|(_, m)| m);
        let run = get(META_RUN)?;
        let s = |k: &str| run.get(k).cloned().unwrap_or_default();
        let mut info = RunInfo {
            program_version: s("program_version"),
            engine: s("engine"),
            scene_name: s("scene_name"),
            scene_file: s("scene_file"),
            scene_text: scene_text.unwrap_or_default().to_string(),
            overrides: serde_json::from_str(&s("overrides")).unwrap_or_default(),
            solver: get(META_SOLVER).cloned().unwrap_or_default(),
            params: get(META_PARAMS).cloned().unwrap_or_default(),
            shaft: None,
            discs: Vec::new(),
            interfaces: Vec::new(),
        };
        if let Some(geo) = get(META_GEOMETRY) {
            let f = |k: &str| geo.get(k).and_then(|v| v.parse::<f64>().ok());
            if let (Some(radius_m), Some(z_min_m), Some(z_max_m)) =
                (f("shaft.radius_m"), f("shaft.z_min_m"), f("shaft.z_max_m"))
            {
                info.shaft = Some(ShaftGeometry {
                    radius_m,
                    z_min_m,
                    z_max_m,
                });
            }
            let n: usize = geo.get("discs").and_then(|v| v.parse().ok()).unwrap_or(0);
            for i in 0..n {
                let g = |k: &str| f(&format!("disc.{i}.{k}")).unwrap_or(0.0);
                info.discs.push(DiscGeometry {
                    name: geo
                        .get(&format!("disc.{i}.name"))
                        .cloned()
                        .unwrap_or_default(),
                    inner_radius_m: g("inner_radius_m"),
                    outer_radius_m: g("outer_radius_m"),
                    thickness_m: g("thickness_m"),
                    z_m: g("z_m"),
                    teeth: geo
                        .get(&format!("disc.{i}.teeth"))
                        .and_then(|v| v.parse().ok())
                        .unwrap_or(0),
                    teeth_outside: geo
                        .get(&format!("disc.{i}.teeth_outside"))
                        .is_some_and(|v| v == "true"),
                });
            }
            let n: usize = geo
                .get("interfaces")
                .and_then(|v| v.parse().ok())
                .unwrap_or(0);
            for m in 0..n {
                let s = |k: &str| {
                    geo.get(&format!("interface.{m}.{k}"))
                        .cloned()
                        .unwrap_or_default()
                };
                info.interfaces.push(FrictionInterface {
                    lower: s("lower"),
                    upper: s("upper"),
                });
            }
        }
        Some(info)
    }
}

/// Lowercase hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use std::fmt::Write as _;
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        let _ = write!(s, "{b:02x}");
    }
    s
}

/// A number as its shortest round-trip text (`parse::<f64>` gives it back exactly).
pub(crate) fn num(x: f64) -> String {
    format!("{x:?}")
}

fn json_list(items: &[String]) -> String {
    serde_json::to_string(items).unwrap_or_else(|_| "[]".into())
}

/// `YYYY-MM-DDTHH:MM:SS.mmmZ` (RFC 3339, UTC, milliseconds) for a duration since the Unix
/// epoch.
pub(crate) fn utc_text(since_epoch: std::time::Duration) -> String {
    humantime::format_rfc3339_millis(std::time::UNIX_EPOCH + since_epoch).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Known instants: the epoch, a leap day, and the hash of a known text.
    #[test]
    fn utc_text_and_hash() {
        use std::time::Duration;
        assert_eq!(utc_text(Duration::ZERO), "1970-01-01T00:00:00.000Z");
        assert_eq!(
            utc_text(Duration::from_millis(951_782_400_250)),
            "2000-02-29T00:00:00.250Z"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    /// Metadata written by `to_metadata` gives the same info back (numbers exactly).
    #[test]
    fn metadata_round_trip() {
        let info = RunInfo {
            program_version: "0.1.0".into(),
            engine: "reference".into(),
            scene_name: "paper".into(),
            scene_file: "paper.toml".into(),
            scene_text: "[a]\nb = 1\n".into(),
            overrides: vec!["a.b=2".into()],
            solver: [("dt_s".to_string(), "1e-6".to_string())].into(),
            params: [("duration_s".to_string(), "0.1".to_string())].into(),
            shaft: None,
            discs: vec![DiscGeometry {
                name: "d1".into(),
                inner_radius_m: 0.1 / 3.0,
                outer_radius_m: 0.06,
                thickness_m: 0.002,
                z_m: 0.01,
                teeth: 30,
                teeth_outside: false,
            }],
            interfaces: vec![FrictionInterface {
                lower: "plate 0".into(),
                upper: "d1".into(),
            }],
        };
        let meta = info.to_metadata(&[]);
        let back = RunInfo::from_metadata(&meta, Some(&info.scene_text)).unwrap();
        let mut want = info.clone();
        want.shaft = Some(info.shaft_geometry());
        assert_eq!(back, want);
        assert!(RunInfo::from_metadata(&[], None).is_none());
    }
}
